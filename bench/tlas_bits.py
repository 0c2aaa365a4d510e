"""Two-level BVH bits (the built-in BVH's TLAS: moving meshes go two-level under
LANTERN_ACCEL=bvh): four motion-blur test scenes, every integrator, seed 7, 2 x 2 spp, max_depth
4, one thread; writes the images and prints their hashes. From the repository root:
LANTERN_ACCEL=bvh .venv/bin/python bench/tlas_bits.py OUT"""
import hashlib
import os
import sys

import numpy as np

sys.path.insert(0, "python")
sys.path.insert(0, "tests/python")
import lantern  # noqa: E402
import test_deform_motion as dm  # noqa: E402
import test_motion_blur as mb  # noqa: E402
import test_motion_sss as ms  # noqa: E402

out = sys.argv[1]
os.makedirs(out, exist_ok=True)
cases = {"slide": mb._moving("slide"), "spin": mb._moving("spin"),
         "sss_spin": ms._moving("spin"), "deform": dm._deforming(moves=True)}
for name, sc in cases.items():
    for integ in ["pt", "lt", "bdpt", "lvc", "cis"]:
        s = lantern.Session(sc, integrator=integ, seed=7, spp_per_iteration=2, threads=1,
                            max_depth=4, backend="cpu")
        s.step()
        s.step()
        img = np.asarray(s.image())
        np.save(os.path.join(out, f"{name}_{integ}.npy"), img)
        print(name, integ, hashlib.sha1(img.tobytes()).hexdigest()[:16], list(s.warnings)[:1])
