"""Export of scenes built in bpy: counts, units, transforms, camera windows by hand."""

import math

import bpy
import numpy as np
import pytest

from blender_helpers import (add_camera, add_plane, diffuse_material, emission_material,
                             shader_material)


def export(addon):
    from lantern_blender.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get())


def test_default_cube(default_scene, addon):
    scene, report = export(addon)
    assert len(scene.meshes) == 1
    cube = scene.meshes[0]
    assert cube["indices"].shape == (12, 3)
    assert cube["positions"].shape == (24, 3) and cube["normals"].shape == (24, 3)  # per corner
    np.testing.assert_allclose(np.abs(cube["positions"]).max(axis=0), [1, 1, 1], atol=1e-6)
    assert cube["uvs"].shape == (24, 2)
    mat = scene.materials[int(cube["material_ids"][0])]
    assert mat["name"] == "Material"
    np.testing.assert_allclose(mat["base_color"], [0.8, 0.8, 0.8], atol=1e-6)
    (light,) = scene.lights
    assert light["type"] == "point"
    np.testing.assert_allclose(light["power"], [1000, 1000, 1000])  # watts, as Blender stores
    np.testing.assert_allclose(light["radius"], 0.1)
    assert light["visible_camera"] is False
    film = scene.film
    assert (film["width"], film["height"]) == (1920, 1080)
    assert film["filter_width"] == pytest.approx(default_scene.render.filter_size)
    # 50 mm lens on a 36 mm sensor, AUTO fit, wide image: horizontal half-extent 18/50
    tx, ty = 18 / 50, 18 / 50 * 1080 / 1920
    np.testing.assert_allclose(scene.camera["screen"], [-tx, tx, -ty, ty], rtol=1e-6)
    scene.validate()


@pytest.mark.parametrize("fit, res, expect", [
    ("AUTO", (200, 100), lambda s: (s / 2, s / 4)),
    ("AUTO", (100, 200), lambda s: (s / 4, s / 2)),        # portrait: fits the height
    ("HORIZONTAL", (100, 200), lambda s: (s / 2, s)),
    ("VERTICAL", (200, 100), lambda s: (48 / 50, 24 / 50)),  # sensor_height 48 fits the height
])
def test_camera_sensor_fit(empty, addon, fit, res, expect):
    cam = add_camera(empty, lens=50)
    cam.data.sensor_fit = fit
    cam.data.sensor_width, cam.data.sensor_height = 36, 48
    empty.render.resolution_x, empty.render.resolution_y = res
    scene, _ = export(addon)
    hx, hy = expect(36 / 50)
    np.testing.assert_allclose(scene.camera["screen"], [-hx, hx, -hy, hy], rtol=1e-6)


def test_camera_shift_percentage_and_ortho(empty, addon):
    cam = add_camera(empty, lens=35)
    cam.data.shift_x, cam.data.shift_y = 0.1, -0.2
    empty.render.resolution_x, empty.render.resolution_y = 400, 200
    empty.render.resolution_percentage = 50
    scene, _ = export(addon)
    assert (scene.film["width"], scene.film["height"]) == (200, 100)
    h = 18 / 35  # half of the larger dimension; shifts are in units of it (full width)
    np.testing.assert_allclose(scene.camera["screen"],
                               [-h + 0.2 * h, h + 0.2 * h, -h / 2 - 0.4 * h, h / 2 - 0.4 * h],
                               rtol=1e-6)
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 4.0
    cam.data.clip_start, cam.data.clip_end = 0.5, 50
    scene, _ = export(addon)
    assert scene.camera["type"] == "orthographic"
    np.testing.assert_allclose(scene.camera["screen"],
                               [-2 + 0.4, 2 + 0.4, -1 - 0.8, 1 - 0.8], rtol=1e-6)
    assert scene.camera["clip"] == [0.5, 50]


def test_camera_to_world(empty, addon):
    cam = add_camera(empty, location=(1, 2, 3), rotation=(math.pi / 2, 0, 0))
    cam.scale = (2, 2, 2)  # scale must not reach the rigid to_world
    scene, _ = export(addon)
    m = np.asarray(scene.camera["to_world"])
    np.testing.assert_allclose(m[:3, 3], [1, 2, 3], atol=1e-6)
    np.testing.assert_allclose(-m[:3, 2], [0, 1, 0], atol=1e-6)  # looks along +Y
    np.testing.assert_allclose(m[:3, :3].T @ m[:3, :3], np.eye(3), atol=1e-5)


def test_array_modifier_and_transform(empty, addon):
    plane = add_plane(empty, size=1.0, location=(0, 0, 2))
    plane.rotation_euler = (0, 0, math.pi / 2)
    plane.scale = (2, 1, 1)
    mod = plane.modifiers.new("Array", "ARRAY")
    mod.count = 3
    mod.relative_offset_displace = (1.0, 0, 0)
    scene, _ = export(addon)
    (mesh,) = scene.meshes
    assert mesh["indices"].shape == (6, 3)
    p = mesh["positions"].astype(np.float64)
    # local x in [-0.5, 2.5] (three unit plates), scaled by 2 then rotated onto world y
    np.testing.assert_allclose(p[:, 1].min(), -1.0, atol=1e-5)
    np.testing.assert_allclose(p[:, 1].max(), 5.0, atol=1e-5)
    np.testing.assert_allclose(np.abs(p[:, 0]).max(), 0.5, atol=1e-5)
    np.testing.assert_allclose(p[:, 2], 2.0, atol=1e-6)
    n = mesh["normals"]
    np.testing.assert_allclose(n, np.tile([0, 0, 1], (len(n), 1)), atol=1e-5)


@pytest.mark.parametrize("scale", [(3, 1, 1), (-3, 1, 1), (2, 2, 2), (-1, 1, 1)])
def test_scaled_and_mirrored_normals(empty, addon, scale):
    """Shading normals through the inverse transpose stay outward and unit, mirrors included;
    a mirror also flips the winding, so geometric normals stay outward too."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8)
    obj = bpy.context.object
    obj.scale = scale
    bpy.ops.object.shade_smooth()
    scene, _ = export(addon)
    (mesh,) = scene.meshes
    p, n = mesh["positions"].astype(np.float64), mesh["normals"].astype(np.float64)
    # an ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1 has normals along (x/a^2, y/b^2, z/c^2)
    expect = p / np.square(scale)
    expect /= np.linalg.norm(expect, axis=1, keepdims=True)
    assert np.median(np.sum(n * expect, axis=1)) > 0.99
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1, atol=1e-5)
    tri = p[mesh["indices"].astype(np.int64)]
    geometric = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    assert (np.sum(geometric * tri.mean(axis=1), axis=1) > 0).mean() > 0.99


def test_collection_instance(empty, addon):
    coll = bpy.data.collections.new("Source")
    mat = diffuse_material(0.5)
    src = add_plane(empty, size=1.0, material=mat, name="Src")
    empty.collection.objects.unlink(src)
    coll.objects.link(src)
    for i, loc in enumerate([(10, 0, 0), (0, 10, 0)]):
        inst = bpy.data.objects.new(f"Inst{i}", None)
        inst.instance_type = "COLLECTION"
        inst.instance_collection = coll
        inst.location = loc
        empty.collection.objects.link(inst)
    scene, _ = export(addon)
    centres = sorted(tuple(np.round(m["positions"].mean(axis=0), 5)) for m in scene.meshes)
    assert centres == [(0, 10, 0), (10, 0, 0)]
    for m in scene.meshes:
        assert scene.materials[int(m["material_ids"][0])]["base_color"] == pytest.approx([0.5] * 3)


def test_multi_material_slots(empty, addon):
    bpy.ops.mesh.primitive_cube_add()
    obj = bpy.context.object
    obj.data.materials.append(diffuse_material(0.2))
    obj.data.materials.append(emission_material(5.0))
    obj.data.polygons[0].material_index = 1
    scene, _ = export(addon)
    (mesh,) = scene.meshes
    ids = mesh["material_ids"]
    names = [scene.materials[int(i)]["name"] for i in ids]
    assert names.count("Emit") == 2 and names.count("Diffuse") == 10
    emit = next(m for m in scene.materials if m["name"] == "Emit")
    assert emit["emission"] == pytest.approx([5, 5, 5])


@pytest.mark.parametrize("slots", ["none", "empty_slot"])
def test_no_material_is_the_default_principled(empty, addon, slots):
    """An object without a material (no slot, or an empty one) renders as Blender's default
    surface, a Principled BSDF at its defaults (Cycles does, bpy 5.0.1; tests/cycles/
    test_export_parity.py): the exported material is the export of a new material's."""
    bpy.ops.mesh.primitive_cube_add()
    obj = bpy.context.object
    if slots == "empty_slot":
        obj.data.materials.append(None)
    bpy.ops.mesh.primitive_plane_add(location=(5, 0, 0))
    bpy.context.object.data.materials.append(bpy.data.materials.new("Fresh"))
    add_camera(empty)
    scene, report = export(addon)
    assert report.messages == []
    by_name = {m["name"]: m for m in scene.materials}
    cube = next(m for m in scene.meshes if m["positions"][:, 0].max() < 2)
    got = scene.materials[int(cube["material_ids"][0])]
    fresh = dict(by_name["Fresh"], name=got["name"])
    assert got.keys() == fresh.keys() and got["type"] == "principled"
    for k, v in fresh.items():
        assert got[k] == (v if isinstance(v, str) else pytest.approx(v, rel=1e-6)), k


def test_lights(empty, addon):
    def light(kind, **kw):
        data = bpy.data.lights.new(kind, kind)
        for k, v in kw.items():
            setattr(data, k, v)
        obj = bpy.data.objects.new(kind, data)
        empty.collection.objects.link(obj)
        return obj
    light("SPOT", energy=100, color=(1, 0.5, 0.25), spot_size=1.0, spot_blend=0.3)
    area = light("AREA", energy=50, shape="RECTANGLE", size=2.0, size_y=0.5)
    area.scale = (2, 3, 1)
    area.visible_camera = True
    light("SUN", energy=3.0, angle=0.1)
    light("POINT", energy=10, shadow_soft_size=0.05, use_soft_falloff=False)  # a sphere light
    scene, _ = export(addon)
    by = {l["type"]: l for l in scene.lights}
    assert by["point"]["soft_falloff"] is False and by["point"]["radius"] == pytest.approx(0.05)
    assert by["spot"]["soft_falloff"] is True  # Blender's default
    assert by["spot"]["power"] == pytest.approx([100, 50, 25])
    assert by["spot"]["spot_size"] == pytest.approx(1.0)
    assert by["area"]["size"] == pytest.approx([4.0, 1.5])
    assert by["area"]["visible_camera"] is True
    assert by["sun"]["strength"] == pytest.approx([3, 3, 3])
    assert by["sun"]["direction"] == pytest.approx([0, 0, -1])
    scene.validate()


def test_world_and_unknown_nodes(empty, addon):
    world = bpy.data.worlds.new("W")
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.5, 0.25, 1, 1)
    bg.inputs["Strength"].default_value = 2
    empty.world = world
    mat = bpy.data.materials.new("Cartoon")
    nodes = mat.node_tree.nodes
    toon = nodes.new("ShaderNodeBsdfToon")  # not translated: grey diffuse and a warning
    mat.node_tree.links.new(toon.outputs[0], nodes["Material Output"].inputs["Surface"])
    add_plane(empty, material=mat)
    scene, report = export(addon)
    assert scene.world["color"] == pytest.approx([1, 0.5, 2])
    assert any("Cartoon" in m and toon.name in m for m in report.messages)
    out = next(m for m in scene.materials if m["name"] == "Cartoon")
    assert out["type"] == "diffuse" and out["base_color"] == pytest.approx([0.8] * 3)


def test_export_operator(default_scene, addon, tmp_path):
    import lantern
    path = str(tmp_path / "cube.lantern")
    assert bpy.ops.export_scene.lantern(filepath=path) == {"FINISHED"}
    loaded = lantern.load_scene(path)
    assert loaded.meshes[0]["indices"].shape == (12, 3)
    assert loaded.lights[0]["type"] == "point"


def test_geometry_nodes_instances(empty, addon):
    """Instance on Points of two objects: every instance exported at its point, each with the
    instanced object's geometry (not the instancer's, which has none left)."""
    bpy.ops.mesh.primitive_plane_add(size=4)  # points at (+-2, +-2, 0)
    plane = bpy.context.object
    bpy.ops.mesh.primitive_cube_add(size=0.2, location=(0, 0, 10))
    cube = bpy.context.object
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1, radius=0.1, location=(0, 0, 20))
    ico = bpy.context.object
    tree = bpy.data.node_groups.new("GN", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    n = tree.nodes
    gin, gout, join = (n.new("NodeGroupInput"), n.new("NodeGroupOutput"),
                       n.new("GeometryNodeJoinGeometry"))
    for source in (cube, ico):
        info = n.new("GeometryNodeObjectInfo")
        info.inputs["Object"].default_value = source
        on_points = n.new("GeometryNodeInstanceOnPoints")
        tree.links.new(gin.outputs[0], on_points.inputs["Points"])
        tree.links.new(info.outputs["Geometry"], on_points.inputs["Instance"])
        tree.links.new(on_points.outputs[0], join.inputs[0])
    tree.links.new(join.outputs[0], gout.inputs[0])
    plane.modifiers.new("GN", "NODES").node_group = tree
    scene, _ = export(addon)
    inst = [m for m in scene.meshes if "(instance)" in m["name"]]
    assert sorted(len(m["indices"]) for m in inst) == [12] * 4 + [20] * 4
    centres = {tuple(np.round(m["positions"].mean(axis=0)[:2], 3)) for m in inst}
    assert centres == {(-2, -2), (-2, 2), (2, -2), (2, 2)}
    for m in inst:
        assert abs(m["positions"][:, 2]).max() < 0.11  # at the points, not at the sources


def test_textured_principled_warns_and_uses_default(empty, addon):
    mat = diffuse_material(0.3)
    # a node Lantern does not evaluate (Noise and most others compile: test_bl_nodes.py)
    tex = mat.node_tree.nodes.new("ShaderNodeTexGabor")
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    mat.node_tree.links.new(tex.outputs["Value"], bsdf.inputs["Base Color"])
    rgb = mat.node_tree.nodes.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (0, 1, 0, 1)
    bsdf.inputs["Emission Strength"].default_value = 2.0
    mat.node_tree.links.new(rgb.outputs[0], bsdf.inputs["Emission Color"])
    add_plane(empty, material=mat)
    scene, report = export(addon)
    out = next(m for m in scene.materials if m["name"] == mat.name)
    assert out["base_color"] == pytest.approx([0.3] * 3)  # the socket's own value
    assert out["emission"] == pytest.approx([0, 2, 0])    # a constant RGB node is followed
    assert any(mat.name in m and tex.name in m for m in report.messages)


def test_metal_and_glass_nodes_map_to_material_types(empty, addon):
    mats = {
        "p_metal": shader_material("p_metal", "ShaderNodeBsdfPrincipled", **{
            "Base Color": (0.9, 0.6, 0.3, 1), "Metallic": 1.0, "Roughness": 0.2,
            "Specular Tint": (1.0, 0.9, 0.8, 1)})[0],
        "p_glass": shader_material("p_glass", "ShaderNodeBsdfPrincipled", **{
            "Base Color": (0.9, 1.0, 0.95, 1), "Transmission Weight": 1.0, "Roughness": 0.0,
            "IOR": 1.45})[0],
        "p_mixed": shader_material("p_mixed", "ShaderNodeBsdfPrincipled", **{
            "Metallic": 0.3})[0],
        "glossy": shader_material("glossy", "ShaderNodeBsdfGlossy", **{
            "Color": (0.5, 0.5, 0.5, 1), "Roughness": 0.1})[0],
        "metallic": shader_material("metallic", "ShaderNodeBsdfMetallic", **{
            "Base Color": (0.95, 0.64, 0.54, 1), "Edge Tint": (0.99, 0.98, 0.9, 1),
            "Roughness": 0.3})[0],
        "glass": shader_material("glass", "ShaderNodeBsdfGlass", **{
            "Color": (1, 1, 1, 1), "Roughness": 0.05, "IOR": 1.5})[0],
        "refraction": shader_material("refraction", "ShaderNodeBsdfRefraction", **{
            "IOR": 1.33})[0],
        # the cheaper types have no coat or sheen: these stay principled (difftest D16)
        "p_metal_coat": shader_material("p_metal_coat", "ShaderNodeBsdfPrincipled", **{
            "Metallic": 1.0, "Coat Weight": 0.79})[0],
        "p_level0_sheen": shader_material("p_level0_sheen", "ShaderNodeBsdfPrincipled", **{
            "Specular IOR Level": 0.0, "Sheen Weight": 1.0})[0],
    }
    for k, (name, mat) in enumerate(mats.items()):
        add_plane(empty, material=mat, location=(3 * k, 0, 0), name=name)
    scene, report = export(addon)
    got = {m["name"]: m for m in scene.materials}
    assert got["p_metal"]["type"] == "conductor"
    assert got["p_metal"]["base_color"] == pytest.approx([0.9, 0.6, 0.3])
    assert got["p_metal"]["specular_tint"] == pytest.approx([1.0, 0.9, 0.8])
    assert got["p_metal"]["roughness"] == pytest.approx(0.2)
    assert got["p_glass"]["type"] == "principled" and got["p_glass"]["ior"] == pytest.approx(1.45)
    assert got["p_glass"]["roughness"] == 0.0 and got["p_glass"]["transmission"] == 1.0
    assert got["p_mixed"]["type"] == "principled"
    assert got["p_mixed"]["metallic"] == pytest.approx(0.3)
    assert got["p_mixed"]["specular_level"] == pytest.approx(0.5)
    assert got["glossy"]["type"] == "conductor"   # constant reflectance: F = 1 times Color
    assert got["glossy"]["base_color"] == pytest.approx([0.5] * 3)
    assert got["glossy"]["eta"] == [0.0] * 3 and got["glossy"]["k"] == [1.0] * 3
    assert got["metallic"]["type"] == "conductor"
    assert got["metallic"]["specular_tint"] == pytest.approx([0.99, 0.98, 0.9])
    assert got["glass"]["type"] == "dielectric" and got["glass"]["roughness"] == pytest.approx(0.05)
    assert got["refraction"]["type"] == "dielectric" and got["refraction"]["ior"] == pytest.approx(1.33)
    assert any("refraction" in m and "Refraction" in m for m in report.messages)
    assert got["glass"]["tint_reflection"] and not got["refraction"]["tint_reflection"]
    assert got["p_metal_coat"]["type"] == "principled"
    assert got["p_metal_coat"]["metallic"] == 1.0
    assert got["p_metal_coat"]["coat_weight"] == pytest.approx(0.79)
    assert got["p_level0_sheen"]["type"] == "principled"
    assert got["p_level0_sheen"]["sheen_weight"] == pytest.approx(1.0)
