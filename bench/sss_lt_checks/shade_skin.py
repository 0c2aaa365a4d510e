import sys, numpy as np
sys.path.insert(0, "bench")
import os; os.environ.setdefault("LANTERN_SSS_ADJOINT", "walk")
import lantern
from lantern import agreement
from sss_lt_efficiency import shade
sc = shade(16); sc.materials[0]["subsurface_method"] = "random_walk_skin"; sc.materials[0]["roughness"] = float(sys.argv[1])
def rend(integ, k, spp, seed): return [np.asarray(lantern.render(sc, spp=spp, seed=seed+i, max_depth=8, integrator=integ, threads=1), np.float64) for i in range(k)]
R = rend("pt", 16, 64, 101); L = rend("lt", 48, 128, 201)
print("skin lt/pt", np.stack(L).mean(axis=(0,1,2))/np.stack(R).mean(axis=(0,1,2)), "lt se", np.stack(L).mean(axis=(1,2)).std(axis=0,ddof=1)/np.sqrt(48)/np.stack(L).mean(axis=(0,1,2)), "pt se", np.stack(R).mean(axis=(1,2)).std(axis=0,ddof=1)/4/np.stack(R).mean(axis=(0,1,2)))
print(agreement.compare_renders(L, R, block=8))
