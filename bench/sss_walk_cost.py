"""CPU time of pt on the subsurface scenes of tests/cycles/test_subsurface.py (32x32, one
thread), for comparing two builds of the core: walking at every hit (2026-12-06) against the
Lambert lobe after a bounce before it. Run it once per build, alternating builds, and compare the
JSON lines (scene, CPU seconds of the render alone, image mean, the build's label):

    python bench/sss_walk_cost.py LABEL [SPP] [SEEDS]

The render's CPU time is time.process_time() around Session.step (export excluded)."""
import json
import os
import sys
import time

R = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
for p in ("tests/cycles", "tools", "python"):
    sys.path.insert(0, os.path.join(R, p))

import bpy  # noqa: E402,F401
import numpy as np  # noqa: E402

import render_compare as rc  # noqa: E402
import test_subsurface as t  # noqa: E402

label = sys.argv[1]
spp = int(sys.argv[2]) if len(sys.argv) > 2 else 128
seeds = int(sys.argv[3]) if len(sys.argv) > 3 else 2
SCENES = {
    "skin (torus)": t.skin,
    "marble": t.marble,
    "head": t.head,
    "head with eyeballs": lambda: t.head(eyeballs=True),
    "intersecting parts": lambda: t._spheres(t._add_sphere(0.25, (0.25, -0.62, 0.15)), 0.25),
    "inner part 50 cm": lambda: t._spheres(t._add_sphere(0.3, (0.0, -0.3, 0.0)), 0.5),
    "open part 50 cm": lambda: t._spheres(t._open_front, 0.5),
}


def main():
    import lantern
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    for name, build in SCENES.items():
        build()
        scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
        cpu, means = 0.0, []
        for k in range(seeds):
            session = lantern.Session(scene, integrator="pt", backend="cpu",
                                      max_depth=rc.lantern_depth(rc.BOUNCES), seed=1 + k,
                                      spp_per_iteration=spp, threads=1)
            c0 = time.process_time()
            while session.spp < spp:
                session.step()
            cpu += time.process_time() - c0
            means.append(float(np.asarray(session.image())[..., :3].mean()))
        print(json.dumps({"scene": name, "build": label, "cpu_s": round(cpu, 3),
                          "mean": round(float(np.mean(means)), 6), "spp": spp,
                          "seeds": seeds}), flush=True)


main()
