"""Blender's default bulb (a soft-falloff point light of radius 0.1 m) in a shade: pt against the
bidirectional integrators, whose light paths now start on it (integrator/soft_light_path.h).
Noise at equal spp with the seeds' spread, CPU time (one thread) and efficiency 1 / (noise^2 t)
relative to pt. K seeds per integrator, interleaved (seed k of every integrator, then k + 1)
so that a change of the machine's load falls on all alike.

    PYTHONPATH=python .venv/bin/python bench/soft_light_noise.py --seeds 8 --spp 16 --res 32

Run with another build's python/ first on the path to measure it the same way (the results
name the build). Scenes: the fixture box's closed shade with a 0.12 m hole (`shade`) and with a
0.3 m opening (`open_shade`), the sphere light replaced by the soft-falloff default."""

import argparse
import json
import os
import platform
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from cis_noise import jackknife_ratio, noise_of, parse_integrator  # noqa: E402


def make_scene(name, res):
    from lantern import scenes
    opening = {"shade": 0.12, "open_shade": 0.3}[name]
    scene = scenes.fixture_box(res, res, opening=opening, light_power=100.0, light_radius=0.1)
    scene.lights[0]["soft_falloff"] = True  # Blender's default
    return scene


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="shade,open_shade")
    ap.add_argument("--integrators", default="pt,cis,auto")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--res", type=int, default=32)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    import lantern
    cpu = platform.processor() or platform.machine()
    print(f"# lantern from {os.path.dirname(lantern.__file__)}; {cpu}, {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.1f}")
    rows = []
    for scene_name in args.scenes.split(","):
        scene = make_scene(scene_name, args.res)
        specs = args.integrators.split(",")
        images = {k: [] for k in specs}
        times = {k: [] for k in specs}
        lightpaths = {k: [] for k in specs}
        for seed in range(args.seeds):
            for spec in specs:
                name, extra = parse_integrator(spec)
                sess = lantern.Session(scene, integrator=name, seed=1 + seed, threads=1,
                                       spp_per_iteration=args.spp, backend="cpu",
                                       max_depth=args.max_depth, **extra)
                t0 = time.process_time()
                sess.step()
                times[spec].append(time.process_time() - t0)
                images[spec].append(np.asarray(sess.image(), np.float64)[..., :3])
                lightpaths[spec].append(float(sess.stats.get("rays_light", 0)))
        base = np.stack(images[specs[0]])
        t_base = float(np.mean(times[specs[0]]))
        print(f"# {scene_name}: {args.res}x{args.res}, {args.spp} spp, max_depth "
              f"{args.max_depth}, {args.seeds} seeds")
        print("| integrator | noise rms | mean | noise / pt | CPU s | efficiency / pt | "
              "light rays |")
        print("|---|---:|---:|---:|---:|---:|---:|")
        for spec in specs:
            stack = np.stack(images[spec])
            rms, _, mean = noise_of(stack)
            ratio, se = jackknife_ratio(base, stack)
            t = float(np.mean(times[spec]))
            eff = 1.0 / (ratio * ratio * t / t_base)
            eff_se = 2.0 * se / ratio * eff
            print(f"| {spec} | {100 * rms:.2f}% | {mean:.5f} | {ratio:.3f} +- {se:.3f} | "
                  f"{t:.2f} | {eff:.2f} +- {eff_se:.2f} | {np.mean(lightpaths[spec]):.0f} |")
            rows.append({"scene": scene_name, "integrator": spec, "res": args.res,
                         "spp": args.spp, "seeds": args.seeds, "noise_rms": rms, "mean": mean,
                         "ratio": ratio, "ratio_se": se, "cpu_s": t, "efficiency": eff,
                         "efficiency_se": eff_se, "rays_light": float(np.mean(lightpaths[spec]))})
        sys.stdout.flush()
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
