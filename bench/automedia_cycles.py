"""Efficiency of Lantern (pt, cis and the default integrator "auto") against Cycles on two fog
scenes built in bpy (issue 29's efficiency line; docs/volumes.md, docs/auto_integrator.md):

- fog_spot: tests/cycles/test_volumes.py's fog room (a spot's beam with an occluder, the camera
  in a Principled Volume fog box);
- lamp_shade: a lamp in a shade in fog, built as an artist would: a room (floor, walls and
  ceiling of one flipped cube), a side table, a point light inside a cone shade open at the
  bottom and (narrowly) at the top, hung on a thin cord, the room filled with a Principled
  Volume fog box; `lamp_shade` with Soft Falloff off (a sphere light: light paths start on it),
  `lamp_shade_soft` with Blender's default Soft Falloff on (light paths from the bulb's centre
  through the fog since branch softmedia: docs/lvc_notes.md; before, none started there).

K seeds per renderer, one thread each, the tests' Cycles settings (render_compare: no
denoising, adaptive sampling, clamping or light threshold, Filter Glossy 0, max_bounces 16;
Lantern max_depth 18). Efficiency = 1 / (mean pixel variance over seeds x process CPU seconds
per seed); the ratio to Cycles' efficiency is reported per integrator, with auto's choices and
its own estimate of cis over pt ("auto" in --integrators: Lantern's default settings, whose
auto_media, auto's choice in media, is on since branch automoments; "auto_media" names it on,
"auto_nomedia" off: pt in any medium. Until 2026-12-05 "auto" here passed auto_media off).

Each renderer (a Lantern integrator, or Cycles) renders all its seeds in a child process of its
own confined to one CPU (bench/side_process.py; since branch benchproc), timed per seed by that
process's CPU time around the render alone; the per-seed times and the CPU / wall ratio are
printed. Before, Cycles' process CPU time counted an idle TBB worker thread of bpy's that spins
in sched_yield all through a one-thread Cycles render (with or without Lantern in the process):
1.0-2.0x the render's own, by the machine's load (bench/results/2026-12-05-benchproc/). Run
inside bpy's Python:

    nice python bench/automedia_cycles.py --scenes fog_spot lamp_shade lamp_shade_soft \\
        --spp 256 --seeds 8 --out bench/results/2026-12-04-automedia/cycles.txt"""
import argparse
import gc
import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))  # this checkout's lantern
sys.path.insert(0, os.path.join(ROOT, "tests", "cycles"))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "bench"))
if "--worker" in sys.argv:  # a child rendering one side: on one CPU before bpy loads TBB
    import side_process  # noqa: E402
    side_process.one_cpu()
import render_compare as rc  # noqa: E402
import test_volumes as tv  # noqa: E402


def lamp_shade(soft_falloff=False, size=32, density=0.15, radius=0.05):
    """A pendant lamp in a foggy room: the room a 4 m cube seen from inside (grey walls, a warm
    floor), a side table, a 0.05 m point light of 60 W inside a cone shade (0.32 m across at its
    open bottom, 0.12 m at its open top, 0.35 m tall, white inside) on a cord from the ceiling,
    the room filled with a Principled Volume of density `density`; `radius` the bulb's."""
    import bpy
    import bmesh
    from bpy_stage import camera, cube, light, reset
    scene = reset(size)
    wall = tv._material("wall", (0.7, 0.7, 0.7))
    floor = tv._material("floor", (0.6, 0.45, 0.3))
    shade_m = tv._material("shade", (0.85, 0.85, 0.8))
    bpy.ops.mesh.primitive_cube_add(size=4.0, location=(0, 0, 2.0))
    room = bpy.context.active_object
    room.name = "room"
    room.data.materials.append(wall)
    room.data.materials.append(floor)
    for p in room.data.polygons:  # the floor face its own material
        if p.center.z < -1.9:
            p.material_index = 1
    room.data.flip_normals()
    cube("table", (1.0, 0.8, 0.35), 1.0, tv._material("table", (0.4, 0.3, 0.2)),
         scale=(0.6, 0.6, 0.7))
    # the shade: a truncated cone, no caps (open at both ends), both sides shaded
    bpy.ops.mesh.primitive_cone_add(vertices=32, radius1=0.16, radius2=0.06, depth=0.35,
                                    location=(0.0, 0.2, 2.6), end_fill_type="NOTHING")
    shade = bpy.context.active_object
    shade.name = "shade"
    shade.data.materials.append(shade_m)
    bm = bmesh.new()
    bm.from_mesh(shade.data)
    bmesh.ops.solidify(bm, geom=bm.faces[:], thickness=0.005)
    bm.to_mesh(shade.data)
    bm.free()
    cube("cord", (0.0, 0.2, 3.39), 1.0, tv._material("cord", (0.05, 0.05, 0.05)),
         scale=(0.01, 0.01, 1.22))
    lamp = light(scene, "POINT", (0.0, 0.2, 2.65), 60.0, shadow_soft_size=radius)
    lamp.data.use_soft_falloff = soft_falloff
    tv._cube("fog", (0, 0, 2.0), 3.98, tv._volume_material("fog", density, (0.9, 0.9, 0.9)))
    camera(scene, (-1.2, -1.85, 1.3), (82, 0, -22), lens=18.0)


SCENES = {"fog_spot": tv.fog_spot, "lamp_shade": lambda: lamp_shade(False),
          "lamp_shade_soft": lambda: lamp_shade(True),
          # Blender's default point light: radius 0.1 m, Soft Falloff on
          "lamp_shade_soft10": lambda: lamp_shade(True, radius=0.1)}


def _stats(imgs, secs):
    imgs = np.stack(imgs).astype(np.float64)
    var = float(imgs.var(axis=0, ddof=1).mean())
    t = float(np.median(secs))
    seed_means = imgs.mean(axis=(1, 2, 3))  # the image mean's noise, from the seeds
    se = float(seed_means.std(ddof=1) / np.sqrt(len(seed_means)))
    return {"mean": float(imgs.mean()), "se": se, "var": var, "cpu": t, "eff": 1.0 / (var * t)}


def _render_worker(args):
    """One side of the comparison (a Lantern integrator, or "cycles") for all seeds of one
    scene, in this fresh process (on one CPU: no TBB worker to spin); writes the images and
    each seed's process CPU and wall seconds to args.worker_out. Cycles' process never imports
    lantern."""
    import json
    import bpy
    tv.SIZE = args.size
    SCENES[args.scenes[0]]()
    side = args.worker
    imgs, cpu, wall, chose, warnings = [], [], [], [], []
    if side == "cycles":
        bpy.context.scene.render.threads_mode = "FIXED"
        bpy.context.scene.render.threads = 1
        for k in range(args.seeds):
            c0, w0 = time.process_time(), time.perf_counter()
            imgs.append(np.asarray(rc.render_cycles(seed=900 + k, spp=args.spp)[0],
                                   dtype=np.float64)[..., :3])
            cpu.append(time.process_time() - c0)
            wall.append(time.perf_counter() - w0)
        assert "lantern" not in sys.modules, "Cycles' process imported lantern"
    else:
        import lantern
        rc.lantern_bpy.load_addon()
        from lantern_blender.export import export_scene
        scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
        # "auto": Lantern's default settings (auto_media on since branch automoments);
        # "auto_media" names the setting on; "auto_nomedia": off (pt in any medium)
        media = {"auto_media": {"auto_media": True},
                 "auto_nomedia": {"auto_media": False}}.get(side, {})
        for k in range(args.seeds):
            c0, w0 = time.process_time(), time.perf_counter()
            s = lantern.Session(scene, integrator=side.split("_")[0], backend="cpu", **media,
                                max_depth=rc.lantern_depth(rc.BOUNCES), seed=1 + k,
                                spp_per_iteration=args.spp_per_iteration, threads=1)
            while s.spp < args.spp:
                s.step()
            imgs.append(np.asarray(s.image(), dtype=np.float64)[..., :3])
            cpu.append(time.process_time() - c0)
            wall.append(time.perf_counter() - w0)
            st = s.stats
            if side.startswith("auto"):
                chose.append(f"{st['auto_choice']}({st['auto_cis_over_pt']:.2f};"
                             f"{st['auto_pt_iterations']}/{st['auto_cis_iterations']})")
            warnings = sorted(set(s.warnings))
            del s  # no Session outlives its seed
            gc.collect()
    np.savez(args.worker_out, imgs=np.stack(imgs), cpu=np.array(cpu), wall=np.array(wall),
             meta=np.array(json.dumps({"chose": chose, "warnings": warnings})))


def _run_side(args, name, side):
    """Render `side` of scene `name` in a child process (_render_worker); returns its images,
    CPU and wall seconds per seed, auto's choices and the warnings."""
    import json
    import subprocess
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "side.npz")
        cmd = [sys.executable, os.path.abspath(__file__), "--worker", side, "--worker-out", out,
               "--scenes", name, "--spp", str(args.spp), "--seeds", str(args.seeds),
               "--size", str(args.size), "--spp-per-iteration", str(args.spp_per_iteration),
               "--out", os.devnull]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"{side} on {name} failed:\n{r.stdout[-2000:]}{r.stderr[-4000:]}")
        with np.load(out) as z:
            meta = json.loads(str(z["meta"]))
            return z["imgs"], list(z["cpu"]), list(z["wall"]), meta["chose"], meta["warnings"]


def _times(cpu, wall):
    """Per-seed CPU seconds and the CPU / wall ratio (about 1 for one busy thread)."""
    return (f"CPU s per seed {' '.join(f'{c:.2f}' for c in cpu)}; median wall "
            f"{np.median(wall):.2f} s, CPU / wall {np.median(np.array(cpu) / np.array(wall)):.2f}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--integrators", nargs="+", default=["pt", "auto", "cis"])
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--spp-per-iteration", type=int, default=8)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--size", type=int, default=32)
    ap.add_argument("--no-cycles", action="store_true")
    ap.add_argument("--out", required=True)
    ap.add_argument("--worker", help=argparse.SUPPRESS)  # a child process: one side
    ap.add_argument("--worker-out", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        return _render_worker(args)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)

    def emit(line):
        print(line, flush=True)
        with open(args.out, "a") as f:
            f.write(line + "\n")

    emit(f"# {' '.join(sys.argv)}")
    emit(f"# machine: {platform.node()} {platform.machine()}, {os.cpu_count()} cores, load "
         f"{os.getloadavg()[0]:.1f}; {args.size}x{args.size}, {args.spp} spp x {args.seeds} "
         f"seeds, 1 thread, Lantern spp_per_iteration {args.spp_per_iteration}, max_depth "
         f"{rc.lantern_depth(rc.BOUNCES)}, Cycles max_bounces {rc.BOUNCES}; each renderer in "
         f"its own process")
    for name in args.scenes:
        res = {}
        for integ in args.integrators:
            imgs, cpu, wall, chose, warnings = _run_side(args, name, integ)
            r = res[integ] = _stats(imgs, cpu)
            extra = f"; auto chose (cis/pt est.; pt/cis iterations) {' '.join(chose)}" \
                if chose else ""
            emit(f"{name} lantern {integ}: image mean {r['mean']:.5f} +- {r['se']:.5f}; "
                 f"mean pixel variance {r['var']:.4e}; {r['cpu']:.2f} CPU s per seed "
                 f"(median; {_times(cpu, wall)}); efficiency {r['eff']:.4g}{extra}; "
                 f"warnings {warnings}; load {os.getloadavg()[0]:.1f}")
        if args.no_cycles:
            continue
        imgs, cpu, wall, _, _ = _run_side(args, name, "cycles")
        c = _stats(imgs, cpu)
        emit(f"{name} cycles: image mean {c['mean']:.5f} +- {c['se']:.5f}; mean pixel variance "
             f"{c['var']:.4e}; {c['cpu']:.2f} CPU s per seed (median; {_times(cpu, wall)}); "
             f"efficiency {c['eff']:.4g}; load {os.getloadavg()[0]:.1f}")
        emit(f"{name} efficiency / Cycles': " + ", ".join(
            f"{i} {res[i]['eff'] / c['eff']:.2f}x (variance {res[i]['var'] / c['var']:.4g}x, "
            f"CPU {res[i]['cpu'] / c['cpu']:.3g}x; mean {res[i]['mean'] / c['mean']:.4f}, "
            f"z {(res[i]['mean'] - c['mean']) / np.hypot(res[i]['se'], c['se']):+.2f})"
            for i in res))


if __name__ == "__main__":
    main()
