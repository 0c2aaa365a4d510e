"""Blend scenes and Cycles in bench/rmse.py.

A scene named `blend:<builder>` is built in this process with bpy by a builder of
blend_scenes/ (scenes.py, or any module there with a `SCENES` dict of builders), at the run's
resolution, and exported to a `lantern.Scene` through the add-on, so Lantern's integrators and
Cycles render the same .blend. The integrator `cycles` renders the current bpy scene with Cycles
on the CPU (DESIGN.md "Matching Cycles": no denoising, no clamping, no light threshold, no
adaptive sampling, Blackman-Harris 1.5 px, 16 bounces of every kind = Lantern max_depth 18) at
1, 2, 4, ... spp until the time or spp budget is spent; every render is timed on its own (with
persistent data, so the scene is synchronised once) and scored against a Cycles reference of
K seeds, cached like Lantern's. Each renderer is scored against its own converged image: where
Lantern does not yet translate a material the way Cycles renders it, the two converge to
different images, and their RMSE curves still compare speed against error fairly."""

import importlib
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
BOUNCES = 16  # Cycles max_bounces of every kind; Lantern max_depth = BOUNCES + 2


def _blend_builders():
    """Every builder of blend_scenes/: scenes.SCENES plus any bench module's SCENES."""
    sys.path.insert(0, str(ROOT / "blend_scenes"))
    builders = {}
    for path in sorted((ROOT / "blend_scenes").glob("*.py")):
        if path.stem in ("build",):
            continue
        try:
            mod = importlib.import_module(path.stem)
        except Exception:  # a module that is not a builder collection (or needs arguments)
            continue
        table = getattr(mod, "SCENES", None)
        if isinstance(table, dict):
            for name, fn in table.items():
                builders.setdefault(name, fn)
        bench = getattr(mod, "BENCH", None)  # bench_registry: name -> BenchBlend(build=...)
        if isinstance(bench, dict):
            for name, spec in bench.items():
                fn = getattr(spec, "build", None)
                if callable(fn):
                    builders.setdefault(name, fn)
    return builders


def build_blend(name, width, height, export=True):
    """Build blend scene `name` into the current bpy data at width x height and export it
    through the add-on. Returns the lantern.Scene (None with export False: lantern is then
    not imported, for a process that renders only Cycles: bench/side_process.py)."""
    import bpy
    sys.path.insert(0, str(ROOT / "tools"))
    import lantern_bpy
    builders = _blend_builders()
    if name not in builders:
        raise KeyError(f"no blend_scenes builder named {name!r} (known: "
                       f"{', '.join(sorted(builders))})")
    builders[name]()
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = int(width), int(height)
    scene.render.resolution_percentage = 100
    if not export:
        return None
    lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    lscene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    for msg in report.messages:
        print(f"  export {name}: {msg}")
    return lscene


def _settings(scene, seed, spp, threads):
    """The comparison settings of tools/render_compare.py (DESIGN.md "Matching Cycles"), plus
    the thread count and persistent data (the scene is synchronised once across the renders)."""
    sys.path.insert(0, str(ROOT / "tools"))
    import render_compare
    assert render_compare.BOUNCES == BOUNCES
    render_compare.cycles_settings(scene, seed, spp)
    scene.render.threads_mode = "FIXED" if threads else "AUTO"
    if threads:
        scene.render.threads = int(threads)
    scene.render.use_persistent_data = True


def render(seed, spp, threads=0):
    """Render the current bpy scene with Cycles: (float32 (H, W, 3), seconds of the render)."""
    import bpy
    sys.path.insert(0, str(ROOT / "tools"))
    import lantern_bpy
    scene = bpy.context.scene
    _settings(scene, seed, spp, threads)
    with tempfile.TemporaryDirectory() as tmp:
        scene.render.filepath = os.path.join(tmp, "cycles.exr")
        t = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        seconds = time.perf_counter() - t
        img = lantern_bpy.read_image_bpy(scene.render.filepath)
    return np.asarray(img, np.float32)[..., :3], seconds


def reference(scene_name, width, height, spp, n_seeds, refs_dir, noise_floor, rebuild=False):
    """Cycles reference of the current bpy scene: K seeds, cached in refs_dir."""
    path = Path(refs_dir) / f"cycles_{scene_name.replace(':', '_')}_{width}x{height}.npz"
    if path.exists() and not rebuild:
        z = np.load(path)
        if int(z["spp"]) >= spp and int(z["n_seeds"]) >= n_seeds:
            return {k: (z[k] if z[k].ndim else z[k].item()) for k in z.files} | {
                "path": str(path), "cached": True, "integrator": "cycles"}
    per_seed = max(1, math.ceil(spp / n_seeds))
    print(f"reference {scene_name} (Cycles): {per_seed * n_seeds} spp over {n_seeds} seeds")
    images, wall = [], 0.0
    for k in range(n_seeds):
        img, s = render(900 + k, per_seed)
        images.append(img.astype(np.float64))
        wall += s
    stack = np.stack(images)
    mean = stack.mean(axis=0)
    se = stack.std(axis=0, ddof=1) / math.sqrt(n_seeds)
    floor, rel_floor = noise_floor(se, mean)
    ref = {"image": mean.astype(np.float32), "se": se.astype(np.float32),
           "spp": per_seed * n_seeds, "n_seeds": n_seeds, "wall_s": wall,
           "rmse_floor": floor, "rel_rmse_floor": rel_floor}
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, **ref)
    return ref | {"path": str(path), "cached": False, "integrator": "cycles"}


def run(lantern, scene_name, ref, args, next_spp=lambda n: 2 * n):
    """Cycles at 1, 2, 4, ... spp while the budget lasts; each render scored on its own.
    Returns (run dict in bench/rmse.py's format, final image)."""
    checkpoints, spp, img = [], 1, None
    floor, rel_floor = ref["rmse_floor"], ref["rel_rmse_floor"]
    while True:
        img, seconds = render(args.seed + 1, spp, args.threads)
        e = lantern.metrics.rmse(img, ref["image"])
        rel = lantern.metrics.relative_rmse(img, ref["image"])
        checkpoints.append({"spp": spp, "seconds": seconds, "rmse": e, "rel_rmse": rel,
                            "rmse_debiased": math.sqrt(max(e * e - floor * floor, 0.0)),
                            "rel_rmse_debiased": math.sqrt(max(rel * rel - rel_floor ** 2, 0.0))})
        print(f"  cycles {spp} spp: {seconds:.2f} s, RMSE {e:.4g}")
        nxt = next_spp(spp)
        # the next render takes about seconds * nxt / spp: stop before it breaks the budget
        if args.time is not None and seconds * nxt / spp > args.time:
            break
        if args.spp is not None and nxt > args.spp:
            break
        spp = nxt
    last = checkpoints[-1]
    run = {"scene": scene_name, "integrator": "cycles", "setup_s": 0.0,
           "checkpoints": checkpoints, "stats": {"renderer": "Cycles (CPU, bpy)",
                                                 "spp": last["spp"],
                                                 "time_total": last["seconds"]},
           "reference": "cycles", "cpu_fraction": None, "load_avg": [os.getloadavg()[0]] * 2}
    return run, img
