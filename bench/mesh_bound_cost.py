"""The cost of a true majorant on a mesh volume's Noise density (gridcolor): renders
tests/python/test_volume_hetero_bdpt.py's noise_smoke (8 x clamp(Noise fBM Fac - 0.45, 0, 1))
with pt, 4 seeds x 64 spp, one thread, and prints the CPU time, the image mean and the mean
per-pixel variance over the seeds. Run once per build, alternating:

    python bench/mesh_bound_cost.py /work/main/python    # the lattice x 1.5 majorant
    python bench/mesh_bound_cost.py python               # the interval bound
"""
import sys, time
src = sys.argv[1]
sys.path.insert(0, src); sys.path.insert(0, "tests/python")
import lantern, numpy as np
import test_volume_hetero_bdpt as t
imgs = []
t0 = time.process_time()
for seed in range(1, 5):
    s = lantern.Session(t.noise_smoke(), integrator="pt", backend="cpu", seed=seed, spp_per_iteration=64, threads=1)
    s.step()
    imgs.append(np.asarray(s.image(), dtype=np.float64)[..., :3])
dt = time.process_time() - t0
im = np.stack(imgs)
print(src, f"cpu {dt:.2f} s for 4 x 64 spp", "mean %.5f" % im.mean(), "per-seed pixel var %.3g" % im.var(axis=0, ddof=1).mean(), s.warnings)
