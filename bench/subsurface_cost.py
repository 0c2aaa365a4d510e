"""What subsurface scattering costs (docs/subsurface.md): pt's time per sample on the unit sphere
of tests/python/test_subsurface_scene.py (base colour 0.9, 0.6, 0.5) with the walk (Random Walk, Skin) against the same
sphere without it, and the scenes without subsurface (principled_box) on this build, to set
beside another build's run of the same script (PYTHONPATH picks the build). Interleaved
repetitions, the median reported, the machine (CPU, load) recorded: on a shared machine only
large differences mean anything.

    PYTHONPATH=python python bench/subsurface_cost.py [--reps 5] [--spp 8]"""
import argparse
import os
import platform
import statistics
import sys
import time

import lantern  # noqa: E402
from lantern import scenes  # noqa: E402


def _sphere(sss=None):
    """A unit icosphere, camera 4 m away, world white (test_subsurface_scene's sphere)."""
    s = lantern.Scene()
    s.film.update(width=32, height=32)
    s.look_at((0.0, -4.0, 0.0), (0.0, 0.0, 0.0), fov=32.0)
    s.world = {"color": [1.0, 1.0, 1.0]}
    kw = {"subsurface": sss} if sss else {}
    m = s.add_material("ball", type="principled", base_color=(0.9, 0.6, 0.5), roughness=0.5,
                       **kw)
    pos, idx = scenes.icosphere(3)
    s.add_mesh(pos, idx, material=m)
    return s


def cases():
    out = {"principled_box (no subsurface)": scenes.principled_box(width=32, height=32),
           "sphere, no subsurface": _sphere()}
    if "subsurface" in lantern.Scene.add_material.__code__.co_varnames:
        for method in ("random_walk", "random_walk_skin"):
            out[f"sphere, {method}"] = _sphere({"weight": 1.0, "radius": [1.0, 0.5, 0.25],
                                                "method": method})
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--spp", type=int, default=8)
    a = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, "
          f"load {os.getloadavg()[0]:.1f}; lantern from {os.path.dirname(lantern.__file__)}")
    times = {name: [] for name in cases()}
    for _ in range(a.reps):
        for name, scene in cases().items():
            t0 = time.perf_counter()
            lantern.render(scene, spp=a.spp, seed=1, threads=1, integrator="pt", max_depth=8)
            times[name].append((time.perf_counter() - t0) / a.spp)
    for name, t in times.items():
        print(f"{name:36s} {1e3 * statistics.median(t):8.2f} ms/spp (median of {a.reps})")


if __name__ == "__main__":
    main()
