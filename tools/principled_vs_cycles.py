"""Principled BSDF, Lantern against Cycles: the blend_scenes Cornell box with every surface a
Principled BSDF of its colour (variant: default, glossy = roughness 0.2, metal = Metallic 0.5,
glass = Transmission 0.5, coat = Coat Weight 1 roughness 0.1, coat_tint, sheen = Sheen Weight 1), 64 x 64, 6 seeds x 256 spp each; prints the mean ratio and the worst
8x8-block z-score. Usage: .venv/bin/python tools/principled_vs_cycles.py [variant]"""
import sys, os, time
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
for sub in ("python", "tools", "blend_scenes"):
    sys.path.insert(0, os.path.join(ROOT, sub))
import numpy as np
import bpy
import render_compare as rc
import scenes as bs
import lantern
from lantern import metrics
variant = sys.argv[1] if len(sys.argv) > 1 else "default"
bs.cornell_box()
scene = bpy.context.scene
scene.render.resolution_x = scene.render.resolution_y = 64
# every material -> a Principled BSDF with the same colour and default specular
for mat in bpy.data.materials:
    nt = mat.node_tree
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    src = out.inputs["Surface"].links[0].from_node if out.inputs["Surface"].is_linked else None
    if src is None or src.type == "EMISSION": continue
    col = src.inputs["Base Color" if src.type == "BSDF_PRINCIPLED" else "Color"].default_value[:]
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL": nt.nodes.remove(n)
    p = nt.nodes.new("ShaderNodeBsdfPrincipled")
    p.inputs["Base Color"].default_value = col
    if variant == "glossy": p.inputs["Roughness"].default_value = 0.2
    if variant == "metal": p.inputs["Metallic"].default_value = 0.5
    if variant == "glass": p.inputs["Transmission Weight"].default_value = 0.5
    if variant == "coat":
        p.inputs["Coat Weight"].default_value = 1.0
        p.inputs["Coat Roughness"].default_value = 0.1
    if variant == "sheen":
        p.inputs["Sheen Weight"].default_value = 1.0
        p.inputs["Sheen Roughness"].default_value = 0.5
    if variant == "coat_tint":
        p.inputs["Coat Weight"].default_value = 1.0
        p.inputs["Coat Tint"].default_value = (0.9, 0.7, 0.5, 1.0)
    nt.links.new(p.outputs[0], out.inputs["Surface"])
K, SPP = 6, 256
t=time.time(); cyc = [rc.render_cycles(seed=10 + k, spp=SPP)[0] for k in range(K)]; tc=time.time()-t
t=time.time(); lan = [rc.render_lantern(seed=20 + k, spp=SPP)[0] for k in range(K)]; tl=time.time()-t
cmp = metrics.compare_sets(lan, cyc, block=8)
ml, mc = np.stack(lan).mean(axis=(0,1,2)), np.stack(cyc).mean(axis=(0,1,2))
print(variant, "lantern/cycles mean ratio", np.round(ml / mc, 4), "worst", cmp, f"(cycles {tc:.0f}s, lantern {tl:.0f}s)")
