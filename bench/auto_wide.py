"""Integrator "auto" on scenes with a feature it used to give to pt alone (branch autowide:
motion blur, ...; tests/python/auto_wide_scenes.py): pt, cis and auto, efficiency
1 / (noise^2 x CPU time), one thread, seeds interleaved (bench/auto_efficiency.py's measure and
summary: noise = mean over pixels of the spread of the luminance between seeds over the mean;
time = process time of one render of --spp one-sample steps, median over seeds; `work` its
deterministic count). Does auto pick the better of pt and cis there?

    PYTHONPATH=python nice .venv/bin/python bench/auto_wide.py --scenes cornell_motion,\\
        lantern_motion --res 48x48 --spp 32 --seeds 6 --out bench/results/2026-12-06-autowide/motion
"""
import argparse
import json
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "python"))
import auto_efficiency as ae  # noqa: E402
import auto_wide_scenes as aws  # noqa: E402
from light_tree_noise import machine  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=",".join(aws.SCENES))
    ap.add_argument("--integrators", default="pt,cis,auto")
    ap.add_argument("--res", default="48x48")
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--max-depth", type=int, default=12)
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    w, h = (int(v) for v in args.res.split("x"))
    integrators = args.integrators.split(",")
    info = {"before": machine(), "command": " ".join(sys.argv)}
    rows = []
    for name in args.scenes.split(","):
        scene = aws.SCENES[name](w, h)
        runs = {i: [] for i in integrators}
        for k in range(args.seeds):
            for integ in integrators:
                runs[integ].append(ae.render_one(scene, integ, 1000 + k, args))
        for integ in integrators:
            r = ae.summarise(name, integ, runs[integ])
            rows.append(r)
            print(json.dumps(r), flush=True)
        by = {r["integrator"]: r for r in rows if r["scene"] == name}
        line = {"scene": name}
        for i in integrators:
            if i != "pt":
                line[f"{i}/pt"] = round(by[i]["efficiency"] / by["pt"]["efficiency"], 3)
                line[f"{i}/pt work"] = round(by[i]["efficiency_work"] /
                                             by["pt"]["efficiency_work"], 3)
        line["auto chose"] = by.get("auto", {}).get("auto")
        print(json.dumps(line), flush=True)
    info["after"] = machine()
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "auto_wide.json"), "w") as f:
            json.dump({"machine": info, "settings": vars(args), "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
