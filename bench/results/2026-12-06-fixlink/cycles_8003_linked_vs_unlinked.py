import copy, json, sys
sys.path.insert(0, "tools"); sys.path.insert(0, "python")
import difftest as dt
import difftest_build as db
import numpy as np
from lantern import metrics
doc = json.load(open("bench/results/2026-12-06-difftest4/pt/case-full-8003.json"))
case = doc["case"]
def cyc(c, seeds=16, spp=32):
    db.build(c)
    return dt.render_cycles(c["bounces"], list(range(1, seeds + 1)), spp, 1)
a = cyc(case)
c2 = copy.deepcopy(case); c2["linking"] = []
b = cyc(c2)
A = np.stack(a).astype(np.float64) if isinstance(a, list) else a
B = np.stack(b).astype(np.float64) if isinstance(b, list) else b
print("CYCLES", metrics.compare_renders(A, B, block=8, name="Cycles linked vs Cycles unlinked"))
print("means", A.mean(axis=(0, 1, 2)), B.mean(axis=(0, 1, 2)))
