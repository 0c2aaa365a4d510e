"""The stage of the node tests (test_nodes.py): an emission-only material on a square plane
(uv 0..1, Generated = uv) or a UV sphere, seen by an orthographic (plane) or perspective
(sphere) camera, rendered with one bounce and a pixel filter of 0.01 px, so that each pixel is
the node's output at the pixel centre: the image is the node's output, for Lantern and Cycles
alike. Lantern renders through the add-on's export (lantern.render, pt), Cycles through bpy."""

import importlib.util
import math
import os
import sys

import bpy
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SIZE = 40


def addon():
    if "lantern_blender" not in sys.modules:
        path = os.path.join(ROOT, "addon")
        spec = importlib.util.spec_from_file_location(
            "lantern_blender", os.path.join(path, "__init__.py"),
            submodule_search_locations=[path])
        module = importlib.util.module_from_spec(spec)
        sys.modules["lantern_blender"] = module
        spec.loader.exec_module(module)
        module.register()
    return sys.modules["lantern_blender"]


def stage(shape="plane", size=SIZE):
    """A fresh scene; returns (scene, node tree, emission node)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.resolution_x = sc.render.resolution_y = size
    sc.render.resolution_percentage = 100
    sc.render.filter_size = 0.01
    sc.cycles.filter_width = 0.01
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    sc.collection.objects.link(cam)
    sc.camera = cam
    if shape == "plane":
        cam.data.type = "ORTHO"
        cam.data.ortho_scale = 2.0
        cam.location = (0.0, 0.0, 3.0)
        mesh = bpy.data.meshes.new("Plane")
        mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
        mesh.uv_layers.new(name="UV")
        for i, c in enumerate([(0, 0), (1, 0), (1, 1), (0, 1)]):
            mesh.uv_layers[0].data[i].uv = c
        obj = bpy.data.objects.new("Plane", mesh)
        sc.collection.objects.link(obj)
    else:
        bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=1.0)
        obj = bpy.context.object
        bpy.ops.object.shade_smooth()
        cam.location, cam.rotation_euler = (0.0, -4.0, 0.0), (math.radians(90), 0.0, 0.0)
        cam.data.lens = 60.0
    mat = bpy.data.materials.new("Node")
    obj.data.materials.append(mat)
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    emit = nt.nodes.new("ShaderNodeEmission")
    nt.links.new(emit.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    world = bpy.data.worlds.new("W")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    sc.world = world
    return sc, nt, emit


def render_lantern(spp=4, integrator="pt", max_depth=1, seed=1):
    """(image H x W x 3, export warnings)."""
    import lantern
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    img = lantern.render(scene, spp=spp, integrator=integrator, max_depth=max_depth, seed=seed)
    return np.asarray(img, np.float64), list(report.messages)


def render_cycles(sc, path, spp=4, bounces=1, seed=0):
    sc.render.engine = "CYCLES"
    sc.cycles.device = "CPU"
    sc.cycles.samples = spp
    sc.cycles.seed = seed
    sc.cycles.use_denoising = False
    sc.cycles.max_bounces = bounces
    # and the diffuse and glossy limits (Cycles' defaults 4; transmission's 12), which
    # max_bounces does not raise: Lantern's max_depth is one limit for every kind. Left at 4, nodes_world's
    # contact shadows read 2 % darker in Cycles (the red sphere's interreflection, 2026-12-02)
    sc.cycles.diffuse_bounces = sc.cycles.glossy_bounces = bounces
    sc.cycles.light_sampling_threshold = 0.0
    sc.cycles.sample_clamp_indirect = 0.0
    sc.view_settings.view_transform = "Standard"
    sc.render.filepath = str(path)
    sc.render.image_settings.file_format = "OPEN_EXR"
    sc.render.image_settings.color_depth = "32"
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    image = bpy.data.images.load(str(path))
    w, h = image.size
    px = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(px)
    bpy.data.images.remove(image)
    sc.render.engine = "LANTERN"
    return px.reshape(h, w, 4)[::-1, :, :3].astype(np.float64)


def relative_error(lantern_img, cycles_img, floor=0.05):
    """|L - C| / max(|C|, floor) per pixel and channel (floor: where the value is near 0)."""
    return np.abs(lantern_img - cycles_img) / np.maximum(np.abs(cycles_img), floor)
