"""World and camera scenes: bpy's sunset HDRI lighting the stage (world_hdri) and seen through a
wide-open lens (world_hdri_dof), a Preetham sky, Blender 5.0's Multiple Scattering sky, the HDRI
seen by a panoramic camera, and transparent film with holdouts. All but the film scenes join
scenes.SCENES through register() (called at the end of scenes.py), so that
tools/make_cycles_refs.py and tests/render build them like the others. The film scenes are not
registered: its Cycles reference needs transparent film, which make_cycles_refs turns off
(tests/render/test_world_film.py renders it)."""

import math

import bpy
from mathutils import Vector

import stage

# scenes.py imports this module at its end (register); this one imports stage, never scenes

SKY_SUN = (math.radians(35.0), math.radians(-30.0))   # elevation, azimuth from +X
SKY_TURBIDITY = 3.0


def sky_world(sun=SKY_SUN, turbidity=SKY_TURBIDITY):
    """The world: a Preetham Sky Texture (the sky type Lantern renders) into the Background."""
    nt = bpy.context.scene.world.node_tree
    sky = nt.nodes.new("ShaderNodeTexSky")
    sky.sky_type = "PREETHAM"
    el, az = sun
    sky.sun_direction = (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
    sky.turbidity = turbidity
    nt.links.new(sky.outputs["Color"], nt.nodes["Background"].inputs["Color"])
    return sky


def world_hdri():
    """No lamps: bpy's sunset.exr (a low sun of ~2000) turned 125 degrees about Z and tilted
    8 degrees about X lights the stage."""
    stage._reset()
    stage._stage()
    stage.hdri_world("sunset.exr", rotation=(math.radians(8), 0.0, math.radians(125)))


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


def world_sky():
    """No lamps: a Preetham sky (sun 35 degrees up, turbidity 3) lights the stage; the camera
    sees the sky above the back wall."""
    stage._reset()
    stage._stage()
    sky_world()


# the Multiple Scattering sky's only change from its defaults: the sun, 15 degrees up, turned
# from +Y (behind the back wall, whose shadow would cover the stage) to the camera's left
SKY_MS_ROTATION = math.radians(210.0)


def world_sky_ms():
    """No lamps: Blender 5.0's default Sky Texture (Multiple Scattering, every setting at its
    default: sun 15 degrees up, Sun Size 0.545 degrees, altitude 100 m, densities 1) but the
    Sun Rotation (210 degrees: the sun behind the camera, to its left) lights the stage; the
    camera sees the sky above the back wall, not the sun."""
    stage._reset()
    stage._stage()
    nt = bpy.context.scene.world.node_tree
    sky = nt.nodes.new("ShaderNodeTexSky")
    assert sky.sky_type == "MULTIPLE_SCATTERING"
    sky.sun_rotation = SKY_MS_ROTATION
    nt.links.new(sky.outputs["Color"], nt.nodes["Background"].inputs["Color"])


def world_pano():
    """world_hdri seen by an equirectangular panoramic camera (the full sphere, 192 x 96) from
    above the stage's floor: the sunset's sun, the stage and the sky in one image."""
    world_hdri()
    scene = bpy.context.scene
    scene.render.resolution_x = 2 * stage.RES
    cam_obj = scene.camera
    cam = cam_obj.data
    cam.type = "PANO"
    cam.panorama_type = "EQUIRECTANGULAR"
    cam_obj.location = (0.3, -2.2, 1.2)
    d = Vector((0.0, 1.0, -0.1))
    cam_obj.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()


def world_film_holdout():
    """Transparent film over a constant world and one area light: the stage, a holdout object
    (the green block, Object > Visibility > Holdout) and a sphere with the Holdout shader; both
    cut the film to alpha 0 where the camera sees them, the world still lights the scene."""
    stage._reset(world_color=(0.3, 0.35, 0.4))
    stage._stage()
    scene = bpy.context.scene
    scene.render.film_transparent = True
    bpy.data.objects["Block"].is_holdout = True
    m = bpy.data.materials.new("Holdout")
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    h = nt.nodes.new("ShaderNodeHoldout")
    nt.links.new(h.outputs["Holdout"], nt.nodes["Material Output"].inputs["Surface"])
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.35, location=(0.2, -1.2, 0.35), segments=32,
                                         ring_count=16)
    sphere = bpy.context.active_object
    sphere.name = "HoldoutSphere"
    sphere.data.materials.append(m)
    bpy.ops.object.shade_smooth()
    stage.light("AREA", "Key", (1.0, -2.0, 3.0), (0.0, 0.3, 0.0), energy=300.0, size=0.8)


def world_film_catcher():
    """world_film_holdout with the floor a shadow catcher (Object > Visibility > Shadow
    Catcher): over the transparent film only the shadows of the boxes, the holdout block and
    the sphere on the floor show, as alpha; the catcher still lights the scene indirectly."""
    world_film_holdout()
    bpy.data.objects["Floor"].is_shadow_catcher = True


def world_visibility():
    """The stage under a constant world hidden from diffuse rays (World > Settings > Ray
    Visibility > Diffuse off), one area light, the box a Glossy BSDF: the diffuse surfaces are
    lit by the lamp alone (and by what the box reflects), the box still mirrors the world, the
    camera sees it above the wall."""
    stage._reset(world_color=(0.6, 0.65, 0.7))
    stage._stage()
    m = bpy.data.materials.new("Glossy")
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    g = nt.nodes.new("ShaderNodeBsdfAnisotropic")  # the Glossy BSDF
    g.inputs["Color"].default_value = (0.8, 0.45, 0.15, 1.0)
    g.inputs["Roughness"].default_value = 0.25
    nt.links.new(g.outputs["BSDF"], nt.nodes["Material Output"].inputs["Surface"])
    box = bpy.data.objects["Box"]
    box.data.materials.clear()
    box.data.materials.append(m)
    bpy.context.scene.world.cycles_visibility.diffuse = False
    stage.light("AREA", "Key", (1.0, -2.0, 3.0), (0.0, 0.3, 0.0), energy=300.0, size=0.8)


def register(scenes_dict):
    """The scenes with a Cycles reference by make_cycles_refs (not the film scenes)."""
    for f in (world_hdri, world_hdri_dof, world_sky, world_sky_ms, world_pano, world_visibility):
        scenes_dict.setdefault(f.__name__, f)
