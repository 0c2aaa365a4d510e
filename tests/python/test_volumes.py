"""Media through the Python scene (docs/volumes.md): the schema's checks, the scene file's round
trip, an absorbing slab rendered through the bindings against Beer-Lambert, and the integrators
without medium vertices handing media scenes to pt with a warning (auto: pt for emissive media,
with the reason, and for any medium unless `auto_media` is set)."""
import math

import numpy as np
import pytest

import lantern
from lantern.scenes import aabb_mesh

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable")

SIGMA_A = [0.2, 0.5, 1.0]


def slab_scene(volume=None, world_volume=None):
    s = lantern.Scene()
    s.film.update(width=8, height=8)
    s.camera = {"type": "orthographic", "screen": [-0.1, 0.1, -0.1, 0.1], "clip": [0.0, 100.0]}
    s.world = {"color": [1.0, 1.0, 1.0]}
    if world_volume is not None:
        s.world["volume"] = world_volume
    m = s.add_material("slab")
    s.materials[m]["volume"] = volume or {"sigma_a": SIGMA_A}
    s.materials[m]["volume_only"] = True
    p, idx = aabb_mesh((-1, -1, -3), (1, 1, -2))
    s.add_mesh(p, idx, material=m)
    return s


def test_box_faces_outwards():
    p, idx = aabb_mesh((-1, -1, -3), (1, 1, -2))
    c = p.mean(axis=0)
    for t in idx:
        a, b, cc = p[t]
        assert np.dot(np.cross(b - a, cc - a), (a + b + cc) / 3 - c) > 0


def test_schema_checks_media():
    s = slab_scene()
    s.validate()
    assert s.materials[0]["volume"] == {"sigma_a": SIGMA_A, "sigma_s": [0.0] * 3,
                                        "emission": [0.0] * 3, "g": 0.0}
    for bad in ({"sigma_a": [-1, 0, 0]}, {"sigma_s": [math.nan] * 3}, {"g": 1.0},
                {"density": 1.0}):
        s = slab_scene(volume=bad)
        with pytest.raises(ValueError):
            s.validate()
    s = slab_scene()
    s.materials[0]["volume_only"] = "yes"
    with pytest.raises(ValueError):
        s.validate()


def test_scene_file_keeps_media(tmp_path):
    s = slab_scene(world_volume={"sigma_s": [0.1, 0.1, 0.1], "g": 0.3})
    path = tmp_path / "media.lantern"
    s.save(str(path))
    t = lantern.load_scene(str(path))
    assert t.materials[0]["volume"]["sigma_a"] == SIGMA_A
    assert t.materials[0]["volume_only"] is True
    assert t.world["volume"]["g"] == pytest.approx(0.3)


def test_absorbing_slab_is_beer_lambert():
    img = lantern.Session(slab_scene(), integrator="pt", seed=1, spp_per_iteration=4,
                          max_depth=1, threads=1)
    img.step()
    got = np.asarray(img.image())[..., :3].reshape(-1, 3).mean(axis=0)
    want = np.exp(-np.array(SIGMA_A))
    np.testing.assert_allclose(got, want, rtol=1e-4)
    # negative control: the slab is there (without it every pixel is the world's 1)
    assert np.all(np.abs(got - 1.0) > 0.1)


@pytest.mark.parametrize("integ", ["lt", "bdpt", "lvc", "cis"])
def test_emissive_media_hand_over_from_lt_only(integ):
    """Emissive media: lt starts light paths on lights only and has no camera gather, so it
    hands the scene to pt and says so; bdpt, lvc and cis gather the emission on their camera
    paths and render it themselves (their images against pt's: test_volume_hetero_bdpt.py)."""
    scene = slab_scene(volume={"sigma_s": [1.0, 1.0, 1.0], "sigma_a": [0.1, 0.2, 0.3],
                               "emission": [0.2, 0.2, 0.2]})
    ref = lantern.Session(scene, integrator="pt", seed=3, spp_per_iteration=2, max_depth=8,
                          threads=1)
    ref.step()
    s = lantern.Session(scene, integrator=integ, seed=3, spp_per_iteration=2, max_depth=8,
                        threads=1)
    s.step()
    handed = any("rendering with pt" in w and "material 'slab'" in w for w in s.warnings)
    assert handed == (integ == "lt"), s.warnings
    # pt's bits exactly when handed over (control: a render of its own otherwise)
    assert np.array_equal(np.asarray(s.image()), np.asarray(ref.image())) == (integ == "lt")


def test_auto_renders_emissive_media_with_pt():
    """auto chooses between pt and cis with homogeneous media (test_auto_media.py); emissive
    ones are pt's alone, and it says so."""
    emissive = slab_scene(volume={"sigma_s": [1.0, 1.0, 1.0], "sigma_a": [0.1, 0.2, 0.3],
                                  "emission": [0.2, 0.2, 0.2]})
    s = lantern.Session(emissive, integrator="auto", seed=3, spp_per_iteration=2,
                        max_depth=1, threads=1)
    s.step()
    assert any("only pt renders" in w and "emissive volume" in w for w in s.warnings)
    assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
    # control: by default the absorbing slab is left to the pilot's trials (cis's among
    # them); with auto_media off auto is pt in any medium (docs/auto_integrator.md, "Media")
    s = lantern.Session(slab_scene(), integrator="auto", seed=3, spp_per_iteration=2,
                        max_depth=1, threads=1)
    s.step()
    assert not any("path tracing" in w for w in s.warnings), s.warnings
    assert s.stats["auto_cis_iterations"] >= 2
    s = lantern.Session(slab_scene(), integrator="auto", seed=3, spp_per_iteration=2,
                        max_depth=1, threads=1, auto_media=False)
    s.step()
    assert any("auto_media" in w for w in s.warnings), s.warnings
    assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
