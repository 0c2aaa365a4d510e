"""The compositor's Denoise node fed with each engine's own Denoising Albedo and Normal, against
a converged Cycles render: RMSE of the denoised image at low sample counts, Lantern (pt) next to
Cycles, on blend_scenes/layers_passes.py (view layer "Full").

For each engine and seed: F12 at N spp with the compositor running Render Layers -> Denoise
(Image, Albedo, Normal) -> output, and the same without the passes (image only) and without
denoising. Then, to tell the passes from the noise of the image they come with, each engine's
image denoised with the other engine's passes (Image nodes on the two multilayer EXRs of that
seed). RMSE over RGB against Cycles at --ref-spp; mean and standard error over the seeds.

    .venv/bin/python bench/denoise_passes.py [--spp 8] [--seeds 4] [--ref-spp 4096] [--res 64]

Writes bench/results/<date>-denoise-passes/{table.md,results.json}."""

import argparse
import datetime
import json
import os
import platform
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
for sub in ("tools", "blend_scenes", "python"):
    sys.path.insert(0, os.path.join(ROOT, sub))
import bpy  # noqa: E402

import exr_passes  # noqa: E402
import lantern_bpy  # noqa: E402
import layers_passes  # noqa: E402
import render_compare as rc  # noqa: E402


def _scene(res):
    scene = layers_passes.layers_passes()
    scene.render.resolution_x = scene.render.resolution_y = res
    scene.view_layers["NoProps"].use = False
    return scene


def _compositor(scene, mode):
    """mode: "noisy" (no compositor), "image" (Denoise of the image alone), "passes"."""
    if mode == "noisy":
        scene.render.use_compositing = False
        return
    scene.render.use_compositing = True
    tree = bpy.data.node_groups.new("Denoise", "CompositorNodeTree")
    tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    scene.compositing_node_group = tree
    rl = tree.nodes.new("CompositorNodeRLayers")
    rl.scene, rl.layer = scene, "Full"
    dn = tree.nodes.new("CompositorNodeDenoise")
    out = tree.nodes.new("NodeGroupOutput")
    tree.links.new(rl.outputs["Image"], dn.inputs["Image"])
    if mode == "passes":
        tree.links.new(rl.outputs["Denoising Albedo"], dn.inputs["Albedo"])
        tree.links.new(rl.outputs["Denoising Normal"], dn.inputs["Normal"])
    tree.links.new(dn.outputs["Image"], out.inputs[0])


def _engine(scene, engine, spp, seed):
    if engine == "cycles":
        rc.cycles_settings(scene, seed=seed, spp=spp)
    else:
        scene.render.engine = "LANTERN"
        s = scene.lantern
        s.samples, s.integrator, s.backend, s.seed = spp, "pt", "cpu", seed
        s.max_depth = rc.lantern_depth(rc.BOUNCES)


def cross(image_exr, passes_exr, res):
    """Denoise of the Combined of one multilayer EXR with the albedo and normal of another."""
    scene = _scene(res)
    _engine(scene, "lantern", 1, 0)  # renders a frame nobody reads; the compositor's is kept
    scene.render.use_compositing = True
    tree = bpy.data.node_groups.new("Cross", "CompositorNodeTree")
    tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    scene.compositing_node_group = tree
    img, aux = (tree.nodes.new("CompositorNodeImage") for _ in range(2))
    for node, path in ((img, image_exr), (aux, passes_exr)):
        node.image = bpy.data.images.load(path, check_existing=False)
        node.layer = "Full"
    dn = tree.nodes.new("CompositorNodeDenoise")
    out = tree.nodes.new("NodeGroupOutput")
    tree.links.new(img.outputs["Combined"], dn.inputs["Image"])
    tree.links.new(aux.outputs["Denoising Albedo"], dn.inputs["Albedo"])
    tree.links.new(aux.outputs["Denoising Normal"], dn.inputs["Normal"])
    tree.links.new(dn.outputs["Image"], out.inputs[0])
    return _write(scene)


def multilayer(engine, spp, seed, res, path):
    scene = _scene(res)
    _engine(scene, engine, spp, seed)
    scene.render.use_compositing = False
    exr_passes.render_passes(scene, path)


def _write(scene):
    st = scene.render.image_settings
    st.media_type = "IMAGE"
    st.file_format, st.color_depth = "OPEN_EXR", "32"
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "out.exr")
        scene.render.filepath = path
        assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
        return exr_passes.read_passes(path)[("", "Combined")][..., :3]


def render(engine, spp, seed, res, mode):
    scene = _scene(res)
    if engine == "cycles":
        rc.cycles_settings(scene, seed=seed, spp=spp)
    else:
        scene.render.engine = "LANTERN"
        s = scene.lantern
        s.samples, s.integrator, s.backend, s.seed = spp, "pt", "cpu", seed
        s.max_depth = rc.lantern_depth(rc.BOUNCES)
    _compositor(scene, mode)
    st = scene.render.image_settings
    st.media_type = "IMAGE"
    st.file_format, st.color_depth = "OPEN_EXR", "32"
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "out.exr")
        scene.render.filepath = path
        assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
        return exr_passes.read_passes(path)[("", "Combined")][..., :3]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, default=8)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    lantern_bpy.load_addon()
    ref = render("cycles", args.ref_spp, 1000, args.res, "noisy")
    rows = {}
    for engine in ("cycles", "lantern"):
        for mode in ("noisy", "image", "passes"):
            errs = [float(np.sqrt(np.mean((render(engine, args.spp, seed, args.res, mode) - ref)
                                          ** 2))) for seed in range(args.seeds)]
            rows[f"{engine}/{mode}"] = {"rmse": float(np.mean(errs)),
                                        "se": float(np.std(errs, ddof=1) / np.sqrt(len(errs))),
                                        "per_seed": errs}
            print(f"{engine:8s} {mode:7s} RMSE {rows[f'{engine}/{mode}']['rmse']:.5f}", flush=True)
    cross_errs = {"cycles/lantern passes": [], "lantern/cycles passes": []}
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(args.seeds):
            paths = {e: os.path.join(tmp, f"{e}{seed}.exr") for e in ("cycles", "lantern")}
            for e, path in paths.items():
                multilayer(e, args.spp, seed, args.res, path)
            for a, b in (("cycles", "lantern"), ("lantern", "cycles")):
                err = np.sqrt(np.mean((cross(paths[a], paths[b], args.res) - ref) ** 2))
                cross_errs[f"{a}/{b} passes"].append(float(err))
    for key, errs in cross_errs.items():
        rows[key] = {"rmse": float(np.mean(errs)),
                     "se": float(np.std(errs, ddof=1) / np.sqrt(len(errs))), "per_seed": errs}
        print(f"{key:24s} RMSE {rows[key]['rmse']:.5f}", flush=True)
    date = datetime.date.today().isoformat()
    out = args.out or os.path.join(ROOT, "bench", "results", f"{date}-denoise-passes")
    os.makedirs(out, exist_ok=True)
    meta = {"scene": "blend_scenes/layers_passes.py (view layer Full)", "res": args.res,
            "spp": args.spp, "seeds": args.seeds, "reference": f"Cycles {args.ref_spp} spp",
            "machine": platform.platform(), "cpus": os.cpu_count(), "bpy": bpy.app.version_string,
            "command": "python bench/denoise_passes.py " + " ".join(sys.argv[1:])}
    with open(os.path.join(out, "results.json"), "w") as f:
        json.dump({"meta": meta, "rows": rows}, f, indent=2)
    mean_ref = float(ref.mean())
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write(f"# Denoise node with each engine's passes ({date})\n\n")
        f.write(f"{meta['scene']}, {args.res} x {args.res}, {args.spp} spp, {args.seeds} seeds; "
                f"reference {meta['reference']} (image mean {mean_ref:.4f}); "
                f"{meta['machine']}, {meta['cpus']} CPUs, bpy {meta['bpy']}.\n\n")
        f.write("| engine | no denoise | Denoise (image) | Denoise (image + albedo + normal) |\n")
        f.write("| --- | --- | --- | --- |\n")
        for engine in ("cycles", "lantern"):
            cells = [f"{rows[f'{engine}/{m}']['rmse']:.5f} ± {rows[f'{engine}/{m}']['se']:.5f}"
                     for m in ("noisy", "image", "passes")]
            f.write(f"| {engine} | " + " | ".join(cells) + " |\n")
        f.write("\nEach image denoised with the other engine's albedo and normal (same seed):\n\n")
        f.write("| image | with Cycles' passes | with Lantern's passes |\n| --- | --- | --- |\n")
        for engine, other in (("cycles", "lantern"), ("lantern", "cycles")):
            own = rows[f"{engine}/passes"]
            xr = rows[f"{engine}/{other} passes"]
            cells = {engine: own, other: xr}
            f.write(f"| {engine} | {cells['cycles']['rmse']:.5f} ± {cells['cycles']['se']:.5f} | "
                    f"{cells['lantern']['rmse']:.5f} ± {cells['lantern']['se']:.5f} |\n")
        f.write(f"\nRMSE over RGB against the reference, mean ± standard error over the seeds. "
                f"`{meta['command']}`\n")
    print(out)


if __name__ == "__main__":
    main()
