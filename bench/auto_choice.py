"""auto's choice per seed (deterministic): after the pilot (first step) and after STEPS steps,
with its estimate of cis over pt and pt's tail (auto_pt_tail: pt's variance through the MIS
identity over its own samples'). No timing.

    PYTHONPATH=python .venv/bin/python bench/auto_choice.py RES STEPS SEEDS [scenes]
"""
import sys
from pathlib import Path

import lantern
from lantern import scenes

sys.path.insert(0, str(Path(__file__).resolve().parent))
from auto_efficiency import SCENES  # noqa: E402

res, steps, seeds = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
names = sys.argv[4].split(",") if len(sys.argv) > 4 else list(SCENES)
for name in names:
    b, kw = SCENES[name]
    sc = getattr(scenes, b)(res, res, **kw)
    out = []
    for k in range(seeds):
        s = lantern.Session(sc, integrator="auto", seed=1000 + k, backend="cpu", threads=1,
                            max_depth=12, spp_per_iteration=1)
        s.step()
        st = s.stats
        first = f"{st['auto_choice']} ({st['auto_cis_over_pt']:.2f}, tail {st['auto_pt_tail']:.2f})"
        for _ in range(steps - 1):
            s.step()
        st = s.stats
        out.append(f"{first} -> {st['auto_choice']} ({st['auto_cis_over_pt']:.2f}; "
                   f"pt {st['auto_pt_iterations']}, cis {st['auto_cis_iterations']})")
    print(f"| {name} | " + " <br> ".join(out) + " |", flush=True)
