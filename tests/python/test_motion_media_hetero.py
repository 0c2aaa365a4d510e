"""A moving heterogeneous volume (docs/motion_blur.md "Volumes", issue 32): a fog box whose
density is a node program (test_volume_hetero_bdpt.py's noise, of the box's own coordinates: a
per-vertex attribute channel, read through the fit of docs/volumes.md) slides and turns over
the shutter; its boundary is hit where it is at the ray's time and its density read at the point
brought back to the exported frame through the box's matrix at that time (scene/motion.h's
medium_ray_exported), in pt, bdpt, lvc, cis and lt. pt against an independent estimate of the
same shutter integral (per seed, J still renders with the box placed exactly at the times
(j + u) / J, its attribute the same object coordinates; the core's motion code not involved),
by lantern.metrics.assert_agreement with its negative controls; controls of the change: the
still frame (the box kept where it was exported, as before), and the same still renders with
the density left where it is at the frame while the box moves (its attribute the exported
world position), must both differ. bdpt and lt against pt's motion render."""
import numpy as np
import pytest

import lantern
from lantern import metrics, session
from lantern.scenes import aabb_mesh

from test_volume_hetero_bdpt import SMOKE, _instr

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

K, SPP, J, SIZE = 8, 64, 16, 24
# pt's motion render and its shutter references: 4 x SPP, where the control "density left at
# the frame" (a 0.6 % effect on one block) stays clear of the threshold (z 12 against 9.2; at
# SPP it read 6.6-7.3, passing or failing with the majorant bricks' noise)
PT_SPP = 4 * SPP
FOG = 1  # the fog box's mesh
OP_COPY, OP_INPUT, OP_MATH, OP_NOISE = 0, 1, 2, 16


def _program(factor=30.0, scale=2.0):
    """Density = factor x clamp(Noise Fac(attribute 0, scale) - 0.45, 0, 1), kTargetDensity."""
    regs = [0.0] * 42
    regs[3:11] = [0.0, scale, 1.0, 0.5, 2.0, 0.0, 1.0, 0.0]
    regs[31] = 0.45
    regs[41] = factor
    read = _instr(OP_INPUT, mode=4, dim=3, src=0, dst=0)
    read[2] = 0  # aux: attribute channel 0
    code = [read,
            _instr(OP_NOISE, mode=3, flags=1 | 2, dim=3, src=0, dst=20),
            _instr(OP_COPY, dim=1, src=20, dst=30),
            _instr(OP_MATH, mode=1, flags=1, src=30, dst=40),
            _instr(OP_MATH, mode=2, src=40, dst=42)]
    return {"target": "density", "code": code, "consts": regs, "num_const": 42, "result": 42}


def _matrix(t):
    """The box's object-to-world matrix at shutter time t: 1.2 m along x, 40 degrees about z."""
    a = np.radians(-20.0 + 40.0 * t)
    m = np.eye(4)
    m[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    m[0, 3] = -0.6 + 1.2 * t
    return m


def _scene(place, coords):
    """A floor, the fog box (object space [-0.6, 0.6]^2 x [0.05, 1.25]) placed by matrix
    `place`, its attribute channel the object coordinates mapped by matrix `coords`."""
    sc = lantern.Scene()
    sc.film["width"] = sc.film["height"] = SIZE
    sc.look_at((0.0, -4.5, 2.2), (0.0, 0.0, 0.6), up=(0, 0, 1), fov=40)
    floor = sc.add_material("floor", base_color=(0.8, 0.8, 0.8))
    sc.add_mesh(np.array([[-6, -6, 0], [6, -6, 0], [6, 6, 0], [-6, 6, 0]], np.float32),
                np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=floor)
    fog = sc.add_material("fog")
    sc.materials[fog].update(volume=dict(SMOKE), volume_only=True, programs=[_program()])
    p, idx = aabb_mesh((-0.6, -0.6, 0.05), (0.6, 0.6, 1.25))
    p = np.asarray(p, np.float64)
    ph = np.c_[p, np.ones(len(p))]
    sc.add_mesh((ph @ place.T)[:, :3].astype(np.float32), idx, material=fog, name="fog")
    sc.attribute_channels = ["orco"]
    sc.meshes[FOG]["attributes"] = (ph @ coords.T)[:, :3].astype(np.float32)
    sc.add_light("point", position=(1.0, -1.5, 3.0), radius=0.0, power=(400.0, 400.0, 400.0))
    sc.world["color"] = (0.1, 0.1, 0.1)
    return sc


def _moving(world=True):
    """Exported at the shutter's middle, 3 matrices over it. world False: a black world (lt)."""
    sc = _scene(_matrix(0.5), np.eye(4))
    sc.meshes[FOG]["motion"] = [_matrix(t) for t in (0.0, 0.5, 1.0)]
    sc.meshes[FOG]["motion_base"] = _matrix(0.5)
    if not world:
        sc.world["color"] = (0.0, 0.0, 0.0)
    return sc


def _render(scene, integrator, seed, spp):
    per_pass = integrator in ("lvc", "cis")
    s = lantern.Session(scene, integrator=integrator, seed=seed, threads=1, max_depth=4,
                        spp_per_iteration=1 if per_pass else spp)
    for _ in range(spp if per_pass else 1):
        s.step()
    return np.asarray(s.image(), np.float64), list(s.warnings)


def _renders(scene, integrator, seed0, spp=SPP):
    out = []
    for k in range(K):
        img, warnings = _render(scene, integrator, seed0 + k, spp)
        assert not warnings, warnings
        out.append(img)
    out = np.stack(out)
    assert np.isfinite(out).all()
    return out


def _reference(follow):
    """Per seed: J still renders at the times (j + u) / J; the density follows the box (its
    object coordinates) or stays where it is at the frame (follow False)."""
    out = []
    for k in range(K):
        u = np.random.default_rng(4000 + k).random()
        imgs = []
        for j in range(J):
            m = _matrix((j + u) / J)
            coords = np.eye(4) if follow else _matrix(0.5) @ np.linalg.inv(m)
            imgs.append(_render(_scene(m, coords), "pt", 100 * k + j, PT_SPP // J)[0])
        out.append(np.mean(imgs, axis=0))
    return np.stack(out)


_PT = {}


def _pt(world):
    if world not in _PT:
        _PT[world] = _renders(_moving(world), "pt", 1, PT_SPP)
    return _PT[world]


def test_moving_hetero_volume_matches_static_average():
    lan = _pt(True)
    metrics.assert_agreement("moving noise fog", lan, _reference(True), block=8, se_floor=1e-6,
                             image_bias=0.02, block_bias=0.10)
    sharp = _renders(_scene(_matrix(0.5), np.eye(4)), "pt", 1, PT_SPP)
    res = metrics.compare_renders(lan, sharp, block=8, se_floor=1e-6)
    print("kept still:", res)
    assert not res.passed, f"the motion render agrees with the still frame: {res}"
    res = metrics.compare_renders(lan, _reference(False), block=8, se_floor=1e-6)
    print("density left at the frame:", res)
    assert not res.passed, f"the motion render agrees with a density left behind: {res}"


@pytest.mark.parametrize("integrator", ["bdpt", "cis", "lt"])
def test_moving_hetero_volume_light_paths_match_pt(integrator):
    world = integrator != "lt"
    spp = SPP * 8 if integrator == "lt" else SPP
    lan = _renders(_moving(world), integrator, 50, spp)
    metrics.assert_agreement(f"moving noise fog {integrator}", lan, _pt(world), block=8,
                             se_floor=1e-6, image_bias=0.03, block_bias=0.10)


def test_grid_volume_stays_still():
    """A density grid (a Volume object's kind) does not follow its moving mesh: the warning,
    and the bits of the scene without the motion."""
    def with_grid(sc):
        g = sc.add_grid(np.full((4, 4, 4), 0.8, np.float32), np.diag([0.4, 0.4, 0.4, 1.0]) @
                        np.array([[1, 0, 0, -2.0], [0, 1, 0, -2.0], [0, 0, 1, 0.0],
                                  [0, 0, 0, 1]]), name="fog:density")
        sc.materials[sc.material_id("fog")].update(density_grid=g, programs=[])
        return sc
    img, warnings = _render(with_grid(_moving()), "pt", 4, 4)
    assert any("bounds a heterogeneous volume that cannot follow it" in w for w in warnings)
    assert np.array_equal(img, _render(with_grid(_scene(_matrix(0.5), np.eye(4))), "pt", 4,
                                       4)[0])
