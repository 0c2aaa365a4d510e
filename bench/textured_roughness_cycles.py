"""A metal sphere in a white world whose Roughness a node graph drives (Voronoi Distance,
Wave Fac, Vector unlinked), Lantern (pt) against Cycles through the add-on (issue 28), and
what each pixel would read with the compensation at its own roughness: Lantern's renders at
constant roughness 0, 0.05, ..., 1 (which match Cycles) interpolated at the pixel's roughness
(the graph's output, rendered noise-free as emission). Also the graph's material with its
Roughness socket's hidden value at 0 and 1 (Blender's default is 0.5). Image means over the
sphere less its silhouette ring; Lantern's standard error from `--seeds` seeds.
Cycles: no denoising, clamping or light threshold; max_bounces 6 = Lantern max_depth 8.

    .venv/bin/python bench/textured_roughness_cycles.py --res 32 --spp 64 --seeds 4
"""
import argparse
import os
import platform
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "cycles"))
sys.path.insert(0, os.path.join(ROOT, "python"))

GRID = np.linspace(0.0, 1.0, 21)


def stage(res, texture, roughness, hidden=0.5):
    """roughness: a float, "graph" (the texture on Roughness) or "map" (the texture as
    emission, black world: the roughness itself at each pixel centre)."""
    import node_stage as st
    sc, nt, emit = st.stage("sphere", size=res)
    bg = sc.world.node_tree.nodes["Background"].inputs["Color"]
    bg.default_value = (0, 0, 0, 1) if roughness == "map" else (1, 1, 1, 1)
    tex = None
    if not isinstance(roughness, float):
        if texture == "voronoi":
            tex = nt.nodes.new("ShaderNodeTexVoronoi").outputs["Distance"]
        else:
            tex = nt.nodes.new("ShaderNodeTexWave").outputs["Fac"]
    if roughness == "map":
        nt.links.new(tex, emit.inputs["Color"])
        return sc
    nt.nodes.remove(emit)
    p = nt.nodes.new("ShaderNodeBsdfPrincipled")
    p.inputs["Base Color"].default_value = (0.9, 0.6, 0.3, 1.0)
    p.inputs["Metallic"].default_value = 1.0
    p.inputs["Roughness"].default_value = hidden if tex is not None else roughness
    if tex is not None:
        nt.links.new(tex, p.inputs["Roughness"])
    nt.links.new(p.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return sc


def lantern_image(spp, seed, max_depth=8):
    import bpy
    import lantern
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    assert list(report.messages) == [], report.messages
    scene.film["filter_width"] = 1e-6
    return np.asarray(lantern.render(scene, spp=spp, integrator="pt", max_depth=max_depth,
                                     seed=seed), np.float64)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--res", type=int, default=32)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=4)
    args = ap.parse_args()
    import node_stage as st
    import test_nodes as tn
    st.addon()
    print(f"# {platform.node()} {platform.processor() or platform.machine()}, "
          f"{args.res}x{args.res}, {args.spp} spp, Lantern {args.seeds} seeds")
    for texture in ("voronoi", "wave"):
        stage(args.res, texture, "map")
        rmap = lantern_image(1, 1, max_depth=1)[..., 0]
        stack = []
        for r in GRID:
            stage(args.res, texture, float(r))
            stack.append(lantern_image(args.spp, 1))
        stack = np.array(stack)
        idx = np.clip(rmap, 0.0, 1.0) * (len(GRID) - 1)
        lo = np.floor(idx).astype(int).clip(0, len(GRID) - 2)
        f = (idx - lo)[..., None]
        ii, jj = np.mgrid[0:args.res, 0:args.res]
        predicted = stack[lo, ii, jj] * (1 - f) + stack[lo + 1, ii, jj] * f
        sc = stage(args.res, texture, "graph")
        img_c = st.render_cycles(sc, f"/tmp/textured_roughness_{os.getpid()}.exr",
                                 spp=args.spp * args.seeds, bounces=6)
        hit = np.abs(img_c - 1.0).max(axis=2) > 1e-6
        cov = tn._covered("sphere", hit[..., None] * np.ones(3))
        c = img_c[cov].mean()
        print(f"{texture}: Cycles mean {c:.4f}; constant-roughness Lantern at each pixel's "
              f"roughness / Cycles {predicted[cov].mean() / c:.4f}")
        for hidden in (0.5, 0.0, 1.0):
            stage(args.res, texture, "graph", hidden)
            means = [lantern_image(args.spp, s)[cov].mean() for s in range(args.seeds)]
            se = np.std(means, ddof=1) / np.sqrt(len(means)) / c
            print(f"  hidden Roughness {hidden}: Lantern / Cycles {np.mean(means) / c:.4f} "
                  f"+- {se:.4f}")


if __name__ == "__main__":
    main()
