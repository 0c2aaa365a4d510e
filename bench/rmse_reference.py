"""Converged references for `bench/rmse.py`, cached as refs/<scene>_<W>x<H>.npz.

A reference is the mean of K >= 4 independent renders (different seeds, spp/K each); their
spread gives the per-pixel standard error of that mean and so the RMSE the reference itself
still carries (its noise floor: a test image can never measure below it)."""

import hashlib
import math
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

MIN_SEEDS = 4
SEED_BASE = 1_000_003  # reference seeds: SEED_BASE + k, never a benchmark run's seed
REL_EPS = 1e-2         # as lantern.metrics.relative_rmse


def scene_hash(scene):
    """Short hash of everything the renderer sees of `scene` (its native dict)."""
    h = hashlib.sha1()

    def feed(value):
        if isinstance(value, dict):
            for key in sorted(value):
                h.update(repr(key).encode())
                feed(value[key])
        elif isinstance(value, (list, tuple)):
            h.update(b"[")
            for item in value:
                feed(item)
            h.update(b"]")
        elif isinstance(value, np.ndarray):
            h.update(f"{value.dtype}{value.shape}".encode())
            h.update(np.ascontiguousarray(value).tobytes())
        else:
            h.update(repr(value).encode())

    feed(scene.to_native())
    return h.hexdigest()[:16]


def noise_floor(se, ref):
    """Expected RMSE and relative RMSE of a mean image with per-pixel standard error `se`."""
    se2 = np.asarray(se, np.float64) ** 2
    ref = np.asarray(ref, np.float64)
    return (float(math.sqrt(se2.mean())),
            float(math.sqrt((se2 / (ref ** 2 + REL_EPS)).mean())))


def ref_path(refs_dir, scene_name, width, height):
    return Path(refs_dir) / f"{scene_name}_{width}x{height}.npz"


def load(path):
    """The cached reference as a dict (arrays and plain values), or None."""
    if not path.exists():
        return None
    try:
        with np.load(path, allow_pickle=False) as z:
            ref = {k: z[k] for k in z.files}
    except (OSError, ValueError) as e:
        print(f"reference {path}: unreadable ({e}); rebuilding")
        return None
    for k, v in list(ref.items()):
        if v.ndim == 0:
            ref[k] = v.item()
    return ref


def mismatch(ref, want):
    """Why cached reference `ref` does not serve settings `want` (None: it does)."""
    if ref is None:
        return "no cached reference"
    if ref.get("scene_hash") != want["scene_hash"]:
        return "the scene changed"
    for key in ("integrator", "max_depth"):
        if ref.get(key) != want[key]:
            return f"{key} {ref.get(key)!r} != {want[key]!r}"
    if ref.get("spp", 0) < want["spp"]:
        return f"spp {ref.get('spp')} < {want['spp']}"
    if ref.get("n_seeds", 0) < MIN_SEEDS:
        return f"only {ref.get('n_seeds')} seeds"
    if set(want["avoid_seeds"]) & set(np.atleast_1d(ref["seeds"]).tolist()):
        return "a benchmark seed is one of the reference's seeds"
    return None


def build(lantern, scene, integrator, spp, n_seeds, threads, max_depth, progress=None):
    """Render the reference: n_seeds independent sessions of ceil(spp / n_seeds) spp each.
    `progress(done_spp, total_spp)` is called after each iteration."""
    if n_seeds < MIN_SEEDS:
        raise ValueError(f"a reference needs at least {MIN_SEEDS} seeds, got {n_seeds}")
    per_seed = max(1, math.ceil(spp / n_seeds))
    spi = min(per_seed, 16)
    seeds = [SEED_BASE + k for k in range(n_seeds)]
    images, wall, done = [], 0.0, 0
    for seed in seeds:
        start = time.perf_counter()
        session = lantern.Session(scene, integrator=integrator, seed=seed, threads=threads,
                                  spp_per_iteration=spi, max_depth=max_depth)
        while session.spp < per_seed:
            before = session.spp
            session.step()
            if progress is not None:
                progress(done + session.spp, per_seed * n_seeds)
            if session.spp <= before:
                raise RuntimeError("reference render made no progress (cancelled?)")
        images.append(np.asarray(session.image(), np.float64))
        wall += time.perf_counter() - start
        done += session.spp
    stack = np.stack(images)
    mean = stack.mean(axis=0)
    se = stack.std(axis=0, ddof=1) / math.sqrt(n_seeds)
    rmse_floor, rel_floor = noise_floor(se, mean)
    return {
        "image": mean.astype(np.float32),
        "se": se.astype(np.float32),
        "spp": int(done),
        "spp_per_seed": int(done // n_seeds),
        "n_seeds": int(n_seeds),
        "seeds": np.array(seeds, dtype=np.uint64),
        "integrator": integrator,
        "max_depth": int(max_depth),
        "threads": int(threads),
        "wall_s": float(wall),
        "rmse_floor": rmse_floor,
        "rel_rmse_floor": rel_floor,
        "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
    }


def get(lantern, scene, scene_name, settings, refs_dir, rebuild=False, progress=None):
    """The reference for `scene` (cached or rendered now and cached). `settings`: integrator,
    spp, n_seeds, threads, max_depth, avoid_seeds (benchmark seeds it must not reuse)."""
    h, w = scene.film["height"], scene.film["width"]
    path = ref_path(refs_dir, scene_name, w, h)
    want = dict(settings, scene_hash=scene_hash(scene))
    cached = None if rebuild else load(path)
    why = "rebuild requested" if rebuild else mismatch(cached, want)
    if why is None:
        cached["path"], cached["cached"] = str(path), True
        return cached
    print(f"reference {scene_name} {w}x{h}: rendering ({why}): {want['integrator']}, "
          f"{want['spp']} spp over {want['n_seeds']} seeds")
    ref = build(lantern, scene, want["integrator"], want["spp"], want["n_seeds"],
                want["threads"], want["max_depth"], progress)
    ref["scene_hash"] = want["scene_hash"]
    ref["lantern_version"] = getattr(lantern, "__version__", "?")
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp.npz")
    np.savez_compressed(tmp, **ref)
    tmp.replace(path)
    ref["path"], ref["cached"] = str(path), False
    return ref
