"""The shadow terminator of smooth-shaded coarse meshes (docs/materials.md "Shadow terminator";
integrator/terminator.h): a mesh's terminator_offset (Cycles' Shadow Terminator Geometry Offset)
lets next-event estimation light a smooth triangle from under its face, with the shadow ray
lifted toward the curved surface its vertex normals describe. On a coarse sphere (20 triangles,
radial normals, a Lambert) under a sphere light at its side: the offset brightens the lit side's
edge (about 10 %) (the control: offset 0, which must not pass against it), and the bidirectional
integrators, which take it at their camera vertices' next-event rays, agree with pt. (Against
Cycles: tests/cycles/test_subsurface.py::test_coarse_head_diffuse.)"""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable")


def coarse_sphere(offset, size=16):
    s = lantern.Scene()
    s.film.update(width=size, height=size)
    s.look_at((0.0, -4.0, 0.0), (0.0, 0.0, 0.0), fov=34.0)
    s.world = {"color": [0.0, 0.0, 0.0]}
    m = s.add_material("grey", base_color=0.8)
    pos, idx = scenes.icosphere(0)
    s.add_mesh(pos, idx, material=m, normals=pos / np.linalg.norm(pos, axis=1, keepdims=True))
    s.meshes[-1]["terminator_offset"] = offset
    # from the side (a sphere light: both techniques, MIS): the terminator down the middle
    s.add_light("point", position=[4.0, -1.0, 1.0], power=[400.0] * 3, radius=0.5)
    return s


def _renders(offset, integrator, seed, k=8, spp=64):
    scene = coarse_sphere(offset)
    return [np.asarray(lantern.render(scene, spp=spp, seed=seed + i, max_depth=4,
                                      integrator=integrator, threads=1), np.float64)
            for i in range(k)]


@pytest.fixture(scope="module")
def pt_on():
    return _renders(0.1, "pt", 101)


def test_offset_lights_the_terminator(pt_on):
    off = _renders(0.0, "pt", 301)
    on_mean, off_mean = np.mean(pt_on), np.mean(off)
    assert on_mean > off_mean * 1.03, (on_mean, off_mean)
    res = metrics.compare_renders(off, pt_on, block=4)
    assert not res.passed, f"offset 0 passed against 0.1: {res}"


def test_invalid_offset_is_refused():
    with pytest.raises(ValueError, match="terminator_offset"):
        coarse_sphere(1.5).validate()


@pytest.mark.parametrize("integ", ["bdpt", "lvc", "cis"])
def test_bidirectional_agree_with_pt(integ, pt_on):
    metrics.assert_agreement(f"{integ} terminator", _renders(0.1, integ, 501), pt_on, block=4)
