"""The stage every scene builder shares (scenes.py, world_scenes.py, features.py, efficiency.py,
layers_passes.py, bench_common.py): an empty file at RES x RES pixels, diffuse and Principled
materials, quads, boxes, the camera, lights, the floor-and-wall set of the light scenes, and an
HDRI world from bpy's studio lights. Imports no builder module."""

import math
import os

import bpy
from mathutils import Vector

RES = 96


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


OUT_DIR = os.path.join(ROOT, "build", "blend_scenes")


# ---- helpers ----

def _reset(world_color=(0.0, 0.0, 0.0)):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = RES
    scene.render.resolution_y = RES
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("World")
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*world_color, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    scene.world = world
    return scene


def principled(name, color):
    m = bpy.data.materials.new(name)
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*color, 1.0)
    p.inputs["Specular IOR Level"].default_value = 0.0
    return m


def diffuse(name, color):
    m = bpy.data.materials.new(name)
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    d = nt.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (*color, 1.0)
    nt.links.new(d.outputs["BSDF"], nt.nodes["Material Output"].inputs["Surface"])
    return m


def emission(name, color, strength):
    m = bpy.data.materials.new(name)
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    e = nt.nodes.new("ShaderNodeEmission")
    e.inputs["Color"].default_value = (*color, 1.0)
    e.inputs["Strength"].default_value = strength
    nt.links.new(e.outputs["Emission"], nt.nodes["Material Output"].inputs["Surface"])
    return m


def principled_emission(name, base, color, strength):
    m = principled(name, base)
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Emission Color"].default_value = (*color, 1.0)
    p.inputs["Emission Strength"].default_value = strength
    return m


def _link(obj):
    bpy.context.scene.collection.objects.link(obj)
    return obj


def quad(name, corners, material):
    """One quad from 4 corners (counter-clockwise seen from the front)."""
    me = bpy.data.meshes.new(name)
    me.from_pydata([Vector(c) for c in corners], [], [(0, 1, 2, 3)])
    me.update()
    me.materials.append(material)
    return _link(bpy.data.objects.new(name, me))


def box(name, center, size, rot_z_deg, material):
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=center,
                                    rotation=(0, 0, math.radians(rot_z_deg)))
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = size
    obj.data.materials.append(material)
    return obj


def camera(location, target, lens=35.0):
    cam = bpy.data.cameras.new("Camera")
    cam.lens = lens
    cam.sensor_fit = "AUTO"
    obj = _link(bpy.data.objects.new("Camera", cam))
    obj.location = location
    d = Vector(target) - Vector(location)
    obj.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = obj
    return obj


def light(kind, name, location, target=None, **props):
    data = bpy.data.lights.new(name, kind)
    for k, v in props.items():
        setattr(data, k, v)
    obj = _link(bpy.data.objects.new(name, data))
    obj.location = location
    if target is not None:
        d = Vector(target) - Vector(location)
        obj.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()
    return obj


def _stage():
    """Shared set for the light scenes: a floor, a back wall, a box and a sphere-ish block,
    seen from the front at an angle."""
    grey = diffuse("Grey", (0.8, 0.8, 0.8))
    quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], grey)
    quad("Back", [(-3, 2, 0), (3, 2, 0), (3, 2, 3), (-3, 2, 3)], diffuse("Wall", (0.6, 0.7, 0.8)))
    box("Box", (-0.6, 0.4, 0.5), (0.9, 0.9, 1.0), 25, principled("Orange", (0.8, 0.45, 0.15)))
    box("Block", (0.8, -0.3, 0.3), (0.6, 0.6, 0.6), -20, diffuse("Green", (0.2, 0.7, 0.3)))
    camera((0.0, -5.5, 2.6), (0.0, 0.3, 0.7), lens=32.0)


def hdri_world(image="sunset.exr", rotation=(0.0, 0.0, 0.0), strength=1.0):
    """The world: an HDRI that bpy ships (datafiles/studiolights/world) through Texture
    Coordinate (Generated) and a Mapping rotation, into the Background."""
    world = bpy.context.scene.world
    nt = world.node_tree
    path = os.path.join(bpy.utils.system_resource("DATAFILES"), "studiolights", "world", image)
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(path, check_existing=True)
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = rotation
    coord = nt.nodes.new("ShaderNodeTexCoord")
    nt.links.new(coord.outputs["Generated"], mapping.inputs["Vector"])
    nt.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    bg = nt.nodes["Background"]
    nt.links.new(env.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = strength
    return world
