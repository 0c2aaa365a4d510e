"""The tables of bench/results/2026-12-07-difftest8/README.md from its logs: cases per set and
integrator by class (the first comparison's status; "differ" where the confirmation confirmed
it, "not confirmed" where not, "caustic" where the glossy-caustic guard cleared it), and each
seed's row. bench/difftest7_table.py's, over the sets a results folder holds.

    .venv/bin/python bench/difftest8_table.py [bench/results/2026-12-07-difftest8]
"""
import json
import os
import sys

INTEGRATORS = ("bdpt", "cis", "lvc", "lt", "auto", "pt")
COLS = ("agree", "inconclusive", "unsupported", "black", "not confirmed", "caustic", "differ")


def rows(root):
    for phase in sorted(os.listdir(root)):
        for integ in INTEGRATORS:
            path = os.path.join(root, phase, integ, "log.jsonl")
            if os.path.isdir(os.path.join(root, phase)) and os.path.exists(path):
                with open(path) as f:
                    for line in f:
                        yield phase, integ, json.loads(line)


def status(e):
    st = e["result"]["status"]
    inv = e.get("investigation") or {}
    if st in ("differ", "nonfinite"):
        if inv.get("glossy_caustic"):
            return "caustic"
        return "differ" if inv.get("verdict", "").startswith("confirmed") else "not confirmed"
    return st


def main(root):
    table, per = {}, {}
    for phase, integ, e in rows(root):
        st = status(e)
        t = table.setdefault((phase, integ), {"cases": 0, "seeds": []})
        t["cases"] += 1
        t[st] = t.get(st, 0) + 1
        if st in ("differ", "not confirmed", "caustic"):
            r = e["result"]
            t["seeds"].append(f"{e['seed']} ({r['mean_rel'][0]:+.1%}, z {r['worst_z']:.1f}"
                              f"{'' if st == 'differ' else ', ' + st})")
        per.setdefault((phase, e["seed"]), {})[integ] = st
    print("| set | integrator | cases | " + " | ".join(COLS) + " | seeds that differ |")
    print("|---" * (len(COLS) + 4) + "|")
    for (phase, integ), t in sorted(table.items(), key=lambda kv: (
            kv[0][0], INTEGRATORS.index(kv[0][1]))):
        print(f"| {phase} | {integ} | {t['cases']} | " +
              " | ".join(str(t.get(c, 0)) for c in COLS) + f" | {', '.join(t['seeds'])} |")
    print()
    for (phase, seed), d in sorted(per.items()):
        print(f"{phase} {seed}: " + ", ".join(f"{i} {d[i]}" for i in INTEGRATORS if i in d))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "results", "2026-12-07-difftest8"))
