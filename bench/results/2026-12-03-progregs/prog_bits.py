"""Renders a node-program scene (bench/node_cost.py export OUT 8: the Cornell box, every Base
Color a Noise -> 6 Math -> ColorRamp graph) with every integrator and pt with 4 light
candidates, fixed seeds, CPU, and saves the images, so that two builds compare bit for bit
(bench/bits_check.py --compare A B). Usage: prog_bits.py REPO_ROOT SCENE OUT"""
import hashlib, os, sys
import numpy as np
sys.path.insert(0, os.path.join(sys.argv[1], "python"))
import lantern
scene_path, out = sys.argv[2], sys.argv[3]
os.makedirs(out, exist_ok=True)
for integ, kw in [("pt", {}), ("lt", {}), ("bdpt", {}), ("lvc", {}), ("cis", {}),
                  ("pt_ris4", {"light_candidates": 4})]:
    s = lantern.Session(lantern.load_scene(scene_path), integrator=integ.split("_")[0], seed=7,
                        spp_per_iteration=2, backend="cpu", threads=2, **kw)
    s.step(); s.step()
    img = s.image()
    np.save(os.path.join(out, f"nodes8_{integ}.npy"), img)
    print(f"nodes8 {integ}: {hashlib.sha1(img.tobytes()).hexdigest()[:16]} mean {img.mean():.6g}")
