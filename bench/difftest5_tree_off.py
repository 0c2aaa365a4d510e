"""A tester case (.json) compared with Cycles whose light tree is off (use_light_tree False;
Lantern as always), to tell a Lantern difference from Cycles' light tree with linked lights
(fixlink found 8003's excess to be the tree's). difftest5 (cis 10022).

    nice .venv/bin/python bench/difftest5_tree_off.py CASE.json --integrator pt --spp 64 \
        [--tree on|off] [--edit "c.pop('linking')"] [--json OUT.jsonl]
"""
import argparse
import json
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import difftest_run as dr  # noqa: E402
import render_compare as rc  # noqa: E402

dt = dr.difftest


def main():
    p = argparse.ArgumentParser()
    p.add_argument("case")
    p.add_argument("--integrator", default="pt")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--seeds", type=int, default=16)
    p.add_argument("--base", type=int, default=5000)
    p.add_argument("--tree", default="off", choices=("on", "off"))
    p.add_argument("--edit", default="")
    p.add_argument("--json", default=None)
    a = p.parse_args()
    if a.tree == "off":
        orig = rc.cycles_settings

        def no_tree(sc, *args, **kw):
            orig(sc, *args, **kw)
            sc.cycles.use_light_tree = False
        rc.cycles_settings = no_tree
    doc = json.load(open(a.case))
    c = doc.get("case", doc)
    exec(a.edit, {"c": c})
    st = dt.Settings(seeds=a.seeds, spp=a.spp, cycles_spp=a.spp, integrator=a.integrator)
    t0 = time.process_time()
    res = dt.run_case(c, st, base=a.base, controls=False)
    print(f"[tree {a.tree}{' ' + a.edit if a.edit else ''}] {a.integrator} {a.seeds}x{a.spp}: "
          f"{res.line()} (cpu {time.process_time() - t0:.0f} s)")
    print(res.text)
    if a.json:
        with open(a.json, "a") as f:
            f.write(json.dumps({"case": a.case, "tree": a.tree, "edit": a.edit,
                                "integrator": a.integrator, "seeds": a.seeds, "spp": a.spp,
                                "status": res.status, "mean_rel": res.mean_rel,
                                "worst_z": res.worst_z, "text": res.text}) + "\n")


if __name__ == "__main__":
    main()
