"""lt with subsurface: the same settings and seeds render the same bits? (helper ltsss)

PYTHONPATH=python python bench/sss_lt_checks/determinism.py REPEATS SPP SIZE [METHOD] [THREADS...]
Renders the hollow wax sphere (hollow.py's, no floor, max_depth 8) REPEATS times a thread count
with seed 7 and counts the renders whose bits differ from the first (1 thread)."""
import os, sys, hashlib
import numpy as np
os.environ.setdefault("LANTERN_SSS_ADJOINT", "walk")
sys.path.insert(0, "python")
import lantern
from lantern import scenes

reps, spp, size = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
method = sys.argv[4] if len(sys.argv) > 4 else "random_walk"
threads = [int(t) for t in sys.argv[5:]] or [1, 2]
s = lantern.Scene(); s.film.update(width=size, height=size)
s.look_at((0.0, -4.0, 0.8), (0.0, 0.0, 0.0), fov=40.0); s.world = {"color": [0.0, 0.0, 0.0]}
wax = s.add_material("wax", type="principled", base_color=(0.9, 0.75, 0.5), roughness=0.5,
                     subsurface={"weight": 1.0, "radius": [0.3, 0.2, 0.1], "method": method})
pos, tri = scenes.icosphere(3); pos = np.asarray(pos)
s.add_mesh(pos, tri, material=wax)
s.add_mesh(pos * 0.92, np.asarray(tri)[:, ::-1].copy(), material=wax)
s.add_light("point", position=[0.0, 0.0, 0.0], power=[100.0] * 3, radius=0.0)
ref = None
for t in threads:
    digests = {}
    for r in range(reps):
        img = np.ascontiguousarray(lantern.render(s, spp=spp, seed=7, max_depth=8,
                                                  integrator="lt", threads=t), np.float32)
        h = hashlib.sha1(img.tobytes()).hexdigest()[:12]
        digests.setdefault(h, []).append(float(img.mean()))
        if ref is None:
            ref = h
    diff = sum(len(v) for k, v in digests.items() if k != ref)
    print(f"threads {t}: {reps} renders, {diff} differ from the first; digests "
          + ", ".join(f"{k} x{len(v)} mean {v[0]:.5g}" for k, v in digests.items()), flush=True)
