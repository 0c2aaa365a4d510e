"""Bits of subsurface renders for a before / after check of a change that must keep the CPU's
images (bench/bits_check.py has no subsurface scene): a Skin and a Random Walk sphere on a floor
under a point light, 24 x 24, 8 spp, seed 3, max_depth 8, one thread, with pt, lt, bdpt, lvc and
cis (camera and light paths walk; lantern.scenes_sss.lit_sphere, world 0.05); prints each
image's hash and mean.

    python bench/sss_bits.py PYTHON_DIR > before.txt   # PYTHON_DIR: where that build's lantern is
    python bench/sss_bits.py PYTHON_DIR > after.txt
    diff before.txt after.txt"""
import hashlib, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
import lantern
from lantern import scenes_sss
def sphere(method):  # (the same scene as before scenes_sss: a PYTHON_DIR older than it lacks it)
    return scenes_sss.lit_sphere(24, 24, method=method, world=0.05)
for method in ("random_walk_skin", "random_walk"):
    for integ in ("pt", "lt", "bdpt", "lvc", "cis"):
        img = np.asarray(lantern.render(sphere(method), spp=8, seed=3, max_depth=8, integrator=integ, threads=1), np.float32)
        print(method, integ, hashlib.sha1(img.tobytes()).hexdigest()[:16], float(img.mean()))
