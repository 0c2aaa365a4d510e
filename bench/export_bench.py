"""Export speed: a ~1M-triangle mesh built in bpy, exported to a lantern.Scene (median of 3).

Run: .venv/bin/python bench/export_bench.py [--tris N]"""

import argparse
import importlib.util
import math
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import bpy

ADDON = Path(__file__).resolve().parents[1] / "addon"


def load_addon():
    spec = importlib.util.spec_from_file_location(
        "lantern_blender", ADDON / "__init__.py", submodule_search_locations=[str(ADDON)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["lantern_blender"] = module
    spec.loader.exec_module(module)
    module.register()
    return module


def cpu_model():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tris", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    load_addon()
    from lantern_blender.export import export_scene
    bpy.ops.wm.read_factory_settings(use_empty=True)
    n = max(1, int(math.sqrt(args.tris / 2)))  # an n x n grid has 2 n^2 triangles
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=n, y_subdivisions=n, size=2)
    obj = bpy.context.object
    obj.data.materials.append(bpy.data.materials.new("Grey"))
    bpy.ops.object.shade_smooth()
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    bpy.context.scene.collection.objects.link(cam)
    bpy.context.scene.camera = cam
    depsgraph = bpy.context.evaluated_depsgraph_get()
    times, tris = [], 0
    for _ in range(args.repeat):
        t = time.perf_counter()
        scene, _ = export_scene(depsgraph)
        times.append(time.perf_counter() - t)
        tris = sum(len(m["indices"]) for m in scene.meshes)
    print(f"triangles: {tris}")
    print(f"export to lantern.Scene: median {statistics.median(times):.3f} s "
          f"(runs: {', '.join(f'{t:.3f}' for t in times)})")
    print(f"machine: {cpu_model()}, {os.cpu_count()} logical cores; bpy {bpy.app.version_string}")


if __name__ == "__main__":
    main()
