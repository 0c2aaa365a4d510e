"""What node graphs cost per shading point, against the graph's node count: the Cornell box
(blend_scenes cornell_box, every surface diffuse) with each material's Base Color driven by a
graph of N nodes: a Noise Texture (fBm, 2 octaves) on Generated coordinates, then N - 2 Math
nodes (alternating multiply-add and sine, so that nothing folds), then a ColorRamp. Counted in
instructions (valgrind callgrind; deterministic on a shared machine), as material_cost.py does.

    .venv/bin/python bench/node_cost.py export OUT_DIR 0 4 8 16 32 64   # bpy: OUT_DIR/nodes_N.lantern
    valgrind --tool=callgrind --callgrind-out-file=/tmp/cg.out \\
        .venv/bin/python bench/node_cost.py run OUT_DIR/nodes_N.lantern pt 3

N = 0 is the plain diffuse box (no programs). Take the difference between 3 and 1 steps, as
material_cost.py does, so that start-up and scene loading cancel; bench/results/*-node-cost/
holds a table."""
import os
import sys

here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def export(out_dir, counts):
    import importlib.util

    import bpy
    sys.path.insert(0, os.path.join(here, "python"))
    sys.path.insert(0, os.path.join(here, "blend_scenes"))
    spec = importlib.util.spec_from_file_location(
        "lantern_blender", os.path.join(here, "addon", "__init__.py"),
        submodule_search_locations=[os.path.join(here, "addon")])
    addon = importlib.util.module_from_spec(spec)
    sys.modules["lantern_blender"] = addon
    spec.loader.exec_module(addon)
    addon.register()
    import scenes
    from lantern_blender.export import export_scene
    os.makedirs(out_dir, exist_ok=True)
    for n in counts:
        scenes.build("cornell_box")
        sc = bpy.context.scene
        sc.render.resolution_x = sc.render.resolution_y = 48
        if n > 0:
            for mat in bpy.data.materials:
                _graph(mat, n)
        scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
        if report.messages:
            print(f"nodes {n}: {report.messages}")
        progs = [p for m in scene.materials for p in m.get("programs", [])]
        instrs = sum(len(p["code"]) for p in progs)
        scene.save(os.path.join(out_dir, f"nodes_{n}.lantern"))
        print(f"nodes {n}: {len(progs)} programs, {instrs} instructions exported")


def _graph(mat, n):
    nt = mat.node_tree
    target = next((nd for nd in nt.nodes if nd.type in ("BSDF_PRINCIPLED", "BSDF_DIFFUSE")),
                  None)
    if target is None:
        return
    sock = target.inputs["Base Color"] if "Base Color" in target.inputs else \
        target.inputs["Color"]
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Detail"].default_value = 1.0
    prev = noise.outputs["Fac"]
    for i in range(max(n - 2, 0)):
        m = nt.nodes.new("ShaderNodeMath")
        m.operation = "MULTIPLY_ADD" if i % 2 == 0 else "SINE"
        nt.links.new(prev, m.inputs[0])
        m.inputs[1].default_value, m.inputs[2].default_value = 1.3, 0.1
        prev = m.outputs[0]
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    nt.links.new(prev, ramp.inputs[0])
    nt.links.new(ramp.outputs["Color"], sock)


def run(path, integrator, steps):
    sys.path.insert(0, os.path.join(here, "python"))
    import lantern
    session = lantern.Session(lantern.load_scene(path), integrator=integrator, seed=1,
                              spp_per_iteration=4, threads=1)
    for _ in range(steps):
        session.step()


if __name__ == "__main__":
    if sys.argv[1] == "export":
        export(sys.argv[2], [int(x) for x in sys.argv[3:]] or [0, 4, 16, 64])
    else:
        run(sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else "pt",
            int(sys.argv[4]) if len(sys.argv) > 4 else 1)
