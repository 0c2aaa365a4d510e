"""`python -m lantern`: render a `.lantern` scene file (whole, or one sample chunk of it for a
render farm), merge sample chunks, or print a summary of a scene.

Errors print one line and exit non-zero; `--debug` shows the traceback instead."""

import argparse
import sys
import time
from pathlib import Path

EXIT_ERROR = 1
EXIT_USAGE = 2


def _positive_int(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {value}")
    return value


def _nonnegative_int(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {value}")
    return value


def _positive_float(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {value}")
    return value


def build_parser():
    parser = argparse.ArgumentParser(prog="python -m lantern",
                                     description="Lantern: render and inspect scene files.")
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    r = sub.add_parser("render", help="render a .lantern scene to an image")
    r.add_argument("scene", help="scene file (.lantern)")
    r.add_argument("-o", "--output", required=True, help="output image (.exr, .png or .npy)")
    r.add_argument("--spp", type=_positive_int, default=64, help="samples per pixel (64)")
    r.add_argument("--integrator", default="auto",
                   choices=("auto", "pt", "bdpt", "lvc", "cis", "lt"),
                   help="integrator (auto: pt or cis, whichever the render measures as more "
                        "efficient)")
    r.add_argument("--backend", default="auto", choices=("cpu", "cuda", "auto"),
                   help="backend (auto)")
    r.add_argument("--seed", type=_nonnegative_int, default=0, help="random seed (0)")
    r.add_argument("--chunk", type=_nonnegative_int, default=0,
                   help="sample chunk index: chunks of one seed hold independent samples, "
                        "merged with `merge` (0)")
    r.add_argument("--threads", type=_nonnegative_int, default=0,
                   help="CPU threads, 0 = all cores (0)")
    r.add_argument("--max-depth", type=_positive_int, default=16,
                   help="maximum path depth (16)")
    r.add_argument("--spp-per-iteration", type=_positive_int, default=1,
                   help="samples per pixel per iteration (1)")
    r.add_argument("--connections", type=_positive_int, default=5,
                   help="bdpt/lvc/cis: cache vertices each camera vertex connects to, N (5)")
    r.add_argument("--candidates", type=_positive_int, default=10,
                   help="cis: candidates resampled into the N connections, M (10)")
    r.add_argument("--sort", default=None, action=argparse.BooleanOptionalAction,
                   help="sort each bounce by material type (default: on for cis only)")
    r.add_argument("--time-limit", type=_positive_float, default=None,
                   help="stop after this many seconds")
    r.add_argument("--png", default=None, help="also write an sRGB PNG preview here")
    r.add_argument("--half", action="store_true", help="write the EXR as half floats")
    r.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                   help=argparse.SUPPRESS)
    r.add_argument("-q", "--quiet", action="store_true", help="no progress output")

    m = sub.add_parser("import-mitsuba", help="convert a Mitsuba 3 XML scene to .lantern")
    m.add_argument("scene", help="Mitsuba scene (.xml)")
    m.add_argument("-o", "--output", required=True, help="output scene file (.lantern)")
    m.add_argument("--width", type=_positive_int, default=None, help="film width override")
    m.add_argument("--height", type=_positive_int, default=None, help="film height override")
    m.add_argument("-D", "--define", action="append", default=[], metavar="NAME=VALUE",
                   help="override a <default> parameter (repeatable)")
    m.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                   help=argparse.SUPPRESS)

    g = sub.add_parser("merge", help="merge sample chunks of one frame (EXRs), weighted by "
                                     "the samples each records")
    g.add_argument("inputs", nargs="+", help="chunk EXRs")
    g.add_argument("-o", "--output", required=True, help="merged EXR")
    g.add_argument("--half", action="store_true", help="write the EXR as half floats")
    g.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                   help=argparse.SUPPRESS)

    c = sub.add_parser("gpu-check", help="the GPU self-check of backend auto: read its cached "
                                         "verdict for this GPU, or run it")
    c.add_argument("--again", action="store_true", help="run it again, replacing the verdict")
    c.add_argument("--timeout", type=float, default=None,
                   help="seconds the check may take (default 180; tools/gpu_check.sh's budget)")
    c.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                   help=argparse.SUPPRESS)

    i = sub.add_parser("info", help="print a summary of a .lantern scene")
    i.add_argument("scene", help="scene file (.lantern)")
    i.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                   help=argparse.SUPPRESS)
    return parser


def _rays(stats):
    """Total rays traced so far from the core's stats (`rays_total`, else the sum of the
    per-kind `rays_*` counters, else a `rays` dict or number)."""
    total = stats.get("rays_total")
    if isinstance(total, (int, float)):
        return total
    rays = stats.get("rays")
    if isinstance(rays, dict):
        return sum(v for v in rays.values() if isinstance(v, (int, float)))
    if isinstance(rays, (int, float)):
        return rays
    return sum(v for k, v in stats.items()
               if k.startswith("rays_") and isinstance(v, (int, float)))


def cmd_render(args):
    from . import imageio, merge
    from .scene import load_scene
    from .session import Session

    if Path(args.output).suffix.lower() not in (".exr", ".png", ".npy"):
        raise ValueError(f"output {args.output!r}: use an .exr, .png or .npy file name")
    if args.chunk and Path(args.output).suffix.lower() != ".exr":
        raise ValueError(f"--chunk {args.chunk}: a sample chunk is merged later and must "
                         f"record its samples: write an .exr")
    if args.png and Path(args.png).suffix.lower() != ".png":
        raise ValueError(f"--png {args.png!r}: the preview file name must end in .png")
    scene = load_scene(args.scene)
    seed = merge.chunk_seed(args.seed, args.chunk)
    session = Session(scene, integrator=args.integrator, backend=args.backend, seed=seed,
                      threads=args.threads, max_depth=args.max_depth,
                      spp_per_iteration=args.spp_per_iteration, connections=args.connections,
                      candidates=args.candidates, sort=args.sort)
    for w in session.warnings:
        print(f"lantern: warning: {w}", file=sys.stderr)
    used = session.backend
    if not args.quiet:
        gpu = ""
        if used == "cuda":
            from .session import cuda_info
            info = cuda_info()
            gpu = f" ({info.get('name') or 'GPU'}, {info.get('memory_bytes', 0) / 2**30:.0f} GiB)"
        print(f"lantern: backend {used}{gpu} (asked: {args.backend})", file=sys.stderr)
    start = time.monotonic()
    last_print = -1.0
    try:
        while session.spp < args.spp:
            before = session.spp
            session.step()
            elapsed = time.monotonic() - start
            done = session.spp >= args.spp or session.spp <= before
            if not args.quiet and (elapsed - last_print >= 0.5 or done):
                last_print = elapsed
                rays = _rays(session.stats)
                rate = f", {rays / elapsed / 1e6:.2f} Mrays/s" if rays and elapsed > 0 else ""
                print(f"\rlantern: {session.spp}/{args.spp} spp, {elapsed:.1f} s{rate}",
                      end="", file=sys.stderr, flush=True)
            if session.spp <= before:
                break
            if args.time_limit is not None and elapsed >= args.time_limit:
                break
    except KeyboardInterrupt:
        print("\nlantern: interrupted, writing the image so far", file=sys.stderr)
    if not args.quiet:
        print(file=sys.stderr)
    img = session.image()
    meta = merge.chunk_metadata(merge.scene_identity(scene, args.max_depth), session.spp,
                                seed, args.chunk, args.integrator)
    imageio.write_image(args.output, img, half=args.half, metadata=meta)
    if args.png:
        imageio.write_image(args.png, img)
    if not args.quiet:
        print(f"lantern: wrote {args.output} ({session.spp} spp, "
              f"{time.monotonic() - start:.1f} s, backend {used})", file=sys.stderr)
    return 0


def cmd_import_mitsuba(args):
    import logging

    from .mitsuba import load_mitsuba

    # the warnings are printed below, once
    logging.getLogger("lantern.mitsuba").addHandler(logging.NullHandler())
    params = {}
    for d in args.define:
        if "=" not in d:
            raise ValueError(f"-D {d!r}: expected NAME=VALUE")
        k, v = d.split("=", 1)
        params[k] = v
    scene = load_mitsuba(args.scene, width=args.width, height=args.height, params=params)
    for w in scene.metadata["warnings"]:
        print(f"lantern: warning: {w}", file=sys.stderr)
    scene.save(args.output)
    depth = scene.metadata["max_depth"]
    print(f"lantern: wrote {args.output} ({scene!r}); render with "
          f"--max-depth {depth if depth is not None else 1024}", file=sys.stderr)
    return 0


def cmd_merge(args):
    from .merge import merge_files

    spp = merge_files(args.inputs, args.output, half=args.half)
    print(f"lantern: wrote {args.output} ({len(args.inputs)} chunks, {spp} spp)",
          file=sys.stderr)
    return 0


def cmd_info(args):
    from .scene import load_scene

    scene = load_scene(args.scene)
    s = scene.summary()
    lights = ", ".join(f"{n} {t}" for t, n in sorted(s["light_types"].items())) or "none"
    print(f"scene:      {args.scene}")
    print(f"resolution: {s['resolution']} ({s['camera']} camera)")
    print(f"meshes:     {s['meshes']} ({s['triangles']} triangles, {s['vertices']} vertices)")
    print(f"materials:  {s['materials']} ({s['emissive_materials']} emissive)")
    print(f"lights:     {s['lights']} ({lights})")
    print(f"world:      {s['world_color']}")
    return 0


def cmd_gpu_check(args):
    import json

    from . import gpu_selfcheck
    from .session import cuda_info

    info = cuda_info()
    if not info.get("available"):
        print(f"lantern: no usable GPU: {info.get('reason')}", file=sys.stderr)
        return EXIT_ERROR
    v = gpu_selfcheck.verdict(info, again=args.again, timeout=args.timeout)
    print(json.dumps(dict(v, key=gpu_selfcheck.key(info)), indent=1, sort_keys=True))
    # 0: the core set and every feature's cases that ran passed
    feats = v.get("features") if isinstance(v.get("features"), dict) else {}
    return 0 if v.get("ok") and all(f.get("ok") for f in feats.values()) else EXIT_ERROR


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_usage(sys.stderr)
        print("python -m lantern: error: a command is required "
              "(render, merge, info, import-mitsuba, gpu-check)", file=sys.stderr)
        return EXIT_USAGE
    handler = {"render": cmd_render, "info": cmd_info, "merge": cmd_merge,
               "import-mitsuba": cmd_import_mitsuba, "gpu-check": cmd_gpu_check}[args.command]
    try:
        return handler(args)
    except KeyboardInterrupt:
        print("lantern: interrupted", file=sys.stderr)
        return 130
    except Exception as e:  # one line for users; the traceback with --debug
        if args.debug:
            raise
        msg = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        print(f"lantern: error: {msg}", file=sys.stderr)
        return EXIT_ERROR


if __name__ == "__main__":
    sys.exit(main())
