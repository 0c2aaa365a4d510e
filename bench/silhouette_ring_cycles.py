"""The metal sphere's silhouette ring against Cycles (issue 28): a Principled metal sphere in a
white world, base colour a constant grey or a Wave Texture's Color (Vector unlinked), means
over the sphere's interior, its second outermost pixel ring and its outermost one; Lantern (pt,
max_depth 8) `--seeds` seeds of `--spp`, its standard error from them; Cycles 1024 spp
(max_bounces 6, no denoising, clamping or light threshold), pixel-centre filters on both.

    .venv/bin/python bench/silhouette_ring_cycles.py --res 48 --spp 64 --seeds 8
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "cycles"))
sys.path.insert(0, os.path.join(ROOT, "python"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--res", type=int, default=48)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    args = ap.parse_args()
    import bpy
    import lantern
    import node_stage as st
    import test_nodes as tn
    st.addon()
    from lantern_blender.export import export_scene
    for base in ("grey", "wave"):
        sc, nt, emit = st.stage("sphere", size=args.res)
        sc.world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
        nt.nodes.remove(emit)
        p = nt.nodes.new("ShaderNodeBsdfPrincipled")
        p.inputs["Metallic"].default_value = 1.0
        nt.links.new(p.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
        if base == "grey":
            p.inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1.0)
        else:
            w = nt.nodes.new("ShaderNodeTexWave")
            w.inputs["Scale"].default_value = 1.0
            nt.links.new(w.outputs["Color"], p.inputs["Base Color"])
        scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
        assert list(report.messages) == []
        imgs = [np.asarray(lantern.render(scene, spp=args.spp, integrator="pt", max_depth=8,
                                          seed=s), np.float64) for s in range(args.seeds)]
        img_c = st.render_cycles(sc, f"/tmp/silhouette_ring_{os.getpid()}.exr", spp=1024,
                                 bounces=6)
        hit = np.abs(img_c - 1.0).max(axis=2) > 1e-6
        inner = tn._covered("sphere", hit[..., None] * np.ones(3))
        core = tn._covered("sphere", inner[..., None] * np.ones(3))
        for name, m in (("interior", core), ("ring 2", inner & ~core), ("ring 1", hit & ~inner)):
            means = np.array([im[m].mean() for im in imgs])
            c = img_c[m].mean()
            print(f"{base} {name}: Lantern / Cycles {means.mean() / c:.4f} +- "
                  f"{means.std(ddof=1) / np.sqrt(len(means)) / c:.4f} ({int(m.sum())} px)")


if __name__ == "__main__":
    main()
