import sys, os, time, numpy as np
sys.path.insert(0, "bench"); sys.path.insert(0, "tests/python"); sys.path.insert(0, "python")
os.environ.setdefault("LANTERN_SSS_ADJOINT", "walk")
import lantern
from lantern import scenes
rough=float(sys.argv[1]); md=int(sys.argv[2]); kp,sp,kl,sl=[int(x) for x in sys.argv[3].split(",")]; size=int(sys.argv[4]); floor=sys.argv[5]=="floor"
s = lantern.Scene(); s.film.update(width=size, height=size)
s.look_at((0.0, -4.0, 0.8), (0.0, 0.0, 0.0), fov=40.0); s.world = {"color": [0.0, 0.0, 0.0]}
wax = s.add_material("wax", type="principled", base_color=(0.9, 0.75, 0.5), roughness=rough,
    subsurface={"weight": 1.0, "radius": [0.3*float(os.environ.get("RSCALE","1")), 0.2*float(os.environ.get("RSCALE","1")), 0.1*float(os.environ.get("RSCALE","1"))], "method": os.environ.get("SSS_METHOD", "random_walk")})
pos, tri = scenes.icosphere(3); pos = np.asarray(pos)
s.add_mesh(pos, tri, material=wax)
s.add_mesh(pos * 0.92, np.asarray(tri)[:, ::-1].copy(), material=wax)
if floor:
    import sss_lt_efficiency as E
    E._quad(s, s.add_material("floor", base_color=float(os.environ.get("FLOOR_ALBEDO", "0.5"))), float(os.environ.get("FLOOR_Z", "-1.0")), float(os.environ.get("FLOOR_HALF", "4.0")))
if os.environ.get("EXTRA_MAT"): s.add_material("extra", base_color=0.5)
s.add_light("point", position=[0.0, 0.0, 0.0], power=[100.0] * 3, radius=0.0)
def rend(integ, k, spp, seed):
    return np.array([np.asarray(lantern.render(s, spp=spp, seed=seed+i, max_depth=md, integrator=integ, threads=1), np.float64).mean() for i in range(k)])
P = rend("pt", kp, sp, 101); L = rend("lt", kl, sl, 201)
r = L.mean()/P.mean(); sl_=L.std(ddof=1)/np.sqrt(kl)/L.mean(); sp_=P.std(ddof=1)/np.sqrt(kp)/P.mean()
print(f"floor {floor} rough {rough} md {md}: pt {P.mean():.5g} (se {sp_*100:.1f}%) lt {L.mean():.5g} (se {sl_*100:.1f}%, median/mean {np.median(L)/L.mean():.2f}) ratio {r:.3f} +- {r*np.hypot(sl_,sp_):.3f}", flush=True)
