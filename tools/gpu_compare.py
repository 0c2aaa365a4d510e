"""CUDA against CPU, statistically: the same scenes, integrators and settings rendered on two
backends must converge to the same image (DESIGN.md "Verification" 5).

Per scene and integrator, K independent seeds on each backend (different seeds on the two, so
the sets are independent); per 8x8 block and channel z = (mean_a - mean_b) / sqrt(se_a^2 +
se_b^2) with standard errors from the spread of the seeds: the comparison of every render test
(lantern.metrics.compare_renders, tests/README.md: a Welch t-test per block, Bonferroni at alpha
1e-3 over the blocks, and z-tests of the image mean and the block-weighted mean with a 0.2 %
cap; a correct GPU fails a case with probability <= 2e-3). Every image must be finite, and
each session must really have run on the backend asked for (no silent fallback). Each row
also says the smallest whole-image bias the case resolves ("detects").

    python3 tools/gpu_compare.py [--backends cpu,cuda] [--integrators pt,bdpt,lvc,cis]
        [--scenes bench/scenes/bench_fixture.lantern,...|files|features] [--size 64] [--seeds 8]
        [--spp 64] [--out DIR] [--quick]

Scenes: .lantern files (their film is scaled to --size pixels wide, aspect kept) or names of
lantern.scenes builders (cornell_box, features_box, ...), subsurface_skin (here) or fog_box
(lantern.gpu_selfcheck_run's); "files" and "features" name the default scenes' two groups.
Writes compare.json, compare.md (after each row: a timeout keeps the rows done) and one PNG per
scene (the two backends' mean images side by side, pt) under --out; a session that raises
fails its row and the next rows still run. Exit status:
0 all agree, 1 a disagreement or a non-finite pixel, 2 a backend unavailable."""

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))

import lantern  # noqa: E402
from lantern import imageio, metrics, session  # noqa: E402
from lantern.gpu_selfcheck_run import render_seeds  # noqa: E402

# a light in a fixture, glossy metal, caustics through glass (the paper's hard cases, exported
# from Blender), and alpha, textures, normal map and mix shaders (lantern.scenes.features_box(64,
# 64) saved as a file)
# and subsurface_skin (below): every walk stage (pt's, the bidirectional camera and light
# paths', lt's; docs/cuda_backend.md "Subsurface walks of bdpt, lvc, cis and lt"), with lt too
# and fog_box (lantern.gpu_selfcheck_run's: homogeneous fog and a heterogeneous smoke cube, the
# medium stages of every integrator, lt's too)
FILE_SCENES = ["bench/scenes/bench_fixture.lantern", "bench/scenes/bench_glossy.lantern",
               "bench/scenes/bench_caustics.lantern", "bench/scenes/gpu_features.lantern"]
FEATURE_SCENES = ["subsurface_skin", "fog_box"]
DEFAULT_SCENES = FILE_SCENES + FEATURE_SCENES
# --scenes may name these groups (tools/gpu_check.sh runs "features" and "files" apart)
SCENE_GROUPS = {"files": FILE_SCENES, "features": FEATURE_SCENES}
# integrators a scene adds to --integrators (lt renders Skin and these media itself)
EXTRA_INTEGRATORS = {"subsurface_skin": ["lt"], "fog_box": ["lt"]}


def subsurface_skin(width, height):
    """A unit sphere with Skin subsurface on a grey floor under a point light, world black
    (lantern.scenes_sss.lit_sphere, the lit sphere of tests/python/test_subsurface_bidir_light.py
    and of the GPU self-check's skin/* cases): camera paths walk it (pt, bdpt, lvc, cis) and so do
    light paths (bdpt, lvc, cis, lt)."""
    from lantern import scenes_sss
    return scenes_sss.lit_sphere(width, height, method="random_walk_skin")


def load(name, size, hard_falloff=True):
    """A scene by .lantern path (film scaled to `size` wide) or lantern.scenes builder name.
    hard_falloff: point and spot lights lose Blender's soft falloff, so that the bidirectional
    integrators trace light paths from them (with it they render those lights by camera-side
    techniques only: the same estimator as pt, which would test nothing new)."""
    path = Path(name)
    if not path.is_absolute():
        path = ROOT / path
    if name.endswith(".lantern"):
        scene = lantern.load_scene(str(path))
        w, h = int(scene.film["width"]), int(scene.film["height"])
        scene.film["width"] = int(size)
        scene.film["height"] = max(8, int(round(size * h / w / 8.0)) * 8)
        if hard_falloff:
            for light in scene.lights:
                if light.get("type") in ("point", "spot"):
                    light["soft_falloff"] = False
        return scene
    from lantern import scenes
    from lantern.gpu_selfcheck_run import fog_box
    builder = ({"subsurface_skin": subsurface_skin, "fog_box": fog_box}.get(name)
               or getattr(scenes, name, None))
    if not callable(builder):
        raise ValueError(f"scene {name!r}: not a .lantern file nor a lantern.scenes builder")
    return builder(width=int(size), height=int(size))


def render_set(scene, backend, integrator, seeds, spp, max_depth):
    """K renders (4 iterations of spp/4 each, as the cross-integrator test), the backend the
    sessions really used, and the seconds spent."""
    t0 = time.perf_counter()
    images, used = render_seeds(scene, backend, integrator, seeds, spp, max_depth, iterations=4)
    return images, used, time.perf_counter() - t0


def compare_one(scene, name, integrator, backends, k, spp, max_depth, scale_b=1.0):
    a_name, b_name = backends
    a, used_a, t_a = render_set(scene, a_name, integrator, range(1000, 1000 + k), spp, max_depth)
    b, used_b, t_b = render_set(scene, b_name, integrator, range(5000, 5000 + k), spp, max_depth)
    b = [x * np.float32(scale_b) for x in b]  # 1 except in the tool's own test
    finite = bool(all(np.isfinite(x).all() for x in a + b))
    res = metrics.compare_renders(a, b, block=8)
    passed, cmp = res.passed, res.blocks
    fell_back = [f"{want} ran on {got}" for want, got in ((a_name, used_a), (b_name, used_b))
                 if got != [want]]
    row = {"scene": name, "integrator": integrator, "backends": list(backends),
           "worst_z": round(cmp.worst, 3), "threshold": round(cmp.threshold(1e-3), 3),
           "blocks": cmp.n, "mean_rel": [round(float(x), 6) for x in res.mean_rel],
           "mean_allowed": round(float(max(res.mean_allowed[0])), 6),
           "detects": round(res.detectable_bias(), 5), "finite": finite,
           "mean_a": float(np.mean(a)), "mean_b": float(np.mean(b)),
           "seconds_a": round(t_a, 3), "seconds_b": round(t_b, 3), "fell_back": fell_back,
           "passed": bool(passed and finite and not fell_back), "detail": str(cmp)}
    return row, np.mean(a, axis=0), np.mean(b, axis=0)


def write_tables(out, args, rows):
    """compare.json and compare.md under out (None: nothing) for the rows so far."""
    if not out:
        return
    ok = all(r["passed"] for r in rows) and bool(rows)
    (out / "compare.json").write_text(json.dumps({"args": vars(args), "rows": rows,
                                                  "passed": ok}, indent=1))
    lines = ["| scene | integrator | worst z | threshold | mean diff (allowed) | detects | "
             "finite | ok |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['scene']} | {r['integrator']} | {r['error']} | | | | | NO |")
            continue
        lines.append(f"| {r['scene']} | {r['integrator']} | {r['worst_z']:.2f} | "
                     f"{r['threshold']:.2f} | {max(r['mean_rel'], key=abs):+.3%} "
                     f"({r['mean_allowed']:.3%}) | {r['detects']:.2%} | "
                     f"{r['finite']} | {'yes' if r['passed'] else 'NO'} |")
    (out / "compare.md").write_text("\n".join(lines) + "\n")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--backends", default="cpu,cuda", help="two backends (cpu,cuda)")
    p.add_argument("--integrators", default="pt,bdpt,lvc,cis")
    p.add_argument("--scenes", default=",".join(DEFAULT_SCENES))
    p.add_argument("--size", type=int, default=64, help="image width in pixels (64)")
    p.add_argument("--seeds", type=int, default=8, help="independent renders per set (8)")
    p.add_argument("--spp", type=int, default=64, help="samples per render (64)")
    p.add_argument("--max-depth", type=int, default=8)
    p.add_argument("--scale-b", type=float, default=1.0,
                   help="testing the tool: multiply the second backend's images (must fail)")
    p.add_argument("--soft-falloff", action="store_true",
                   help="keep the files' soft-falloff point lights (bidirectional = pt then)")
    p.add_argument("--out", default=None, help="folder for compare.json/.md and PNGs")
    p.add_argument("--quick", action="store_true",
                   help="toy size for checking the tool: 16 px, 4 seeds, 8 spp, one scene")
    args = p.parse_args(argv)
    if args.quick:
        args.size, args.seeds, args.spp = 16, 4, 8
        if args.scenes in (",".join(DEFAULT_SCENES), "files"):
            args.scenes = DEFAULT_SCENES[0]
    args.scenes = ",".join(",".join(SCENE_GROUPS.get(n.strip(), [n.strip()]))
                           for n in args.scenes.split(",") if n.strip())
    backends = [b.strip() for b in args.backends.split(",") if b.strip()]
    if len(backends) != 2:
        p.error("--backends needs exactly two names, e.g. cpu,cuda")
    for b in backends:
        reason = session.backend_unavailable(b)
        if reason:
            print(f"gpu_compare: backend {b!r} unavailable: {reason}", file=sys.stderr)
            return 2
    out = Path(args.out) if args.out else None
    if out:
        out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in [s.strip() for s in args.scenes.split(",") if s.strip()]:
        scene = load(name, args.size, hard_falloff=not args.soft_falloff)
        label = Path(name).stem
        previews = []
        integrators = [i.strip() for i in args.integrators.split(",") if i.strip()]
        integrators += [i for i in EXTRA_INTEGRATORS.get(name, []) if i not in integrators]
        for integrator in integrators:
            try:
                row, mean_a, mean_b = compare_one(scene, label, integrator, backends, args.seeds,
                                                  args.spp, args.max_depth, args.scale_b)
            except Exception as e:  # a launch error: the row fails, the next ones still run
                rows.append({"scene": label, "integrator": integrator,
                             "backends": list(backends), "passed": False,
                             "error": f"{type(e).__name__}: {str(e).strip()[:300]}"})
                print(f"{label:>18} {integrator:>5}: FAIL {rows[-1]['error']}", flush=True)
                write_tables(out, args, rows)
                continue
            rows.append(row)
            print(f"{label:>18} {integrator:>5}: worst |z| {row['worst_z']:6.2f} (threshold "
                  f"{row['threshold']:.2f}), image mean {max(row['mean_rel'], key=abs):+.3%} "
                  f"(allowed {row['mean_allowed']:.3%}), detects {row['detects']:.2%}, means "
                  f"{row['mean_a']:.5g} vs {row['mean_b']:.5g}, "
                  f"{'ok' if row['passed'] else 'FAIL'}"
                  f"{'' if row['finite'] else ' NON-FINITE'}"
                  f"{' ' + '; '.join(row['fell_back']) if row['fell_back'] else ''}", flush=True)
            write_tables(out, args, rows)  # after each row: a timeout or a crash keeps them
            if integrator == "pt" or not previews:
                previews = [mean_a, mean_b]
        if out and previews:
            imageio.write_image(str(out / f"compare_{label}.png"),
                                np.concatenate(previews, axis=1), backend="builtin")
    ok = all(r["passed"] for r in rows) and bool(rows)
    write_tables(out, args, rows)
    print(f"gpu_compare: {sum(r['passed'] for r in rows)}/{len(rows)} agree "
          f"({backends[0]} vs {backends[1]})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
