import copy, json, sys
sys.path.insert(0, "tools"); sys.path.insert(0, "python")
import difftest as dt
import difftest_build as db
import render_compare as rc
import numpy as np
from lantern import metrics
orig = rc.cycles_settings
def no_tree(sc, *a, **k):
    orig(sc, *a, **k)
    sc.cycles.use_light_tree = False
rc.cycles_settings = no_tree
doc = json.load(open("bench/results/2026-12-06-difftest4/pt/case-full-8003.json"))
case = doc["case"]
def cyc(c):
    db.build(c)
    return np.stack(dt.render_cycles(c["bounces"], list(range(1, 17)), 32, 1)).astype(np.float64)
A = cyc(case)
c2 = copy.deepcopy(case); c2["linking"] = []
B = cyc(c2)
print("NOTREE", metrics.compare_renders(A, B, block=8, name="Cycles (light tree off) linked vs unlinked"))
