import sys, time, copy, numpy as np
sys.path.insert(0, "bench"); sys.path.insert(0, "tests/python"); sys.path.insert(0, "python")
import os; os.environ.setdefault("LANTERN_SSS_ADJOINT", "walk")
import lantern
from lantern import scenes
import sss_lt_efficiency as E
r_out = float(sys.argv[1]); r_in = float(sys.argv[2]); md = int(sys.argv[3])
kp, sp, kl, sl = [int(x) for x in sys.argv[4].split(",")]; size = int(sys.argv[5])
def shade2(size):
    s = lantern.Scene()
    s.film.update(width=size, height=size)
    s.look_at((0.0, -4.0, 0.8), (0.0, 0.0, 0.0), fov=40.0)
    s.world = {"color": [0.0, 0.0, 0.0]}
    ss = {"weight": 1.0, "radius": [0.3, 0.2, 0.1], "method": "random_walk"}
    wo = s.add_material("wax_out", type="principled", base_color=(0.9, 0.75, 0.5), roughness=r_out, subsurface=dict(ss))
    wi = s.add_material("wax_in", type="principled", base_color=(0.9, 0.75, 0.5), roughness=r_in, subsurface=dict(ss))
    pos, tri = scenes.icosphere(3); pos = np.asarray(pos)
    s.add_mesh(pos, tri, material=wo)
    s.add_mesh(pos * 0.92, np.asarray(tri)[:, ::-1].copy(), material=wi)
    floor = s.add_material("floor", base_color=0.5)
    E._quad(s, floor, -1.0, 4.0)
    s.add_light("point", position=[0.0, 0.0, 0.0], power=[100.0] * 3, radius=0.0)
    return s
sc = shade2(size)
def rend(integ, k, spp, seed):
    return np.array([np.asarray(lantern.render(sc, spp=spp, seed=seed+i, max_depth=md, integrator=integ, threads=1), np.float64).mean() for i in range(k)])
t=time.process_time(); P = rend("pt", kp, sp, 101); tp=time.process_time()-t
t=time.process_time(); L = rend("lt", kl, sl, 201); tl=time.process_time()-t
r = L.mean()/P.mean()
se = r*np.sqrt((L.std(ddof=1)/np.sqrt(kl)/L.mean())**2 + (P.std(ddof=1)/np.sqrt(kp)/P.mean())**2)
print(f"outer rough {r_out} inner rough {r_in} max_depth {md}: pt {P.mean():.5g} (se {P.std(ddof=1)/np.sqrt(kp)/P.mean()*100:.1f}%, {tp:.0f}s) lt {L.mean():.5g} (se {L.std(ddof=1)/np.sqrt(kl)/L.mean()*100:.1f}%, {tl:.0f}s, median/mean {np.median(L)/L.mean():.2f}) ratio {r:.3f} +- {se:.3f}", flush=True)
