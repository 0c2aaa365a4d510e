"""A fixed amount of work on a diffuse-only scene, for counting instructions with valgrind
(deterministic, unlike wall time on a shared machine): what new material code costs a scene
that does not use it. Run it for 1 and for k steps and take the difference (set-up cancels):

    valgrind --tool=callgrind --callgrind-out-file=/tmp/cg.out \\
        .venv/bin/python bench/material_cost.py <dir holding the lantern package> pt 3

The package directory may be another build's install (pip install --target DIR <checkout>)."""
import os
import sys

here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "python"))
import lantern  # noqa: E402
from lantern import scenes  # noqa: E402

integrator = sys.argv[2] if len(sys.argv) > 2 else "pt"
steps = int(sys.argv[3]) if len(sys.argv) > 3 else 1
session = lantern.Session(scenes.cornell_box(width=48, height=48), integrator=integrator,
                          seed=1, spp_per_iteration=4, threads=1)
for _ in range(steps):
    session.step()
