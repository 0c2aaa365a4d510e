import os
import sys, time
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/
import lantern
from lantern import scenes
from auto_efficiency import SCENES
res = int(sys.argv[1]); npool = int(sys.argv[2]); fr = float(sys.argv[3]); names = sys.argv[4].split(",")
for name in names:
    b, kw = SCENES[name]
    sc = getattr(scenes, b)(res, res, **kw)
    cis, cc = [], []
    t0 = time.time()
    for k in range(npool):
        s = lantern.Session(sc, integrator="cis", seed=70000 + k, backend="cpu", threads=1, max_depth=12,
                            moment_channels=True, light_path_fraction=fr)
        s.step(); cis.append(s.image().astype(np.float64)); st = s.stats
        v = st["rays_camera"] + st["rays_indirect"]
        cc.append(((v + st["rays_shadow"] + st["rays_connection"] + 3.6 * v) / res**2,
                   (st["rays_light"] + st["rays_light_tracing"]) / res**2))
    np.savez(f"/tmp/auto4/poollf_{name}_{res}_{fr}.npz", cis=np.array(cis), ccis=np.array(cc))
    print(name, fr, round(time.time() - t0, 1), np.mean(cc, axis=0), flush=True)
