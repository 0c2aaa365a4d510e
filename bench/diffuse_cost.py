"""Time per sample of a diffuse-only scene (the Cornell box, 128 x 128, 4 spp per iteration,
best of 5 double steps) for pt and cis: run it on two builds to see what new material code
costs a scene that does not use it. Usage: bench/diffuse_cost.py [path to a lantern package
parent; default: this checkout python/]"""
import sys, time
import os
sys.path.insert(0, sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import lantern
from lantern import scenes
print(lantern.__file__)
sc = scenes.cornell_box(width=128, height=128)
for integ in ["pt", "cis"]:
    s = lantern.Session(sc, integrator=integ, seed=1, spp_per_iteration=4)
    s.step()
    best = 1e9
    for rep in range(5):
        t = time.perf_counter(); s.step(); s.step(); best = min(best, time.perf_counter() - t)
    print(integ, f"{best/8*1000:.2f} ms per spp (best of 5)")
