"""The shadow terminator of a moving smooth-shaded coarse mesh (D49, docs/difftest.md; issue 32):
a mesh's terminator_offset (integrator/terminator.h) holds on a mesh that turns over the shutter,
its shadow rays lifted where the mesh is at the path's time (terminator_lift_moved). Before, the
core dropped the offset of every moving mesh (its lift read the still corners), so a turning
low-poly smooth mesh rendered as with offset 0: darker along the terminator (D49: -3 % of
Cycles' image mean, a block -8 %).

- pt on a coarse sphere (20 triangles, radial normals, a Lambert, offset 0.1) turning and
  sliding over the shutter, under a sphere light at its side, against an independent estimate of
  the same shutter integral: each seed's reference averages 2 J still renders with the sphere
  placed at the times (j + u) / J and (j + 1 - u) / J (u uniform per seed; exact matrices), by
  lantern.metrics.assert_agreement with its negative controls (3 % image, 10 % block: what
  16 x 16 pixels, 8 seeds of 64 samples resolve).
- The same with the sphere's vertices sliding (deformation blur, mesh["deform"]).
- Negative control: the moving sphere with offset 0 (what the core rendered before) must not
  agree with that reference.
- bdpt (its camera vertices' next-event rays take the lift too) against pt."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

from shutter_ref import shutter_average

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable")

K, SPP, J, SIZE = 8, 64, 8, 16
# the image resolves about 2 % here: controls at 3 % (image) and 10 % (block); the effect is
# 6 % of the image, 19 % of a block
BIAS = dict(image_bias=0.03, block_bias=0.10)
AXIS = np.array([0.3, 0.8, 0.5]) / np.linalg.norm([0.3, 0.8, 0.5])


def _rot(axis, a):
    x, y, z = axis
    c, s, t = np.cos(a), np.sin(a), 1.0 - np.cos(a)
    m = np.eye(4)
    m[:3, :3] = [[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                 [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                 [t * x * z - s * y, t * y * z + s * x, t * z * z + c]]
    return m


def _at(t):
    """Object-to-world at shutter time t: 1.2 rad about a fixed axis (constant speed: the
    steps' slerp is exact) and a 0.2 m slide (linear)."""
    m = _rot(AXIS, 1.2 * t)
    m[:3, 3] = (0.2 * t - 0.1, 0.0, 0.0)
    return m


def _scene(placed, offset=0.1):
    s = lantern.Scene()
    s.film.update(width=SIZE, height=SIZE)
    s.look_at((0.0, -4.0, 0.0), (0.0, 0.0, 0.0), fov=34.0)
    s.world = {"color": [0.0, 0.0, 0.0]}
    m = s.add_material("grey", base_color=0.8)
    pos, idx = scenes.icosphere(0)
    nrm = pos / np.linalg.norm(pos, axis=1, keepdims=True)
    r = np.asarray(placed)
    s.add_mesh((pos @ r[:3, :3].T + r[:3, 3]).astype(np.float32), idx, material=m,
               normals=(nrm @ r[:3, :3].T).astype(np.float32))
    s.meshes[-1]["terminator_offset"] = offset
    # from the side (a sphere light: both techniques, MIS): the terminator down the middle
    s.add_light("point", position=[4.0, -1.0, 1.0], power=[400.0] * 3, radius=0.5)
    return s


def _slid(t):
    """The deforming case's placement at t: the frame's turn, its vertices slid 0.4 m in x (and
    0.1 m in z) over the shutter (deformation blur: the corners move, the normals do not)."""
    m = _at(0.5)
    m[:3, 3] += (0.4 * t - 0.2, 0.0, 0.1 * t - 0.05)
    return m


def _moving(offset=0.1, steps=3, deform=False):
    if deform:
        s = _scene(_slid(0.5), offset)
        pos = np.asarray(scenes.icosphere(0)[0], np.float64)
        s.meshes[0]["deform"] = np.stack(
            [pos @ _slid(t)[:3, :3].T + _slid(t)[:3, 3]
             for t in np.linspace(0.0, 1.0, steps)]).astype(np.float32)
        return s
    s = _scene(_at(0.5), offset)
    s.meshes[0]["motion"] = [_at(t) for t in np.linspace(0.0, 1.0, steps)]
    s.meshes[0]["motion_base"] = _at(0.5)
    return s


def _render(scene, seed, spp, integrator="pt"):
    ses = lantern.Session(scene, integrator=integrator, seed=seed, threads=1, max_depth=2,
                          spp_per_iteration=spp)
    ses.step()
    assert not list(ses.warnings), list(ses.warnings)
    return np.asarray(ses.image(), np.float64)


def _renders(scene, seed0, integrator="pt"):
    return np.stack([_render(scene, seed0 + k, SPP, integrator) for k in range(K)])


def _reference(seed, at=_at):
    return shutter_average(lambda t: _scene(at(t)), _render, seed, 2000, SPP, J, antithetic=True)


@pytest.fixture(scope="module")
def pt_moving():
    return _renders(_moving(), 1)


def test_turning_smooth_mesh_keeps_its_terminator(pt_moving):
    assert np.isfinite(pt_moving).all() and pt_moving.mean() > 0.0
    ref = np.stack([_reference(k) for k in range(K)])
    metrics.assert_agreement("turning terminator", pt_moving, ref, block=4, **BIAS)
    # negative control: offset 0 on the moving sphere (what the core rendered before, D49)
    res = metrics.compare_renders(_renders(_moving(0.0), 1), ref, block=4)
    assert not res.passed, f"the moving sphere without its offset agrees: {res}"


def test_deforming_smooth_mesh_keeps_its_terminator():
    """Deformation blur (mesh["deform"]): the lift on the triangle's corners at the time."""
    ref = np.stack([_reference(k, _slid) for k in range(K)])
    metrics.assert_agreement("deforming terminator", _renders(_moving(deform=True), 1), ref,
                             block=4, **BIAS)
    res = metrics.compare_renders(_renders(_moving(0.0, deform=True), 1), ref, block=4)
    assert not res.passed, f"the deforming sphere without its offset agrees: {res}"


def test_turning_terminator_bdpt_matches_pt(pt_moving):
    metrics.assert_agreement("turning terminator bdpt", _renders(_moving(), 101, "bdpt"),
                             pt_moving, block=4, **BIAS)
