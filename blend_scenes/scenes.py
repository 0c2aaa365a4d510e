"""Builders for the test and benchmark scenes, in bpy. Each builder starts from an empty file,
builds the scene and leaves it as the current bpy data; `build(name, path)` saves it.

Every scene is small (RES x RES pixels) and diffuse, so Cycles and Lantern both converge on 2
cores in CI time. Surfaces use the Diffuse BSDF (roughness 0: Lambert in Cycles). A Principled
BSDF with only Base Color set is NOT diffuse in Cycles (its dielectric specular layer, IOR 1.5,
adds a neutral glossy reflection), so `principled()` sets Specular IOR Level to 0, which leaves
Cycles' Lambertian diffuse lobe alone; it is used for a few surfaces to cover the add-on's
Principled path. Lights are
invisible to the camera (Blender 5.0's default). The world is black except in `world_color`."""

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


# ---- scenes ----

def cornell_box():
    """Cornell box 2x2x2 m: red left, green right, white floor/ceiling/back, a tall and a short
    box, a 0.5 x 0.4 m rectangular area light 1 cm under the ceiling, facing down."""
    _reset()
    white = diffuse("White", (0.73, 0.73, 0.73))
    red = diffuse("Red", (0.63, 0.065, 0.05))
    green = diffuse("Green", (0.14, 0.45, 0.091))
    quad("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], white)
    quad("Ceiling", [(-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2)], white)
    quad("Back", [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)], white)
    quad("Left", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)], red)
    quad("Right", [(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)], green)
    box("TallBox", (-0.35, 0.3, 0.6), (0.6, 0.6, 1.2), 17, principled("BoxWhite", (0.73, 0.73, 0.73)))
    box("ShortBox", (0.35, -0.3, 0.3), (0.6, 0.6, 0.6), -17, white)
    light("AREA", "CeilingLight", (0, 0, 1.99), shape="RECTANGLE", size=0.5, size_y=0.4,
          energy=60.0)
    camera((0, -3.9, 1.0), (0, 0, 1.0), lens=35.0)


def light_point():
    _reset()
    _stage()
    light("POINT", "Point", (0.5, -1.0, 2.5), shadow_soft_size=0.15, energy=400.0)


def light_point_sphere():
    """light_point with soft falloff off: Cycles renders a sphere light of that radius, which is
    also what light paths (bdpt, lvc, cis, lt) can start on."""
    light_point()
    bpy.data.lights["Point"].use_soft_falloff = False


def light_spot():
    _reset()
    _stage()
    light("SPOT", "Spot", (1.5, -1.5, 3.0), target=(0, 0.3, 0), shadow_soft_size=0.1,
          energy=1500.0, spot_size=math.radians(50), spot_blend=0.3)


def _area(shape, size, size_y=None):
    _reset()
    _stage()
    props = {"shape": shape, "size": size, "energy": 300.0}
    if size_y is not None:
        props["size_y"] = size_y
    light("AREA", "Area", (0.3, -1.2, 2.8), target=(0, 0.3, 0), **props)


def light_area_square():
    _area("SQUARE", 0.8)


def light_area_rectangle():
    _area("RECTANGLE", 1.2, 0.4)


def light_area_disk():
    _area("DISK", 0.8)


def light_area_ellipse():
    _area("ELLIPSE", 1.2, 0.5)


def light_sun():
    _reset()
    _stage()
    light("SUN", "Sun", (0, 0, 5), target=(-0.8, 1.2, 0), energy=3.0, angle=math.radians(10))


def emissive_mesh():
    """No lamps: a Emission-shader panel (both sides emit) lights the stage."""
    _reset()
    _stage()
    quad("Panel", [(-0.4, -1.0, 2.2), (0.4, -1.0, 2.2), (0.4, -0.4, 2.6), (-0.4, -0.4, 2.6)],
         emission("Glow", (1.0, 0.9, 0.7), 15.0))


def principled_emission_mesh():
    """No lamps: a block with Principled emission (base colour + emission) lights the stage."""
    _reset()
    _stage()
    box("Glowing", (0.9, 0.9, 1.4), (0.5, 0.5, 0.3), 10,
        principled_emission("GlowP", (0.5, 0.5, 0.5), (0.7, 0.85, 1.0), 12.0))


def world_color():
    """No lamps: only a constant world colour (0.5, 0.6, 0.8) lights the stage."""
    _reset(world_color=(0.5, 0.6, 0.8))
    _stage()


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


def world_hdri():
    """No lamps: bpy's sunset.exr (a low sun of ~2000) turned 125 degrees about Z and tilted
    8 degrees about X lights the stage."""
    _reset()
    _stage()
    hdri_world("sunset.exr", rotation=(math.radians(8), 0.0, math.radians(125)))


def world_hdri_dof():
    """world_hdri seen through a wide-open lens: f/0.5 on the 32 mm camera (radius 3.2 cm),
    focused on the orange box (its focus object), a 6-blade aperture turned 15 degrees."""
    world_hdri()
    cam = bpy.context.scene.camera.data
    cam.dof.use_dof = True
    cam.dof.aperture_fstop = 0.5
    cam.dof.focus_object = bpy.data.objects["Box"]
    cam.dof.aperture_blades = 6
    cam.dof.aperture_rotation = math.radians(15)


SCENES = {f.__name__: f for f in (
    cornell_box, light_point, light_point_sphere, light_spot, light_area_square,
    light_area_rectangle, light_area_disk, light_area_ellipse, light_sun, emissive_mesh,
    principled_emission_mesh, world_color, world_hdri, world_hdri_dof)}


def build(name, path=None):
    """Build scene `name` into the current bpy data and save it; returns the .blend path."""
    SCENES[name]()
    path = path or os.path.join(OUT_DIR, name + ".blend")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=path, check_existing=False)
    return path


import world_scenes  # noqa: E402  (blend_scenes/world_scenes.py: sky, panorama)
world_scenes.register(SCENES)
