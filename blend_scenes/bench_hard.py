"""Small hard cases (256 x 256, 3 x 3 x 2.5 m closed rooms, every light inside a fixture):
`bench_fixture` a bulb in a nearly closed box with a 6 cm opening, `bench_caustics` glass over
a diffuse floor lit by a small bulb in a cup, `bench_tiny_light` a 1 mm bulb, `bench_glossy`
facing metal panels around a metal Suzanne."""

import bench_common as bc

RES = (256, 256)
H = 2.5


def _room(holes=()):
    walls = bc.matte("Walls", (0.7, 0.7, 0.7))
    floor = bc.matte("FloorGrey", (0.6, 0.6, 0.58))
    bc.room(-1.5, 1.5, -1.5, 1.5, H, floor, walls, walls, holes)
    bc.look((0.0, -1.45, 1.5), (0.0, 0.4, 0.6), 20.0)
    return walls


def bench_fixture():
    """A bulb (radius 2 cm, 100 W) in a closed 40 x 40 x 25 cm box under the ceiling whose only
    opening is a 6 x 6 cm square in its bottom: all direct light leaves through it."""
    bc.start(*RES)
    walls = _room()
    metal = bc.matte("HousingPaint", (0.8, 0.8, 0.8))
    x0, x1, y0, y1, z0, z1 = -0.2, 0.2, 0.2, 0.6, H - 0.25, H - 0.001
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    bc.mesh_object("Housing", v, [[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7],
                                  [4, 5, 6, 7]], metal)
    bc.holed_plane("HousingBottom", x0, x1, y0, y1, z0, [(-0.03, 0.03, 0.37, 0.43)], metal)
    bc.bulb("FixtureBulb", (0.0, 0.4, (z0 + z1) / 2), 100.0, radius=0.02)
    bc.block("Plinth", (0.3, 0.5, 0.25), (0.5, 0.5, 0.5), walls, bevel=0.01)
    bc.suzanne("Suzanne", (0.3, 0.5, 0.8), 0.25, bc.matte("Clay", (0.7, 0.5, 0.4)), levels=2)
    return bc.finish()


def bench_caustics():
    """A glass sphere and a glass Suzanne above a white diffuse floor; a 1 cm bulb in a small
    cup under the ceiling: the caustics are reachable only through specular chains."""
    bc.start(*RES)
    _room()
    glass = bc.glass("Glass")
    bc.lathe("GlassSphere", _sphere(0.3, 32), 64, glass, center=(-0.35, 0.4, 0.55))
    bc.suzanne("GlassSuzanne", (0.5, 0.5, 0.45), 0.3, glass, levels=2)
    bc.cup_light("CupBulb", 0.0, 0.5, H, 80.0, 0.01, bc.matte("CupPaint", (0.8, 0.8, 0.8)))
    return bc.finish()


def bench_tiny_light():
    """A 1 mm bulb (20 W) in a 2 cm cup: next-event hits are rare for light paths and BSDF
    samples never hit it; lacquered blocks and a Suzanne under it."""
    bc.start(*RES)
    walls = _room()
    bc.cup_light("TinyBulb", 0.0, 0.4, H - 0.4, 20.0, 0.001, walls, cup_r=0.02, cup_h=0.04)
    lathe_wire = bc.metal("Wire", (0.6, 0.6, 0.6), 0.4)
    bc.lathe("Hanger", [(0.003, H - 0.4), (0.003, H)], 8, lathe_wire, (0.0, 0.4, 0))
    red, teal = bc.coated("RedLacquer", (0.6, 0.1, 0.05)), bc.coated("Teal", (0.1, 0.4, 0.4))
    bc.block("BlockA", (-0.5, 0.5, 0.3), (0.5, 0.5, 0.6), red, rot_z=20, bevel=0.02)
    bc.block("BlockB", (0.5, 0.2, 0.2), (0.4, 0.4, 0.4), teal, rot_z=-15, bevel=0.02)
    bc.suzanne("Suzanne", (0.0, 0.5, 0.3), 0.3, bc.coated("Ivory", (0.8, 0.78, 0.7)), levels=2)
    return bc.finish()


def bench_glossy():
    """Two near-mirror metal panels facing each other (roughness 0.05) around a rough metal
    Suzanne on a lacquered floor; one recessed ceiling light: glossy inter-reflection."""
    bc.start(*RES)
    trim = bc.matte("Trim", (0.8, 0.8, 0.8))
    hole = [bc.recessed_light("Recessed", 0.0, -0.2, H, 0.25, 0.15, 60.0, trim)]
    _room(hole)
    steel = bc.metal("Mirror", (0.9, 0.9, 0.9), 0.05)
    copper = bc.metal("Copper", (0.95, 0.64, 0.54), 0.15)
    for name, x in (("PanelLeft", -0.8), ("PanelRight", 0.8)):
        bc.block(name, (x, 0.5, 0.8), (0.03, 1.2, 1.2), steel, bevel=0.005)
    bc.block("Pedestal", (0.0, 0.5, 0.3), (0.4, 0.4, 0.6), bc.coated("Black", (0.02, 0.02, 0.02)))
    bc.suzanne("Suzanne", (0.0, 0.5, 0.85), 0.28, copper, levels=2)
    return bc.finish()


def _sphere(r, rings):
    import math
    return [(0.0 if k in (0, rings) else r * math.sin(math.pi * k / rings),
             -r * math.cos(math.pi * k / rings)) for k in range(rings + 1)]
