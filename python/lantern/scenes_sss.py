"""Subsurface test scenes built in numpy (docs/subsurface.md).

- `lit_sphere`: the lit subsurface sphere of the bidirectional and lt tests
  (tests/python/test_subsurface_bidir.py and those importing its `lit_sphere`), of
  `tools/gpu_compare.py`'s `subsurface_skin`, of `bench/sss_bits.py` and of the GPU self-check's
  `skin/*` cases: one builder, so that they render the same scene."""

import numpy as np

from .scene import Scene
from .scenes import icosphere


def lit_sphere(width=16, height=16, method="random_walk_skin", radius_scale=1.0, world=0.0):
    """A unit sphere with subsurface scattering (`method` "random_walk_skin" or "random_walk",
    radius (0.4, 0.2, 0.1) m x `radius_scale`, base colour (0.8, 0.6, 0.4), roughness 0.5) on a
    grey floor under a point light of 300 W at (1.5, -1, 2), the world's colour `world` (grey):
    camera paths walk it (pt, bdpt, lvc, cis), and with Skin light paths too (bdpt, lvc, cis,
    lt); the walk carries light into the sphere's shadow side."""
    s = Scene()
    s.film.update(width=width, height=height)
    s.look_at((0.0, -4.0, 0.6), (0.0, 0.0, -0.3), fov=40.0)
    s.world = {"color": [world] * 3}
    r = [0.4 * radius_scale, 0.2 * radius_scale, 0.1 * radius_scale]
    m = s.add_material("ball", type="principled", base_color=(0.8, 0.6, 0.4), roughness=0.5,
                       subsurface={"weight": 1.0, "radius": r, "method": method})
    pos, idx = icosphere(2)
    s.add_mesh(pos, idx, material=m)
    f = s.add_material("floor", base_color=0.5)
    q = np.array([[-3, -3, -1], [3, -3, -1], [3, 3, -1], [-3, 3, -1]], np.float32)
    s.add_mesh(q, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=f)
    s.add_light("point", position=[1.5, -1.0, 2.0], power=[300.0] * 3, radius=0.0)
    return s
