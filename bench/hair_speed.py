"""Seconds per sample of a fur ball (lantern.scenes_hair.fur_ball) with pt on one thread, against
the same ball without its fur, through Embree's curves and the built-in curve BVH:

    python bench/hair_speed.py [SIZE] [STRANDS] [SPP]

Prints one line per (accel, fur) with the median of 3 runs; the machine's load beside it."""
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "python"))
import lantern  # noqa: E402
from lantern.scenes_hair import fur_ball  # noqa: E402


def seconds(scene, spp):
    s = lantern.Session(scene, integrator="pt", backend="cpu", threads=1, seed=1, max_depth=8,
                        spp_per_iteration=spp)
    t = time.perf_counter()
    s.step()
    return (time.perf_counter() - t) / spp


if __name__ == "__main__":
    size = int(sys.argv[1]) if len(sys.argv) > 1 else 64
    strands = int(sys.argv[2]) if len(sys.argv) > 2 else 3000
    spp = int(sys.argv[3]) if len(sys.argv) > 3 else 4
    for accel in ("embree", "bvh"):
        os.environ["LANTERN_ACCEL"] = accel
        for fur in (True, False):
            scene = fur_ball(size, size, num_strands=strands)
            if not fur:
                scene.curves = []
            runs = sorted(seconds(scene, spp) for _ in range(3))
            segs = sum(len(c["points"]) - len(c["offsets"]) + 1 for c in scene.curves)
            print(f"{accel:6s} {'fur' if fur else 'bare':4s} {segs:7d} segments: "
                  f"{runs[1] * 1e3:8.1f} ms/spp at {size}x{size} (load {os.getloadavg()[0]:.1f})",
                  flush=True)
