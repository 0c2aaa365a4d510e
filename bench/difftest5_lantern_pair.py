"""Render a tester case (.json) with two Lantern integrators at their own samples and compare
them block by block (the tester's statistics, no Cycles): is a bidirectional integrator's
difference from Cycles its own, or what a path tracer misses at the run's samples? difftest5.

    nice .venv/bin/python bench/difftest5_lantern_pair.py CASE.json --a bdpt:16 --b pt:256 \
        [--edit "c['camera'].pop('motion')"] [--edit-b "c.pop('linking')"] [--seeds 16] \
        [--base 5000]
"""
import argparse
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import difftest_run as dr  # noqa: E402

dt = dr.difftest


def main():
    p = argparse.ArgumentParser()
    p.add_argument("case")
    p.add_argument("--a", default="bdpt:16")
    p.add_argument("--b", default="pt:256")
    p.add_argument("--seeds", type=int, default=16)
    p.add_argument("--base", type=int, default=5000)
    p.add_argument("--edit", default="")
    p.add_argument("--edit-b", default=None, help="side b renders the case with this edit "
                   "too (after --edit), exported again: one integrator, two scenes")
    p.add_argument("--save", default=None, help="an .npz of both sides")
    a = p.parse_args()
    doc = json.load(open(a.case))
    c = doc.get("case", doc)
    exec(a.edit, {"c": c})
    dt.db.build(c)
    scene, warned = dt.export_lantern()
    print("warnings", warned)
    seeds = [a.base + 1 + k for k in range(a.seeds)]
    out = {}
    if a.edit_b is not None and a.a == a.b:
        a.b += " (edited)"
    for side in (a.a, a.b):
        if side == a.b and a.edit_b is not None:
            exec(a.edit_b, {"c": c})
            dt.db.build(c)
            scene, warned = dt.export_lantern()
            print("warnings (b)", warned)
        integ, spp = side.split(" ")[0].split(":")
        t0 = time.process_time()
        out[side] = dt.render_lantern(scene, c["bounces"], seeds, int(spp), integ, 1)
        print(f"{side}: {time.process_time() - t0:.1f} s CPU")
    res = dr.compare(out[a.a], out[a.b], controls=False)
    print(f"{a.a} against {a.b}: {res.line()}")
    print(res.text)
    for side, x in out.items():
        x = np.stack(x)
        bl = x.reshape(x.shape[0], 4, 8, 4, 8, 3).mean(axis=(2, 4))
        print(side, "block means (channel 1):")
        print(np.array2string(bl.mean(axis=0)[..., 1], precision=4))
    if a.save:
        np.savez_compressed(a.save, **{k.replace(":", "_"): np.stack(v) for k, v in out.items()})


if __name__ == "__main__":
    main()
