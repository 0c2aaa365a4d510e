import sys
import numpy as np
sys.argv = sys.argv[:1] + ["64", "x"]
exec(open("/tmp/auto4/sim.py").read().split("variants = {")[0])
res = 64
names = "cornell,many_lights,room_area_point,room_spot_sun_world,principled,glossy,fixture,glass_lantern".split(",")
V = {"4pt+2cis": (4, 2, 1), "2pt+2cis@1/4": (2, 2, 4), "2pt+2cis@1/8": (2, 2, 8), "3pt+2cis@1/8": (3, 2, 8),
     "2pt+3cis@1/8": (2, 3, 8), "2pt+2cis@1/16": (2, 2, 16), "2pt+3cis@1/16": (2, 3, 16)}
rng = np.random.default_rng(3)
for name in names:
    d = np.load(f"/tmp/auto4/pool_{name}_{res}.npz")
    pt = d["pt"].reshape(len(d["pt"]), -1); cis = d["cis"].reshape(len(d["cis"]), -1, 3)
    cpt = d["cpt"].sum(axis=1).mean(); ccam, cl = d["ccis"].mean(axis=0)
    P = pt.shape[1]; out = []
    for v, (n, nc, fc) in V.items():
        ests = []
        for trial in range(60):
            ip = rng.choice(len(pt), n, replace=False); ic = rng.choice(len(cis), nc, replace=False)
            pix_c = np.arange(rng.integers(fc), P, fc)
            ests.append(estimate(pt[ip], cis[ic], cpt, ccam + cl, np.arange(P), pix_c))
        ests = np.array(ests)
        cost = n + nc * (ccam / fc + cl) / cpt
        out.append(f"{v}: cost {cost:.1f}, cis {np.mean(ests > 1):.2f}, med {np.median(ests):.2f} [{np.percentile(ests, 5):.2f}, {np.percentile(ests, 95):.2f}] min {ests.min():.2f} max {ests.max():.2f}")
    print(name, "\n  " + "\n  ".join(out), flush=True)
