"""Per-pixel noise at equal spp, the QMC sampler (core/sampler.h) against the old PCG stream.

Noise = RMS over pixels of the spread (sd) between K independent seeds, relative to the image
mean, one thread, both samplers in the same run. The PCG build is this checkout compiled with
-DLANTERN_RNG_PCG (core/rng.h keeps the old stream behind that flag for this bench only):

    cmake -S . -B build/pcg -G Ninja -DCMAKE_BUILD_TYPE=Release -DLANTERN_BUILD_PYTHON=ON \\
          -DLANTERN_BUILD_TESTS=OFF -DLANTERN_CUDA=OFF -DPython_EXECUTABLE=$PY \\
          -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG -DLANTERN_RNG_PCG"
    cmake --build build/pcg --target _core
    $PY bench/qmc_noise.py --scenes cornell_box,glossy_box --spp 1,4,16,64 --seeds 16
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


def _package_with(core_so, tmp):
    """A copy of python/lantern whose _core is `core_so`, importable from `tmp`."""
    dst = Path(tmp) / "lantern"
    shutil.copytree(ROOT / "python" / "lantern", dst, ignore=shutil.ignore_patterns("_core*"))
    (dst / Path(core_so).name).symlink_to(Path(core_so).resolve())
    return tmp


def _child(args):
    """Render every (scene, spp, progressive) at K seeds; print one JSON line per case."""
    import lantern
    import lantern.scenes
    for name in args.scenes.split(","):
        scene = getattr(lantern.scenes, name)(width=args.res, height=args.res)
        for spp in [int(x) for x in args.spp.split(",")]:
            for progressive in (False, True) if spp in args.progressive_at else (False,):
                imgs, t = [], 0.0
                for seed in range(args.seeds):
                    s = lantern.Session(scene, integrator=args.integrator, seed=1000 + seed,
                                        threads=1, max_depth=args.max_depth,
                                        spp_per_iteration=1 if progressive else spp)
                    t0 = time.perf_counter()
                    for _ in range(spp if progressive else 1):
                        s.step()
                    t += time.perf_counter() - t0
                    imgs.append(np.asarray(s.image(), dtype=np.float64)[..., :3].mean(axis=2))
                imgs = np.stack(imgs)
                mean = float(imgs.mean())
                var = imgs.var(axis=0, ddof=1)
                noise = float(np.sqrt(var.mean())) / mean
                # the median pixel's: robust to the rare fireflies that dominate the mean at low spp
                noise_med = float(np.sqrt(np.median(var))) / mean
                print(json.dumps({"scene": name, "spp": spp, "progressive": progressive,
                                  "noise": noise, "noise_med": noise_med, "mean": mean,
                                  "ms_per_spp": 1e3 * t / (args.seeds * spp)}), flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="cornell_box,glossy_box")
    ap.add_argument("--spp", default="1,4,16,64")
    ap.add_argument("--progressive-at", default="16", help="spp also run as 1-spp iterations")
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--max-depth", type=int, default=12)
    ap.add_argument("--integrator", default="pt")
    ap.add_argument("--qmc", default=str(next((ROOT / "build" / "dev").glob("_core*.so"), "")))
    ap.add_argument("--pcg", default=str(next((ROOT / "build" / "pcg").glob("_core*.so"), "")))
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    args.progressive_at = [int(x) for x in args.progressive_at.split(",") if x]
    if args.child:
        return _child(args)
    rows = {}
    for label, so in (("pcg", args.pcg), ("qmc", args.qmc)):
        if not so or not Path(so).exists():
            sys.exit(f"no _core for {label}: build it (see the docstring) or pass --{label}")
        with tempfile.TemporaryDirectory() as tmp:
            _package_with(so, tmp)
            cmd = [sys.executable, __file__, "--child"] + [a for a in (argv or sys.argv[1:])]
            out = subprocess.run(cmd, env={"PYTHONPATH": tmp, "PATH": "/usr/bin:/bin"},
                                 capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            r = json.loads(line)
            rows.setdefault((r["scene"], r["spp"], r["progressive"]), {})[label] = r
    print(f"{args.integrator}, {args.res}x{args.res}, {args.seeds} seeds, one thread, "
          f"max_depth {args.max_depth}; noise = RMS per-pixel sd between seeds / image mean")
    print("| scene | spp | iterations | PCG noise | QMC noise | variance PCG/QMC | "
          "median pixel: PCG/QMC | mean PCG, QMC | ms/spp PCG, QMC |")
    print("|---|---|---|---|---|---|---|---|---|")
    for (scene, spp, prog), r in rows.items():
        p, q = r["pcg"], r["qmc"]
        print(f"| {scene} | {spp} | {spp if prog else 1} | {100 * p['noise']:.2f}% | "
              f"{100 * q['noise']:.2f}% | {(p['noise'] / q['noise']) ** 2:.2f} | "
              f"{(p['noise_med'] / q['noise_med']) ** 2:.2f} | "
              f"{p['mean']:.4f}, {q['mean']:.4f} | {p['ms_per_spp']:.0f}, {q['ms_per_spp']:.0f} |")


if __name__ == "__main__":
    sys.exit(main())
