"""Per-pixel noise and efficiency at equal spp, the QMC sampler (core/sampler.h) against PCG.

Noise = RMS over pixels of the spread (sd) between K independent seeds, relative to the image
mean; efficiency = 1 / (noise^2 x time), time the worker process's CPU time (a loaded
machine's wall time mostly measures the other processes; both are recorded). One thread. Both
samplers run in the same run, in two worker processes that take turns seed by seed (the order
alternates), so a change of the machine's load hits both alike. The PCG build is this checkout
compiled with -DLANTERN_RNG_PCG (core/rng.h then makes Rng the pseudo-random Pcg32 stream used
before issue 14):

    cmake -S . -B build/pcg -G Ninja -DCMAKE_BUILD_TYPE=Release -DLANTERN_BUILD_PYTHON=ON \\
          -DLANTERN_BUILD_TESTS=OFF -DLANTERN_CUDA=OFF -DPython_EXECUTABLE=$PY \\
          -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG -DLANTERN_RNG_PCG"
    cmake --build build/pcg --target _core
    $PY bench/qmc_noise.py --scenes cornell_box,glossy_box,room_area_point,room_spot_sun_world \\
        --integrators pt,cis --spp 4,16,64 --seeds 8

Scenes: `lantern.scenes` builders, and two rooms built here from the same parts (the issue's
"room lit by an area light and a small point light" and "room lit by a spot, a sun and a
world colour"; blend_scenes/bench_rooms.py's are 0.6-1.8M triangles, too slow for K seeds x
two samplers x two integrators on one thread).
"""
import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def room_area_point(width=64, height=64):
    """The Cornell box (walls and boxes) under its ceiling rectangle light (25 W), plus a small
    sphere light (2 cm, 4 W) low in the back-left corner."""
    import lantern.scenes as ls
    scene = ls.cornell_box(width=width, height=height, light_power=25.0)
    scene.add_light("point", position=[-0.8, 0.8, 0.3], radius=0.02, power=[4.0] * 3,
                    soft_falloff=False, visible_camera=False)
    return scene


def room_spot_sun_world(width=64, height=64):
    """The Cornell box without its area light, lit by a spot in the top-right corner aimed at the
    floor (60 W, 50 degree cone), a sun shining in through the open front (strength 3, 3 degree
    disk) and a dim blue world colour (0.05, 0.06, 0.08)."""
    import lantern.scenes as ls
    scene, white, red, green = ls._box_room(width, height)
    ls._walls(scene, white, red, green)
    ls._boxes(scene, white, white)
    m = np.eye(4)
    eye, target = np.array([0.8, -0.6, 1.9]), np.array([-0.2, 0.3, 0.0])
    z = eye - target  # the cone points along local -Z
    z /= np.linalg.norm(z)
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, np.cross(z, x), z, eye
    scene.add_light("spot", to_world=m.tolist(), radius=0.05, power=[60.0] * 3,
                    spot_size=np.radians(50.0), spot_blend=0.3, visible_camera=False)
    scene.add_light("sun", direction=[-0.3, 0.8, -0.5], angle=np.radians(3.0),
                    strength=[3.0] * 3)
    scene.world["color"] = [0.05, 0.06, 0.08]
    return scene


LOCAL_SCENES = {"room_area_point": room_area_point, "room_spot_sun_world": room_spot_sun_world}


def _package_with(core_so, tmp):
    """A copy of python/lantern whose _core is `core_so`, importable from `tmp`."""
    dst = Path(tmp) / "lantern"
    shutil.copytree(ROOT / "python" / "lantern", dst, ignore=shutil.ignore_patterns("_core*"))
    (dst / Path(core_so).name).symlink_to(Path(core_so).resolve())
    return tmp


def _worker():
    """Serve render requests from stdin (one JSON line each): render, reply with the image."""
    import lantern
    import lantern.scenes
    scenes = {}
    for line in sys.stdin:
        q = json.loads(line)
        key = (q["scene"], q["res"])
        if key not in scenes:
            build = LOCAL_SCENES.get(q["scene"]) or getattr(lantern.scenes, q["scene"])
            scenes[key] = build(width=q["res"], height=q["res"])
        s = lantern.Session(scenes[key], integrator=q["integrator"], seed=q["seed"], threads=1,
                            max_depth=q["max_depth"], spp_per_iteration=1)
        w0, c0 = time.perf_counter(), time.process_time()
        for _ in range(q["spp"]):
            s.step()
        t, wall = time.process_time() - c0, time.perf_counter() - w0
        img = np.asarray(s.image(), dtype=np.float64)[..., :3].mean(axis=2)
        sys.stdout.write(json.dumps({"t": t, "wall": wall, "img": img.ravel().tolist()}) + "\n")
        sys.stdout.flush()


class Worker:
    def __init__(self, so, tmp):
        _package_with(so, tmp)
        self.p = subprocess.Popen([sys.executable, __file__, "--worker"], text=True,
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  env={"PYTHONPATH": tmp, "PATH": "/usr/bin:/bin"})

    def render(self, **q):
        self.p.stdin.write(json.dumps(q) + "\n")
        self.p.stdin.flush()
        r = json.loads(self.p.stdout.readline())
        return np.array(r["img"]), r["t"], r["wall"]

    def close(self):
        self.p.stdin.close()
        self.p.wait()


def _stats(imgs, times, walls, spp):
    imgs = np.stack(imgs)
    mean = float(imgs.mean())
    var = imgs.var(axis=0, ddof=1)
    t = float(np.mean(times))
    noise, noise_med = float(np.sqrt(var.mean())) / mean, float(np.sqrt(np.median(var))) / mean
    return {"noise": noise, "noise_med": noise_med, "mean": mean, "t": t,
            "ms_per_spp": 1e3 * t / spp, "wall_ms_per_spp": 1e3 * float(np.mean(walls)) / spp}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="cornell_box,glossy_box,room_area_point,"
                                        "room_spot_sun_world")
    ap.add_argument("--integrators", default="pt,cis")
    ap.add_argument("--spp", default="4,16,64")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--max-depth", type=int, default=12)
    ap.add_argument("--qmc", default=str(next((ROOT / "build" / "dev").glob("_core*.so"), "")))
    ap.add_argument("--pcg", default=str(next((ROOT / "build" / "pcg").glob("_core*.so"), "")))
    ap.add_argument("--json", help="also write every row here")
    ap.add_argument("--names", default="PCG,QMC", help="the two builds' names in the table")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--table-from", help="print the table of a --json file; render nothing")
    args = ap.parse_args(argv)
    if args.worker:
        return _worker()
    if args.table_from:
        return print_table(json.loads(Path(args.table_from).read_text()), args)
    for label, so in (("pcg", args.pcg), ("qmc", args.qmc)):
        if not so or not Path(so).exists():
            sys.exit(f"no _core for {label}: build it (see the docstring) or pass --{label}")
    rows = []
    with tempfile.TemporaryDirectory() as ta, tempfile.TemporaryDirectory() as tb:
        workers = {"pcg": Worker(args.pcg, ta), "qmc": Worker(args.qmc, tb)}
        for integrator in args.integrators.split(","):
            for scene in args.scenes.split(","):
                for spp in [int(x) for x in args.spp.split(",")]:
                    out = {"pcg": ([], [], []), "qmc": ([], [], [])}
                    for k in range(args.seeds):
                        order = ("pcg", "qmc") if k % 2 == 0 else ("qmc", "pcg")
                        for label in order:
                            res = workers[label].render(
                                scene=scene, res=args.res, integrator=integrator,
                                seed=1000 + k, spp=spp, max_depth=args.max_depth)
                            for lst, v in zip(out[label], res):
                                lst.append(v)
                    r = {"integrator": integrator, "scene": scene, "spp": spp}
                    for label in out:
                        r[label] = _stats(*out[label], spp)
                    rows.append(r)
                    print(json.dumps(r), file=sys.stderr, flush=True)
        for w in workers.values():
            w.close()
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    print_table(rows, args)


def print_table(rows, args):
    a, b = args.names.split(",")
    print(f"{args.res}x{args.res}, {args.seeds} seeds, one thread, max_depth {args.max_depth}; "
          "noise = RMS per-pixel sd between seeds / image mean (median pixel: the median "
          "pixel's sd); time = the worker's CPU time (wall time in the json); "
          "efficiency = 1/(noise^2 time)")
    print(f"| integrator | scene | spp | {a} noise | {b} noise | variance {a}/{b} | median pixel "
          f"{a}/{b} | CPU ms/spp {a}, {b} | efficiency {b}/{a} | median pixel | "
          f"mean {a}, {b} |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        p, q = r["pcg"], r["qmc"]
        t = p["t"] / q["t"]
        v, vm = (p["noise"] / q["noise"]) ** 2, (p["noise_med"] / q["noise_med"]) ** 2
        print(f"| {r['integrator']} | {r['scene']} | {r['spp']} | {100 * p['noise']:.2f}% | "
              f"{100 * q['noise']:.2f}% | {v:.2f} | {vm:.2f} | {p['ms_per_spp']:.1f}, "
              f"{q['ms_per_spp']:.1f} | {v * t:.2f} | {vm * t:.2f} | "
              f"{p['mean']:.4f}, {q['mean']:.4f} |")

if __name__ == "__main__":
    sys.exit(main())
