"""bdpt's efficiency on subsurface scenes before and after its light paths walk (docs/subsurface.md,
"Light paths walk"; integrator/bdpt_sss_light.h). Two builds of the core (their python/ folders:
--before, --after), each seed rendered in its own process, the two builds alternating seed by
seed so that the machine's load falls on both alike; CPU time is the worker's process time for
its render (one thread). Reported per scene and build: the image mean, the mean per-pixel
variance over seeds (pixels whose mean is > 1 % of the image mean), CPU s/seed, efficiency
1 / (variance x time), after / before, and the two builds' agreement
(lantern.agreement.compare_renders, block 8).

Scenes: bench/sss_lt_efficiency.py's caustic (a glass ball focusing a small sphere light onto a
Skin slab) and backlit (a 2 cm Skin slab lit from behind by a small sphere light), and the test
slab (tests/python/test_subsurface_scene.py's slab_scene with Skin: 10 cm lit from behind by a
large emissive quad, orthographic).

    PYTHONPATH=python nice python bench/sss_bidir_light_efficiency.py --before /work/main/python \\
        --after python --seeds 8 --out bench/results/2026-12-06-sssbidir/efficiency.txt"""
import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def _scene(name, size):
    import lantern  # noqa: F401  (the worker's build)
    if name == "slab":
        sys.path.insert(0, os.path.join(HERE, "..", "tests", "python"))
        from test_subsurface_scene import slab_scene
        s = slab_scene(1.0)
        s.materials[0].update(subsurface_method="random_walk_skin")
        s.film.update(width=size // 2, height=size // 2)
        return s
    sys.path.insert(0, HERE)
    import sss_lt_efficiency as lte
    return lte.SCENES[name](size)


def worker(args):
    import lantern
    scene = _scene(args.scene, args.size)
    c0 = time.process_time()
    s = lantern.Session(scene, integrator=args.integrator, backend="cpu", seed=args.seed,
                        max_depth=args.max_depth, spp_per_iteration=args.spp, threads=1)
    while s.spp < args.spp:
        s.step()
    img = np.asarray(s.image(), dtype=np.float64)[..., :3]
    cpu = time.process_time() - c0
    np.save(args.npy, img)
    print(json.dumps({"cpu": cpu, "warnings": list(s.warnings)}))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before")
    ap.add_argument("--after")
    ap.add_argument("--size", type=int, default=32)
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--integrator", default="bdpt")
    ap.add_argument("--scenes", nargs="+", default=["caustic", "backlit", "slab"])
    ap.add_argument("--out")
    ap.add_argument("--worker", action="store_true")
    ap.add_argument("--scene")
    ap.add_argument("--seed", type=int)
    ap.add_argument("--npy")
    args = ap.parse_args()
    if args.worker:
        return worker(args)
    sys.path.insert(0, os.path.abspath(args.after))
    from lantern import agreement
    builds = {"before": os.path.abspath(args.before), "after": os.path.abspath(args.after)}
    machine = (f"{platform.node()} {platform.processor() or platform.machine()}, "
               f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    lines = [f"subsurface, {args.integrator} before / after its light paths walk: "
             f"{args.size}x{args.size} ({args.size // 2} for slab), max_depth {args.max_depth}, "
             f"{args.seeds} seeds x {args.spp} spp, 1 thread, builds alternating per seed; "
             f"{machine}"]
    tmp = tempfile.mkdtemp(prefix="sss_bidir_")
    for name in args.scenes:
        imgs = {b: [] for b in builds}
        cpu = {b: [] for b in builds}
        for k in range(args.seeds):
            order = list(builds) if k % 2 == 0 else list(builds)[::-1]
            for b in order:
                npy = os.path.join(tmp, f"{name}_{b}_{k}.npy")
                env = dict(os.environ, PYTHONPATH=builds[b])
                out = subprocess.run(
                    [sys.executable, os.path.abspath(__file__), "--worker", "--scene", name,
                     "--seed", str(1 + k), "--npy", npy, "--size", str(args.size), "--spp",
                     str(args.spp), "--max-depth", str(args.max_depth), "--integrator",
                     args.integrator], env=env, check=True, capture_output=True, text=True)
                rep = json.loads(out.stdout.strip().splitlines()[-1])
                assert not any("rendering with pt" in w for w in rep["warnings"]), rep
                imgs[b].append(np.load(npy))
                cpu[b].append(rep["cpu"])
        eff = {}
        for b in builds:
            a = np.stack(imgs[b])
            mean = a.mean(axis=0)
            lit = mean.mean(axis=-1) > 0.01 * mean.mean()
            var = a.var(axis=0, ddof=1).mean(axis=-1)[lit].mean()
            t = float(np.mean(cpu[b]))
            eff[b] = 1.0 / (var * t)
            lines.append(f"  {name} {b}: image mean {a.mean():.5f}; mean pixel variance "
                         f"{var:.4e}; CPU {t:.3f} s/seed; efficiency {eff[b]:.4g}")
        res = agreement.compare_renders(imgs["after"], imgs["before"], block=8)
        lines.append(f"  {name} efficiency after / before: {eff['after'] / eff['before']:.2f}x; "
                     f"{res}")
        print("\n".join(lines[-3:]), flush=True)
    if args.out:
        os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
        with open(args.out, "a") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
