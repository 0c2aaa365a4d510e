"""Bits of the volume scenes with node programs and grids (tests/python/test_volume_hetero_bdpt's
five: noise_smoke, grid_smoke, emissive_box, glowing_smoke, color_smoke; test_volume_fire's
fire) by pt, cis and bdpt at fixed seeds, written as hashes to a folder, so that two builds can
be compared bit for bit (bench/bits_check.py's ordinary scenes hold no media):

    PYTHONPATH=python python bench/volume_bits_check.py --out /tmp/a   # build A
    PYTHONPATH=python python bench/volume_bits_check.py --out /tmp/b   # build B
    python bench/volume_bits_check.py --compare /tmp/a /tmp/b
"""
import argparse
import hashlib
import os
import sys

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, os.path.join(ROOT, "python"))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))


def scenes():
    from test_volume_fire import fire_scene
    from test_volume_hetero_bdpt import SCENES
    out = {name: make for name, make in SCENES.items()}
    out["fire"] = fire_scene
    return out


def render(scene, integrator):
    import lantern
    s = lantern.Session(scene, integrator=integrator, seed=7, spp_per_iteration=2, max_depth=4,
                        threads=1)
    s.step()
    return np.asarray(s.image(), np.float32)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out")
    ap.add_argument("--compare", nargs=2)
    a = ap.parse_args()
    if a.compare:
        fa, fb = (dict(line.split() for line in open(os.path.join(d, "hashes.txt")))
                  for d in a.compare)
        same = [k for k in fa if fb.get(k) == fa[k]]
        diff = [k for k in fa if fb.get(k) != fa[k]]
        print(f"{len(same)} identical, {len(diff)} differ: {diff}")
        sys.exit(1 if diff else 0)
    os.makedirs(a.out, exist_ok=True)
    lines = []
    for name, make in scenes().items():
        for integ in ("pt", "cis", "bdpt"):
            img = render(make(), integ)
            h = hashlib.sha256(img.tobytes()).hexdigest()[:16]
            lines.append(f"{name}:{integ} {h}")
            print(lines[-1], flush=True)
    with open(os.path.join(a.out, "hashes.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
