"""Build the benchmark scenes of blend_scenes/bench_registry.py and export each to a .lantern
file through the add-on's exporter (what File > Export > Lantern Scene writes), reporting build
and export times, triangles, lights (and whether each sits inside a fixture) and file size.

    .venv/bin/python tools/export_bench_scenes.py [NAME ...] [--out DIR] [--blend] [--json F]

Default out: build/bench_scenes/ (git-ignored). The small hard cases are committed in
bench/scenes/ (`--out bench/scenes bench_fixture bench_caustics bench_tiny_light bench_glossy`)."""

import argparse
import importlib.util
import json
import os
import sys
import time
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "blend_scenes"))
import bench_common  # noqa: E402
import bench_registry  # noqa: E402


def load_addon():
    if "lantern_blender" in sys.modules:
        return sys.modules["lantern_blender"]
    addon = ROOT / "addon"
    spec = importlib.util.spec_from_file_location(
        "lantern_blender", addon / "__init__.py", submodule_search_locations=[str(addon)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["lantern_blender"] = module
    spec.loader.exec_module(module)
    module.register()
    return module


def export_one(name, out_dir, save_blend):
    from lantern_blender.export import export_scene
    spec = bench_registry.BENCH[name]
    t0 = time.perf_counter()
    tris = spec.build()
    t_build = time.perf_counter() - t0
    if save_blend:
        path = ROOT / "build" / "blend_scenes" / f"{name}.blend"
        path.parent.mkdir(parents=True, exist_ok=True)
        bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False)
    enclosed = bench_common.light_enclosure()
    t0 = time.perf_counter()
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    t_export = time.perf_counter() - t0
    out = Path(out_dir) / f"{name}.lantern"
    out.parent.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    scene.save(out)
    t_save = time.perf_counter() - t0
    lights = [{"name": obj.name, "type": obj.data.type, "power_w": round(obj.data.energy, 3),
               "enclosed": {"up": enclosed[obj.name][0], "sides": enclosed[obj.name][1]}}
              for obj in bpy.context.scene.objects if obj.type == "LIGHT"]
    r = bpy.context.scene.render
    return {"scene": name, "triangles": tris, "exported_triangles": scene.triangle_count,
            "target": spec.target_tris, "resolution": [r.resolution_x, r.resolution_y],
            "lights": lights, "materials": len(scene.materials), "file": str(out),
            "bytes": out.stat().st_size, "build_s": round(t_build, 2),
            "export_s": round(t_export, 2), "save_s": round(t_save, 2),
            "warnings": report.messages, "material_notes": dict(bench_common.NOTES)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("names", nargs="*", help=f"default: all of {', '.join(bench_registry.BENCH)}")
    ap.add_argument("--out", default=str(ROOT / "build" / "bench_scenes"))
    ap.add_argument("--blend", action="store_true", help="also save build/blend_scenes/NAME.blend")
    ap.add_argument("--json", help="write the report here too")
    args = ap.parse_args()
    load_addon()
    rows = []
    for name in args.names or list(bench_registry.BENCH):
        row = export_one(name, args.out, args.blend)
        rows.append(row)
        lights = ", ".join(f"{lt['name']} {lt['type']} {lt['power_w']} W "
                           f"(up {'hit' if lt['enclosed']['up'] else 'OPEN'}, "
                           f"sides {lt['enclosed']['sides']}/4)" for lt in row["lights"])
        print(f"{name}: {row['triangles']:,} triangles (target {row['target']:,}), "
              f"{row['resolution'][0]}x{row['resolution'][1]}, {row['bytes'] / 1e6:.1f} MB, "
              f"build {row['build_s']} s, export {row['export_s']} s, save {row['save_s']} s")
        print(f"  lights: {lights}")
        for mat, note in row["material_notes"].items():
            print(f"  material {mat}: {note}")
        for w in row["warnings"]:
            print(f"  warning: {w}")
        sys.stdout.flush()
    total = sum(r["bytes"] for r in rows)
    print(f"total {total / 1e6:.1f} MB in {len(rows)} files under {args.out}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    os.chdir(ROOT)
    sys.exit(main())
