"""The export of a node graph on a Volume object's Density (addon/export/volume_objects.py,
docs/volumes.md "Node graphs on volume inputs"): a "density" program whose grid reads (kOpGrid)
name the scene's grids (the object's file's, each added once), a grid the file lacks reading
-1 (0, Cycles' missing attribute) with a warning by name; Volume Scatter's layout grid is the
first grid the graph reads, Principled Volume's its Density Attribute grid, which the program
multiplies by; a lone Attribute node keeps the older path (no program); a graph on Emission
Strength a "volume_emission" program, its colour factor the flame's (a lone Attribute the flame
grid, as before)."""

import os

import bpy
import numpy as np
import pytest

import lantern

from test_bl_volume_objects import _fire_vdb, _material, _smoke, _volume_object, export

pytestmark = pytest.mark.skipif(not lantern.vdb_available(), reason="built without OpenVDB")

OP_GRID = 29     # kOpGrid (native/src/scene/material_program_ops.h)
OP_MATH = 2


def _graph(v, names, socket="Density"):
    """Attribute names[0] (Fac) x 2 (+ Attribute names[1]) -> v's socket."""
    nt = v.id_data
    a = nt.nodes.new("ShaderNodeAttribute")
    a.attribute_name = names[0]
    mul = nt.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    mul.inputs[1].default_value = 2.0
    nt.links.new(a.outputs["Fac"], mul.inputs[0])
    out = mul
    if len(names) > 1:
        b = nt.nodes.new("ShaderNodeAttribute")
        b.attribute_name = names[1]
        add = nt.nodes.new("ShaderNodeMath")
        add.operation = "ADD"
        nt.links.new(mul.outputs[0], add.inputs[0])
        nt.links.new(b.outputs["Fac"], add.inputs[1])
        out = add
    nt.links.new(out.outputs[0], v.inputs[socket])


def _grid_reads(prog, scene):
    """The scene grid names (or None for -1) the program's kOpGrid instructions read."""
    out = []
    for w in prog["code"]:
        if w[0] & 0xFF == OP_GRID:
            k = w[2] if w[2] < 2 ** 31 else w[2] - 2 ** 32
            out.append(None if k < 0 else scene.grids[k]["name"].split(":")[-1])
    return out


def test_scatter_graph_reads_its_grids(empty, addon, tmp_path):
    path = _fire_vdb(tmp_path)
    mat, v = _material("scatter")
    nt = mat.node_tree
    nt.links.remove(v.inputs["Density"].links[0])
    _graph(v, ["flame", "ghost"])
    _volume_object(empty, path, mat)
    scene, report = export(addon)
    m, _, layout = _smoke(scene)
    progs = m.get("programs") or []
    assert [p["target"] for p in progs] == ["density"]
    assert layout["name"].endswith(":flame")        # the first grid the graph reads
    assert sorted(_grid_reads(progs[0], scene), key=str) == sorted(["flame", None], key=str)
    ghost = [x for x in report.messages if "ghost" in x]
    assert len(ghost) == 1, report.messages
    assert not [x for x in report.messages if "is not rendered (" in x and "Density" in x]


def test_principled_graph_multiplies_by_its_density_attribute(empty, addon, tmp_path):
    path = _fire_vdb(tmp_path)
    mat, v = _material("principled")
    _graph(v, ["flame"])
    _volume_object(empty, path, mat)
    scene, report = export(addon)
    assert not [x for x in report.messages if "Smoke" in x], report.messages
    m, _, layout = _smoke(scene)
    prog = m["programs"][0]
    assert layout["name"].endswith(":density")
    assert sorted(_grid_reads(prog, scene)) == ["density", "flame"]
    # two multiplies: the graph's x 2 and the Density Attribute's grid
    assert sum(1 for w in prog["code"] if w[0] & 0xFF == OP_MATH and (w[0] >> 8) & 0xFF == 2) == 2
    # the program renders: the grids' values through the bindings' scene
    assert len({g["name"] for g in scene.grids}) == len(scene.grids)


def test_lone_attribute_keeps_the_grid_path(empty, addon, tmp_path):
    path = _fire_vdb(tmp_path)
    mat, _ = _material("scatter")    # Attribute "density" straight into Density
    _volume_object(empty, path, mat)
    scene, report = export(addon)
    m, _, layout = _smoke(scene)
    assert not m.get("programs") and layout["name"].endswith(":density")


def test_emission_strength_graph_is_a_program(empty, addon, tmp_path):
    path = _fire_vdb(tmp_path)
    mat, v = _material("principled")
    v.inputs["Emission Color"].default_value = (1.0, 0.5, 0.25, 1)
    nt = mat.node_tree
    a = nt.nodes.new("ShaderNodeAttribute")
    a.attribute_name = "flame"
    mr = nt.nodes.new("ShaderNodeMapRange")
    nt.links.new(a.outputs["Fac"], mr.inputs["Value"])
    nt.links.new(mr.outputs["Result"], v.inputs["Emission Strength"])
    _volume_object(empty, path, mat)
    scene, report = export(addon)
    assert not [x for x in report.messages if "Smoke" in x], report.messages
    m, _, layout = _smoke(scene)
    progs = {p["target"]: p for p in m["programs"]}
    assert list(progs) == ["volume_emission"] and layout["name"].endswith(":density")
    assert _grid_reads(progs["volume_emission"], scene) == ["flame"]
    assert m.get("flame_grid") is None
    assert np.allclose(m["volume"]["flame_emission"], [1.0, 0.5, 0.25])
    # control: the lone Attribute node keeps the flame grid (no program)
    nt.links.new(a.outputs["Fac"], v.inputs["Emission Strength"])
    scene, _ = export(addon)
    m, _, _ = _smoke(scene)
    assert not m.get("programs") and m.get("flame_grid") is not None


def _two_extents_vdb(tmp_path):
    """density: a 4 x 3 x 2 block of 0.1 m voxels; heat: 3^3 voxels of 0.5 m about it."""
    import lantern._core as core
    path = os.path.join(str(tmp_path), "extents.vdb")
    dens = np.arange(24, dtype=np.float32).reshape(2, 3, 4) + 1.0   # nz, ny, nx

    def cube(v, lo):
        return np.array([[v, 0, 0, lo], [0, v, 0, lo], [0, 0, v, lo], [0, 0, 0, 1]], np.float64)
    core.vdb_write_list(path, [
        {"name": "density", "voxels": dens, "index_to_object": cube(0.1, 0.0)},
        {"name": "heat", "voxels": np.ones((3, 3, 3), np.float32),
         "index_to_object": cube(0.5, -0.6)}])
    return path, dens


def test_medium_spans_every_grid_its_graph_reads(empty, addon, tmp_path):
    """D45 (docs/difftest.md): Principled Volume, Density Attribute cleared, density + heat on
    Density: the box and the layout block cover heat's support too (Cycles' volume mesh covers
    the active voxels of each grid the shader reads); the density voxels keep their places.
    Control: density alone keeps its own block."""
    path, dens = _two_extents_vdb(tmp_path)
    mat, v = _material("principled")
    v.inputs["Density Attribute"].default_value = ""
    _graph(v, ["density", "heat"])
    obj = _volume_object(empty, path, mat)
    scene, report = export(addon)
    assert not [x for x in report.messages if "Smoke" in x], report.messages
    m, mesh, layout = _smoke(scene)
    assert layout["name"].endswith(":density")
    world = np.array(obj.matrix_world, np.float64)
    heat_lo = world @ np.array([-0.6 - 0.5, -0.6 - 0.5, -0.6 - 0.5, 1.0])
    heat_hi = world @ np.array([-0.6 + 3 * 0.5] * 3 + [1.0])
    pos = np.asarray(mesh["positions"], np.float64)
    assert (pos.min(axis=0) <= heat_lo[:3] + 1e-5).all(), (pos.min(axis=0), heat_lo)
    assert (pos.max(axis=0) >= heat_hi[:3] - 1e-5).all(), (pos.max(axis=0), heat_hi)
    vox = np.asarray(layout["voxels"])
    assert vox.size > dens.size and np.isclose(vox.sum(), dens.sum())
    # voxel (i, j, k) of the grown block sits where the density grid's index says
    to_world = np.asarray(layout["index_to_world"], np.float64)
    k, j, i = np.argwhere(vox == dens.max())[0]
    assert np.allclose(to_world @ [i, j, k, 1.0], world @ [0.3, 0.2, 0.1, 1.0], atol=1e-6)
    # control: the density alone, no block grows
    nt = mat.node_tree
    nt.links.new(nt.nodes["Attribute"].outputs["Fac"], v.inputs["Density"])
    scene, _ = export(addon)
    _, mesh, layout = _smoke(scene)
    assert np.array_equal(np.asarray(layout["voxels"]), dens)
