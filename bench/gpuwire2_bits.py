"""pt / bdpt bits on subsurface, hair and moving hair scenes, to compare two builds' CPU output
bit for bit (gpuwire2: the walk's start and exit out of line on the device must leave the host's
bits as they were; bench/results/2026-12-06-gpuwire2):

    LANTERN_ACCEL=bvh PYTHONPATH=<a build's python dir> python bench/gpuwire2_bits.py out.json
"""
import hashlib
import json
import os
import sys

import numpy as np

import lantern
from lantern.scenes_hair import fur_ball

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests",
                                "python"))
from test_subsurface_scene import sphere_scene  # noqa: E402


def turn(steps=3):
    out = []
    for u in np.linspace(0.0, 1.0, steps):
        a = (u - 0.5) * np.pi / 3.0
        m = np.eye(4)
        m[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
        m[0, 3] = 0.3 * (u - 0.5)
        out.append(m)
    return out


def hair(moving=False, sss=False):
    s = fur_ball(24, 24, num_strands=150, world=0.3)
    if sss:
        m = s.materials[s.material_id("skin")]
        m.update(type="principled", subsurface={"weight": 1.0, "radius": [0.3, 0.2, 0.1],
                                                "method": "random_walk", "anisotropy": 0.0})
    if moving:
        for part in (s.meshes[0], s.curves[0]):
            part["motion"] = turn()
            part["motion_base"] = np.eye(4)
    return s

cases = {
    "sss_sphere": lambda: sphere_scene(radius=(0.3, 0.2, 0.1), size=16),
    "hair": lambda: hair(),
    "hair_moving": lambda: hair(moving=True),
    "hair_sss": lambda: hair(sss=True),
    "hair_sss_moving": lambda: hair(moving=True, sss=True),
}
out = {}
for name, make in cases.items():
    for integ in ("pt", "bdpt"):
        img = np.asarray(lantern.render(make(), spp=4, seed=5, max_depth=6, integrator=integ,
                                        threads=1))
        out[f"{name}/{integ}"] = [hashlib.sha1(img.tobytes()).hexdigest()[:16], float(img.mean())]
json.dump(out, open(sys.argv[1], "w"), indent=1)
print(json.dumps(out, indent=1))
