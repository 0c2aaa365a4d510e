"""The world map's importance distribution is built once per content (scene/envmap_build.cpp
build_envmap_cached), not per Session: a viewport restart makes a new Session from the same
export. Times lantern.Session construction for a scene lit by a map (bpy's sunset.exr,
1024 x 512, or a synthetic map of the same size without bpy) the first time and again.

    .venv/bin/python bench/world_envmap_cache.py [--width 1024]
"""

import argparse
import os
import platform
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                "python"))
import lantern  # noqa: E402  (this checkout's)


def sunset_or_synthetic(width):
    try:
        import bpy
        path = os.path.join(bpy.utils.system_resource("DATAFILES"), "studiolights", "world",
                            "sunset.exr")
        img = bpy.data.images.load(path)
        w, h = img.size
        px = np.empty(w * h * 4, np.float32)
        img.pixels.foreach_get(px)
        return "sunset.exr", np.ascontiguousarray(px.reshape(h, w, 4)[..., :3])
    except ImportError:
        h = width // 2
        rng = np.random.default_rng(1)
        return "synthetic", rng.random((h, width, 3), np.float32)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    name, rgb = sunset_or_synthetic(a.width)
    scene = lantern.Scene()
    scene.film.update(width=32, height=32)
    scene.world = {"color": [0.0, 0.0, 0.0], "map": rgb, "strength": [1.0, 1.0, 1.0]}
    times = []
    for _ in range(a.repeats):
        t0 = time.perf_counter()
        lantern.Session(scene, integrator="pt", threads=1)
        times.append(time.perf_counter() - t0)
    print(f"machine: {platform.node()} {platform.processor() or platform.machine()}")
    print(f"map {name} {rgb.shape[1]}x{rgb.shape[0]}: Session() first {times[0]:.3f} s, "
          f"then {', '.join(f'{t:.3f}' for t in times[1:])} s")


if __name__ == "__main__":
    main()
