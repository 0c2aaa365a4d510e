"""The tables of bench/results/2026-12-07-difftest7/README.md from its logs: cases per
integrator and class (the first comparison's status; "confirmed" / "not confirmed" from the
investigation), and the seeds that differ.

    .venv/bin/python bench/difftest7_table.py [bench/results/2026-12-07-difftest7]
"""
import json
import os
import sys

INTEGRATORS = ("bdpt", "cis", "lvc", "auto", "pt")


def rows(root):
    for phase in ("p1", "p2"):
        for integ in INTEGRATORS:
            path = os.path.join(root, phase, integ, "log.jsonl")
            if os.path.exists(path):
                with open(path) as f:
                    for line in f:
                        yield phase, integ, json.loads(line)


def main(root):
    table = {}
    for phase, integ, e in rows(root):
        st = e["result"]["status"]
        inv = e.get("investigation") or {}
        if st == "differ":
            st = "differ" if inv.get("verdict", "").startswith("confirmed") else "not confirmed"
        t = table.setdefault((phase, integ), {"cases": 0, "seeds": []})
        t["cases"] += 1
        t[st] = t.get(st, 0) + 1
        if st in ("differ", "not confirmed"):
            r = e["result"]
            t["seeds"].append(f"{e['seed']} ({r['mean_rel'][0]:+.1%}, z {r['worst_z']:.1f})")
    cols = ("agree", "inconclusive", "unsupported", "black", "not confirmed", "differ")
    print("| set | integrator | cases | " + " | ".join(cols) + " | seeds that differ |")
    print("|---" * (len(cols) + 4) + "|")
    for (phase, integ), t in sorted(table.items(), key=lambda kv: (
            kv[0][0], INTEGRATORS.index(kv[0][1]))):
        print(f"| {phase} | {integ} | {t['cases']} | " +
              " | ".join(str(t.get(c, 0)) for c in cols) + f" | {', '.join(t['seeds'])} |")
    per = {}
    for phase, integ, e in rows(root):
        per.setdefault((phase, e["seed"]), {})[integ] = e["result"]["status"]
    print()
    for (phase, seed), d in sorted(per.items()):
        print(f"{phase} {seed}: " + ", ".join(f"{i} {d[i]}" for i in INTEGRATORS if i in d))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "results", "2026-12-07-difftest7"))
