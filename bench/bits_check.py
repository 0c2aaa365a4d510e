"""Renders every integrator on a few committed scenes with fixed seeds and writes the images
(and their hashes) to a folder, so that two builds can be compared bit for bit:

    python bench/bits_check.py --out /tmp/a      # build A
    python bench/bits_check.py --out /tmp/b      # build B
    python bench/bits_check.py --compare /tmp/a /tmp/b

Used for issue 13 (one wavefront): a change of schedule must keep the CPU's bits where the
algorithm did not change. Small sizes: a check of identity, not of convergence. Beyond the
scenes' own materials: the features box with its mix leaves textured (every integrator), pt
with resampled next-event estimation (light_candidates 4) there and on the many-light stage,
and with --node-scene a node-program scene (bench/node_cost.py export OUT 8: every Base Color a
Noise -> 6 Math -> ColorRamp graph) with every integrator."""
import argparse
import hashlib
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "python"))
import lantern  # noqa: E402
from lantern import scenes  # noqa: E402

SCENES = ["cornell_box", "fixture_box", "glass_lantern", "features_box", "bench_glossy"]
INTEGRATORS = ["pt", "lt", "bdpt", "lvc", "cis"]


def small(scene, width):
    h = max(1, round(scene.film["height"] * width / scene.film["width"]))
    scene.film["width"], scene.film["height"] = width, h
    return scene


def features_textured_mix(width):
    """features_box with its mix leaves textured: the back wall's diffuse and metal leaves take
    the floor's checker as base colour (and the metal as roughness)."""
    scene = scenes.features_box(width, width)
    checker = scene.materials[scene.material_id("checker_floor")]["base_color_texture"]
    for name, keys in (("mix_diffuse", ["base_color_texture"]),
                       ("mix_metal", ["base_color_texture", "roughness_texture"])):
        m = scene.materials[scene.material_id(name)]
        for k in keys:
            m[k] = checker
    return scene


def render_one(out, name, scene, integ, threads, **settings):
    tag = integ + "".join(f"_{k}{v}" for k, v in sorted(settings.items()))
    try:
        s = lantern.Session(scene, integrator=integ, seed=7, spp_per_iteration=2,
                            backend="cpu", threads=threads, **settings)
        s.step()
        s.step()
        img = s.image()
    except Exception as e:  # an integrator that cannot render the scene says why
        print(f"{name} {tag}: {e}")
        return
    np.save(os.path.join(out, f"{name}_{tag}.npy"), img)
    print(f"{name} {tag}: {hashlib.sha1(img.tobytes()).hexdigest()[:16]}")


def render_all(out, width, threads, node_scene=None, integrators=None):
    global INTEGRATORS
    INTEGRATORS = integrators or INTEGRATORS
    os.makedirs(out, exist_ok=True)
    here = os.path.dirname(__file__)
    for name in SCENES:
        if name.startswith("bench_"):
            scene = small(lantern.load_scene(os.path.join(here, "scenes", name + ".lantern")),
                          width)
        else:
            scene = getattr(scenes, name)(width, width)
        for integ in INTEGRATORS:
            render_one(out, name, scene, integ, threads)
    textured = features_textured_mix(width)
    for integ in INTEGRATORS:
        render_one(out, "features_textured_mix", textured, integ, threads)
    render_one(out, "features_textured_mix", textured, "pt", threads, light_candidates=4)
    render_one(out, "many_lights_stage", scenes.many_lights_stage(width, width), "pt", threads,
               light_candidates=4)
    if node_scene:
        nodes = small(lantern.load_scene(node_scene), width)
        for integ in INTEGRATORS:
            render_one(out, "nodes", nodes, integ, threads)
        render_one(out, "nodes", nodes, "pt", threads, light_candidates=4)


def compare(a, b):
    same = True
    for f in sorted(os.listdir(a)):
        x = np.load(os.path.join(a, f))
        pb = os.path.join(b, f)
        if not os.path.exists(pb):
            print(f"{f}: missing in {b}")
            same = False
            continue
        y = np.load(pb)
        eq = np.array_equal(x, y)
        same &= eq
        rel = float(np.abs(x.mean() - y.mean()) / max(abs(x.mean()), 1e-12))
        print(f"{f}: {'identical' if eq else 'DIFFERENT'} (mean {x.mean():.6g} vs "
              f"{y.mean():.6g}, relative {rel:.2e})")
    return same


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--out")
    ap.add_argument("--compare", nargs=2)
    ap.add_argument("--width", type=int, default=64)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--node-scene", help="a node-program scene (bench/node_cost.py export)")
    ap.add_argument("--integrators", default=",".join(INTEGRATORS),
                    help="comma-separated (auto too: its choice on these scenes)")
    args = ap.parse_args()
    if args.compare:
        sys.exit(0 if compare(*args.compare) else 1)
    render_all(args.out, args.width, args.threads, args.node_scene, args.integrators.split(","))
