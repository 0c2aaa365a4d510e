"""Image textures and normal maps from Blender's nodes: what the exporter writes, and F12
pixels against analytic values (a plane under a uniform white world reflects exactly its
albedo; under a sun, albedo/pi E cos of the mapped normal)."""

import math

import bpy
import numpy as np
import pytest

import lantern
from blender_helpers import add_camera, add_plane, render_exr

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")

CHECKER = np.array([[[200, 30, 10, 255], [10, 180, 60, 255]],
                    [[90, 90, 90, 255], [250, 250, 250, 255]]], np.uint8)  # rows bottom to top


def export():
    from lantern_blender.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get())


def srgb_to_linear(c):
    c = np.asarray(c, np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def make_image(name, texels, colorspace="sRGB"):
    """An 8-bit packed image holding `texels` ((H, W, 4) uint8, rows bottom to top)."""
    h, w = texels.shape[:2]
    img = bpy.data.images.new(name, w, h, alpha=True)
    img.colorspace_settings.name = colorspace
    img.pixels.foreach_set((texels.astype(np.float32) / 255.0).ravel())
    img.pack()
    return img


def textured_material(image, socket="Base Color", interpolation="Closest", extension="REPEAT"):
    mat = bpy.data.materials.new("Textured")
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Specular IOR Level"].default_value = 0.0   # exactly Lambert
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = interpolation
    tex.extension = extension
    nt.links.new(tex.outputs["Color"], bsdf.inputs[socket])
    return mat, tex


def add_uvs(plane):
    """The plane's uv map: (0, 0) at its lower-left corner (add_plane makes none)."""
    plane.data.uv_layers.new(name="UVMap")
    for loop, uv in zip(plane.data.uv_layers[0].data, [(0, 0), (1, 0), (1, 1), (0, 1)]):
        loop.uv = uv
    return plane


def white_world(scene):
    world = bpy.data.worlds.new("White")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world


def ortho_camera(scene, size=2.0):
    cam = add_camera(scene, location=(0, 0, 5))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = size
    scene.render.resolution_x = scene.render.resolution_y = 32


def test_export_image_texture(empty, addon):
    img = make_image("Checker", CHECKER)
    mat, tex = textured_material(img, extension="MIRROR")
    mapping = mat.node_tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (2.0, 3.0, 1.0)
    mapping.inputs["Location"].default_value = (0.25, 0.5, 0.0)
    mat.node_tree.links.new(mapping.outputs[0], tex.inputs["Vector"])
    add_plane(empty, material=mat)
    scene, report = export()
    (t,) = scene.textures
    assert t["pixels"].dtype == np.uint8 and t["pixels"].shape == (2, 2, 4)
    np.testing.assert_array_equal(t["pixels"], CHECKER)
    assert (t["colorspace"], t["wrap"], t["interpolation"]) == ("srgb", "mirror", "closest")
    np.testing.assert_allclose(t["uv_transform"], [[2, 0, 0.25], [0, 3, 0.5]], atol=1e-6)
    m = scene.materials[1]
    assert m["base_color_texture"] == 0 and m["type"] == "diffuse"
    scene.validate()


def test_export_channels_non_color_and_sharing(empty, addon):
    """Roughness from the green channel of a packed Non-Color map, metallic from its blue one:
    one image read once, two textures (different outputs)."""
    orm = make_image("ORM", CHECKER, colorspace="Non-Color")
    mat = bpy.data.materials.new("ORM")
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = orm
    sep = nt.nodes.new("ShaderNodeSeparateColor")
    nt.links.new(tex.outputs["Color"], sep.inputs[0])
    nt.links.new(sep.outputs["Green"], bsdf.inputs["Roughness"])
    nt.links.new(sep.outputs["Blue"], bsdf.inputs["Metallic"])
    nt.links.new(tex.outputs["Alpha"], bsdf.inputs["Alpha"])
    add_plane(empty, material=mat)
    scene, report = export()
    m = scene.materials[1]
    assert m["type"] == "principled"
    outputs = {scene.textures[m[k]]["output"] for k in
               ("roughness_texture", "metallic_texture", "alpha_texture")}
    assert outputs == {"green", "blue", "alpha"}
    assert all(t["colorspace"] == "linear" for t in scene.textures)
    assert scene.textures[0]["pixels"] is scene.textures[1]["pixels"]  # read once
    scene.validate()


def test_missing_image_is_magenta_with_warning(empty, addon, tmp_path, errors):
    # an image file that existed when the .blend was made and is gone now
    path = tmp_path / "gone.png"
    src = bpy.data.images.new("Src", 4, 4)
    src.filepath_raw = str(path)
    src.file_format = "PNG"
    src.save()
    img = bpy.data.images.load(str(path))
    img.name = "Gone"
    path.unlink()
    img.reload()
    mat, _ = textured_material(img)
    add_plane(empty, size=100.0, material=mat)
    scene, report = export()
    assert scene.materials[1]["base_color"] == [1.0, 0.0, 1.0]
    assert "base_color_texture" not in scene.materials[1]
    assert any("missing" in w and "Gone" in w for w in report.messages)
    # and the F12 render shows it: magenta under a white world, a warning, no error
    white_world(empty)
    ortho_camera(empty)
    empty.lantern.samples = 4
    px = render_exr(empty, tmp_path)[..., :3]
    np.testing.assert_allclose(px[8:24, 8:24].mean(axis=(0, 1)), [1, 0, 1], atol=0.05)
    assert any(c[0] == "WARNING" and "Gone" in c[1] for c in errors)
    assert not [c for c in errors if c[0] == "ERROR"]


def test_textured_plane_f12_matches_texture(empty, addon, tmp_path, errors):
    img = make_image("Checker", CHECKER)
    mat, _ = textured_material(img)
    add_uvs(add_plane(empty, size=2.0, material=mat))
    white_world(empty)
    ortho_camera(empty)
    empty.lantern.samples = 16
    px = render_exr(empty, tmp_path)[..., :3].astype(np.float64)  # top row first
    expected = srgb_to_linear(CHECKER[..., :3] / 255.0)
    for ty in range(2):
        for tx in range(2):
            rows = slice(16 - 16 * ty + 3, 32 - 16 * ty - 3)   # texel row ty from the bottom
            cols = slice(16 * tx + 3, 16 * tx + 13)
            block = px[rows, cols].reshape(-1, 3)
            se = block.std(axis=0, ddof=1) / math.sqrt(len(block)) + 1e-4
            z = np.abs(block.mean(axis=0) - expected[ty, tx]) / se
            assert z.max() < 5.0, (tx, ty, block.mean(axis=0), expected[ty, tx])
    assert not [c for c in errors if c[0] == "ERROR"]


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_normal_map_f12(empty, addon, tmp_path, errors, integrator):
    """A constant tangent-space normal map tilting the normal 30 degrees towards +x (the
    plane's +u, so MikkTSpace's tangent), a sun from +x 45 degrees up: cos 15 instead of
    cos 45."""
    b = (round((math.sin(math.radians(30)) + 1) * 127.5), 128,
         round((math.cos(math.radians(30)) + 1) * 127.5), 255)
    img = make_image("Normal", np.array([[b]], np.uint8), colorspace="Non-Color")
    mat = bpy.data.materials.new("Bumpy")
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1)
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nt.links.new(tex.outputs["Color"], nmap.inputs["Color"])
    nt.links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    add_uvs(add_plane(empty, size=2.0, material=mat))
    sun = bpy.data.lights.new("Sun", "SUN")
    sun.energy = 2.0
    sun.angle = 0.0
    obj = bpy.data.objects.new("Sun", sun)
    obj.rotation_euler = (0.0, math.radians(45), 0.0)  # -Z tilted: light travels towards -x
    empty.collection.objects.link(obj)
    ortho_camera(empty)
    empty.lantern.integrator = integrator
    empty.lantern.samples = 8
    scene, _ = export()
    assert scene.meshes[0]["tangents"] is not None
    px = render_exr(empty, tmp_path)[..., :3]
    n = np.array([2 * v / 255 - 1 for v in b[:3]])
    n /= np.linalg.norm(n)
    light = np.array([math.sin(math.radians(45)), 0.0, math.cos(math.radians(45))])
    expected = 0.5 / math.pi * 2.0 * float(n @ light)
    mean = float(px[6:26, 6:26].mean())
    assert abs(mean - expected) < 0.01 * expected, (mean, expected, 0.5 / math.pi * 2 * light[2])
    assert not [c for c in errors if c[0] == "ERROR"]
