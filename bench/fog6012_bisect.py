"""Issue 32 / difftest case 6012 (a partly metallic glossy room in world Volume Absorption
fog, lamps): bisection by variants of the case with the room, its fog and its lights only.
Each variant renders both sides live (tools/difftest.py run_case, seeds base+1..) and prints
Lantern / Cycles - 1 per channel with the agreement test's verdict.

    nice .venv/bin/python bench/fog6012_bisect.py --spp 32 --integrator pt \
        --variant base "" --variant dense "fog(c, 10)" ... [--json out.jsonl]

Edits are Python statements on `c` (the case) with the helpers below in scope.
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

CASE = os.path.join(ROOT, "bench/results/2026-12-06-difftest3/bdpt/case-full-6012-original.json")


def room_only(c):
    """The room, its fog and lights (no plane, no hair)."""
    c["objects"] = [o for o in c["objects"] if o["kind"] == "room"]


def fog(c, factor):
    c["world_volume"]["nodes"]["v0"]["inputs"]["Density"] *= factor


def room(c, **inputs):
    c["materials"]["room"]["nodes"]["n0"]["inputs"].update(
        {k.replace("_", " "): v for k, v in inputs.items()})


def lamps(c, keep):
    c["lights"] = [l for k, l in enumerate(c["lights"]) if k in keep]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--spp", type=int, default=32)
    p.add_argument("--seeds", type=int, default=16)
    p.add_argument("--base", type=int, default=7000)
    p.add_argument("--integrator", default="pt")
    p.add_argument("--case", default=CASE)
    p.add_argument("--variant", nargs=2, action="append", metavar=("NAME", "EDIT"))
    p.add_argument("--json", default=None, help="append a line per variant")
    p.add_argument("--full", action="store_true", help="the whole case (plane and hair too)")
    p.add_argument("--no-roulette", action="store_true",
                   help="Cycles with Min Light Bounces at the bounce count (roulette off, "
                        "as tools/difftest_run.py renders it; D51)")
    a = p.parse_args()
    if a.no_roulette:
        import difftest_run  # noqa: F401 (patches difftest.cycles_settings)
    doc = json.load(open(a.case))
    case0 = doc.get("case", doc)
    st = dt.Settings(seeds=a.seeds, spp=a.spp, cycles_spp=a.spp, integrator=a.integrator)
    for name, edit in a.variant or [("base", "")]:
        c = copy.deepcopy(case0)
        if not a.full:
            room_only(c)
        exec(edit, dict(globals(), c=c))
        t0 = time.process_time()
        res = dt.run_case(c, st, base=a.base, controls=False)
        cpu = time.process_time() - t0
        print(f"[{name}] {a.integrator} {a.seeds}x{a.spp}"
              f"{' full' if a.full else ''}{' no-roulette' if a.no_roulette else ''}: "
              f"{res.line()} (cpu {cpu:.0f} s)",
              flush=True)
        if a.json:
            with open(a.json, "a") as f:
                f.write(json.dumps({"variant": name, "edit": edit, "integrator": a.integrator,
                                    "full": a.full, "no_roulette": a.no_roulette,
                                    "seeds": a.seeds, "spp": a.spp, "base": a.base,
                                    "status": res.status, "mean_rel": res.mean_rel,
                                    "detects": res.detects, "worst_z": res.worst_z,
                                    "text": res.text}) + "\n")


if __name__ == "__main__":
    main()
