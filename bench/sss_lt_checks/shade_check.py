import sys, numpy as np
sys.path.insert(0, "bench"); sys.path.insert(0, "tests/python")
import os; os.environ.setdefault("LANTERN_SSS_ADJOINT", "walk")
import lantern
from lantern import agreement
from sss_lt_efficiency import shade
rough = float(sys.argv[1]); k = int(sys.argv[2])
sc = shade(16); sc.materials[0]["roughness"] = rough
def rend(integ, k, spp, seed): return [np.asarray(lantern.render(sc, spp=spp, seed=seed+i, max_depth=8, integrator=integ, threads=1), np.float64) for i in range(k)]
R = rend("pt", 16, 64, 101); L = rend("lt", k, 128, 201)
print("rough", rough, "ratio", np.stack(L).mean(axis=(0,1,2))/np.stack(R).mean(axis=(0,1,2)), "lt se", np.stack(L).mean(axis=(1,2)).std(axis=0,ddof=1)/np.sqrt(k)/np.stack(L).mean(axis=(0,1,2)))
print(agreement.compare_renders(L, R, block=8))
