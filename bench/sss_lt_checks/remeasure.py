"""lt / pt on the hollow wax shade (hollow.py's scene, no floor), in independent seed groups.

PYTHONPATH=python python bench/sss_lt_checks/remeasure.py METHOD ROUGH MAX_DEPTH GROUPS K SPP PT_K PT_SPP
Each group: K lt renders of SPP (seeds from 10000 + group * K), against one pt reference of
PT_K x PT_SPP; prints each group's lt / pt with the seeds' standard error, then all pooled."""
import os, sys, time
import numpy as np
os.environ.setdefault("LANTERN_SSS_ADJOINT", "walk")
sys.path.insert(0, "python")
import lantern
from lantern import scenes

method, rough, md = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
groups, k, spp, pk, pspp = (int(x) for x in sys.argv[4:9])
s = lantern.Scene(); s.film.update(width=8, height=8)
s.look_at((0.0, -4.0, 0.8), (0.0, 0.0, 0.0), fov=40.0); s.world = {"color": [0.0, 0.0, 0.0]}
wax = s.add_material("wax", type="principled", base_color=(0.9, 0.75, 0.5), roughness=rough,
                     subsurface={"weight": 1.0, "radius": [0.3, 0.2, 0.1], "method": method})
pos, tri = scenes.icosphere(3); pos = np.asarray(pos)
s.add_mesh(pos, tri, material=wax)
s.add_mesh(pos * 0.92, np.asarray(tri)[:, ::-1].copy(), material=wax)
s.add_light("point", position=[0.0, 0.0, 0.0], power=[100.0] * 3, radius=0.0)


def mean(integ, sp, seed):
    ses = lantern.Session(s, integrator=integ, seed=seed, spp_per_iteration=min(sp, 64),
                          max_depth=md, threads=1)
    assert not any("rendering with pt" in w for w in ses.warnings), ses.warnings
    while ses.spp < sp:
        ses.step()
    return float(np.asarray(ses.image(), np.float64).mean())


t0 = time.process_time()
P = np.array([mean("pt", pspp, 101 + i) for i in range(pk)])
tp = time.process_time() - t0
p, sp_ = P.mean(), P.std(ddof=1) / np.sqrt(pk) / P.mean()
print(f"{method} rough {rough} max_depth {md}: pt {p:.5g} (se {sp_ * 100:.2f} %, {pk} x {pspp}, "
      f"{tp:.0f} s)", flush=True)
allL = []
t0 = time.process_time()
for g in range(groups):
    L = np.array([mean("lt", spp, 10000 + g * k + i) for i in range(k)])
    allL.append(L)
    sl = L.std(ddof=1) / np.sqrt(k) / L.mean()
    r = L.mean() / p
    print(f"  group {g}: lt {k} x {spp}: lt / pt {r:.3f} +- {r * np.hypot(sl, sp_):.3f} "
          f"(lt se {sl * 100:.1f} %, median / mean {np.median(L) / L.mean():.2f})", flush=True)
L = np.concatenate(allL)
sl = L.std(ddof=1) / np.sqrt(L.size) / L.mean()
r = L.mean() / p
print(f"  pooled {L.size} x {spp}: lt / pt {r:.3f} +- {r * np.hypot(sl, sp_):.3f} "
      f"(median / mean {np.median(L) / L.mean():.2f}; lt CPU {time.process_time() - t0:.0f} s)",
      flush=True)
