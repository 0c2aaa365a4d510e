"""An emissive sphere inside a solid glass sphere (issue 28), Lantern against Cycles through
the add-on: per renderer K seeds, image means and the emitter's disc, with the standard error
from the seeds. Smooth glass (Glass BSDF, IOR 1.5) and a rough one (roughness 0.3); a grey
floor lit through the glass. Cycles' settings: tools/render_compare.py (no denoising,
clamping or light threshold; Filter Glossy 0; max_bounces 16 = Lantern max_depth 18).

    .venv/bin/python bench/glass_emitter_cycles.py --res 64 --seeds 4 --spp 128 \\
        --out bench/results/2026-12-04-glass-emitter
"""
import argparse
import json
import os
import platform
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "python"))


def build(res, roughness):
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = res
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("black")
    scene.world.color = (0.0, 0.0, 0.0)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.6)
    glass_obj = bpy.context.object
    bpy.ops.object.shade_smooth()
    glass = bpy.data.materials.new("glass")
    glass.use_nodes = True
    nt = glass.node_tree
    nt.nodes.clear()
    g = nt.nodes.new("ShaderNodeBsdfGlass")
    g.inputs["IOR"].default_value = 1.5
    g.inputs["Roughness"].default_value = roughness
    g.distribution = "GGX"
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(g.outputs[0], out.inputs["Surface"])
    glass_obj.data.materials.append(glass)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=0.3)
    lamp_obj = bpy.context.object
    lamp = bpy.data.materials.new("lamp")
    lamp.use_nodes = True
    nt = lamp.node_tree
    nt.nodes.clear()
    e = nt.nodes.new("ShaderNodeEmission")
    e.inputs["Strength"].default_value = 2.0
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(e.outputs[0], out.inputs["Surface"])
    lamp_obj.data.materials.append(lamp)
    bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0.0, 0.0, -0.6))
    floor = bpy.data.materials.new("floor")
    floor.use_nodes = True
    floor.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.7, 0.7, 0.7, 1)
    floor.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
    bpy.context.object.data.materials.append(floor)
    cam = bpy.data.cameras.new("cam")
    cam.lens_unit = "FOV"
    cam.angle = np.radians(30.0)
    cam_obj = bpy.data.objects.new("cam", cam)
    scene.collection.objects.link(cam_obj)
    cam_obj.location = (0.0, -4.0, 0.3)
    cam_obj.rotation_euler = (np.radians(86.0), 0.0, 0.0)
    scene.camera = cam_obj


def disc(res):
    yy, xx = np.mgrid[0:res, 0:res] + 0.5
    return np.hypot(xx - res / 2, yy - res / 2) < 0.25 * res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--spp", type=int, default=128)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    import render_compare as rc
    rows = []
    for rough in (0.0, 0.3):
        build(args.res, rough)
        imgs = {"cycles": [], "lantern": []}
        for k in range(args.seeds):
            imgs["cycles"].append(rc.render_cycles(k, args.spp)[0])
            imgs["lantern"].append(rc.render_lantern(k, args.spp, threads=1)[0])
        m = disc(args.res)
        row = {"roughness": rough}
        for name, ims in imgs.items():
            ims = np.asarray(ims, np.float64)
            for part, sel in (("image", np.ones_like(m)), ("centre disc", m)):
                v = ims[:, sel].mean(axis=(1, 2))
                row[f"{name} {part}"] = (float(v.mean()), float(v.std(ddof=1) / np.sqrt(len(v))))
        for part in ("image", "centre disc"):
            (a, sa), (b, sb) = row[f"lantern {part}"], row[f"cycles {part}"]
            row[f"ratio {part}"] = (a / b, (a / b) * np.hypot(sa / a, sb / b))
        rows.append(row)
        print(json.dumps(row))
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "glass_emitter.json"), "w") as f:
            json.dump({"machine": platform.processor() or platform.machine(),
                       "node": platform.node(), "args": vars(args), "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
