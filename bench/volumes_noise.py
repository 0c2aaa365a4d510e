"""Noise and time of Lantern (pt) on the volume scenes of tests/cycles/test_volumes.py, for
before/after measurements of a sampling change (docs/volumes.md): the scene is exported once,
rendered with K seeds, and the spread over seeds gives per-pixel variance. Reported: the
relative standard error of the image mean over one seed, the mean per-pixel relative standard
deviation (over pixels whose mean is > 1 % of the image mean), the process CPU time per seed
(and the wall time; the shared machine's load moves wall time by tens of percent) and the
efficiency 1 / (mean pixel variance x CPU time); with --cycles the same for Cycles (CPU, the tests'
settings; in a child process of its own since branch benchproc) and the ratio of the two
efficiencies. Run inside bpy's Python:

    nice python bench/volumes_noise.py --scenes fog_spot --spp 64 --seeds 8 \\
        --out bench/results/2026-12-04-volumes2/noise.txt"""
import argparse
import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if "--root" in sys.argv:  # another checkout's lantern and scenes (a "before" measurement)
    ROOT = os.path.abspath(sys.argv[sys.argv.index("--root") + 1])
sys.path.insert(0, os.path.join(ROOT, "python"))  # this checkout's lantern
sys.path.insert(0, os.path.join(ROOT, "tests", "cycles"))
sys.path.insert(0, os.path.join(ROOT, "tools"))
if "--cycles-worker" in sys.argv and sys.argv[sys.argv.index("--threads") + 1] == "1":
    # Cycles' child rendering with one thread: on one CPU before bpy loads TBB
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import side_process  # noqa: E402
    side_process.one_cpu()
import render_compare as rc  # noqa: E402
import test_volumes as tv  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", nargs="+", default=["fog_spot"])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--label", default="")
    ap.add_argument("--root", default=ROOT, help="the checkout to measure (default: this one)")
    ap.add_argument("--cycles", action="store_true",
                    help="also Cycles (CPU, the tests' settings, the same threads), for the "
                         "efficiency ratio; its time per seed includes writing and reading an EXR")
    ap.add_argument("--out", required=True)
    ap.add_argument("--cycles-worker", help=argparse.SUPPRESS)  # a child: Cycles' seeds
    args = ap.parse_args()
    if args.cycles_worker:
        return _cycles_worker(args)
    import bpy
    import lantern
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    machine = (f"{platform.node()} {platform.processor() or platform.machine()}, "
               f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    for name in args.scenes:
        tv.SCENES[name]()
        scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
        imgs, secs = [], []
        for k in range(args.seeds):
            t0, c0 = time.perf_counter(), time.process_time()
            s = lantern.Session(scene, integrator="pt", backend="cpu",
                                max_depth=rc.lantern_depth(rc.BOUNCES), seed=1 + k,
                                spp_per_iteration=args.spp, threads=args.threads)
            while s.spp < args.spp:
                s.step()
            imgs.append(np.asarray(s.image(), dtype=np.float64)[..., :3])
            secs.append((time.perf_counter() - t0, time.process_time() - c0))
        line = _stats(name, f"Lantern pt {args.label}", np.stack(imgs), secs, args, machine)
        if args.cycles:
            cimgs, csecs = _cycles_side(name, args)
            cline = _stats(name, "Cycles", cimgs, csecs, args, machine)
            lv, lt = line[1], line[2]
            cv, ct = cline[1], cline[2]
            ratio = (cv * ct) / (lv * lt)
            text = (f"{name}: efficiency Lantern pt {args.label} / Cycles = {ratio:.3g} "
                    f"(variance x process CPU time per seed, {args.spp} spp, {args.threads} "
                    f"thread(s); "
                    f"image means {line[3]:.5f} / {cline[3]:.5f})")
            print(text, flush=True)
            with open(args.out, "a") as f:
                f.write(text + "\n")


def _cycles_side(name, args):
    """Cycles' seeds of scene `name` in a child process on one CPU that never imports lantern
    (otherwise an idle TBB worker of bpy's spins through a one-thread Cycles render and adds
    up to its CPU time again: bench/results/2026-12-05-benchproc/)."""
    import subprocess
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "cycles.npz")
        r = subprocess.run([sys.executable, os.path.abspath(__file__), "--cycles-worker", out,
                            "--scenes", name, "--spp", str(args.spp), "--seeds",
                            str(args.seeds), "--threads", str(args.threads), "--root", ROOT,
                            "--out", os.devnull], capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"Cycles on {name} failed:\n{r.stderr[-4000:]}")
        with np.load(out) as z:
            return z["imgs"], [tuple(x) for x in z["secs"]]


def _cycles_worker(args):
    import bpy
    tv.SCENES[args.scenes[0]]()
    bpy.context.scene.render.threads_mode = "FIXED"
    bpy.context.scene.render.threads = args.threads
    cimgs, csecs = [], []
    for k in range(args.seeds):
        t0, c0 = time.perf_counter(), time.process_time()
        cimgs.append(np.asarray(rc.render_cycles(seed=900 + k, spp=args.spp)[0],
                                dtype=np.float64)[..., :3])
        csecs.append((time.perf_counter() - t0, time.process_time() - c0))
    assert "lantern" not in sys.modules, "the Cycles process imported lantern"
    np.savez(args.cycles_worker, imgs=np.stack(cimgs), secs=np.array(csecs))


def _stats(name, who, imgs, secs, args, machine):
    """Writes one result line; returns (line, mean pixel variance, time per seed, image mean)."""
    mean = imgs.mean(axis=0)
    var = imgs.var(axis=0, ddof=1)
    lum_mean = mean.mean()
    rel_img = imgs.mean(axis=(1, 2, 3)).std(ddof=1) / lum_mean
    mask = mean > 0.01 * lum_mean
    rel_px = float(np.mean(np.sqrt(var[mask]) / mean[mask]))
    wall = float(np.median([w for w, _ in secs]))
    t = float(np.median([c for _, c in secs]))  # process CPU seconds: the load moves them less
    eff = 1.0 / (var.mean() * t)
    line = (f"{name} {who}: {args.seeds} seeds x {args.spp} spp, {args.threads} "
            f"thread(s); image mean {lum_mean:.5f}; rel. se of the image mean "
            f"{rel_img:.4f}; mean pixel rel. sd {rel_px:.4f}; mean pixel variance "
            f"{var.mean():.3e}; {t:.2f} CPU s ({wall:.2f} s wall) per seed; efficiency "
            f"1/(var CPU t) {eff:.4g}; "
            f"{machine}")
    print(line, flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "a") as f:
        f.write(line + "\n")
    return line, float(var.mean()), t, float(lum_mean)


if __name__ == "__main__":
    main()
