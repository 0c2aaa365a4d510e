"""Render one small scene many times with the same seed and settings and count the images that
differ from the first, bit for bit (DESIGN.md: same seed, same settings, same backend: same
image on the CPU). Issue 12: a race in the CPU thread pool made 47 of 1,500 identical cis
renders differ with 2 threads.

    python tools/determinism.py --renders 1000 --threads 2            # the acceptance run
    python tools/determinism.py --renders 200 --threads 8 --integrator lvc --size 24

Each render is a fresh Session (scene build, thread pool, iterations), so a race anywhere from
the acceleration-structure build to the film shows. Exit status 1 when any render differs.
tests/python/test_determinism.py runs a short version in CI."""

import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if os.path.join(ROOT, "python") not in sys.path:
    sys.path.insert(0, os.path.join(ROOT, "python"))


def default_scene(size=16, name="cornell_box"):
    """A scene of lantern.scenes at size x size; by default the Cornell box: diffuse walls, two
    boxes, an area light (every cis stage runs: light pass, cache, sort, resampled connections,
    light tracing, film). features_box adds textures, normal maps and several material types."""
    from lantern import scenes
    return getattr(scenes, name)(width=size, height=size)


def render_once(scene, integrator, threads, spp, iterations, seed=7, backend="cpu"):
    """One fresh Session: `iterations` steps of `spp` samples per pixel; the float32 image."""
    from lantern import Session
    s = Session(scene, integrator=integrator, threads=threads, backend=backend, seed=seed,
                spp_per_iteration=spp)
    for _ in range(iterations):
        s.step()
    return s.image()


def run(renders, threads, integrator="cis", size=16, spp=2, iterations=2, scene=None,
        backend="cpu", progress=None, scene_name="cornell_box"):
    """Renders a first image and then `renders` more; returns a dict: renders, differ (how many
    of those are not bit-identical to the first), first_differ (index of the first that differs, or None), max_abs (largest
    pixel difference seen), pixels_differ (most pixels one differing render changed), seconds."""
    scene = scene if scene is not None else default_scene(size, scene_name)
    t0 = time.monotonic()
    ref = render_once(scene, integrator, threads, spp, iterations, backend=backend)
    ref_bytes = ref.tobytes()
    out = {"renders": renders, "differ": 0, "first_differ": None, "max_abs": 0.0,
           "pixels_differ": 0, "finite": bool(np.isfinite(ref).all())}
    for k in range(1, renders + 1):
        img = render_once(scene, integrator, threads, spp, iterations, backend=backend)
        if img.tobytes() != ref_bytes:
            out["differ"] += 1
            if out["first_differ"] is None:
                out["first_differ"] = k
            diff = np.abs(img.astype(np.float64) - ref)
            out["max_abs"] = max(out["max_abs"], float(np.nanmax(diff)))
            out["pixels_differ"] = max(out["pixels_differ"],
                                       int((diff.max(axis=2) > 0).sum()))
        if progress is not None:
            progress(k, renders, out["differ"])
    out["seconds"] = time.monotonic() - t0
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--renders", type=int, default=1000, help="renders compared with a first one")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--integrator", default="cis", choices=("pt", "lt", "bdpt", "lvc", "cis"))
    p.add_argument("--size", type=int, default=16, help="film width and height in pixels")
    p.add_argument("--spp", type=int, default=2, help="samples per pixel per iteration")
    p.add_argument("--iterations", type=int, default=2, help="steps per render")
    p.add_argument("--backend", default="cpu")
    p.add_argument("--scene", default="cornell_box",
                   help="a scene function of lantern.scenes (cornell_box, features_box, ...)")
    a = p.parse_args(argv)
    if a.renders < 1:
        p.error("--renders must be at least 1")

    def progress(done, total, differ):
        if done % 100 == 0 or done == total:
            print(f"  {done}/{total} renders, {differ} differ", file=sys.stderr, flush=True)

    r = run(a.renders, a.threads, a.integrator, a.size, a.spp, a.iterations,
            backend=a.backend, progress=progress, scene_name=a.scene)
    print(f"{r['differ']} of {r['renders']} repeated renders differ from the first "
          f"({a.scene}, {a.integrator}, {a.size}x{a.size}, {a.threads} threads, {a.spp} spp x "
          f"{a.iterations} iterations, backend {a.backend}, {r['seconds']:.1f} s)")
    if r["differ"]:
        print(f"first differing render: {r['first_differ']}; largest pixel difference "
              f"{r['max_abs']:.3g}; up to {r['pixels_differ']} pixels changed")
    return 1 if r["differ"] else 0


if __name__ == "__main__":
    sys.exit(main())
