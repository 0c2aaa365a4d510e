"""difftest4's case pt 8003 (an emissive ico whose Receiver Collection includes the room, four
unlinked lamps) bisected (fixlink; results: bench/results/2026-12-06-fixlink). Modes:
  lantern   Lantern pt, the case with and without its link (16 seeds x 32 spp)
  cycles    Cycles, with and without the link
  tree-off  Cycles with use_light_tree False, with and without the link
  noshadow  Lantern with the ico casting no shadow, and as is, each against Cycles (linked)

    nice .venv/bin/python bench/fixlink_8003.py MODE
"""
import copy
import json
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "python"))
import difftest as dt  # noqa: E402
import difftest_build as db  # noqa: E402
import render_compare as rc  # noqa: E402

CASE = os.path.join(ROOT, "bench/results/2026-12-06-difftest4/pt/case-full-8003.json")
SEEDS, SPP = list(range(1, 17)), 32


def _pair(render):
    from lantern import metrics
    case = json.load(open(CASE))["case"]
    unlinked = copy.deepcopy(case)
    unlinked["linking"] = []
    out = []
    for c in (case, unlinked):
        db.build(c)
        out.append(np.stack(render(c)).astype(np.float64))
    print(metrics.compare_renders(out[0], out[1], block=8, name="linked vs unlinked"))


def _lantern(c):
    scene, _ = dt.export_lantern()
    return dt.render_lantern(scene, c["bounces"], SEEDS, SPP, "pt", 1)


def _cycles(c):
    return dt.render_cycles(c["bounces"], SEEDS, SPP, 1)


def main(mode):
    if mode == "lantern":
        _pair(_lantern)
    elif mode in ("cycles", "tree-off"):
        if mode == "tree-off":
            orig = rc.cycles_settings

            def no_tree(sc, *a, **k):
                orig(sc, *a, **k)
                sc.cycles.use_light_tree = False
            rc.cycles_settings = no_tree
        _pair(_cycles)
    elif mode == "noshadow":
        case = json.load(open(CASE))["case"]
        st = dt.Settings(seeds=len(SEEDS), spp=SPP, cycles_spp=SPP, integrator="pt")

        def noshadow(scene):
            for m in scene.meshes:
                if m.get("name", "").startswith("ico"):
                    m["cast_shadow"] = False
        for name, mut in (("ico casts no shadow (Lantern)", noshadow), ("as is", None)):
            res = dt.run_case(copy.deepcopy(case), st, controls=False, mutate=mut)
            print(name, res.line(), flush=True)
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "")
