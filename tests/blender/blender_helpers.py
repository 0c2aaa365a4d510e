"""Scene-building helpers for tests/blender (a unique module name: tests/python has its own
conftest, so tests never import helpers from `conftest`)."""

import bpy
import numpy as np


def empty_scene():
    """Factory settings, no objects, Lantern selected, a tiny 32 x 24 resolution (the `empty`
    fixture; tools/false_alarm.py builds its Blender scenes on it too)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "LANTERN"
    scene.render.resolution_x, scene.render.resolution_y = 32, 24
    scene.render.resolution_percentage = 100
    return scene


def add_camera(scene, location=(0, 0, 5), rotation=(0, 0, 0), lens=50.0, name="Camera"):
    data = bpy.data.cameras.new(name)
    data.lens = lens
    obj = bpy.data.objects.new(name, data)
    obj.location, obj.rotation_euler = location, rotation
    scene.collection.objects.link(obj)
    scene.camera = obj
    return obj


def add_plane(scene, size=2.0, location=(0, 0, 0), material=None, name="Plane"):
    mesh = bpy.data.meshes.new(name)
    h = size / 2
    mesh.from_pydata([(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [], [(0, 1, 2, 3)])
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    if material is not None:
        mesh.materials.append(material)
    scene.collection.objects.link(obj)
    return obj


def emission_material(strength, color=(1, 1, 1)):
    mat = bpy.data.materials.new("Emit")
    nodes = mat.node_tree.nodes
    bsdf = nodes["Principled BSDF"]
    nodes.remove(bsdf)
    emit = nodes.new("ShaderNodeEmission")
    emit.inputs["Color"].default_value = (*color, 1)
    emit.inputs["Strength"].default_value = strength
    mat.node_tree.links.new(emit.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat


def diffuse_material(albedo):
    mat = bpy.data.materials.new("Diffuse")
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (albedo, albedo, albedo, 1)
    return mat


def shader_material(name, idname, **inputs):
    """A material whose Surface is one shader node `idname` (e.g. "ShaderNodeBsdfGlass") with
    the given input values; returns (material, node)."""
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    node = nt.nodes.new(idname)
    for key, v in inputs.items():
        node.inputs[key].default_value = v
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    nt.links.new(node.outputs[0], out.inputs["Surface"])
    return mat, node


def render_exr(scene, tmp_path, name="out.exr"):
    """F12 to an EXR, then the written file's float pixels, top row first (H, W, 4)."""
    path = str(tmp_path / name)
    scene.render.filepath = path
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    image = bpy.data.images.load(path)
    w, h = image.size
    pixels = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(h, w, 4)[::-1]
