"""Pools of 1-spp pt images and cis moment images per scene (64x64), for offline pilot study."""
import os
import sys, json, time
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/
import lantern
from lantern import scenes
from auto_efficiency import SCENES
res = int(sys.argv[1]); npool = int(sys.argv[2]); names = sys.argv[3].split(",")
LUMA = np.array([0.2126, 0.7152, 0.0722])
def cost(st, cis, pixels):
    v = st["rays_camera"] + st["rays_indirect"]
    cam = v + st["rays_shadow"] + st["rays_connection"] + (0.36 * 10 * v if cis else 0)
    light = st["rays_light"] + st["rays_light_tracing"]
    return cam / pixels, light / pixels
for name in names:
    b, kw = SCENES[name]
    sc = getattr(scenes, b)(res, res, **kw)
    pt, cis, cpt, ccis = [], [], [], []
    t0 = time.time()
    for k in range(npool):
        s = lantern.Session(sc, integrator="pt", seed=50000 + k, backend="cpu", threads=1, max_depth=12)
        s.step(); pt.append(s.image().astype(np.float64) @ LUMA); cpt.append(cost(s.stats, False, res*res))
        s = lantern.Session(sc, integrator="cis", seed=60000 + k, backend="cpu", threads=1, max_depth=12,
                            moment_channels=True)
        s.step(); cis.append(s.image().astype(np.float64)); ccis.append(cost(s.stats, True, res*res))
    np.savez(f"/tmp/auto4/pool_{name}_{res}.npz", pt=np.array(pt), cis=np.array(cis),
             cpt=np.array(cpt), ccis=np.array(ccis))
    print(name, round(time.time() - t0, 1), np.mean(cpt, axis=0), np.mean(ccis, axis=0), flush=True)
