"""Render a tester case (.json) and variants of it (Python statements editing `c`, the case)
on both sides and print each comparison: bisection by hand (difftest4, seed 6012).

    nice .venv/bin/python bench/difftest4_variants.py CASE.json --spp 32 --integrator pt \
        --variant base "" --variant nofog "c.pop('world_volume')" ...
"""
import argparse
import copy
import json
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import difftest as dt  # noqa: E402


def main():
    p = argparse.ArgumentParser()
    p.add_argument("case")
    p.add_argument("--spp", type=int, default=32)
    p.add_argument("--seeds", type=int, default=16)
    p.add_argument("--base", type=int, default=0)
    p.add_argument("--integrator", default="pt")
    p.add_argument("--variant", nargs=2, action="append", metavar=("NAME", "EDIT"))
    p.add_argument("--json", default=None, help="append a line per variant")
    a = p.parse_args()
    doc = json.load(open(a.case))
    case0 = doc.get("case", doc)
    st = dt.Settings(seeds=a.seeds, spp=a.spp, cycles_spp=a.spp, integrator=a.integrator)
    for name, edit in a.variant or [("base", "")]:
        c = copy.deepcopy(case0)
        exec(edit, {"c": c})
        t0 = time.process_time()
        res = dt.run_case(c, st, base=a.base, controls=False)
        cpu = time.process_time() - t0
        print(f"[{name}] {a.integrator} {a.seeds}x{a.spp}: {res.line()} (cpu {cpu:.0f} s)",
              flush=True)
        if a.json:
            with open(a.json, "a") as f:
                f.write(json.dumps({"case": a.case, "variant": name, "edit": edit,
                                    "integrator": a.integrator, "seeds": a.seeds,
                                    "spp": a.spp, "base": a.base, "status": res.status,
                                    "mean_rel": res.mean_rel, "worst_z": res.worst_z,
                                    "worst_block": res.worst_block, "text": res.text}) + "\n")


if __name__ == "__main__":
    main()
