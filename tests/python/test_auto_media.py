"""Integrator "auto" in scenes with homogeneous media (native/src/integrator/allocation.h,
docs/auto_integrator.md "Media"; docs/volumes.md): by default auto is pt in any medium (its
choice there fell below pt's efficiency on the fog room, bench/results/2026-12-04-automedia);
with the setting `auto_media` its pt and cis trials choose between the two there too (no moment
channels, no connection map: the medium stages finish a contribution's weight at its shadow ray).

- Default: auto renders the fog room as pt does, bit for bit, with a warning naming the
  setting; control: with auto_media on, the same seed runs cis trials and its image differs.
- Unbiased (auto_media on): auto against pt on the fog room with a spot
  (test_volume_bidir.fog_spot, where it renders cis) by lantern.metrics.assert_agreement with
  its negative controls.
- Its choice with auto_media on (deterministic per seed) against the efficiencies measured in
  bench/ (bench/results/2026-12-04-automedia): cis on the lamp in a shade in fog
  (test_volume_bdpt.lamp_shade; cis many times pt's efficiency), pt on an open fog scene lit by a sun (open_fog below, where
  pt is the more efficient). Negative control: the same lamp scene with the sphere light's
  Soft Falloff on (cis starts no light paths on such a light) goes to pt.
- Emissive media stay pt's alone (a warning says so); a media scene's explicit
  connection_allocation is turned off with a warning."""
import math

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

from test_volume_bidir import _volume_box, fog_spot, renders  # noqa: F401
from test_volume_bdpt import lamp_shade

DEPTH = 8


@pytest.fixture(scope="module", autouse=True)
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")


def open_fog(size=32):
    """An open stage in thin world fog lit by a low sun: a large floor with two boxes, nothing
    around them; every fog point sees the sun (pt's next-event estimate through the fog is
    nearly noise-free), light paths from the sun's disk mostly leave the frame."""
    scene = lantern.Scene()
    scene.film.update(width=int(size), height=int(size))
    scene.look_at((0.0, -6.0, 2.0), (0.0, 0.0, 0.5), fov=60.0)
    ground = scene.add_material("ground", base_color=(0.5, 0.5, 0.45))
    s = 20.0
    scene.add_mesh(*scenes._quad((-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)),
                   material=ground, name="ground")
    for name, center, size_, colour in (("a", (-0.8, 0.5, 0.0), (1.0, 1.0, 1.2), (0.7, 0.3, 0.2)),
                                        ("b", (1.0, -0.3, 0.0), (0.8, 0.8, 0.6), (0.2, 0.5, 0.7))):
        m = scene.add_material(name, base_color=colour)
        scene.add_mesh(*scenes._box(center, size_, 20), material=m, name=name)
    d = np.array([-0.5, 0.6, -0.6])
    scene.add_light("sun", direction=(d / np.linalg.norm(d)).tolist(), strength=[3.0] * 3,
                    angle=math.radians(1.0))
    # a fog box around the stage (world fog would take the sun's light at infinity)
    _volume_box(scene, "fog", {"sigma_s": [0.08, 0.08, 0.08], "sigma_a": [0.01, 0.01, 0.01],
                               "g": 0.3}, (-8.0, -8.0, 0.0), (8.0, 8.0, 4.0))
    return scene


def _choices(scene, seeds, steps=1, spp=1):
    out = []
    for seed in seeds:
        s = lantern.Session(scene, integrator="auto", seed=seed, backend="cpu", max_depth=DEPTH,
                            spp_per_iteration=spp, threads=1, auto_media=True)
        for _ in range(steps):
            s.step()
        assert not any("path tracing" in w for w in s.warnings), s.warnings
        out.append((s.stats["auto_choice"], round(s.stats["auto_cis_over_pt"], 2)))
    return out


def _auto_media_renders(scene, spp, seed0, k_seeds, steps=4):
    """renders() of test_volume_bidir for integrator auto with auto_media on."""
    out = []
    for k in range(k_seeds):
        s = lantern.Session(scene, integrator="auto", seed=seed0 + k, backend="cpu",
                            max_depth=DEPTH, spp_per_iteration=spp // steps, threads=1,
                            auto_media=True)
        for _ in range(steps):
            s.step()
        assert not any("path tracing" in w for w in s.warnings), s.warnings
        out.append(np.asarray(s.image())[..., :3])
    return out


def test_auto_is_pt_in_media_by_default():
    scene = fog_spot()
    images = {}
    for name, settings in (("auto", {"integrator": "auto"}), ("pt", {"integrator": "pt"}),
                           ("auto_media", {"integrator": "auto", "auto_media": True})):
        s = lantern.Session(scene, seed=7, backend="cpu", max_depth=DEPTH, spp_per_iteration=1,
                            threads=1, **settings)
        for _ in range(4):
            s.step()
        images[name] = np.asarray(s.image())
        if name == "auto":
            assert any("auto_media" in w for w in s.warnings), s.warnings
            assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
        if name == "auto_media":  # control: its pilot's cis trials ran
            assert s.stats["auto_cis_iterations"] >= 2, s.stats
    assert np.array_equal(images["auto"], images["pt"])
    assert not np.array_equal(images["auto_media"], images["pt"])


@pytest.mark.long  # 21 s; auto_media is off by default (test_auto_is_pt_in_media_by_default)
def test_auto_agrees_with_pt_in_fog():
    scene = fog_spot()
    auto = _auto_media_renders(scene, 64, 5000, k_seeds=12)
    pt = renders(scene, "pt", 256, 1000, k_seeds=12, max_depth=DEPTH, steps=4)
    metrics.assert_agreement("fog_spot auto vs pt", auto, pt, block=8, image_bias=0.04,
                             block_bias=0.1)


def test_auto_chooses_cis_in_the_lamp_shade_and_pt_in_open_fog():
    """The choice after the checkpoints of the 8th and 16th iteration of one sample (the
    add-on's default). In media the cis trials carry no moment channels, and pt's two trials
    alone often miss the light through the shade's hole (its estimates of cis over pt read
    1.3-3.9 where pt's own renders give cis 11x by the same measure: bench/results/
    2026-12-04-automedia, choice.txt); pt's own iterations see more of it by the checkpoints.
    Measured on these seeds: the lamp 7 of 8 cis, the open fog 8 of 8 pt, the control 6 of 8
    pt."""
    seeds = range(300, 308)
    lamp = _choices(lamp_shade(), seeds, steps=17)
    assert [c for c, _ in lamp].count("cis") >= 7, lamp
    fog = _choices(open_fog(), seeds, steps=17)
    assert [c for c, _ in fog].count("pt") == len(seeds), fog
    # negative control: Soft Falloff on, cis starts no light paths from the lamp (it renders
    # camera paths alone, at its higher cost): pt on most seeds
    soft = lamp_shade()
    for light in soft.lights:
        light["soft_falloff"] = True
    control = _choices(soft, seeds, steps=17)
    assert [c for c, _ in control].count("pt") >= 5, control


def test_emissive_medium_stays_pt_and_connection_allocation_is_off():
    scene = fog_spot()
    scene.world["volume"]["emission"] = [0.1, 0.1, 0.1]
    s = lantern.Session(scene, integrator="auto", seed=1, backend="cpu", max_depth=DEPTH,
                        threads=1, auto_media=True)
    s.step()
    assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
    assert any("emissive" in w and "auto" in w for w in s.warnings), s.warnings
    s = lantern.Session(fog_spot(), integrator="cis", seed=1, backend="cpu", max_depth=DEPTH,
                        threads=1, connection_allocation=True)
    s.step()
    assert any("connection_allocation is off" in w for w in s.warnings), s.warnings
    assert "mean_connections" not in s.stats  # (the allocation reports it when on)
