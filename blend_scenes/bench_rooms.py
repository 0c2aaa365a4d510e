"""`whiteroom` (574K triangles) and `bedroom` (1.8M), 1980 x 1080 as in the paper: furnished
closed rooms made of bevelled and subdivided boxes, surfaces of revolution and draped grids, lit
only by lights inside fixtures (ceiling recesses, pendant shades, table and floor lamps).
Curtains take up whatever the furniture leaves of the triangle target."""

import numpy as np

import bench_common as bc

RES = (1980, 1080)
WHITEROOM_TARGET = 574_000
BEDROOM_TARGET = 1_800_000

VASE = [(0, 0), (0.08, 0), (0.13, 0.08), (0.14, 0.16), (0.09, 0.28), (0.05, 0.33),
        (0.06, 0.37), (0.055, 0.38), (0.04, 0.34), (0, 0.3)]


def _vase(name, x, y, z, scale, material, subdiv):
    prof = [(r * scale, h * scale) for r, h in VASE]
    bc.lathe(name, prof, 48, material, center=(x, y, z), subdiv=subdiv)


def _legs(name, cx, cy, sx, sy, height, material, r=0.02):
    for k, (dx, dy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1))):
        bc.lathe(f"{name}Leg{k}", [(0, 0), (r, 0), (r, height), (0, height)], 16, material,
                 center=(cx + dx * (sx / 2 - 2 * r), cy + dy * (sy / 2 - 2 * r), 0))


def _floor_lamp(name, x, y, power, shade_mat, metal):
    bc.lathe(name + "Stand", [(0, 0), (0.16, 0), (0.16, 0.03), (0.015, 0.045), (0.015, 1.42),
                              (0, 1.42)], 32, metal, center=(x, y, 0))
    bc.shade(name + "Shade", x, y, 1.3, shade_mat, r_bottom=0.25, r_top=0.18, height=0.35)
    return bc.bulb(name, (x, y, 1.5), power, radius=0.03)


def _chair(name, x, y, facing, material):
    bc.block(name + "Seat", (x, y, 0.45), (0.45, 0.45, 0.05), material, bevel=0.01)
    bc.block(name + "Back", (x, y - facing * 0.21, 0.75), (0.45, 0.04, 0.55), material,
             bevel=0.01)
    _legs(name, x, y, 0.45, 0.45, 0.43, material, r=0.015)


def _bookshelf(x0, x1, y, height, frame, covers, rng):
    depth = 0.3
    cx = (x0 + x1) / 2
    for k, xs in enumerate((x0, x1)):
        bc.block(f"ShelfSide{k}", (xs, y, height / 2), (0.03, depth, height), frame, bevel=0.004)
    rows = 5
    for r in range(rows + 1):
        z = 0.05 + r * (height - 0.1) / rows
        bc.block(f"Shelf{r}", (cx, y, z), (x1 - x0, depth, 0.025), frame, bevel=0.004)
        if r == rows:
            break
        x = x0 + 0.03
        k = 0
        while True:
            w = rng.uniform(0.025, 0.05)
            hgt = rng.uniform(0.2, 0.3)
            if x + w > x1 - 0.05:
                break
            bc.block(f"Book{r}_{k}", (x + w / 2, y, z + 0.0125 + hgt / 2), (w, 0.2, hgt),
                     covers[rng.integers(len(covers))], bevel=0.003)
            x += w + 0.003
            k += 1


def whiteroom():
    bc.start(*RES)
    rng = np.random.default_rng(3)
    white = bc.matte("WhitePaint", (0.85, 0.85, 0.83))
    floor = bc.wood("OakFloor")
    enamel = bc.coated("WhiteEnamel", (0.9, 0.9, 0.88))
    x0, x1, y0, y1, h = -4.0, 4.0, -3.0, 3.0, 3.0
    holes = [bc.recessed_light(f"Recessed{k}", x, y, h, 0.3, 0.15, 120.0, white)
             for k, (x, y) in enumerate(((-2.6, -0.4), (-0.8, -0.4), (-2.6, 1.6), (-0.8, 1.6)))]
    bc.room(x0, x1, y0, y1, h, floor, white, white, holes, floor_uv=(8, 6))

    # ---- sofa, pillows, coffee table ----
    linen = bc.fabric("SofaLinen", (0.6, 0.6, 0.58))
    bc.block("SofaBase", (-1.6, 2.45, 0.22), (2.4, 1.0, 0.3), linen, bevel=0.03)
    bc.block("SofaBack", (-1.6, 2.85, 0.62), (2.4, 0.25, 0.6), linen, bevel=0.04, subdiv=3)
    for k, x in enumerate((-2.75, -0.45)):
        bc.block(f"SofaArm{k}", (x, 2.45, 0.45), (0.25, 1.0, 0.55), linen, bevel=0.04, subdiv=3)
    for k, x in enumerate((-2.23, -1.6, -0.97)):
        bc.block(f"SeatCushion{k}", (x, 2.35, 0.47), (0.62, 0.8, 0.2), linen, bevel=0.05,
                 subdiv=4)
    pillow_mats = [bc.fabric("VelvetOchre", (0.7, 0.45, 0.1)),
                   bc.fabric("VelvetTeal", (0.05, 0.35, 0.4))]
    for k, x in enumerate((-2.45, -2.0, -1.2, -0.75)):
        bc.block(f"Pillow{k}", (x, 2.62, 0.75), (0.45, 0.15, 0.42), pillow_mats[k % 2],
                 rot_z=(-8, 5, -4, 9)[k], subdiv=5)
    glass = bc.glass("TableGlass")
    brass = bc.metal("Brass", (0.9, 0.7, 0.4), 0.25)
    bc.block("CoffeeTop", (-1.6, 1.1, 0.42), (1.2, 0.7, 0.03), glass)
    _legs("Coffee", -1.6, 1.1, 1.2, 0.7, 0.405, brass)
    bc.suzanne("Sculpture", (-1.85, 1.1, 0.64), 0.2, bc.metal("Chrome", (0.95, 0.95, 0.95), 0.05),
               levels=3, rot_z=-20)
    _vase("VaseSmall", -1.2, 1.15, 0.435, 0.6, bc.coated("Celadon", (0.45, 0.6, 0.5)), 3)
    _vase("FloorVase", -3.45, 2.6, 0.0, 2.4, bc.coated("Terracotta", (0.6, 0.3, 0.18)), 3)
    _floor_lamp("FloorLamp", -3.45, 1.7, 100.0, bc.fabric("ShadeLinen", (0.85, 0.8, 0.7)), brass)

    # ---- dining table under three pendants ----
    bc.block("DiningTop", (2.5, 1.0, 0.75), (2.2, 1.0, 0.05), floor, bevel=0.01)
    _legs("Dining", 2.5, 1.0, 2.2, 1.0, 0.725, floor, r=0.03)
    for k, (x, y, f) in enumerate(((1.9, 0.25, 1), (3.1, 0.25, 1), (1.9, 1.75, -1),
                                   (3.1, 1.75, -1))):
        _chair(f"Chair{k}", x, y, f, enamel)
    _vase("GlassVase", 2.5, 1.0, 0.775, 0.8, glass, 3)
    black = bc.metal("BlackSteel", (0.05, 0.05, 0.05), 0.4)
    for k, x in enumerate((1.8, 2.5, 3.2)):
        bc.pendant(f"Pendant{k}", x, 1.0, h, 1.05, 90.0, enamel, black, r_bottom=0.2,
                   r_top=0.06, height=0.25)

    # ---- bookshelf ----
    covers = [bc.coated(n, c) for n, c in (("CoverRed", (0.5, 0.08, 0.06)),
                                           ("CoverBlue", (0.08, 0.15, 0.45)),
                                           ("CoverCream", (0.8, 0.75, 0.6)))]
    _bookshelf(0.1, 1.3, 2.82, 2.0, white, covers, rng)

    bc.look((0.0, -2.9, 1.5), (0.0, 1.5, 1.0), 18.0)
    curtains = bc.fabric("CurtainVoile", (0.9, 0.88, 0.82))
    fill = bc.curtain_fill({"CurtainLeft": (-3.93, 1.1, -3.93, 2.9, 0.05, 2.9),
                            "CurtainRight": (3.93, 2.9, 3.93, 1.1, 0.05, 2.9)}, curtains)
    return bc.finish(WHITEROOM_TARGET, fill, keep_uvs=("Floor",))


def _duvet(name, nx, ny, material):
    """Draped over a 1.8 x 1.5 m top at z 0.64 (bed centre x 0.4), hanging 0.35 m down both
    sides, with wrinkles."""
    def surface(u, v):
        s = -1.25 + 2.5 * u
        top = np.abs(s) <= 0.9
        x = np.where(top, 0.4 + s, 0.4 + np.sign(s) * 0.92)
        z = np.where(top, 0.64, 0.64 - (np.abs(s) - 0.9))
        wr = 0.012 * np.sin(23 * u + 3 * np.sin(11 * v)) * np.sin(17 * v)
        x = x + np.where(top, 0.0, np.sign(s) * wr)
        z = z + np.where(top, wr, 0.0)
        return x, 0.75 + 1.5 * v, z
    bc.grid(name, nx, ny, surface, material)


def bedroom():
    bc.start(*RES)
    paint = bc.matte("WarmPaint", (0.8, 0.75, 0.65))
    floor = bc.wood("WalnutFloor")
    x0, x1, y0, y1, h = -3.5, 3.5, -3.0, 3.0, 2.8
    holes = [bc.recessed_light(f"Recessed{k}", x, 0.0, h, 0.3, 0.15, 100.0, paint)
             for k, x in enumerate((-2.0, 2.0))]
    bc.room(x0, x1, y0, y1, h, floor, paint, paint, holes, floor_uv=(7, 6))
    accent = bc.matte("SageAccent", (0.4, 0.5, 0.45))
    bc.mesh_object("AccentWall", [(x0, y1 - 0.01, 0), (x1, y1 - 0.01, 0), (x1, y1 - 0.01, h),
                                  (x0, y1 - 0.01, h)], [[0, 1, 2, 3]], accent)

    # ---- bed ----
    wood_lacquer = bc.coated("DarkWood", (0.2, 0.11, 0.06))
    cotton = bc.fabric("WhiteCotton", (0.85, 0.85, 0.85))
    bc.block("BedFrame", (0.4, 1.85, 0.2), (1.9, 2.25, 0.3), wood_lacquer, bevel=0.02)
    bc.block("Headboard", (0.4, 2.93, 0.8), (1.9, 0.1, 1.1),
             bc.fabric("HeadboardVelvet", (0.25, 0.3, 0.4)), bevel=0.03, subdiv=4)
    bc.block("Mattress", (0.4, 1.85, 0.5), (1.8, 2.1, 0.25), cotton, bevel=0.05, subdiv=4)
    _duvet("Duvet", 600, 360, bc.fabric("DuvetLinen", (0.75, 0.7, 0.62)))
    for k, (x, y, z, r) in enumerate(((0.0, 2.6, 0.75, 8), (0.8, 2.6, 0.75, -6),
                                      (0.05, 2.42, 0.82, -4), (0.75, 2.42, 0.82, 5))):
        bc.block(f"Pillow{k}", (x, y, z), (0.7, 0.18 if k < 2 else 0.14, 0.4), cotton,
                 rot_z=r, subdiv=5)

    # ---- nightstands with lamps, dresser, wardrobe, armchair ----
    shade = bc.fabric("ShadeSilk", (0.9, 0.85, 0.75))
    ceramic = bc.coated("BlueCeramic", (0.1, 0.2, 0.5))
    for k, x in enumerate((-0.9, 1.7)):
        bc.block(f"Nightstand{k}", (x, 2.7, 0.28), (0.5, 0.45, 0.55), wood_lacquer, bevel=0.01)
        bc.table_lamp(f"TableLamp{k}", x, 2.7, 0.555, 60.0, shade, ceramic)
    bc.block("Dresser", (-2.6, 2.65, 0.45), (1.4, 0.5, 0.9), wood_lacquer, bevel=0.01)
    bc.suzanne("DresserSuzanne", (-2.9, 2.6, 1.15), 0.22,
               bc.metal("Silver", (0.97, 0.96, 0.91), 0.1), levels=4, rot_z=25)
    _vase("DresserVase", -2.2, 2.65, 0.9, 0.8, bc.glass("VaseGlass"), 2)
    bc.block("Wardrobe", (3.1, 0.2, 1.1), (0.7, 2.0, 2.2), paint, bevel=0.01)
    chair = bc.fabric("ArmchairWool", (0.55, 0.25, 0.15))
    bc.block("ArmchairBase", (2.2, -1.2, 0.25), (0.85, 0.8, 0.35), chair, rot_z=-30, bevel=0.03)
    bc.block("ArmchairCushion", (2.2, -1.2, 0.5), (0.7, 0.7, 0.18), chair, rot_z=-30,
             bevel=0.04, subdiv=4)
    bc.block("ArmchairBack", (2.4, -0.87, 0.75), (0.85, 0.2, 0.7), chair, rot_z=-30, bevel=0.04,
             subdiv=3)

    # ---- rug, pendant ----
    def pile(u, v):
        return (-1.2 + 3.2 * u, -0.9 + 2.2 * v,
                0.008 + 0.004 * np.sin(350 * u) * np.sin(240 * v))
    bc.grid("Rug", 550, 400, pile, bc.fabric("RugWool", (0.5, 0.15, 0.12)))
    bc.pendant("Pendant", 0.4, 0.2, h, 0.7, 100.0, bc.coated("OpalGlass", (0.9, 0.9, 0.9)),
               bc.metal("BrassCord", (0.9, 0.7, 0.4), 0.3), r_bottom=0.3, r_top=0.1, height=0.35)

    bc.look((-0.8, -2.9, 1.55), (0.4, 1.2, 0.7), 18.0)
    fill = bc.curtain_fill({"CurtainA": (2.0, 2.95, 3.4, 2.95, 0.05, 2.7),
                            "CurtainB": (3.47, 2.9, 3.47, 1.3, 0.05, 2.7)},
                           bc.fabric("CurtainVelvet", (0.3, 0.35, 0.3)))
    return bc.finish(BEDROOM_TARGET, fill, keep_uvs=("Floor",))

