"""Instruction counts (callgrind) of one build for the rows given, one line per row, as
bench/results/2026-12-02-cpu-speed/README.md's attribution table used them:

    python bench/cpu_speed_counts.py PKG SIZE STEPS scene:integrator [scene:integrator ...]

PKG: the python folder of the build to count (its lantern package first on the path)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cpu_speed_ab  # noqa: E402

if __name__ == "__main__":
    pkg, size, steps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    for row in sys.argv[4:]:
        scene, integ = row.rsplit(":", 1)
        print(pkg, scene, integ, size, steps,
              cpu_speed_ab.instructions(pkg, integ, scene, size, steps), flush=True)
