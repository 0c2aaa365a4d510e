"""Light units against Cycles, with no add-on in between: Cycles (bpy) renders a diffuse plane lit
by each light type; the same scene is written by hand as a lantern.Scene. Block means of K
independent seeds per renderer must agree (lantern.metrics.assert_agreement, tests/README.md:
Welch t per 8x8 block, the image mean within the 0.2 % bias cap plus its noise, and negative
controls: +-1 % on the whole image and +-5 % on one block must fail). This pins the core's
conversions (watts to radiance, spot cone, sun disk, pixel filter) to Cycles' own,
independently of the exporter."""

import math

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import lantern  # noqa: E402
from lantern import metrics  # noqa: E402

SIZE, SEEDS, CYCLES_SPP, LANTERN_SPP, BLOCK = 32, 16, 32, 32, 8
SUN_DIR = [0.0, 0.5, -math.sqrt(3) / 2]  # Blender's sun rotated 30 degrees about X


def _cycles_scene(kind):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    s.render.engine = "CYCLES"
    c = s.cycles
    c.device, c.samples, c.use_denoising = "CPU", CYCLES_SPP, False
    c.sample_clamp_indirect = c.sample_clamp_direct = 0.0
    c.light_sampling_threshold, c.max_bounces = 0.0, 0
    c.use_adaptive_sampling = False
    s.render.resolution_x = s.render.resolution_y = SIZE
    s.render.resolution_percentage = 100
    s.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("w")
    s.world = world
    world.node_tree.nodes["Background"].inputs[0].default_value = (0, 0, 0, 1)
    bpy.ops.mesh.primitive_plane_add(size=4, location=(0, 0, 0))
    mat = bpy.data.materials.new("m")
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1)
    bsdf.inputs["Roughness"].default_value = 1.0
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    bpy.context.object.data.materials.append(mat)
    cam = bpy.data.cameras.new("c")
    cam.type, cam.ortho_scale = "ORTHO", 4
    cam_obj = bpy.data.objects.new("c", cam)
    cam_obj.location = (0, 0, 5)
    s.collection.objects.link(cam_obj)
    s.camera = cam_obj
    light = bpy.data.lights.new("L", kind.split("_")[0])
    obj = bpy.data.objects.new("L", light)
    s.collection.objects.link(obj)
    obj.location = (0, 0, 2)
    if kind in {"POINT", "SPOT"}:
        light.energy, light.shadow_soft_size = 100, 0.1
    if kind == "POINT_SPHERE":  # soft falloff off: a true sphere light
        light.energy, light.shadow_soft_size, light.use_soft_falloff = 100, 0.5, False
    if kind == "AREA_ELLIPSE":
        light.energy, light.shape, light.size, light.size_y = 100, "ELLIPSE", 1.5, 0.5
    if kind == "SPOT":
        light.spot_size, light.spot_blend = math.radians(60), 0.5
    if kind == "AREA":
        light.energy, light.shape, light.size = 100, "SQUARE", 1.0
    if kind == "SUN":
        light.energy, light.angle = 3, math.radians(10)
        obj.rotation_euler = (math.radians(30), 0, 0)
    return s


def _cycles_renders(kind, tmp_path, seed0=0):
    s = _cycles_scene(kind)
    s.render.image_settings.file_format = "OPEN_EXR"
    s.render.image_settings.color_depth = "32"
    out = []
    for seed in range(seed0, seed0 + SEEDS):
        s.cycles.seed = seed
        path = str(tmp_path / f"{kind}_{seed}.exr")
        s.render.filepath = path
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(path)
        px = np.array(img.pixels[:], dtype=np.float64).reshape(SIZE, SIZE, 4)[::-1, :, :3]
        bpy.data.images.remove(img)
        out.append(px)
    return np.array(out)


def _lantern_scene(kind):
    s = lantern.Scene()
    s.film.update(width=SIZE, height=SIZE, filter_width=1.5)
    cam = np.eye(4, dtype=np.float32)
    cam[2, 3] = 5
    s.camera.update(type="orthographic", to_world=cam, screen=[-2, 2, -2, 2], clip=[0.1, 100])
    s.world["color"] = [0, 0, 0]
    s.materials = [{"name": "m", "type": "diffuse", "base_color": [0.8] * 3,
                    "emission": [0.0] * 3}]
    quad = np.array([[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]], np.float32)
    s.meshes = [{"name": "plane", "positions": quad,
                 "indices": np.array([[0, 1, 2], [0, 2, 3]], np.uint32), "normals": None,
                 "uvs": None, "material_ids": np.zeros(2, np.uint32)}]
    m = np.eye(4, dtype=np.float32)
    m[2, 3] = 2
    if kind == "POINT":
        s.lights = [dict(type="point", position=[0, 0, 2], radius=0.1, power=[100] * 3)]
    if kind == "POINT_SPHERE":
        s.lights = [dict(type="point", position=[0, 0, 2], radius=0.5, power=[100] * 3,
                         soft_falloff=False)]
    if kind == "AREA_ELLIPSE":
        s.lights = [dict(type="area", to_world=m, shape="ellipse", size=[1.5, 0.5],
                         power=[100] * 3)]
    if kind == "SPOT":
        s.lights = [dict(type="spot", to_world=m, radius=0.1, power=[100] * 3,
                         spot_size=math.radians(60), spot_blend=0.5)]
    if kind == "AREA":
        s.lights = [dict(type="area", to_world=m, shape="rectangle", size=[1, 1],
                         power=[100] * 3)]
    if kind == "SUN":
        s.lights = [dict(type="sun", direction=SUN_DIR, angle=math.radians(10),
                         strength=[3] * 3)]
    return s


@pytest.mark.parametrize("kind", ["POINT", "POINT_SPHERE", "SPOT", "AREA", "AREA_ELLIPSE", "SUN"])
def test_light_matches_cycles(kind, tmp_path):
    cyc = _cycles_renders(kind, tmp_path)
    scene = _lantern_scene(kind)
    lan = np.array([lantern.render(scene, spp=LANTERN_SPP, seed=100 + k, max_depth=2,
                                   integrator="pt")
                    for k in range(SEEDS)], dtype=np.float64)
    assert np.isfinite(lan).all()
    # 16 blocks x 3 channels, Welch dof ~30; the grey plane leaves the channel swap out
    metrics.assert_agreement(f"{kind} vs Cycles", list(lan), list(cyc), block=BLOCK)
