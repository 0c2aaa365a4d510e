import os
import sys
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/
import lantern
from lantern import scenes
from auto_efficiency import SCENES
res, n0, n = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
for name in sys.argv[4].split(","):
    b, kw = SCENES[name]
    sc = getattr(scenes, b)(res, res, **kw)
    out = []
    for k in range(n0, n0 + n):
        s = lantern.Session(sc, integrator="auto", seed=k, backend="cpu", threads=1, max_depth=12)
        s.step(); st = s.stats
        out.append((st["auto_choice"], round(st["auto_cis_over_pt"], 2), round(st["auto_pt_tail"], 2)))
    print(name, sum(c == "cis" for c, _, _ in out), "/", n, sorted(out, key=lambda x: x[1]), flush=True)
