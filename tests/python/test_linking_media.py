"""Light linking with medium vertices in the bidirectional integrators
(integrator/bidir_linking_medium.h) against pt (pt_volume.h: a medium vertex receives as the
surface its path last left, the camera's set 0 before any), statistically (compare_renders:
block means, Student t).

test_linking_bidir.py's room (floor, wall, white ball A, red ball B, the area lamp and the
emissive quad above them) in world fog, the lamp lighting the floor, the wall and ball A (sets
0 and 1), the quad ball B alone (set 2): fog the camera sees before any surface (set 0) takes
the lamp's light and not the quad's; fog seen past ball B the quad's alone. bdpt, lvc and cis
render it themselves (no hand-over) against pt; the control, the scene without the linking,
must fail (lt: test_lt_linking.py). lt's shadow linking beside a heterogeneous volume hands
over to pt, with pt's bits (in homogeneous fog lt renders it: test_lt_linking.py; bdpt, lvc
and cis render shadow linking in media themselves: test_linking_shadow_media.py)."""
import numpy as np
import pytest

import lantern
from lantern import metrics
from lantern.scenes import aabb_mesh

from test_linking_bidir import room

K, SPP = 16, 64  # seeds x samples per pixel (tests/README.md: Welch dof >= 15)
FOG = {"sigma_s": [0.25, 0.25, 0.25], "sigma_a": [0.02, 0.03, 0.05], "g": 0.3}


def foggy(linked=True, shadow=False):
    s = room("red", slab=shadow)
    s.world = {"color": [0.0] * 3, "volume": dict(FOG)}
    if linked:
        s.meshes[2]["light_set"] = 1
        s.meshes[3]["light_set"] = 2
        s.lights[0]["receivers"] = [0, 1]  # the lamp: floor, wall, ball A, fog before them
        s.meshes[4]["receivers"] = [2]     # the quad: ball B (and fog seen past it) alone
    if shadow:
        s.meshes[5]["shadow_set"] = 1
        s.lights[0]["blockers"] = [0]      # the slab casts the lamp no shadow
    return s


def render(scene, integrator, seed, spp=SPP):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=4,
                        spp_per_iteration=spp, threads=1)
    s.step()
    return np.asarray(s.image(), np.float64)[..., :3], s.warnings


def renders(integrator, seed0, linked=True):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(foggy(linked), integrator, seed0 + k)
        out.append(img)
    return out, warnings


@pytest.fixture(scope="module")
def pt_ref(core):
    return renders("pt", 1000)[0]


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_light_linking_in_fog_matches_pt(pt_ref, integrator):
    imgs, warnings = renders(integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself
    metrics.assert_agreement(f"light linking in fog, {integrator} vs pt", imgs, pt_ref,
                             block=4, image_bias=0.025, block_bias=0.1)
    # the control: linking ignored (the scene without it) is seen
    free, _ = renders(integrator, 3000, linked=False)
    assert not metrics.compare_renders(free, pt_ref, block=4).passed


def smoky():
    """foggy(shadow=True) with a small smoke of a density grid (a heterogeneous volume)."""
    s = foggy(shadow=True)
    m4 = np.diag([0.1, 0.1, 0.1, 1.0])
    m4[:3, 3] = (-0.2, -0.2, 0.1)
    g = s.add_grid(np.full((4, 4, 4), 2.0, np.float32), m4, name="smoke:density")
    m = s.add_material("smoke")
    s.materials[m].update(volume=dict(FOG), volume_only=True, density_grid=g)
    s.add_mesh(*aabb_mesh((-0.2, -0.2, 0.1), (0.1, 0.1, 0.4)), material=m, name="smoke")
    return s


def test_hands_over_in_fog(core):
    """lt renders shadow linking in homogeneous fog (test_lt_linking.py); beside a
    heterogeneous volume it stays with pt (allocation.cpp: its walk takes sigma_t's
    transmittance, lt_medium.h), same bits."""
    img, warnings = render(smoky(), "lt", 7, spp=2)
    assert any("graph or grid" in w and "rendering with pt" in w for w in warnings), warnings
    np.testing.assert_array_equal(img, render(smoky(), "pt", 7, spp=2)[0])
    assert not render(foggy(shadow=True), "lt", 7, spp=2)[1]  # (homogeneous: lt's own)
