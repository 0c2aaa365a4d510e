"""Render Blender's factory default scene (cube, light, camera) with Lantern, in bpy.

Writes out/default.exr (linear, 32-bit float) and out/default.png, and exits non-zero when
the written pixels are not all finite or are all zero."""

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lantern_bpy  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--samples", type=int, default=32)
    ap.add_argument("--percentage", type=int, default=50, help="resolution percentage")
    ap.add_argument("--output", default=os.path.join(lantern_bpy.ROOT, "out", "default"),
                    help="output path without extension (.exr and .png are written)")
    args = ap.parse_args(argv)

    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=False)
    lantern_bpy.load_addon()
    scene = bpy.context.scene
    scene.render.engine = "LANTERN"
    scene.render.resolution_percentage = args.percentage
    scene.lantern.samples = args.samples
    w = scene.render.resolution_x * args.percentage // 100
    h = scene.render.resolution_y * args.percentage // 100
    print(f"render_default: {w}x{h}, {args.samples} spp", flush=True)

    last = [0.0]

    def on_stats(_scene, stats=None):
        now = time.perf_counter()
        if now - last[0] > 0.5:
            last[0] = now
            print(f"  {stats}" if stats else f"  rendering... {now - t0:.1f} s", flush=True)

    bpy.app.handlers.render_stats.append(on_stats)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    print(f"render_default: rendered in {time.perf_counter() - t0:.2f} s", flush=True)

    out = os.path.abspath(args.output)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    result = bpy.data.images["Render Result"]
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    result.save_render(out + ".exr", scene=scene)
    settings.file_format = "PNG"
    settings.color_depth = "8"
    result.save_render(out + ".png", scene=scene)

    px = lantern_bpy.read_image_bpy(out + ".exr")
    finite = bool(np.isfinite(px).all())
    mean = float(np.nanmean(px)) if px.size else 0.0
    print(f"render_default: wrote {out}.exr and {out}.png ({px.shape[1]}x{px.shape[0]}), "
          f"mean {mean:.4f}, finite {finite}")
    if px.shape[:2] != (h, w):
        print(f"render_default: FAIL: image is {px.shape[1]}x{px.shape[0]}, expected {w}x{h}")
        return 1
    if not finite:
        print("render_default: FAIL: non-finite pixels")
        return 1
    if not np.any(px > 0):
        print("render_default: FAIL: all pixels are zero (did the render fail?)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
