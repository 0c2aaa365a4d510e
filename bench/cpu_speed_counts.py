"""Instruction counts (callgrind) of one build for the rows given, one line per row, as
bench/results/2026-12-02-cpu-speed/README.md's attribution table used them:

    python bench/cpu_speed_counts.py PKG SIZE STEPS scene:integrator [scene:integrator ...]

PKG: the python folder of the build to count (its lantern package first on the path). With
CG_KEEP=DIR each row's callgrind file of the steps is kept as DIR/scene_integrator.cg, for
callgrind_annotate per function (a build linked unstripped: nanobind_add_module's NOSTRIP)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cpu_speed_ab  # noqa: E402

if __name__ == "__main__":
    pkg, size, steps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    for row in sys.argv[4:]:
        scene, integ = row.rsplit(":", 1)
        keep = os.environ.get("CG_KEEP")
        keep = keep and os.path.join(keep, f"{cpu_speed_ab.label(scene)}_{integ}.cg")
        print(pkg, scene, integ, size, steps,
              cpu_speed_ab.instructions(pkg, integ, scene, size, steps, keep), flush=True)
