"""Image textures and normal maps from Blender's nodes: what the exporter writes, and F12
pixels against analytic values (a plane under a uniform white world reflects exactly its
albedo; under a sun, albedo/pi E cos of the mapped normal)."""

import math

import bpy
import numpy as np
import pytest

import lantern
from lantern import metrics
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


def lambert_material(name, albedo, normal_image=None):
    """A Principled BSDF that is exactly Lambert (Specular IOR Level 0), optionally with
    `normal_image` through a tangent-space Normal Map node on its Normal."""
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (albedo, albedo, albedo, 1)
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    if normal_image is not None:
        tex = nt.nodes.new("ShaderNodeTexImage")
        tex.image = normal_image
        nmap = nt.nodes.new("ShaderNodeNormalMap")
        nt.links.new(tex.outputs["Color"], nmap.inputs["Color"])
        nt.links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    return mat


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


def test_export_coat_normal(empty, addon):
    """A Normal Map on Coat Normal -> coat_normal_texture and strength, tangents exported, no
    fallback warning; the base's own Normal Map stays normal_texture."""
    mat = bpy.data.materials.new("Coated")
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Coat Weight"].default_value = 1.0
    for socket, strength in (("Coat Normal", 0.6), ("Normal", 1.0)):
        tex = nt.nodes.new("ShaderNodeTexImage")
        tex.image = make_image(socket, np.array([[[160, 128, 250, 255]]], np.uint8),
                               colorspace="Non-Color")
        nmap = nt.nodes.new("ShaderNodeNormalMap")
        nmap.inputs["Strength"].default_value = strength
        nt.links.new(tex.outputs["Color"], nmap.inputs["Color"])
        nt.links.new(nmap.outputs["Normal"], bsdf.inputs[socket])
    add_uvs(add_plane(empty, material=mat))
    scene, report = export()
    m = scene.materials[1]
    assert m["type"] == "principled" and m["coat_weight"] == 1.0
    assert scene.textures[m["coat_normal_texture"]]["name"].startswith("Coat Normal")
    assert scene.textures[m["normal_texture"]]["name"].startswith("Normal")
    assert m["coat_normal_strength"] == pytest.approx(0.6)
    assert scene.meshes[0]["tangents"] is not None
    assert not any("Coat Normal" in w for w in report.messages), report.messages
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
    empty.lantern.samples = 64
    px = render_exr(empty, tmp_path)[..., :3].astype(np.float64)
    region = px[8:24, 8:24].reshape(-1, 3)
    # magenta exactly: green is 0 with no noise; red and blue, a z-test from the pixels' spread
    # (the world's MIS makes them noisy), and a 1 % error either way must fail it
    mean = region.mean(axis=0)
    se = region.std(axis=0, ddof=1) / math.sqrt(len(region)) + 1e-4
    z = np.abs(mean - [1, 0, 1]) / se
    z_off = min(np.abs(mean - [1 + d, 0, 1 + d]).max() / se.max() for d in (0.01, -0.01))
    print(f"missing image: mean {mean}, |z| {z.max():.2f}, 1 % off {z_off:.1f}")
    assert z.max() < 5 and mean[1] == 0.0, mean
    assert z_off > 5, f"a 1 % error would pass: |z| {z_off:.1f}"
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


def normal_map_scene(scene, integrator):
    """test_normal_map_f12's plane, sun and camera; returns the mapped normal n, the direction
    to the sun and the exact radiance rho E (n . l) G1 / pi."""
    b = (round((math.sin(math.radians(30)) + 1) * 127.5), 128,
         round((math.cos(math.radians(30)) + 1) * 127.5), 255)
    img = make_image("Normal", np.array([[b]], np.uint8), colorspace="Non-Color")
    mat = lambert_material("Bumpy", 0.5, normal_image=img)
    add_uvs(add_plane(scene, size=2.0, material=mat))
    sun = bpy.data.lights.new("Sun", "SUN")
    sun.energy = 2.0
    sun.angle = 0.0
    obj = bpy.data.objects.new("Sun", sun)
    obj.rotation_euler = (0.0, math.radians(45), 0.0)  # -Z tilted: light travels towards -x
    scene.collection.objects.link(obj)
    ortho_camera(scene)
    scene.lantern.integrator = integrator
    scene.lantern.samples = 8 if integrator == "pt" else 16
    n = np.array([2 * v / 255 - 1 for v in b[:3]])
    n /= np.linalg.norm(n)
    light = np.array([math.sin(math.radians(45)), 0.0, math.cos(math.radians(45))])
    tilt = math.acos(n[2])  # the map's tilt off the plane's normal, 30 degrees to rounding
    alpha2 = min(math.tan(tilt) ** 2 / 8.0, 1.0)
    g1 = 2.0 / (1.0 + math.sqrt(1.0 + alpha2 * math.tan(math.radians(45)) ** 2))
    return n, light, 0.5 / math.pi * 2.0 * float(n @ light) * g1


def normal_map_seeds(scene, tmp_path, seeds):
    """One F12 a seed of the normal-map scene: RGB float64 (32, 32, 3) each."""
    imgs = []
    for k in seeds:
        scene.lantern.seed = k
        imgs.append(render_exr(scene, tmp_path, f"s{k}.exr")[..., :3].astype(np.float64))
    return imgs


# the 4x4 blocks inside the plane's [8, 24) pixels
NORMAL_MAP_MASK = np.zeros((8, 8), bool)
NORMAL_MAP_MASK[2:6, 2:6] = True


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_normal_map_f12(empty, addon, tmp_path, errors, integrator):
    """A constant tangent-space normal map tilting the normal 30 degrees towards +x (the
    plane's +u, so MikkTSpace's tangent), a sun from +x 45 degrees up: cos 15 instead of
    cos 45, times Cycles' bump shadowing term (docs/nodes.md "Bump and displacement"): the GGX
    masking G1 with alpha^2 = tan^2(30 deg) / 8 at the sun's 45 degrees to the plane's own
    normal, 0.9898."""
    n, light, expected = normal_map_scene(empty, integrator)
    scene, _ = export()
    assert scene.meshes[0]["tangents"] is not None
    assert abs(expected - 0.5 / math.pi * 2 * light[2]) > 0.2 * expected  # tilt is visible
    if integrator == "pt":
        # pt sees only the sun here: noise-free, every pixel to 1e-4
        px = render_exr(empty, tmp_path)[6:26, 6:26, :3].astype(np.float64)
        err = np.abs(px / expected - 1.0)
        assert err.max() <= 1e-4, (float(err.max()), float(px.mean()), expected)
    else:
        # cis also splats light paths (noisy): 16 seeds against the exact value, the 4x4
        # blocks inside the plane's [8, 24) pixels (tests/README.md)
        imgs = normal_map_seeds(empty, tmp_path, range(10, 26))
        metrics.assert_agreement(f"normal map F12 {integrator}", imgs,
                                 np.full((32, 32, 3), expected), block=4,
                                 mask=NORMAL_MAP_MASK, bias_cap=1e-4)
    assert not [c for c in errors if c[0] == "ERROR"]


NAN = float("nan")
HOSTILE = {
    "nan base color": {"Base Color": (NAN, 0.5, NAN, 1.0)},
    "negative and >1 base color": {"Base Color": (-1.0, 0.5, 7.0, 1.0)},
    "roughness 0 metal": {"Roughness": 0.0, "Metallic": 1.0},
    "roughness 1": {"Roughness": 1.0},
    "nan roughness": {"Roughness": NAN, "Metallic": 0.5},
    "ior 1 glass": {"IOR": 1.0, "Transmission Weight": 1.0},
    "ior below 1 glass": {"IOR": 0.5, "Transmission Weight": 1.0, "Roughness": 0.2},
    "ior 1 specular": {"IOR": 1.0},
    "alpha 0": {"Alpha": 0.0},
    "nan alpha": {"Alpha": NAN},
    "coat ior 1": {"Coat Weight": 1.0, "Coat IOR": 1.0, "Coat Roughness": 0.0},
    "huge sheen": {"Sheen Weight": 1e6},
    "negative emission": {"Emission Color": (-1.0, 1.0, 1.0, 1.0), "Emission Strength": 5.0},
    "nan emission strength": {"Emission Strength": NAN},
}


@pytest.mark.parametrize("case", list(HOSTILE))
def test_hostile_principled_inputs_render_finite(empty, addon, tmp_path, errors, case):
    """Bad input through the add-on: the render finishes, every pixel is finite and >= 0,
    and the engine reports no error (a warning at most)."""
    mat = bpy.data.materials.new("Hostile")
    p = mat.node_tree.nodes["Principled BSDF"]
    for k, v in HOSTILE[case].items():
        p.inputs[k].default_value = v
    bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12, radius=1.0)
    bpy.context.object.data.materials.append(mat)
    add_plane(empty, size=20.0, location=(0, 0, -1.0))
    white_world(empty)
    add_camera(empty, location=(0, -6, 1), rotation=(math.radians(80), 0, 0))
    empty.lantern.samples = 8
    px = render_exr(empty, tmp_path)
    assert np.isfinite(px).all(), case
    assert (px[..., :3] >= 0).all(), case
    assert px[..., :3].max() > 0, case  # something rendered (the world at least)
    assert not [c for c in errors if c[0] == "ERROR"], errors


def test_zero_length_normals_from_a_normal_map(empty, addon, tmp_path, errors):
    """A float normal map of 0.5 grey decodes to the zero vector everywhere, a NaN one to NaN:
    the plain normal is kept, every pixel finite, the image as without the map."""
    results = []
    for value in (0.5, NAN, None):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        scene = bpy.context.scene
        scene.render.engine = "LANTERN"
        img = None
        if value is not None:
            img = bpy.data.images.new("N", 4, 4, float_buffer=True)
            img.colorspace_settings.name = "Non-Color"
            img.pixels.foreach_set(np.full(64, value, np.float32))
            img.pack()
        mat = lambert_material("Flat", 0.8, normal_image=img)
        add_uvs(add_plane(scene, size=2.0, material=mat))
        sun = bpy.data.lights.new("Sun", "SUN")
        sun.energy = 2.0
        scene.collection.objects.link(bpy.data.objects.new("Sun", sun))
        ortho_camera(scene)
        scene.lantern.samples = 4
        px = render_exr(scene, tmp_path, f"n{len(results)}.exr")[..., :3]
        assert np.isfinite(px).all()
        results.append(float(px[8:24, 8:24].mean()))
    np.testing.assert_allclose(results[:2], results[2], rtol=1e-3)
    assert not [c for c in errors if c[0] == "ERROR"]


def test_viewport_texture_cache(empty, addon):
    """Viewport re-exports reuse the pixels of unchanged images (no second read of a large
    image when a light moves) and read an image again once its stamp changes."""
    from lantern_blender.export import export_scene
    img = make_image("Checker", CHECKER)
    mat, _ = textured_material(img)
    add_plane(empty, material=mat)
    cache = {}
    deps = bpy.context.evaluated_depsgraph_get
    first, _ = export_scene(deps(), texture_cache=cache)
    again, _ = export_scene(deps(), texture_cache=cache)
    assert again.textures[0]["pixels"] is first.textures[0]["pixels"]
    fresh, _ = export_scene(deps())             # final renders never use the cache
    assert fresh.textures[0]["pixels"] is not first.textures[0]["pixels"]
    img.colorspace_settings.name = "Non-Color"
    changed, _ = export_scene(deps(), texture_cache=cache)
    assert changed.textures[0]["pixels"] is not first.textures[0]["pixels"]
    assert changed.textures[0]["colorspace"] == "linear"


def test_emission_image_exports_as_emission_texture(empty, addon, tmp_path, errors):
    """An image on an Emission node's Color: emission_texture with the strength as multiplier;
    F12 of the plane in a black world shows texel x strength."""
    img = make_image("Screen", CHECKER)
    mat = bpy.data.materials.new("Screen")
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    emit = nt.nodes.new("ShaderNodeEmission")
    emit.inputs["Strength"].default_value = 3.0
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = "Closest"
    nt.links.new(tex.outputs["Color"], emit.inputs["Color"])
    nt.links.new(emit.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    add_uvs(add_plane(empty, size=2.0, material=mat))
    ortho_camera(empty)
    scene, report = export()
    m = scene.materials[1]
    assert m["emission"] == [3.0] * 3 and scene.textures[m["emission_texture"]]["pixels"].shape \
        == (2, 2, 4)
    assert "_emission_mean" not in m
    empty.lantern.samples = 4
    px = render_exr(empty, tmp_path)[..., :3]
    expected = srgb_to_linear(CHECKER[..., :3] / 255.0) * 3.0
    np.testing.assert_allclose(px[19:29, 3:13].reshape(-1, 3).mean(axis=0), expected[0, 0],
                               rtol=1e-3)
    np.testing.assert_allclose(px[3:13, 19:29].reshape(-1, 3).mean(axis=0), expected[1, 1],
                               rtol=1e-3)
    assert not [c for c in errors if c[0] == "ERROR"]
