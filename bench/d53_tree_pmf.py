"""D53 (docs/difftest.md): a lamp with Cast Shadow off makes the image depend on the light
pick's probabilities. Renders the D53 case (tests/cycles/difftest_cases/) with Cycles, its light
tree on or off, or with Lantern, its light tree on or off (LANTERN_LIGHT_TREE=0: the global
power CDF), and stores each seed's 8 x 8 block means; `compare` runs the agreement test
(lantern.metrics.compare_renders) on every pair and prints block (2, 2).

    nice .venv/bin/python bench/d53_tree_pmf.py render cycles-tree --spp 64 --out DIR
    nice .venv/bin/python bench/d53_tree_pmf.py render lantern-cdf --spp 256 --shadow --out DIR
    .venv/bin/python bench/d53_tree_pmf.py compare DIR

--shadow: every lamp casts shadows (the control: the pick's probabilities then change nothing).
One thread each side; Cycles without its roulette (tools/difftest_run.py's settings).
"""
import argparse
import glob
import json
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "python"))
CASE = os.path.join(ROOT, "tests", "cycles", "difftest_cases",
                    "d53_unshadowed_lamp_beside_crossing_lamp.json")
VARIANTS = ("cycles-tree", "cycles-notree", "lantern-tree", "lantern-cdf")


def render(variant, seeds, spp, shadow):
    if variant == "lantern-cdf":   # read when the scene is built (scene_lights.cpp)
        os.environ["LANTERN_LIGHT_TREE"] = "0"
    import difftest_run  # noqa: F401 (Cycles' roulette off, as the tester renders)
    import difftest
    import difftest_build as db
    case = json.load(open(CASE))["case"]
    db.build(case)
    import bpy
    if shadow:
        for o in bpy.data.objects:
            if o.type == "LIGHT":
                o.data.use_shadow = True
    ids = list(range(1, seeds + 1))
    if variant.startswith("cycles"):
        base = difftest.cycles_settings

        def settings(sc, *a):
            base(sc, *a)
            sc.cycles.use_light_tree = variant == "cycles-tree"
        difftest.cycles_settings = settings
        imgs = difftest.render_cycles(case["bounces"], ids, spp, 1)
    else:
        scene, _ = difftest.export_lantern()
        imgs = difftest.render_lantern(scene, case["bounces"], ids, spp, "pt", 1)
    a = np.stack(imgs)
    k, h, w, c = a.shape
    return a.reshape(k, h // 8, 8, w // 8, 8, c).mean(axis=(2, 4))


def compare(out):
    from lantern import metrics
    sets = {os.path.basename(p)[:-4]: np.load(p)["blocks"]
            for p in sorted(glob.glob(f"{out}/*.npz"))}
    for n, b in sets.items():
        m, se = b[:, 2, 2].mean(0), b[:, 2, 2].std(0, ddof=1) / np.sqrt(len(b))
        print(f"{n:26s} block (2, 2) {np.round(m, 4)} +- {np.round(se, 4)}")
    names = list(sets)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if a.split("_")[1:] != b.split("_")[1:]:   # same shadow and spp only
                continue
            r = metrics.compare_renders(list(sets[a]), list(sets[b]), block=1, alpha=1e-3)
            print(f"{a} vs {b}: {'agree' if r.passed else 'DIFFER'}, worst z "
                  f"{float(r.blocks.worst):.1f} at {tuple(int(x) for x in r.blocks.worst_index)}, "
                  f"image mean {np.round(100 * (r.mean_a / r.mean_b - 1), 2)} %")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("what", choices=("render", "compare"))
    p.add_argument("variant", nargs="?", choices=VARIANTS)
    p.add_argument("--seeds", type=int, default=16)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--shadow", action="store_true")
    p.add_argument("--out", default="bench/results/2026-12-07-fixd53")
    a = p.parse_args()
    if a.what == "compare":
        return compare(a.out)
    b = render(a.variant, a.seeds, a.spp, a.shadow)
    os.makedirs(a.out, exist_ok=True)
    name = f"{a.variant}_{'shadow' if a.shadow else 'noshadow'}_{a.spp}"
    np.savez_compressed(os.path.join(a.out, name + ".npz"), blocks=b)
    print(name, "saved")


if __name__ == "__main__":
    main()
