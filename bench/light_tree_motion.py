"""The light tree's bounds over the shutter for a moving emitter (issue 32, docs/motion_blur.md
"A moving emitter"): the tree built with each moving emissive triangle's box over the shutter
(the default) against the frame's bounds alone (LANTERN_LIGHT_TREE_SHUTTER=0, the behaviour
before), pt, one thread, the two taking turns seed by seed in one process (the variable is read
when a scene is built).

Scenes: a 24 m floor seen from above; an emissive 0.8 x 0.4 m quad 1 m over it sliding along x
over the shutter (3 steps), and `--still` dim still point lights on a line beside its path, so
that the tree has a choice and the frame's bounds place the moving lamp where it is at the frame
only. "far": 10 m, exported at the shutter's middle (Position Center: the frame's bounds at the
path's middle); "far_start": 10 m, exported at the shutter's opening (Position Start: the frame's
bounds at one end of the path); "near": 0.4 m (the bounds hardly change: alike in noise too).

Measured per mode: the image mean (luminance) and its standard error over seeds (the two modes
must agree: both are unbiased, only the light-selection probabilities differ), the noise (mean
over pixels of the per-pixel standard deviation of the luminance between seeds, over the image
mean), CPU seconds a render (process time, median over seeds) and the efficiency 1 / (noise^2 x
time); plus lantern.metrics.compare_renders of the two modes' image sets.

    PYTHONPATH=python .venv/bin/python bench/light_tree_motion.py --seeds 16 --spp 16 \\
        --out bench/results/2026-12-06-mbleft
"""
import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np

LUM = np.array([0.2126, 0.7152, 0.0722])
QUAD = np.array([[-0.4, -0.2, 0, 1], [0.4, -0.2, 0, 1], [0.4, 0.2, 0, 1], [-0.4, 0.2, 0, 1]])


def scene(res, slide, still, frame_at=0.5):
    import lantern
    sc = lantern.Scene()
    sc.film["width"], sc.film["height"] = res
    sc.look_at((0.0, -7.0, 9.0), (0.0, 0.0, 0.0), up=(0, 0, 1), fov=70)
    floor = sc.add_material("floor", base_color=(0.8, 0.8, 0.8))
    lamp = sc.add_material("lamp", base_color=(0.0, 0.0, 0.0), emission=(40.0, 36.0, 30.0))
    sc.add_mesh(np.array([[-12, -12, 0], [12, -12, 0], [12, 12, 0], [-12, 12, 0]], np.float32),
                np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=floor)
    quad = QUAD.copy()
    quad[:, 2] = 1.0  # 1 m over the floor; exported at shutter time frame_at (x there)
    quad[:, 0] += slide * (frame_at - 0.5)
    sc.add_mesh(quad[:, :3].astype(np.float32), np.array([[0, 2, 1], [0, 3, 2]], np.uint32),
                material=lamp, name="lamp")
    steps = [np.eye(4) for _ in range(3)]
    for m, t in zip(steps, (0.0, 0.5, 1.0)):
        m[0, 3] = slide * (t - frame_at)
    sc.meshes[1]["motion"] = steps
    sc.meshes[1]["motion_base"] = np.eye(4)
    for k in range(still):  # dim still lights on a line beside the lamp's path
        x = -9.0 + 18.0 * (k + 0.5) / still
        sc.add_light("point", position=(x, 3.0, 2.0), radius=0.05, power=(20.0, 20.0, 20.0))
    sc.world["color"] = (0.0, 0.0, 0.0)
    return sc


def render(sc, seed, spp, shutter):
    import lantern
    os.environ["LANTERN_LIGHT_TREE_SHUTTER"] = "1" if shutter else "0"
    s = lantern.Session(sc, integrator="pt", seed=seed, backend="cpu", threads=1, max_depth=3,
                        spp_per_iteration=spp)
    assert not s.warnings, list(s.warnings)
    c0 = time.process_time()
    s.step()
    return np.asarray(s.image(), np.float64), time.process_time() - c0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--res", default="48x48")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--still", type=int, default=6)
    ap.add_argument("--cases", default="far:10:0.5,far_start:10:0,near:0.4:0.5",
                    help="name:slide metres:the frame's shutter time (0.5 Center, 0 Start)")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    from lantern import metrics
    res = tuple(int(v) for v in args.res.split("x"))
    report = {"machine": platform.node(), "cpu": platform.processor(), "args": vars(args),
              "loadavg_start": os.getloadavg(), "cases": {}}
    for case in args.cases.split(","):
        name, slide, frame_at = case.split(":")
        sc = scene(res, float(slide), args.still, float(frame_at))
        imgs = {True: [], False: []}
        cpu = {True: [], False: []}
        for k in range(args.seeds):  # A/B in turns, the same seeds
            for shutter in ((True, False) if k % 2 == 0 else (False, True)):
                img, t = render(sc, 1000 + k, args.spp, shutter)
                imgs[shutter].append(img)
                cpu[shutter].append(t)
        out = {}
        for shutter in (True, False):
            x = np.stack(imgs[shutter])
            lum = x @ LUM
            means = lum.reshape(len(lum), -1).mean(axis=1)
            m = float(means.mean())
            noise = float(lum.std(axis=0, ddof=1).mean() / m)
            t = float(np.median(cpu[shutter]))
            out["shutter" if shutter else "frame"] = {
                "image_mean": m, "image_mean_se": float(means.std(ddof=1) / np.sqrt(len(means))),
                "noise": noise, "cpu_s": t, "efficiency": 1.0 / (noise ** 2 * t)}
        cmp = metrics.compare_renders(np.stack(imgs[True]), np.stack(imgs[False]), block=8,
                                      se_floor=1e-6)
        out["compare_renders_passed"] = bool(cmp.passed)
        out["compare_renders"] = str(cmp)
        a, b = out["shutter"], out["frame"]
        out["mean_diff_sigma"] = (a["image_mean"] - b["image_mean"]) / float(
            np.hypot(a["image_mean_se"], b["image_mean_se"]))
        out["variance_ratio_frame_over_shutter"] = (b["noise"] / a["noise"]) ** 2
        out["efficiency_ratio_shutter_over_frame"] = a["efficiency"] / b["efficiency"]
        report["cases"][name] = out
        print(name, json.dumps(out, indent=1), flush=True)
    report["loadavg_end"] = os.getloadavg()
    if args.out:
        Path(args.out).mkdir(parents=True, exist_ok=True)
        (Path(args.out) / "light_tree_motion.json").write_text(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
