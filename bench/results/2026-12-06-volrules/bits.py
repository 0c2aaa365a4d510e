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
