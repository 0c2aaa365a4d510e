"""Export of Volume objects (addon/export/volume_objects.py, docs/volumes.md): the grid read from
the object's file and placed by the grid's transform times the object's matrix, the box over its
trilinear support, the material's coefficients per unit of the grid (Principled Volume's Density
times its Density Attribute grid; Volume Scatter whose Density is an Attribute node), Cycles'
object-space density (Render Space "Object" divides by the scale along the diagonal, "World"
does not), a material reading a grid the file lacks (a warning by name, not rendered), and
Principled Volume's Color Attribute (the colour grid and its coefficients; a float grid as the
colour, a vec3 grid as the density)."""

import math
import os

import bpy
import numpy as np
import pytest

import lantern

pytestmark = pytest.mark.skipif(not lantern.vdb_available(), reason="built without OpenVDB")

VOXEL = 0.1


def export(addon):
    from lantern_blender.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get())


def _vdb(tmp_path):
    import lantern._core as core
    path = os.path.join(str(tmp_path), "smoke.vdb")
    vox = np.zeros((4, 5, 6), np.float32)   # nz, ny, nx
    vox[1:3, 1:4, 1:5] = np.arange(24, dtype=np.float32).reshape(2, 3, 4) + 1.0
    m = np.array([[VOXEL, 0, 0, 1.0], [0, VOXEL, 0, 0], [0, 0, VOXEL, 0], [0, 0, 0, 1]])
    core.vdb_write(path, "density", vox, m)
    return path, vox[1:3, 1:4, 1:5]


def _volume_object(empty, path, material=None, scale=(1, 1, 1), rot_z=0.0):
    vol = bpy.data.volumes.new("Smoke")
    vol.filepath = path
    if material is not None:
        vol.materials.append(material)
    obj = bpy.data.objects.new("Smoke", vol)
    empty.collection.objects.link(obj)
    obj.location = (0.5, -0.25, 2.0)
    obj.scale = scale
    obj.rotation_euler = (0, 0, rot_z)
    return obj


def _material(kind):
    mat = bpy.data.materials.new(kind)
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    out = nt.nodes["Material Output"]
    if kind == "principled":
        v = nt.nodes.new("ShaderNodeVolumePrincipled")
        v.inputs["Density"].default_value = 3.0
        v.inputs["Color"].default_value = (0.5, 0.6, 0.7, 1)
    else:
        v = nt.nodes.new("ShaderNodeVolumeScatter")
        v.inputs["Color"].default_value = (0.2, 0.4, 0.8, 1)
        v.inputs["Density"].default_value = 7.0   # linked: the socket's value is not used
        a = nt.nodes.new("ShaderNodeAttribute")
        a.attribute_name = "density"
        nt.links.new(a.outputs["Fac"], v.inputs["Density"])
    nt.links.new(v.outputs[0], out.inputs["Volume"])
    return mat, v


def _smoke(scene):
    mat = next(m for m in scene.materials if m.get("density_grid") is not None)
    mesh = next(m for m in scene.meshes if m["name"] == "Smoke")
    return mat, mesh, scene.grids[mat["density_grid"]]


def test_grid_is_placed_by_its_transform_and_the_objects(empty, addon, tmp_path):
    path, block = _vdb(tmp_path)
    mat, _ = _material("principled")
    obj = _volume_object(empty, path, mat, scale=(1.5, 1.5, 1.5), rot_z=math.radians(30))
    scene, report = export(addon)
    assert not [m for m in report.messages if "Smoke" in m], report.messages
    m, mesh, grid = _smoke(scene)
    assert np.array_equal(grid["voxels"], block)
    # block voxel (0, 0, 0) is the grid's index (1, 1, 1): object (1.1, 0.1, 0.1)
    want = np.array(obj.matrix_world) @ [1.0 + VOXEL, VOXEL, VOXEL, 1.0]
    assert np.allclose(grid["index_to_world"] @ [0, 0, 0, 1], want, atol=1e-5)
    want = np.array(obj.matrix_world) @ [1.0 + 3 * VOXEL, 2 * VOXEL, 3 * VOXEL, 1.0]
    assert np.allclose(grid["index_to_world"] @ [2, 1, 2, 1], want, atol=1e-5)
    # the box: the block's support [-1, n] per axis in the world, 12 triangles
    corners = np.linalg.inv(grid["index_to_world"].astype(np.float64)) @ \
        np.c_[mesh["positions"], np.ones(8)].T
    assert np.allclose(corners[:3].min(axis=1), [-1, -1, -1], atol=1e-4)
    assert np.allclose(corners[:3].max(axis=1), [4, 3, 2], atol=1e-4)
    assert len(mesh["indices"]) == 12 and m["volume_only"]
    # Principled Volume: scattering Color x Density per unit of the grid, divided by the
    # object-space factor |R S (1, 1, 1) / sqrt 3| = 1.5
    assert np.allclose(m["volume"]["sigma_s"], np.array([0.5, 0.6, 0.7]) * 3.0 / 1.5)


def test_attribute_node_on_density_and_render_space(empty, addon, tmp_path):
    path, _ = _vdb(tmp_path)
    mat, _ = _material("scatter")
    obj = _volume_object(empty, path, mat, scale=(2.0, 1.0, 0.5))
    scene, report = export(addon)
    assert not [m for m in report.messages if "Smoke" in m], report.messages
    m, _, _ = _smoke(scene)
    k = math.sqrt((4.0 + 1.0 + 0.25) / 3.0)   # the scale along the unit diagonal
    assert np.allclose(m["volume"]["sigma_s"], np.array([0.2, 0.4, 0.8]) / k)
    obj.data.render.space = "WORLD"   # the grid's values as they are (control)
    scene, _ = export(addon)
    m, _, _ = _smoke(scene)
    assert np.allclose(m["volume"]["sigma_s"], [0.2, 0.4, 0.8])


def test_a_grid_the_file_lacks_is_named(empty, addon, tmp_path):
    path, _ = _vdb(tmp_path)
    mat, v = _material("principled")
    v.inputs["Density Attribute"].default_value = "smoke"
    _volume_object(empty, path, mat)
    scene, report = export(addon)
    assert not scene.grids and not [m for m in scene.meshes if m["name"] == "Smoke"]
    hits = [m for m in report.messages if "Smoke" in m and "no grid named 'smoke'" in m]
    assert len(hits) == 1, report.messages


def _fire_vdb(tmp_path, names=("density", "temperature", "flame")):
    import lantern._core as core
    path = os.path.join(str(tmp_path), "fire.vdb")
    vox = np.zeros((4, 5, 6), np.float32)
    vox[1:3, 1:4, 1:5] = 1.0
    grids = [(n, np.ascontiguousarray(vox * (k + 1))) for k, n in enumerate(names)]
    m = np.array([[VOXEL, 0, 0, 1.0], [0, VOXEL, 0, 0], [0, 0, VOXEL, 0], [0, 0, 0, 1]])
    core.vdb_write_grids(path, grids, m)
    return path


def _fire_material():
    """Principled Volume with Blackbody (Temperature 1200 x the "temperature" grid) and an
    Attribute "flame" x 3 on Emission Strength (Blender's fire setup)."""
    mat, v = _material("principled")
    nt = mat.node_tree
    v.inputs["Blackbody Intensity"].default_value = 0.8
    v.inputs["Temperature"].default_value = 1200.0
    v.inputs["Blackbody Tint"].default_value = (1.0, 0.5, 0.25, 1)
    v.inputs["Emission Color"].default_value = (1.0, 0.4, 0.1, 1)
    a = nt.nodes.new("ShaderNodeAttribute")
    a.attribute_name = "flame"
    mul = nt.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    mul.inputs[1].default_value = 3.0
    nt.links.new(a.outputs["Fac"], mul.inputs[0])
    nt.links.new(mul.outputs[0], v.inputs["Emission Strength"])
    return mat, v


def test_fire_grids_are_exported_with_their_parameters(empty, addon, tmp_path):
    path = _fire_vdb(tmp_path)
    mat, _ = _fire_material()
    _volume_object(empty, path, mat)
    scene, report = export(addon)
    assert not [m for m in report.messages if "Smoke" in m], report.messages
    m, _, grid = _smoke(scene)
    t, f = scene.grids[m["temperature_grid"]], scene.grids[m["flame_grid"]]
    assert t["name"].endswith(":temperature") and f["name"].endswith(":flame")
    assert np.allclose(t["voxels"], 2.0) and np.allclose(f["voxels"], 3.0)
    assert np.allclose(t["index_to_world"], grid["index_to_world"])
    vol = m["volume"]
    assert vol["blackbody_intensity"] == pytest.approx(0.8)
    assert vol["temperature"] == pytest.approx(1200.0)
    assert np.allclose(vol["blackbody_tint"], [1.0, 0.5, 0.25])
    assert np.allclose(vol["flame_emission"], [3.0, 1.2, 0.3])
    # the blackbody is per point now: no constant blackbody or socket strength in "emission"
    assert np.allclose(vol["emission"], 0.0)
    # control: without the temperature grid named, the constant blackbody of the socket's T
    mat.node_tree.nodes["Principled Volume"].inputs["Temperature Attribute"].default_value = ""
    scene, _ = export(addon)
    m, _, _ = _smoke(scene)
    assert m.get("temperature_grid") is None and max(m["volume"]["emission"]) > 0.0


def test_fire_grids_the_file_lacks_are_named(empty, addon, tmp_path):
    path = _fire_vdb(tmp_path, names=("density",))
    mat, _ = _fire_material()
    _volume_object(empty, path, mat)
    scene, report = export(addon)
    m, _, _ = _smoke(scene)
    assert m.get("temperature_grid") is None and m.get("flame_grid") is None
    said = " ".join(report.messages)
    assert "'temperature' (Temperature Attribute) is not in the object's file" in said, said
    assert "'flame' on its emission strength is not in the object's file" in said, said
    # as Cycles: the socket's temperature everywhere, no flame emission
    assert max(m["volume"]["emission"]) > 0.0


def test_fire_emission_follows_the_object_space_density(empty, addon, tmp_path):
    """Render Space "Object": Cycles divides the emission (blackbody, flame) by the scale along
    the diagonal as it does the density; "World" keeps it (control)."""
    path = _fire_vdb(tmp_path)
    mat, _ = _fire_material()
    obj = _volume_object(empty, path, mat, scale=(1.0, 1.0, 1.3))
    k = math.sqrt((1.0 + 1.0 + 1.69) / 3.0)
    scene, _ = export(addon)
    vol = _smoke(scene)[0]["volume"]
    assert np.allclose(vol["flame_emission"], np.array([3.0, 1.2, 0.3]) / k)
    assert np.allclose(vol["blackbody_tint"], np.array([1.0, 0.5, 0.25]) / k)
    obj.data.render.space = "WORLD"
    scene, _ = export(addon)
    vol = _smoke(scene)[0]["volume"]
    assert np.allclose(vol["flame_emission"], [3.0, 1.2, 0.3])


def _colour_vdb(tmp_path, colour_as_float=False):
    """density and a vec3 "color" grid (a float one with colour_as_float) of one transform."""
    import lantern._core as core
    path = os.path.join(str(tmp_path), "colour.vdb")
    m = np.array([[VOXEL, 0, 0, 1.0], [0, VOXEL, 0, 0], [0, 0, VOXEL, 0], [0, 0, 0, 1]])
    den = np.ones((3, 3, 3), np.float32)
    col = np.zeros((3, 3, 3, 3), np.float32)
    col[..., 0], col[..., 1], col[..., 2] = 0.25, 0.5, 1.0
    core.vdb_write_list(path, [
        {"name": "density", "voxels": den, "index_to_object": m},
        {"name": "color", "voxels": col[..., 1].copy() if colour_as_float else col,
         "index_to_object": m}])
    return path


def test_colour_attribute_exports_the_colour_grid(empty, addon, tmp_path):
    """Principled Volume's Color Attribute naming a vec3 grid: the grid is exported and the
    shader's part of the coefficients moves to color_scatter / color_absorb / color_base
    (Cycles: scattering Color c Density, absorption max(1 - Color c, 0) x max(1 - sqrt(Absorption
    Color), 0) x Density)."""
    mat, v = _material("principled")   # Density 3, Color (0.5, 0.6, 0.7)
    v.inputs["Absorption Color"].default_value = (0.25, 0.25, 0.25, 1)
    v.inputs["Color Attribute"].default_value = "color"
    _volume_object(empty, _colour_vdb(tmp_path), mat)
    scene, report = export(addon)
    assert not [m for m in report.messages if "Smoke" in m], report.messages
    m, _, _ = _smoke(scene)
    g = scene.grids[m["color_grid"]]
    assert g["name"].endswith(":color") and g["voxels"].shape == (3, 3, 3, 3)
    assert np.allclose(g["voxels"][1, 1, 1], [0.25, 0.5, 1.0])
    vol = m["volume"]
    assert np.allclose(vol["color_scatter"], [1.5, 1.8, 2.1])   # Color x Density
    assert np.allclose(vol["color_absorb"], [1.5, 1.5, 1.5])    # (1 - sqrt(0.25)) x Density
    assert np.allclose(vol["color_base"], [0.5, 0.6, 0.7])
    assert np.allclose(vol["sigma_s"], 0.0, atol=1e-6) and np.allclose(vol["sigma_a"], 0.0,
                                                                       atol=1e-6)
    # control: the attribute cleared, the socket's own coefficients and no colour grid
    v.inputs["Color Attribute"].default_value = ""
    scene, _ = export(addon)
    m, _, _ = _smoke(scene)
    assert m.get("color_grid") is None and np.allclose(m["volume"]["sigma_s"], [1.5, 1.8, 2.1])


def test_colour_grid_kinds(empty, addon, tmp_path):
    """A float grid as the Color Attribute reads grey (its value in 3 channels, as Cycles); a
    vec3 grid as the density says so by name and the object does not render."""
    mat, v = _material("principled")
    v.inputs["Color Attribute"].default_value = "color"
    _volume_object(empty, _colour_vdb(tmp_path, colour_as_float=True), mat)
    scene, report = export(addon)
    m, _, _ = _smoke(scene)
    assert np.allclose(scene.grids[m["color_grid"]]["voxels"][0, 0, 0], [0.5, 0.5, 0.5])
    v.inputs["Color Attribute"].default_value = ""
    v.inputs["Density Attribute"].default_value = "color"
    (tmp_path / "vec3").mkdir()
    bpy.data.objects["Smoke"].data.filepath = _colour_vdb(tmp_path / "vec3")
    scene, report = export(addon)
    said = " ".join(report.messages)
    assert "grid 'color' is a vec3 (colour) grid" in said, said
    assert not [m for m in scene.materials if m.get("density_grid") is not None]


@pytest.mark.parametrize("kind", ["VOLUME_SCATTER", "VOLUME_ABSORPTION", "PRINCIPLED_VOLUME"])
def test_attribute_node_on_color_reads_the_colour_grid(empty, addon, tmp_path, kind):
    """An Attribute node's Color on a volume shader's Color: the grid's colour stands for the
    Color (color_base 1), no warning; Volume Scatter scatters c D, Volume Absorption absorbs
    max(1 - c, 0) D, Principled Volume both (Cycles' closures with Color = c). A grid the file
    lacks reads 0: Volume Scatter then scatters nothing, the others absorb D (x A)."""
    mat = bpy.data.materials.new(kind)
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new({"VOLUME_SCATTER": "ShaderNodeVolumeScatter",
                      "VOLUME_ABSORPTION": "ShaderNodeVolumeAbsorption",
                      "PRINCIPLED_VOLUME": "ShaderNodeVolumePrincipled"}[kind])
    v.inputs["Density"].default_value = 2.0
    v.inputs["Color"].default_value = (0.3, 0.3, 0.3, 1)   # linked: not used
    a = nt.nodes.new("ShaderNodeAttribute")
    a.attribute_name = "color"
    nt.links.new(a.outputs["Color"], v.inputs["Color"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    if kind == "PRINCIPLED_VOLUME":
        v.inputs["Absorption Color"].default_value = (0.25, 0.25, 0.25, 1)
    else:   # their density: an Attribute node (per unit of the grid: Density's value unused)
        d = nt.nodes.new("ShaderNodeAttribute")
        d.attribute_name = "density"
        nt.links.new(d.outputs["Fac"], v.inputs["Density"])
    _volume_object(empty, _colour_vdb(tmp_path), mat)
    scene, report = export(addon)
    assert not [m for m in report.messages if "Smoke" in m or "linked" in m], report.messages
    m, _, _ = _smoke(scene)
    assert scene.grids[m["color_grid"]]["voxels"].shape == (3, 3, 3, 3)
    vol = m["volume"]
    want_s = {"VOLUME_SCATTER": 1.0, "VOLUME_ABSORPTION": 0.0, "PRINCIPLED_VOLUME": 2.0}[kind]
    want_a = {"VOLUME_SCATTER": 0.0, "VOLUME_ABSORPTION": 1.0, "PRINCIPLED_VOLUME": 1.0}[kind]
    assert np.allclose(vol["color_scatter"], want_s) and np.allclose(vol["color_absorb"], want_a)
    assert np.allclose(vol["color_base"], 1.0)
    assert np.allclose(vol["sigma_s"], 0.0, atol=1e-6) and np.allclose(vol["sigma_a"], 0.0,
                                                                       atol=1e-6)
    # control: a grid the file lacks reads 0 (Cycles' missing attribute), named in a warning
    a.attribute_name = "nothing"
    scene, report = export(addon)
    assert any("'nothing' on the Color" in msg for msg in report.messages), report.messages
    m, _, _ = _smoke(scene)
    assert m.get("color_grid") is None
    assert np.allclose(m["volume"]["sigma_s"], 0.0, atol=1e-6)
    assert np.allclose(m["volume"]["sigma_a"], want_a)


def test_colour_attribute_times_a_colour_graph(empty, addon, tmp_path):
    """Principled Volume's Color Attribute beside a graph on its Color (issue 29): Cycles
    multiplies the two, so the "volume_color" program ends in the graph's colour times the
    colour grid's (kOpGrid of "color"), no colour grid of the material's own and no warning.
    Control: the Color Attribute naming a grid the file lacks leaves the graph alone (Cycles
    leaves the Color as it is), no kOpGrid of it."""
    from lantern_blender.export.node_ops import OP
    mat, v = _material("principled")
    v.inputs["Color Attribute"].default_value = "color"
    nt = mat.node_tree
    a, ramp = nt.nodes.new("ShaderNodeAttribute"), nt.nodes.new("ShaderNodeValToRGB")
    a.attribute_name = "density"
    nt.links.new(a.outputs["Fac"], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], v.inputs["Color"])
    _volume_object(empty, _colour_vdb(tmp_path), mat)
    scene, report = export(addon)
    assert not [m for m in report.messages if "Smoke" in m], report.messages
    m, _, _ = _smoke(scene)
    assert m.get("color_grid") is None
    prog = next(p for p in m["programs"] if p["target"] == "volume_color")
    grids = [w[2] for w in prog["code"] if w[0] & 0xFF == OP["grid"]]
    assert sorted(scene.grids[g]["name"].split(":")[-1] for g in grids) == ["color", "density"]
    assert np.allclose(m["volume"]["color_scatter"], [3.0] * 3)   # Density x the weight
    v.inputs["Color Attribute"].default_value = "missing"
    scene, report = export(addon)
    m, _, _ = _smoke(scene)
    prog = next(p for p in m["programs"] if p["target"] == "volume_color")
    grids = [w[2] for w in prog["code"] if w[0] & 0xFF == OP["grid"]]
    assert [scene.grids[g]["name"].split(":")[-1] for g in grids] == ["density"]
    assert m.get("color_grid") is None
