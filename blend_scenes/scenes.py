"""Builders for the test and benchmark scenes, in bpy. Each builder starts from an empty file,
builds the scene and leaves it as the current bpy data; `build(name, path)` saves it.

Every scene is small (RES x RES pixels) and diffuse, so Cycles and Lantern both converge on 2
cores in CI time. Surfaces use the Diffuse BSDF (roughness 0: Lambert in Cycles). A Principled
BSDF with only Base Color set is NOT diffuse in Cycles (its dielectric specular layer, IOR 1.5,
adds a neutral glossy reflection), so `principled()` sets Specular IOR Level to 0, which leaves
Cycles' Lambertian diffuse lobe alone; it is used for a few surfaces to cover the add-on's
Principled path. Lights are
invisible to the camera (Blender 5.0's default). The world is black except in `world_color`."""

import math
import os

import bpy

from stage import (  # noqa: F401 (the builders' helpers, read as scenes.X by the other builders)
    OUT_DIR, RES, ROOT, _link, _reset, _stage, box, camera, diffuse, emission, hdri_world, light,
    principled, principled_emission, quad)


# ---- scenes ----

def cornell_box():
    """Cornell box 2x2x2 m: red left, green right, white floor/ceiling/back, a tall and a short
    box, a 0.5 x 0.4 m rectangular area light 1 cm under the ceiling, facing down."""
    _reset()
    white = diffuse("White", (0.73, 0.73, 0.73))
    red = diffuse("Red", (0.63, 0.065, 0.05))
    green = diffuse("Green", (0.14, 0.45, 0.091))
    quad("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], white)
    quad("Ceiling", [(-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2)], white)
    quad("Back", [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)], white)
    quad("Left", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)], red)
    quad("Right", [(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)], green)
    box("TallBox", (-0.35, 0.3, 0.6), (0.6, 0.6, 1.2), 17, principled("BoxWhite", (0.73, 0.73, 0.73)))
    box("ShortBox", (0.35, -0.3, 0.3), (0.6, 0.6, 0.6), -17, white)
    light("AREA", "CeilingLight", (0, 0, 1.99), shape="RECTANGLE", size=0.5, size_y=0.4,
          energy=60.0)
    camera((0, -3.9, 1.0), (0, 0, 1.0), lens=35.0)


def light_point():
    _reset()
    _stage()
    light("POINT", "Point", (0.5, -1.0, 2.5), shadow_soft_size=0.15, energy=400.0)


def light_point_sphere():
    """light_point with soft falloff off: Cycles renders a sphere light of that radius, which is
    also what light paths (bdpt, lvc, cis, lt) can start on."""
    light_point()
    bpy.data.lights["Point"].use_soft_falloff = False


def light_spot():
    _reset()
    _stage()
    light("SPOT", "Spot", (1.5, -1.5, 3.0), target=(0, 0.3, 0), shadow_soft_size=0.1,
          energy=1500.0, spot_size=math.radians(50), spot_blend=0.3)


def _area(shape, size, size_y=None):
    _reset()
    _stage()
    props = {"shape": shape, "size": size, "energy": 300.0}
    if size_y is not None:
        props["size_y"] = size_y
    light("AREA", "Area", (0.3, -1.2, 2.8), target=(0, 0.3, 0), **props)


def light_area_square():
    _area("SQUARE", 0.8)


def light_area_rectangle():
    _area("RECTANGLE", 1.2, 0.4)


def light_area_disk():
    _area("DISK", 0.8)


def light_area_ellipse():
    _area("ELLIPSE", 1.2, 0.5)


def light_sun():
    _reset()
    _stage()
    light("SUN", "Sun", (0, 0, 5), target=(-0.8, 1.2, 0), energy=3.0, angle=math.radians(10))


def emissive_mesh():
    """No lamps: a Emission-shader panel (both sides emit) lights the stage."""
    _reset()
    _stage()
    quad("Panel", [(-0.4, -1.0, 2.2), (0.4, -1.0, 2.2), (0.4, -0.4, 2.6), (-0.4, -0.4, 2.6)],
         emission("Glow", (1.0, 0.9, 0.7), 15.0))


def principled_emission_mesh():
    """No lamps: a block with Principled emission (base colour + emission) lights the stage."""
    _reset()
    _stage()
    box("Glowing", (0.9, 0.9, 1.4), (0.5, 0.5, 0.3), 10,
        principled_emission("GlowP", (0.5, 0.5, 0.5), (0.7, 0.85, 1.0), 12.0))


def world_color():
    """No lamps: only a constant world colour (0.5, 0.6, 0.8) lights the stage."""
    _reset(world_color=(0.5, 0.6, 0.8))
    _stage()


SCENES = {f.__name__: f for f in (
    cornell_box, light_point, light_point_sphere, light_spot, light_area_square,
    light_area_rectangle, light_area_disk, light_area_ellipse, light_sun, emissive_mesh,
    principled_emission_mesh, world_color)}


def build(name, path=None):
    """Build scene `name` into the current bpy data and save it; returns the .blend path."""
    SCENES[name]()
    path = path or os.path.join(OUT_DIR, name + ".blend")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=path, check_existing=False)
    return path


import world_scenes  # noqa: E402  (blend_scenes/world_scenes.py: sky, panorama)
world_scenes.register(SCENES)
