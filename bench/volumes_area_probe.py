"""A probe of Lantern against Cycles on the fog cube of tests/cycles/test_volumes_nested.py under
an area light (volumes3, bench/results/2026-12-04-volumes3): the image mean ratio and the 4 x 4
block ratios of 2 seeds x SPP each, for a variant of the scene. Run inside bpy's Python:

    nice python bench/volumes_area_probe.py big      # the 1.5 m light 1 m above the fog
    nice python bench/volumes_area_probe.py small    # a 0.2 m light there
    nice python bench/volumes_area_probe.py far      # the 1.5 m light 4 m above the fog
    nice python bench/volumes_area_probe.py nofog    # no fog (the light alone)

(--root DIR: another checkout's lantern, a "before" measurement)."""
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if "--root" in sys.argv:
    ROOT = os.path.abspath(sys.argv[sys.argv.index("--root") + 1])
sys.path.insert(0, os.path.join(ROOT, "python"))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "tests", "cycles"))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy  # noqa: E402
import render_compare as rc  # noqa: E402
import test_volumes_nested as t  # noqa: E402

SPP = 128


def main():
    variant = sys.argv[1]
    t.nested()
    light = bpy.data.objects["AREA"]
    light.data.size = 1.5
    bpy.data.objects.remove(bpy.data.objects["inner"])
    if variant == "small":
        light.data.size = 0.2
    elif variant == "far":
        light.location = (0.3, -0.6, 6.0)
    elif variant == "nofog":
        bpy.data.objects.remove(bpy.data.objects["fog"])
    cyc = np.mean([rc.render_cycles(seed=980 + k, spp=SPP)[0] for k in range(2)], axis=0)
    lan = np.mean([rc.render_lantern(seed=1 + k, spp=SPP, threads=2)[0] for k in range(2)],
                  axis=0)
    blocks = lambda x: x.reshape(4, 8, 4, 8, 3).mean(axis=(1, 3, 4))  # noqa: E731
    print(variant, "image mean ratio Lantern / Cycles", lan.mean() / cyc.mean())
    with np.errstate(invalid="ignore", divide="ignore"):
        print(np.round(blocks(lan) / blocks(cyc), 3))


if __name__ == "__main__":
    main()
