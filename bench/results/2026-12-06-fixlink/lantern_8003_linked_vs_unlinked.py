import copy, json, sys, os
sys.path.insert(0, "tools"); sys.path.insert(0, "python")
import difftest as dt
import difftest_build as db
import numpy as np
doc = json.load(open("bench/results/2026-12-06-difftest4/pt/case-full-8003.json"))
case = doc["case"]
def lan(c, seeds=16, spp=32):
    db.build(c)
    scene, w = dt.export_lantern()
    print("receivers", [(m.get("name"), m.get("light_set"), m.get("receivers")) for m in scene.meshes], w)
    return dt.render_lantern(scene, c["bounces"], list(range(1, seeds+1)), spp, "pt", 1)
a = lan(case)
c2 = copy.deepcopy(case); c2["linking"] = []
b = lan(c2)
from lantern import metrics
print(metrics.compare_renders(a, b, block=8, name="linked vs unlinked"))
print(a.mean(axis=(0,1,2)), b.mean(axis=(0,1,2)))
