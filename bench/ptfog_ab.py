"""Paired A/B of pt builds (or settings) on a saved fog scene (branch ptfog, issue 29): for each
seed, each variant renders in a fresh process on one CPU (taskset -c 0), the variants' order
alternating from seed to seed; CPU seconds of the render's steps alone (a warm-up Session first,
so that the per-process tables are not billed), the images saved, and per variant the image
mean, the mean pixel variance over the seeds and the median CPU time, as ratios to the first
variant. Seeds 1..K as bench/automedia_cycles.py's Lantern side (256 spp, spp_per_iteration 8,
max_depth 18, one thread), so a variant with the first's bits reads its variance to the digit.

    # 1. the scenes, exported once (the Python with bpy)
    python bench/ptfog_ab.py --save lamp_shade_soft fog_spot --save-dir /tmp
    # 2. the A/B: VARIANT is name=PKG[:ENV=V,...], PKG a folder holding a `lantern` package
    python bench/ptfog_ab.py --scene /tmp/ptfog_lamp_shade_soft.lantern --seeds 8 \\
        --variant base=/tmp/base --variant new=/tmp/new

ENV sets environment variables of that variant's processes (RRD=k: rr_depth k)."""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def save(names, out_dir):
    """Export bench/automedia_cycles.py's scenes through this checkout's add-on (bpy)."""
    for p in ("python", "tests/cycles", "tools", "bench"):
        sys.path.insert(0, os.path.join(ROOT, p))
    import bpy
    import automedia_cycles as am
    import render_compare as rc
    import test_volumes as tv
    tv.SIZE = 32
    for name in names:
        am.SCENES[name]()
        rc.lantern_bpy.load_addon()
        from lantern_blender.export import export_scene
        scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
        scene.save(os.path.join(out_dir, f"ptfog_{name}.lantern"))


def one(pkg, scene_path, seed, out, spp):
    """One seed in this process: prints {"steps": CPU s, "rays": ...}; the image to out."""
    sys.path.insert(0, pkg)
    import lantern
    scene = lantern.load_scene(scene_path)
    kw = dict(integrator="pt", backend="cpu", threads=1, max_depth=18,
              rr_depth=int(os.environ.get("RRD", "4")))
    w = lantern.Session(scene, seed=99, spp_per_iteration=1, **kw)  # warm-up, not timed
    w.step()
    del w
    s = lantern.Session(scene, seed=seed, spp_per_iteration=8, **kw)
    c1 = time.process_time()
    while s.spp < spp:
        s.step()
    img = np.asarray(s.image(), dtype=np.float64)[..., :3]
    c2 = time.process_time()
    np.save(out, img)
    rays = {k: v for k, v in s.stats.items() if k.startswith("rays_")}
    print(json.dumps({"steps": c2 - c1, "rays": rays}))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--save", nargs="+")
    ap.add_argument("--save-dir", default="/tmp")
    ap.add_argument("--scene")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--variant", action="append")
    ap.add_argument("--work", default="/tmp/ptfog_ab")
    ap.add_argument("--one", nargs=4, help=argparse.SUPPRESS)  # PKG SCENE SEED OUT
    a = ap.parse_args()
    if a.save:
        return save(a.save, a.save_dir)
    if a.one:
        return one(a.one[0], a.one[1], int(a.one[2]), a.one[3], a.spp)
    os.makedirs(a.work, exist_ok=True)
    vs = []
    for v in a.variant:
        name, rest = v.split("=", 1)
        pkg, _, envs = rest.partition(":")
        env = dict(os.environ)
        for e in filter(None, envs.split(",")):
            k, val = e.split("=")
            env[k] = val
        vs.append((name, pkg, env))
    res = {n: {"img": [], "steps": []} for n, _, _ in vs}
    tag = os.path.splitext(os.path.basename(a.scene))[0]
    for k in range(a.seeds):
        for n, pkg, env in (vs if k % 2 == 0 else vs[::-1]):
            out = os.path.join(a.work, f"{tag}_{n}_{k}.npy")
            r = subprocess.run(["taskset", "-c", "0", sys.executable, os.path.abspath(__file__),
                                "--spp", str(a.spp), "--one", pkg, a.scene, str(k + 1), out],
                               capture_output=True, text=True, env=env)
            if r.returncode:
                sys.exit(r.stderr[-2000:])
            j = json.loads(r.stdout.strip().splitlines()[-1])
            res[n]["img"].append(np.load(out))
            res[n]["steps"].append(j["steps"])
            res[n]["rays"] = j["rays"]
    print(f"# {' '.join(sys.argv)}\n# load {os.getloadavg()[0]:.1f}")
    base = None
    for n, _, _ in vs:
        imgs = np.stack(res[n]["img"])
        var = float(imgs.var(axis=0, ddof=1).mean())
        t = float(np.median(res[n]["steps"]))
        sm = imgs.mean(axis=(1, 2, 3))
        se = float(sm.std(ddof=1) / np.sqrt(len(sm)))
        if base is None:
            base = (var, t, res[n]["img"])
        same = all(np.array_equal(x, y) for x, y in zip(res[n]["img"], base[2]))
        print(f"{n}: mean {imgs.mean():.5f} +- {se:.5f}; variance {var:.4e} ({var / base[0]:.4f}x)"
              f"; steps CPU s {t:.3f} ({t / base[1]:.3f}x; "
              f"{' '.join(f'{x:.2f}' for x in res[n]['steps'])}); efficiency "
              f"{base[0] * base[1] / (var * t):.3f}x; images {'identical' if same else 'differ'}"
              f"; shadow rays {res[n]['rays']['rays_shadow']}, indirect "
              f"{res[n]['rays']['rays_indirect']}", flush=True)


if __name__ == "__main__":
    main()
