"""Viewport latency: from an edit to the first new image, through the add-on's viewport path
(view_update -> view_draw -> the refining thread's first published image), against a full
re-export of the same scene. Not a test: it times, and writes bench/results/.

The object move is served by the running session since two-level instancing
(Session.move_instance: no bottom-level BVH build); before, by a new session and a whole BVH.

Changes: a camera orbit (the view matrix turned 5 degrees about the scene centre), an object
move (the largest mesh object, 0.1 m) and a material colour edit (that object's first
material); "full" is what the viewport did before incremental updates: export everything, new
session (BVH build). The viewport region is --region (default 960 x 540); regions from 256 x 256
get a quarter-resolution first iteration, so "first image" is that coarse image and "full res"
the first image at the region's resolution. main_thread_s: how long view_draw blocked Blender.

Run (bpy 5.0.1; builds the scenes from blend_scenes/):
    .venv/bin/python bench/viewport_latency.py --scenes monkeybox,bedroom [--repeat 3]"""

import argparse
import datetime
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import bpy
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))
sys.path.insert(0, str(ROOT / "blend_scenes"))
sys.path.insert(0, str(ROOT / "tools"))


class _Engine:
    def __init__(self, engine_module):
        self._lantern = engine_module.EngineState()
        self.reports = []

    def report(self, kind, message):
        self.reports.append((kind, message))

    def tag_redraw(self):
        pass


class _Draw:
    def update(self, image, serial):
        pass

    def draw(self, *args):
        pass


def _context(scene, view_matrix, window, size):
    return SimpleNamespace(scene=scene, region=SimpleNamespace(width=size[0], height=size[1]),
                           region_data=SimpleNamespace(view_matrix=view_matrix,
                                                       window_matrix=window,
                                                       is_perspective=True))


def _orbit(view_matrix, center, degrees):
    """The view turned about the vertical axis through `center` (world space)."""
    from mathutils import Matrix
    rot = (Matrix.Translation(center) @ Matrix.Rotation(math.radians(degrees), 4, "Z")
           @ Matrix.Translation(-center))
    return view_matrix @ rot


def _wait_image(state, serial, width, timeout=600.0):
    """Seconds until the refining thread publishes an image after `serial` (and, with
    `width`, one of that width); raises if it fails or times out."""
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < timeout:
        if state.error is not None:
            raise state.error
        with state.lock:
            ok = state.image_serial > serial and (
                width is None or state.image.shape[1] == width)
        if ok:
            return time.perf_counter(), time.process_time()
        time.sleep(0.0005)
    raise TimeoutError("no image")


def measure(addon, engine, ctx, edit, size):
    """(main thread s, first image s, first full-resolution image s, process CPU s to the
    first image) of one change. The CPU time (every thread of the process, the polling
    included) is what the machine's load changes least."""
    state = engine._lantern
    with state.lock:
        serial = state.image_serial
    t0, c0 = time.perf_counter(), time.process_time()
    ctx = edit(ctx)
    addon.engine.view_draw(engine, ctx, bpy.context.evaluated_depsgraph_get())
    t_main = time.perf_counter() - t0
    first, c_first = _wait_image(state, serial, None)
    t_full = _wait_image(state, serial, size[0])[0] - t0
    state.pause()  # the next change starts from an idle viewport
    return t_main, first - t0, t_full, c_first - c0


def _updates(addon, engine, ctx, fn):
    """Apply fn; view_update sees the depsgraph's updates, as in Blender."""
    def handler(scene, depsgraph):
        addon.engine.view_update(engine, ctx, depsgraph)
    bpy.app.handlers.depsgraph_update_post.append(handler)
    try:
        fn()
        bpy.context.view_layer.update()
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(handler)


def run_scene(addon, name, size, repeat):
    import bench_registry
    from lantern_blender.export.changes import FULL, Changes
    spec = bench_registry.BENCH[name]
    t = time.perf_counter()
    tris = spec.build()
    build_s = time.perf_counter() - t
    scene = bpy.context.scene
    scene.render.engine = "LANTERN"
    scene.lantern.preview_samples = 0
    meshes = [o for o in scene.objects if o.type == "MESH"]
    target = max(meshes, key=lambda o: len(o.data.polygons))
    material = target.active_material
    depsgraph = bpy.context.evaluated_depsgraph_get()
    window = scene.camera.calc_matrix_camera(depsgraph, x=size[0], y=size[1])
    view = scene.camera.matrix_world.inverted()
    corners = [o.matrix_world @ v.co for o in meshes for v in o.data.vertices[:1]]
    center = sum(corners, corners[0] * 0) / len(corners)
    engine = _Engine(addon.engine)
    engine._lantern.draw = _Draw()
    ctx = _context(scene, view, window, size)
    addon.engine.view_update(engine, ctx, depsgraph)
    first = measure(addon, engine, ctx, lambda c: c, size)
    rows = {"initial": [first]}
    angle = [0.0]

    def orbit(c):
        angle[0] += 5.0
        return _context(scene, _orbit(view, center, angle[0]), window, size)

    def move(c):
        _updates(addon, engine, c, lambda: setattr(
            target, "location", target.location + type(target.location)((0.1, 0, 0))))
        return c

    def recolor(c):
        bsdf = material.node_tree.nodes.get("Principled BSDF") if material else None
        if bsdf is not None:
            col = bsdf.inputs["Base Color"]
            _updates(addon, engine, c, lambda: setattr(
                col, "default_value", (np.random.rand(), 0.3, 0.2, 1.0)))
        return c

    def full(c):
        engine._lantern.sync.note(Changes(FULL))
        return c

    for what, edit in (("camera orbit", orbit), ("object move", move),
                       ("material colour", recolor), ("full re-export", full)):
        rows[what] = [measure(addon, engine, ctx, edit, size) for _ in range(repeat)]
        ctx = _context(scene, _orbit(view, center, angle[0]), window, size)
    counts = dict(engine._lantern.sync.counts)
    engine._lantern.free()
    return {"scene": name, "triangles": tris, "build_s": build_s, "object": target.name,
            "material": material.name if material else None,
            "integrator": scene.lantern.integrator, "last_full_counts": counts,
            "rows": {k: [list(map(float, r)) for r in v] for k, v in rows.items()}}


def machine():
    cpu = "unknown"
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                   if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    return {"cpu": cpu, "cores": os.cpu_count(), "load_1min": os.getloadavg()[0],
            "python": platform.python_version(), "bpy": ".".join(map(str, bpy.app.version)),
            "commit": commit, "date": datetime.datetime.now(datetime.timezone.utc).isoformat()}


def table(results):
    lines = ["| scene | change | main thread s | first image s | full res s | x faster than full "
             "| CPU s to first image |", "|---|---|---|---|---|---|---|"]
    for r in results:
        med = {k: [statistics.median(c) for c in zip(*v)] for k, v in r["rows"].items()}
        full = med["full re-export"][1]
        for what, (m, f, fr, cpu) in med.items():
            lines.append(f"| {r['scene']} ({r['triangles'] / 1e6:.2f}M tris) | {what} | "
                         f"{m:.3f} | {f:.3f} | {fr:.3f} | {full / f:.1f} | {cpu:.3f} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default="monkeybox,bedroom")
    ap.add_argument("--region", default="960x540")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    size = tuple(int(x) for x in args.region.split("x"))
    from lantern_bpy import load_addon
    addon = load_addon()
    mach = machine()
    results = [run_scene(addon, name, size, args.repeat) for name in args.scenes.split(",")]
    mach["load_1min_end"] = os.getloadavg()[0]
    out = Path(args.out or ROOT / "bench" / "results" /
               f"{datetime.date.today().isoformat()}-viewport-latency")
    out.mkdir(parents=True, exist_ok=True)
    doc = {"machine": mach, "region": size, "repeat": args.repeat, "results": results}
    (out / "results.json").write_text(json.dumps(doc, indent=1))
    text = (f"# Viewport latency ({size[0]} x {size[1]} region, median of {args.repeat})\n\n"
            f"Machine: {mach['cpu']}, {mach['cores']} cores, 1-minute load {mach['load_1min']:.2f} "
            f"at the start, {mach['load_1min_end']:.2f} at the end; bpy {mach['bpy']}; commit "
            f"{mach['commit']}.\n\n{table(results)}\n")
    (out / "results.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
