"""Offline pilot variants from the pools: choice distribution and pilot cost."""
import sys, math
import numpy as np
from math import lgamma, exp, sqrt
res = int(sys.argv[1]); names = sys.argv[2].split(",")
def c4(m): return 1.0 if m < 2 else sqrt(2.0/(m-1))*exp(lgamma(m/2)-lgamma((m-1)/2))
def sdsum(x):  # x: (m, npx)
    m = x.shape[0]
    return np.sqrt(np.maximum(0, x.var(axis=0, ddof=1))).sum() if m > 1 else 0.0
def estimate(pt, cis, cpt, ccis, pix_pt, pix_cis):
    """pt: (n, P) lumas, cis: (nc, P, 3) moments; pix_*: index arrays. Per-pixel means of sd."""
    n, nc = len(pt), len(cis)
    sd_pt = sdsum(pt[:, pix_pt]) / len(pix_pt) / c4(n)
    c = cis[:, pix_cis]
    sd_cis_m = sdsum(c[..., 0]) / len(pix_cis)
    sd_cis = sd_cis_m / c4(nc)
    mean = c[..., 0].mean(axis=0)
    sd_id = np.sqrt(np.maximum(0, c[..., 1].mean(axis=0) - mean**2)).sum() / len(pix_cis)
    missed = c[..., 2].mean(axis=0).sum(); light = np.abs(mean).sum()
    var_pt = sd_pt**2; var_cis = sd_cis**2
    if sd_cis_m > 0:
        idv = (sd_id / sd_cis_m * sd_cis)**2
        var_pt = max(var_pt, idv)
    if light > 0 and missed > 0.01 * light: return 1e6
    return var_pt * cpt / (max(var_cis, 1e-6*var_pt) * ccis)
variants = {  # name: (n_pt, pt_frac, n_cis, cis_frac)
    "full 4pt+2cis": (4, 1, 2, 1),
    "2pt+2cis": (2, 1, 2, 1),
    "4pt+2cis@1/2": (4, 1, 2, 2),
    "2pt+2cis@1/4": (2, 1, 2, 4),
    "4pt+2cis@1/4": (4, 1, 2, 4),
    "2pt+4cis@1/8": (2, 1, 4, 8),
    "2pt+3cis@1/4": (2, 1, 3, 4),
    "4pt+4cis@1/8": (4, 1, 4, 8),
}
rng = np.random.default_rng(1)
for name in names:
    d = np.load(f"/tmp/auto4/pool_{name}_{res}.npz")
    pt, cis = d["pt"].reshape(len(d["pt"]), -1), d["cis"].reshape(len(d["cis"]), -1, 3)
    cpt = d["cpt"].sum(axis=1).mean(); ccis_cam, ccis_l = d["ccis"].mean(axis=0)
    P = pt.shape[1]
    out = []
    for v, (n, fp, nc, fc) in variants.items():
        ests = []
        for trial in range(24):
            ip = rng.choice(len(pt), n, replace=False); ic = rng.choice(len(cis), nc, replace=False)
            off = rng.integers(fc)
            pix_c = np.arange(off, P, fc)
            ests.append(estimate(pt[ip], cis[ic], cpt, ccis_cam + ccis_l, np.arange(P), pix_c))
        ests = np.array(ests)
        cost = n * cpt / cpt + nc * (ccis_cam + ccis_l) / fc / cpt  # light scaled with subset
        out.append(f"{v}: cost {cost:.1f} pt-samples, cis chosen {np.mean(ests > 1):.2f}, est med {np.median(ests):.2f} [{np.percentile(ests, 5):.2f}, {np.percentile(ests, 95):.2f}]")
    print(name, "\n  " + "\n  ".join(out), flush=True)
