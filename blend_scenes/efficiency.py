"""Ordinary scenes for the Lantern-against-Cycles efficiency table (bench/efficiency_cycles.py,
issue 14): closed rooms lit the way artists light them, and a stage with many small lights.
Diffuse surfaces only (scenes.py's rule), so the two renderers converge to the same image.

| Scene | Made of |
|---|---|
| `room_area_point` | 5 x 5 x 2.8 m room, camera inside; a 1.0 x 0.5 m area light 200 W under the ceiling facing down, and a small point light (10 W, radius 5 cm) low in the far corner |
| `room_spot_sun_world` | the same room with a window in the right wall: a sun (4 W/m², 2°) through it, a world colour (0.4, 0.5, 0.7) seen and lighting through it, and a spot (600 W, 40°) from a ceiling corner aimed at the floor |
| `small_room_two_lights` | issue 28's "several lights": a closed 2 x 2 x 2 m room, a rough Principled ball (roughness 0.5) on the floor, a 0.5 x 0.3 m area light 30 W 2 cm under the ceiling facing down and a point light 15 W (radius 5 cm, soft falloff) at mid height; `_area` / `_point`: one light alone |
| `many_lights` | the stage of scenes.py lit by 24 point lights of different colours and powers (5-120 W, radius 5 cm) |
"""

import math

import numpy as np

import scenes as sc

W, D, H = 5.0, 5.0, 2.8
WINDOW = (-0.6, 1.0, 0.9, 2.2)  # right wall (x = W/2): y0, y1, z0, z1


def _room(window=False):
    """Floor, ceiling, four walls (the right one with a window when asked), a table, a cabinet
    and a block; the camera stands inside near the front wall."""
    x, y = W / 2, D / 2
    white = sc.diffuse("White", (0.8, 0.8, 0.8))
    sc.quad("Floor", [(-x, -y, 0), (x, -y, 0), (x, y, 0), (-x, y, 0)],
            sc.diffuse("Floor", (0.55, 0.45, 0.35)))
    sc.quad("Ceiling", [(-x, -y, H), (-x, y, H), (x, y, H), (x, -y, H)], white)
    sc.quad("Back", [(-x, y, 0), (x, y, 0), (x, y, H), (-x, y, H)], white)
    sc.quad("Front", [(-x, -y, 0), (-x, -y, H), (x, -y, H), (x, -y, 0)], white)
    sc.quad("Left", [(-x, -y, 0), (-x, y, 0), (-x, y, H), (-x, -y, H)],
            sc.diffuse("Blue", (0.35, 0.45, 0.7)))
    right = sc.diffuse("Sand", (0.75, 0.65, 0.45))
    if not window:
        sc.quad("Right", [(x, -y, 0), (x, -y, H), (x, y, H), (x, y, 0)], right)
    else:
        y0, y1, z0, z1 = WINDOW
        for k, (ya, yb, za, zb) in enumerate(((-y, y0, 0, H), (y1, y, 0, H), (y0, y1, 0, z0),
                                              (y0, y1, z1, H))):
            sc.quad(f"Right{k}", [(x, ya, za), (x, ya, zb), (x, yb, zb), (x, yb, za)], right)
    sc.box("Table", (0.3, 0.8, 0.375), (1.4, 0.8, 0.75), 10, sc.diffuse("Wood", (0.5, 0.3, 0.15)))
    sc.box("Cabinet", (-1.9, 1.7, 0.6), (0.8, 0.6, 1.2), 0, sc.principled("Red", (0.7, 0.2, 0.15)))
    sc.box("Block", (1.5, -0.6, 0.25), (0.5, 0.5, 0.5), 30, sc.diffuse("Green", (0.2, 0.6, 0.3)))
    sc.camera((0.0, -2.2, 1.5), (0.2, 1.0, 0.9), lens=20.0)


def room_area_point():
    sc._reset()
    _room()
    sc.light("AREA", "Area", (0.4, 0.6, H - 0.02), target=(0.4, 0.6, 0.0), shape="RECTANGLE",
             size=1.0, size_y=0.5, energy=200.0)
    sc.light("POINT", "CornerLamp", (-2.2, 2.2, 0.4), shadow_soft_size=0.05, energy=10.0)


def room_spot_sun_world():
    sc._reset(world_color=(0.4, 0.5, 0.7))
    _room(window=True)
    # from outside, high to the right: through the window onto the floor and the table
    sc.light("SUN", "Sun", (6.0, 0.2, 5.0), target=(0.0, 0.4, 0.0), energy=4.0,
             angle=math.radians(2))
    sc.light("SPOT", "Spot", (-2.3, -2.3, H - 0.05), target=(-0.8, 0.3, 0.0),
             shadow_soft_size=0.05, energy=600.0, spot_size=math.radians(40), spot_blend=0.2)


def many_lights():
    sc._reset()
    sc._stage()
    rng = np.random.default_rng(14)
    for k in range(24):
        px, py = rng.uniform(-2.5, 2.5), rng.uniform(-2.5, 1.8)
        pz = rng.uniform(0.3, 2.6)
        colour = 0.3 + 0.7 * rng.uniform(size=3)
        obj = sc.light("POINT", f"Lamp{k}", (px, py, pz), shadow_soft_size=0.05,
                       energy=float(rng.uniform(5.0, 120.0)))
        obj.data.color = tuple(float(c) for c in colour)


# lantern.scenes.SMALL_ROOM_WALLS, kept equal by hand: floor, ceiling, back, front, left, right
SMALL_ROOM_WALLS = (
    ((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0), (0.6, 0.6, 0.6)),
    ((-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2), (0.8, 0.8, 0.8)),
    ((-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2), (0.8, 0.8, 0.8)),
    ((-1, -1, 0), (-1, -1, 2), (1, -1, 2), (1, -1, 0), (0.8, 0.8, 0.8)),
    ((-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2), (0.7, 0.2, 0.15)),
    ((1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0), (0.2, 0.6, 0.25)))


def _small_room(lights):
    """lantern.scenes.small_room_two_lights in Blender (flat-shaded icosphere ball)."""
    import bpy
    sc._reset()
    for k, (a, b, c, d, colour) in enumerate(SMALL_ROOM_WALLS):
        sc.quad(f"Wall{k}", [a, b, c, d], sc.diffuse(f"Wall{k}", colour))
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=4, radius=0.3, location=(0.3, 0.3, 0.3))
    ball = bpy.context.active_object
    ball.name = "Ball"
    m = bpy.data.materials.new("Ball")
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (0.8, 0.5, 0.3, 1.0)
    p.inputs["Roughness"].default_value = 0.5
    ball.data.materials.append(m)
    sc.camera((0.0, -0.9, 1.0), (0.0, 1.0, 0.9), lens=18.0)
    if lights in ("both", "area"):
        sc.light("AREA", "Area", (0.0, 0.2, 1.98), target=(0.0, 0.2, 0.0), shape="RECTANGLE",
                 size=0.5, size_y=0.3, energy=30.0)
    if lights in ("both", "point"):
        sc.light("POINT", "Point", (-0.6, 0.5, 0.7), shadow_soft_size=0.05, energy=15.0,
                 use_soft_falloff=True)


def small_room_two_lights():
    _small_room("both")


def small_room_two_lights_area():
    _small_room("area")


def small_room_two_lights_point():
    _small_room("point")


SCENES = {f.__name__: f for f in (room_area_point, room_spot_sun_world, many_lights,
                                  small_room_two_lights, small_room_two_lights_area,
                                  small_room_two_lights_point)}
