"""`monkeybox`: the paper's smallest scene (196K triangles, 1024 x 1024) in character: three
level-3 Suzannes (metal, glass, lacquer) on pedestals in a closed room with a wooden floor, lit
only by lights inside fixtures (a pendant shade, two ceiling recesses)."""

import numpy as np

import bench_common as bc

TARGET = 196_000
RES = (1024, 1024)


def monkeybox():
    bc.start(*RES)
    wall = bc.matte("WallPaint", (0.75, 0.73, 0.7))
    back = bc.matte("BackWallPaint", (0.35, 0.45, 0.6))
    trim = bc.matte("TrimWhite", (0.85, 0.85, 0.85))
    floor = bc.wood("FloorWood")
    x0, x1, y0, y1, h = -2.5, 2.5, -3.0, 2.5, 3.0
    holes = [bc.recessed_light("RecessedLeft", -1.4, 0.6, h, 0.4, 0.2, 150.0, trim),
             bc.recessed_light("RecessedRight", 1.4, 0.6, h, 0.4, 0.2, 150.0, trim)]
    bc.room(x0, x1, y0, y1, h, floor, wall, wall, holes, floor_uv=(5, 5.5))
    bc.mesh_object("BackWall", [(x0, y1 - 0.01, 0), (x1, y1 - 0.01, 0), (x1, y1 - 0.01, h),
                                (x0, y1 - 0.01, h)], [[0, 1, 2, 3]], back)

    stone = bc.coated("PedestalLacquer", (0.8, 0.78, 0.72))
    looks = [("Gold", bc.metal("Gold", (1.0, 0.71, 0.29), 0.2)),
             ("Glass", bc.glass("MonkeyGlass")),
             ("Red", bc.coated("RedLacquer", (0.6, 0.05, 0.04)))]
    for k, (name, mat) in enumerate(looks):
        x = -1.4 + 1.4 * k
        bc.block(f"Pedestal{name}", (x, 0.6, 0.45), (0.6, 0.6, 0.9), stone, bevel=0.02)
        bc.suzanne(f"Suzanne{name}", (x, 0.6, 1.3), 0.42, mat, levels=3, rot_z=-12 + 12 * k)

    velvet = bc.fabric("BlueVelvet", (0.1, 0.15, 0.4))
    brass = bc.metal("Brass", (0.9, 0.7, 0.4), 0.35)
    bc.pendant("Pendant", -0.2, -0.6, h, 1.0, 200.0, bc.fabric("ShadeLinen", (0.85, 0.8, 0.7)),
               brass)
    bc.look((0.0, -2.8, 1.6), (0.0, 0.6, 1.0), 24.0)

    def rug(name, tris):
        n = max(2, round((tris / 2) ** 0.5))
        bc.grid(name, n, n, lambda u, v: (-2.0 + 4.0 * u, -1.2 + 2.8 * v,
                                          0.004 + 0.003 * np.sin(40 * u) * np.sin(40 * v)),
                velvet)
    return bc.finish(TARGET, (rug, ["Rug"]), keep_uvs=("Floor",))
