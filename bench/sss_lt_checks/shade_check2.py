import sys, numpy as np
sys.path.insert(0, "bench"); sys.path.insert(0, "tests/python")
import os; os.environ.setdefault("LANTERN_SSS_ADJOINT", "walk")
import lantern
from sss_lt_efficiency import shade
rough = float(sys.argv[1]); k = int(sys.argv[2]); spp = int(sys.argv[3]); floor = sys.argv[4] == "floor"
sc = shade(16); sc.materials[0]["roughness"] = rough
if not floor:
    sc.meshes = [m for m in sc.meshes if m.get("material") != sc.material_id("floor")] if hasattr(sc, "meshes") else sc.meshes
def rend(integ, k, spp, seed): return np.stack([np.asarray(lantern.render(sc, spp=spp, seed=seed+i, max_depth=8, integrator=integ, threads=1), np.float64) for i in range(k)])
R = rend("pt", 8, 128, 101); L = rend("lt", k, spp, 201)
def blocks(a): return a.reshape(a.shape[0], 2, 8, 2, 8, 3).mean(axis=(2, 4))
A, B = blocks(L), blocks(R)
np.set_printoptions(precision=3, suppress=True)
print("rough", rough, "k", k, "spp", spp)
print("lt/pt blocks", (A.mean(0)/B.mean(0)).transpose(2,0,1))
print("lt per-seed rel sd of blocks", (A.std(0)/A.mean(0)).transpose(2,0,1))
print("median-of-seeds / mean", (np.median(A,0)/A.mean(0)).transpose(2,0,1))
