"""Bits of subsurface renders for a before / after check of a change that must keep the CPU's
images (bench/bits_check.py has no subsurface scene): a Skin and a Random Walk sphere on a floor
under a point light, 24 x 24, 8 spp, seed 3, max_depth 8, one thread, with pt, lt, bdpt, lvc and
cis (camera and light paths walk); prints each image's hash and mean.

    python bench/sss_bits.py PYTHON_DIR > before.txt   # PYTHON_DIR: where that build's lantern is
    python bench/sss_bits.py PYTHON_DIR > after.txt
    diff before.txt after.txt"""
import hashlib, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
import lantern
from lantern import scenes
def sphere(method):
    s = lantern.Scene()
    s.film.update(width=24, height=24)
    s.look_at((0.0, -4.0, 0.6), (0.0, 0.0, -0.3), fov=40.0)
    s.world = {"color": [0.05, 0.05, 0.05]}
    m = s.add_material("ball", type="principled", base_color=(0.8, 0.6, 0.4), roughness=0.5,
                       subsurface={"weight": 1.0, "radius": [0.4, 0.2, 0.1], "method": method})
    pos, idx = scenes.icosphere(2)
    s.add_mesh(pos, idx, material=m)
    f = s.add_material("floor", base_color=0.5)
    q = np.array([[-3, -3, -1], [3, -3, -1], [3, 3, -1], [-3, 3, -1]], np.float32)
    s.add_mesh(q, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=f)
    s.add_light("point", position=[1.5, -1.0, 2.0], power=[300.0] * 3, radius=0.0)
    return s
for method in ("random_walk_skin", "random_walk"):
    for integ in ("pt", "lt", "bdpt", "lvc", "cis"):
        img = np.asarray(lantern.render(sphere(method), spp=8, seed=3, max_depth=8, integrator=integ, threads=1), np.float32)
        print(method, integ, hashlib.sha1(img.tobytes()).hexdigest()[:16], float(img.mean()))
