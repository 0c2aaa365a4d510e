"""A/B bits of what bench/bits_check.py does not reach: features_box with its mix leaves
textured (the back wall's diffuse and metal leaves take the floor's checker as base colour and
roughness) for every integrator, and pt with resampled next-event estimation (light_candidates
4) on that scene and on the many-light scene. Run once per build (python dir first on the
path), then --compare."""
import argparse, hashlib, os, sys
import numpy as np
ap = argparse.ArgumentParser()
ap.add_argument("--python"); ap.add_argument("--out"); ap.add_argument("--compare", nargs=2)
a = ap.parse_args()
if a.compare:
    ok = True
    for f in sorted(os.listdir(a.compare[0])):
        x, y = np.load(os.path.join(a.compare[0], f)), np.load(os.path.join(a.compare[1], f))
        eq = np.array_equal(x, y); ok &= eq
        print(f"{f}: {'identical' if eq else 'DIFFERENT'} (mean {x.mean():.6g} vs {y.mean():.6g})")
    sys.exit(0 if ok else 1)
sys.path.insert(0, a.python)
import lantern
from lantern import scenes
os.makedirs(a.out, exist_ok=True)
def textured(w):
    s = scenes.features_box(w, w)
    checker = s.materials[s.material_id("checker_floor")]["base_color_texture"]
    for name, keys in (("mix_diffuse", ["base_color_texture"]),
                       ("mix_metal", ["base_color_texture", "roughness_texture"])):
        m = s.materials[s.material_id(name)]
        for k in keys: m[k] = checker
    return s
jobs = [("features_textured_mix", textured, i, {}) for i in ["pt", "lt", "bdpt", "lvc", "cis"]]
jobs.append(("features_textured_mix_ris4", textured, "pt", {"light_candidates": 4}))
many = ["many_lights_stage"]
for n in many[:1]:
    jobs.append((n + "_ris4", lambda w, n=n: getattr(scenes, n)(w, w), "pt", {"light_candidates": 4}))
for name, make, integ, kw in jobs:
    s = lantern.Session(make(48), integrator=integ, seed=7, spp_per_iteration=2, backend="cpu",
                        threads=2, **kw)
    s.step(); s.step(); img = s.image()
    np.save(os.path.join(a.out, f"{name}_{integ}.npy"), img)
    print(name, integ, hashlib.sha1(img.tobytes()).hexdigest()[:16], float(img.mean()))
