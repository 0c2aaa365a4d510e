"""Render each blend scene with Cycles (CPU, from bpy) with K independent seeds and store a
compact reference per scene in tests/render/refs/<scene>.npz (+ <scene>.json: settings, spp,
Blender version, timings). Settings follow DESIGN.md "Matching Cycles".

    .venv/bin/python tools/make_cycles_refs.py [--spp N] [--seeds K] [SCENE ...]"""

import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_compare as rc  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--spp", type=int, default=rc.CYCLES_SPP)
    ap.add_argument("--seeds", type=int, default=rc.SEEDS)
    ap.add_argument("scenes", nargs="*")
    args = ap.parse_args(argv)
    import bpy
    sys.path.insert(0, os.path.join(rc.ROOT, "blend_scenes"))
    import scenes
    names = args.scenes or list(scenes.SCENES)
    os.makedirs(rc.REF_DIR, exist_ok=True)
    for name in names:
        blend = rc.build_scene(name)
        t0 = time.perf_counter()
        images = []
        for k in range(args.seeds):
            img, settings = rc.render_cycles(seed=1000 + k, spp=args.spp)
            images.append(img)
        dt = time.perf_counter() - t0
        st = rc.stats_over_seeds(images)
        np.savez_compressed(os.path.join(rc.REF_DIR, name + ".npz"), **st)
        settings.pop("seed")
        meta = {"scene": name, "blend_script": "blend_scenes/scenes.py:" + name,
                "renderer": "Cycles (CPU)", "blender_version": bpy.app.version_string,
                "spp_per_seed": args.spp, "seeds": [1000 + k for k in range(args.seeds)],
                "block": rc.BLOCK, "resolution": list(images[0].shape[1::-1]),
                "settings": settings, "lantern_max_depth": rc.lantern_depth(rc.BOUNCES),
                "render_seconds": round(dt, 2),
                "image_mean": float(st["mean"].mean())}
        with open(os.path.join(rc.REF_DIR, name + ".json"), "w") as f:
            json.dump(meta, f, indent=1, sort_keys=True)
            f.write("\n")
        print(f"{name}: mean {meta['image_mean']:.5f}, {dt:.1f} s ({blend})", flush=True)


if __name__ == "__main__":
    sys.exit(main())
