"""Image hashes of tests/python/test_volume_hetero_bdpt.py's SCENES (pt and cis, 8 spp, seed 3,
one thread; sha1 of the float32 image): which volume scenes keep their bits between two builds.

    python bench/hetero_bits.py /tmp/base_build_python > a.txt
    python bench/hetero_bits.py python > b.txt; paste a.txt b.txt
"""
import sys, hashlib
sys.path.insert(0, sys.argv[1]); sys.path.insert(0, "tests/python")
import lantern, numpy as np
import test_volume_hetero_bdpt as t
for name, f in t.SCENES.items():
    for integ in ("pt", "cis"):
        s = lantern.Session(f(), integrator=integ, backend="cpu", seed=3, spp_per_iteration=8, threads=1)
        s.step()
        im = np.asarray(s.image(), dtype=np.float32)
        print(name, integ, hashlib.sha1(im.tobytes()).hexdigest()[:16])
