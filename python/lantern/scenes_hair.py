"""Strand test scenes built in numpy (docs/curves.md): fur on a sphere and a hair furnace.

- `fur_ball`: a diffuse sphere with radial fur strands (a few keys each, bent by gravity),
  lit by an area light and a dim world; Principled Hair or any other material on the fur.
- `hair_furnace`: white, non-absorbing, untilted Principled Hair strands in a uniform white
  world of radiance `world`: without absorption or tilt every scattering keeps all the
  energy (bsdf/hair.h), so every pixel sees exactly `world` (paths cut by max_depth aside)."""

import numpy as np

from .scene import Scene
from .scenes import icosphere


def fur_strands(num_strands=300, keys=5, sphere_radius=0.5, length=0.35, root_radius=0.01,
                tip_radius=0.002, droop=0.15, seed=1):
    """Points (P, 3), radius (P,), offsets (S + 1,) of strands rooted on a sphere about the
    origin, growing along the normal and drooping in -z."""
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(num_strands, 3))
    n = v / np.linalg.norm(v, axis=1, keepdims=True)
    t = np.linspace(0.0, 1.0, keys)
    root = n * sphere_radius * 0.98
    pts = (root[:, None, :] + n[:, None, :] * (length * t)[None, :, None]
           - np.array([0.0, 0.0, droop])[None, None, :] * (t ** 2)[None, :, None])
    rad = np.broadcast_to(root_radius + (tip_radius - root_radius) * t, (num_strands, keys))
    offsets = np.arange(num_strands + 1, dtype=np.uint32) * keys
    return (pts.reshape(-1, 3).astype(np.float32), rad.reshape(-1).astype(np.float32), offsets)


def fur_ball(width=32, height=32, num_strands=300, hair=None, material_type="hair",
             base_color=(0.8, 0.5, 0.3), light_power=300.0, world=0.1, **strand_args):
    """A furry sphere seen from -y; `hair`: add_material's hair dict (type "hair"), else
    `material_type` with `base_color` (e.g. "principled", "diffuse") on the strands."""
    scene = Scene()
    scene.film.update(width=int(width), height=int(height))
    scene.look_at((0.0, -3.0, 0.3), (0.0, 0.0, 0.0), fov=38.0)
    scene.world["color"] = [world] * 3
    skin = scene.add_material("skin", base_color=(0.6, 0.6, 0.6))
    pos, idx = icosphere(3, 0.5)
    scene.add_mesh(pos, idx, material=skin, name="ball")
    if material_type == "hair":
        fur = scene.add_material("fur", type="hair", roughness=0.3,
                                 hair=hair if hair is not None else
                                 {"parametrization": "melanin", "melanin": 0.4})
    else:
        fur = scene.add_material("fur", type=material_type, base_color=base_color)
    pts, rad, off = fur_strands(num_strands, **strand_args)
    scene.add_curves(pts, rad, off, material=fur, name="fur")
    to_world = np.eye(4)
    to_world[:3, 3] = (1.5, -1.5, 2.0)
    scene.add_light("area", to_world=_facing(to_world[:3, 3]).tolist(), power=[light_power] * 3,
                    size=[1.0, 1.0])
    return scene


def _facing(pos):
    """A light frame at pos whose -z faces the origin."""
    z = np.asarray(pos, float) / np.linalg.norm(pos)  # local +z away from the origin
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, y, z, pos
    return m


def hair_furnace(width=16, height=16, num_strands=400, world=1.0, offset=0.0, seed=3):
    """Non-absorbing Principled Hair strands (absorption 0, Offset `offset`) filling the view in
    a uniform world of radiance `world`; with offset 0 every pixel is exactly `world`."""
    scene = Scene()
    scene.film.update(width=int(width), height=int(height))
    scene.look_at((0.0, -2.5, 0.0), (0.0, 0.0, 0.0), fov=30.0)
    scene.world["color"] = [world] * 3
    fur = scene.add_material("white_hair", type="hair", roughness=0.3, ior=1.55,
                             hair={"parametrization": "absorption", "absorption": [0.0] * 3,
                                   "radial_roughness": 0.3, "offset": offset})
    pts, rad, off = fur_strands(num_strands, keys=4, sphere_radius=0.05, length=0.8,
                                root_radius=0.01, tip_radius=0.01, droop=0.0, seed=seed)
    scene.add_curves(pts, rad, off, material=fur, name="white_fur")
    return scene
