import sys, time, numpy as np
sys.path.insert(0, "bench"); sys.path.insert(0, "tests/python"); sys.path.insert(0, "python")
import os
os.environ.setdefault("LANTERN_SSS_ADJOINT", "walk")
import lantern
from sss_lt_efficiency import shade
rough = float(sys.argv[1]); depths = [int(x) for x in sys.argv[2].split(",")]
kp, sp, kl, sl = [int(x) for x in sys.argv[3].split(",")]
size = int(sys.argv[4]) if len(sys.argv) > 4 else 16
sc = shade(size); sc.materials[0]["roughness"] = rough
if os.environ.get("SSS_METHOD"): sc.materials[0]["subsurface_method"] = os.environ["SSS_METHOD"]
def rend(integ, k, spp, seed, md):
    return np.array([np.asarray(lantern.render(sc, spp=spp, seed=seed+i, max_depth=md, integrator=integ, threads=1), np.float64).mean() for i in range(k)])
for md in depths:
    t=time.process_time(); P = rend("pt", kp, sp, 101, md); tp=time.process_time()-t
    t=time.process_time(); L = rend("lt", kl, sl, 201, md); tl=time.process_time()-t
    r = L.mean()/P.mean()
    se = r*np.sqrt((L.std(ddof=1)/np.sqrt(kl)/L.mean())**2 + (P.std(ddof=1)/np.sqrt(kp)/P.mean())**2)
    print(f"rough {rough} max_depth {md}: pt {P.mean():.5g} (se {P.std(ddof=1)/np.sqrt(kp)/P.mean()*100:.1f}%, {tp:.0f}s) lt {L.mean():.5g} (se {L.std(ddof=1)/np.sqrt(kl)/L.mean()*100:.1f}%, {tl:.0f}s, median/mean {np.median(L)/L.mean():.2f}) ratio {r:.3f} +- {se:.3f}", flush=True)
