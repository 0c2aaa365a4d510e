"""The child process of the GPU self-check (gpu_selfcheck.py): renders the conformance set on
the GPU and on the CPU and compares them. Run by the parent only:

    python -m lantern.gpu_selfcheck_run [--double pass|fail|nan|hang|crash] [--cases a/b,...]

Protocol (stdout): "start <case>" before each case (so that a parent whose child hung or
crashed can name the case), "case {json}" after it (case, ok, reason), then one "result {json}"
line: ok (the core set passed), reason, case, cases, features (per feature of
gpu_selfcheck.FEATURE_CASES reached: ok, case, reason). The core set runs first and stops at its
first failure; then each feature's cases, a feature's rest skipped after its first failure, the
other features still checked. Exit status 0 when every case passed, 1 when one failed;
anything else is a crash.

The set (32 x 32, max_depth 6, pt and cis each): a diffuse furnace, the features box (a
textured floor, an alpha card, a normal map, mix shaders, glass), a glass lantern around a
light, a glossy ball under an environment map with a sun, a fur ball (strands: the curve BVH
and the hair lobe) and the fur ball turning and sliding over the shutter (motion blur: the
two-level BVH's moving instance, a strand set entered through its matrix at the ray's time);
then the feature cases (gpu_selfcheck.FEATURE_CASES, 16 x 16): the lit Skin sphere
(lantern.scenes_sss: pt's walk, cis's camera and light paths' walks, lt's adjoint walk) and the
fog box (homogeneous fog and a heterogeneous smoke cube: pt's volume path, cis's and lt's
medium stages). Each case renders SEEDS seeds of SPP samples (CASE_SPP: lt's) on each side and
compares them with lantern.metrics.compare_renders (8 x 8 blocks and the image mean,
Bonferroni at 1e-3); a failed comparison is rendered again with fresh seeds and counts only
when that fails too (a correct GPU then fails a case with probability about (2e-3)^2). The
doubles stand in for the GPU renderer: "pass" renders on the CPU (other seeds), "fail" does so
25 % too bright, "nan" puts a NaN in a pixel, "hang" sleeps, "crash" aborts the process;
"fail:skin" (any double, any scene) fails that scene's cases only."""

import argparse
import json
import os
import sys
import time

import numpy as np

from lantern.gpu_selfcheck import FEATURE_CASES, FEATURE_LABELS, feature_of

SIZE = 32
SKIN_SIZE = 16   # the feature cases: 4 blocks of 8 x 8 each, what the furnace has
FOG_SIZE = 16
SEEDS = 8
SPP = 8
# lt splats its light paths onto the film: at 8 spp skin/lt let a 25 % too bright GPU pass (its
# image mean's noise 3-6 %); at these counts a GPU 10 % too bright fails every feature case
CASE_SPP = {"skin/lt": 128, "fog/lt": 32}
MAX_DEPTH = 6
CORE_CASES = ("furnace/pt", "features/pt", "envmap/pt", "hair/pt", "motion/pt", "furnace/cis",
              "features/cis", "glass/cis", "envmap/cis", "hair/cis", "motion/cis")
# (glass/pt: pt cannot render the lantern in seconds, noise 5-8 %)
CASES = CORE_CASES + tuple(c for cases in FEATURE_CASES.values() for c in cases)
ABSURD = 1e7   # a pixel brighter than this in these scenes is a fault, not light


def _envmap_scene(size):
    from lantern import Scene, scenes
    scene = Scene()
    scene.film.update(width=size, height=size)
    scene.look_at((0.0, -3.0, 0.4), (0.0, 0.0, 0.0), fov=45.0)
    gloss = scene.add_material("gloss", type="conductor", base_color=(0.9, 0.7, 0.5),
                               roughness=0.3)
    pos, idx = scenes.icosphere(3, 0.9)
    scene.add_mesh(pos, idx, material=gloss, name="ball")
    h, w = 16, 32
    up = np.clip((np.arange(h)[::-1] + 0.5) / h * 2.0 - 1.0, 0.0, 1.0)
    sky = np.empty((h, w, 3), np.float32)
    sky[..., 0], sky[..., 1], sky[..., 2] = (0.3 + 0.4 * up)[:, None], 0.35 + 0.4 * up[:, None], \
        (0.4 + 0.6 * up)[:, None]
    sky[h // 2:] *= 0.3
    sky[3:6, 9:12] = [40.0, 36.0, 28.0]   # a sun: importance sampling matters
    scene.world = {"color": [0.0, 0.0, 0.0], "map": sky, "strength": [1.0, 1.0, 1.0]}
    return scene


def _turn_steps(steps=3):
    """A sixth of a turn about z and a 0.3 m slide along x over the shutter, the identity at its
    middle (where the scene's positions are exported): (steps, 4, 4)."""
    out = []
    for u in np.linspace(0.0, 1.0, steps):
        a = (u - 0.5) * np.pi / 3.0
        m = np.eye(4)
        m[:2, :2] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
        m[0, 3] = 0.3 * (u - 0.5)
        out.append(m)
    return out


def _hair_scene(size, moving=False):
    """The fur ball (lantern.scenes_hair); moving: it turns and slides over the shutter, the ball
    by its matrices and the fur with it (the strands' CurveSetMotion)."""
    from lantern.scenes_hair import fur_ball
    scene = fur_ball(size, size, num_strands=150, world=0.3)
    if moving:
        for part in (scene.meshes[0], scene.curves[0]):
            part["motion"] = _turn_steps()
            part["motion_base"] = np.eye(4)
    return scene


def fog_box(width=16, height=16):
    """The Cornell box without its boxes in homogeneous world fog, with a smoke cube of a
    density ramp (a heterogeneous volume) under the light: pt's volume path, the bidirectional
    medium vertices of both kinds (bdpt_medium_stages.h, bdpt_medium_hetero.h) and lt's
    (lt_medium.h); the self-check's fog/* cases and tools/gpu_compare.py's fog_box."""
    from lantern import scenes
    scene = scenes.cornell_box(width, height, boxes=False)
    scene.world["volume"] = {"sigma_s": [0.3, 0.3, 0.3], "sigma_a": [0.02, 0.03, 0.05], "g": 0.3}
    m4 = np.diag([0.2, 0.2, 0.2, 1.0])
    m4[:3, 3] = (-0.3, -0.3, 0.4)
    ramp = np.linspace(0.5, 4.0, 4, dtype=np.float32)
    g = scene.add_grid(np.ascontiguousarray(np.broadcast_to(ramp, (4, 4, 4))), m4,
                       name="smoke:density")
    m = scene.add_material("smoke")
    scene.materials[m].update(volume={"sigma_s": [1.0, 1.0, 1.0], "sigma_a": [0.1, 0.1, 0.1],
                                      "g": 0.3}, volume_only=True, density_grid=g)
    scene.add_mesh(*scenes.aabb_mesh((-0.3, -0.3, 0.4), (0.3, 0.3, 1.0)), material=m,
                   name="smoke")
    return scene


def scene_for(name, size=SIZE):
    from lantern import scenes
    if name == "furnace":  # every path runs to max_depth: the smallest film that has 4 blocks
        return scenes.furnace_sphere(albedo=0.5, emission=1.0, width=16, height=16)
    if name == "features":
        return scenes.features_box(width=size, height=size)
    if name == "glass":
        return scenes.glass_lantern(width=size, height=size)
    if name == "envmap":
        return _envmap_scene(size)
    if name == "hair":
        return _hair_scene(size)
    if name == "motion":
        return _hair_scene(size, moving=True)
    if name == "skin":
        from lantern import scenes_sss
        return scenes_sss.lit_sphere(SKIN_SIZE, SKIN_SIZE, method="random_walk_skin")
    if name == "fog":
        return fog_box(FOG_SIZE, FOG_SIZE)
    raise ValueError(f"unknown self-check scene {name!r}")


def render_seeds(scene, backend, integrator, seeds, spp, max_depth, iterations=2, check=None,
                 **settings):
    """One image per seed (a Session of `iterations` steps of spp // iterations samples, at
    least 1) and the backends the sessions ran on; check(session), when given, sees each
    session after its steps. tools/gpu_compare.py renders its sets with it too."""
    import lantern
    images, used = [], set()
    for seed in seeds:
        s = lantern.Session(scene, backend=backend, integrator=integrator, seed=seed,
                            max_depth=max_depth, spp_per_iteration=max(1, spp // iterations),
                            **settings)
        for _ in range(iterations):
            s.step()
        if check is not None:
            check(s)
        images.append(s.image())
        used.add(s.backend)
    return images, sorted(used)


def render(scene, backend, integrator, seeds, spp=SPP):
    """One image per seed; raises when a session did not run on `backend`."""
    def check(s):
        if s.backend != backend:
            raise RuntimeError(f"the session rendered on {s.backend}, not {backend}: "
                               f"{'; '.join(s.warnings)}")
    images, _ = render_seeds(scene, backend, integrator, seeds, spp, MAX_DEPTH, check=check,
                             threads=0)
    return [np.asarray(im, np.float64) for im in images]


def gpu_renderer(double):
    """The GPU renderer, or a test double standing in for it: (scene, integrator, seeds, spp,
    name) -> images. A double "kind:scene" (e.g. "fail:skin") is that kind on the cases of that
    scene and "pass" on the others: a fault in one feature's stages."""
    if double and ":" in double:
        kind, target = double.split(":", 1)
        hit, miss = _renderer(kind), _renderer("pass")
        return lambda scene, integ, seeds, spp, name=None: \
            (hit if name == target else miss)(scene, integ, seeds, spp)
    base = _renderer(double)
    return lambda scene, integ, seeds, spp, name=None: base(scene, integ, seeds, spp)


def _renderer(double):
    def cpu(scene, integ, seeds, spp):  # the doubles: the CPU with other seeds
        return render(scene, "cpu", integ, [s + 7919 for s in seeds], spp)
    if not double:
        return lambda scene, integ, seeds, spp: render(scene, "cuda", integ, seeds, spp)
    if double == "pass":
        return cpu
    if double == "fail":
        return lambda *args: [1.25 * im for im in cpu(*args)]
    if double == "nan":
        def nan(*args):
            ims = cpu(*args)
            h, w = ims[0].shape[:2]
            ims[0][h // 2, w // 2, 1] = np.nan
            return ims
        return nan
    if double == "hang":
        def hang(*args):
            time.sleep(3600.0)
            return []
        return hang
    if double == "crash":
        def crash(*args):
            sys.stdout.flush()
            os.abort()
        return crash
    raise ValueError(f"unknown self-check double {double!r}")


def check_values(images):
    """None when every pixel is finite, non-negative and below ABSURD, else what is wrong."""
    for k, im in enumerate(images):
        bad = ~np.isfinite(im)
        if bad.any():
            y, x = np.argwhere(bad)[0][:2]
            return f"{int(bad.sum())} non-finite values (first at pixel ({x}, {y}) of seed {k})"
        if im.min() < -1e-6:
            return f"a negative pixel value {im.min():.3g}"
        if im.max() > ABSURD:
            return f"a pixel value of {im.max():.3g}"
    return None


def run_case(case, gpu, round_=0):
    """None when the case passes, else the reason."""
    from lantern import metrics
    scene_name, integ = case.split("/")
    scene = scene_for(scene_name)
    seeds = [1000 * round_ + k for k in range(SEEDS)]
    spp = CASE_SPP.get(case, SPP)
    try:
        a = gpu(scene, integ, seeds, spp, scene_name)
    except Exception as e:  # a launch error, an out-of-memory, a fallback
        return f"the GPU render raised {type(e).__name__}: {str(e).strip()[:300]}"
    bad = check_values(a)
    if bad:
        return f"the GPU image has {bad}"
    b = render(scene, "cpu", integ, [s + 104729 for s in seeds], spp)
    res = metrics.compare_renders(a, b, block=8)
    if res.passed:
        return None
    first = str(res).strip().splitlines()
    return f"the GPU image differs from the CPU's ({first[0] if first else 'no detail'})"


def run_set(cases, gpu):
    """(ok, cases done, features, failed case, reason): the core cases first (stopping at the
    first failure), then each feature's (skipping a feature's rest after its first failure)."""
    cases = sorted(cases, key=lambda c: feature_of(c) is not None)  # stable: core first
    done, features = [], {}
    for case in cases:
        feature = feature_of(case)
        if feature and not features.get(feature, {}).get("ok", True):
            continue
        print(f"start {case}", flush=True)
        why = run_case(case, gpu)
        if why and "differs" in why:
            print(f"confirm {case}", flush=True)  # fresh seeds: one unlucky comparison is no fault
            why = run_case(case, gpu, round_=1)
        entry = {"case": case, "ok": why is None, "reason": why or ""}
        done.append(entry)
        print("case " + json.dumps(entry), flush=True)
        if feature is None and why:
            return False, done, features, case, f"the GPU self-check failed on '{case}': {why}"
        if feature:
            features[feature] = {"ok": why is None, "case": case,
                                 "reason": f"the GPU self-check failed on '{case}': {why}"
                                 if why else ""}
    failed = [(f, v) for f, v in features.items() if not v["ok"]]
    reason = f"the GPU passed {sum(e['ok'] for e in done)} cases"
    if failed:
        reason += "; " + "; ".join(f"{FEATURE_LABELS[f]} stays on the CPU: {v['reason']}"
                                   for f, v in failed)
    return True, done, features, (failed[0][1]["case"] if failed else ""), reason


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--double", default=None)
    ap.add_argument("--cases", default=None)
    a = ap.parse_args(argv)
    cases = a.cases.split(",") if a.cases else list(CASES)
    ok, done, features, case, reason = run_set(cases, gpu_renderer(a.double))
    result = {"ok": ok, "case": case, "cases": done, "features": features, "reason": reason}
    print("result " + json.dumps(result), flush=True)
    return 0 if ok and all(e["ok"] for e in done) else 1


if __name__ == "__main__":
    sys.exit(main())
