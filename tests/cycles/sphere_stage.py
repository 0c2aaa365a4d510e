"""The stage the sphere tests of tests/cycles share (test_anisotropy.py, test_coat_normal.py): a
smooth UV sphere of radius 1 at the origin, a camera 4.5 m in front looking 18 degrees down, a
300 W 1 m area light up and to the right, and a dark constant world."""
import math

import bpy


def sphere_scene(size, material_name):
    """A factory-empty scene rendered at size x size with the sphere and a new material (not yet
    assigned: the test builds its nodes first); returns (scene, sphere, material)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.resolution_x = sc.render.resolution_y = size
    sc.render.resolution_percentage = 100
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
    obj = bpy.context.object
    bpy.ops.object.shade_smooth()
    return sc, obj, bpy.data.materials.new(material_name)


def camera_light_world(sc):
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.location, cam.rotation_euler = (0, -4.5, 1.5), (math.radians(72), 0, 0)
    sc.collection.objects.link(cam)
    sc.camera = cam
    light = bpy.data.lights.new("Area", "AREA")
    light.energy, light.size = 300.0, 1.0
    lo = bpy.data.objects.new("Area", light)
    lo.location, lo.rotation_euler = (2, -2, 3), (math.radians(40), math.radians(30), 0)
    sc.collection.objects.link(lo)
    world = bpy.data.worlds.new("W")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.05, 0.05, 0.05, 1)
    sc.world = world
