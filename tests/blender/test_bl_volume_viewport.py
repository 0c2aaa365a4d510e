"""Volume objects in the viewport's incremental export (export/sync.py, docs/volumes.md): the
first sync holds the object's grid and box as a fresh export does; a move places the grid again
(the core refuses to move the box alone: a new session, from the synced scene), and a material
edit converts the volume again; after each, the synced scene's grid, box and coefficients are
those of a fresh export of the edited scene, and differ from before the edit (control)."""

import os

import bpy
import numpy as np
import pytest

import lantern
from test_bl_viewport_sync import _apply, _fresh, _refined, _start, stage  # noqa: F401

pytestmark = [
    pytest.mark.skipif(not lantern.session.native_available(), reason="native core not built"),
    pytest.mark.skipif(not lantern.vdb_available(), reason="built without OpenVDB")]


def _smoke(stage, tmp_path):
    import lantern._core as core
    path = os.path.join(str(tmp_path), "smoke.vdb")
    c = np.linspace(-1, 1, 10)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    vox = np.ascontiguousarray(np.clip(1 - (x * x + y * y + z * z), 0, None).astype(np.float32))
    core.vdb_write(path, "density", vox, np.diag([0.1, 0.1, 0.1, 1.0]))
    mat = bpy.data.materials.new("SmokeMat")
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Density"].default_value = 4.0
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    vol = bpy.data.volumes.new("Smoke")
    vol.filepath = path
    vol.materials.append(mat)
    obj = bpy.data.objects.new("Smoke", vol)
    stage.collection.objects.link(obj)
    obj.location = (-0.5, 0.0, 0.3)
    bpy.context.view_layer.update()
    return obj, v


def _volume(scene):
    mat = next(m for m in scene.materials if m is not None and m.get("density_grid") is not None)
    mesh = next(m for m in scene.meshes if m["name"] == "Smoke")
    return mat, mesh, scene.grids[mat["density_grid"]]


def _same(synced, fresh):
    a, b = _volume(synced), _volume(fresh)
    assert a[0]["volume"] == b[0]["volume"]
    np.testing.assert_allclose(a[1]["positions"], b[1]["positions"], atol=1e-6)
    np.testing.assert_array_equal(a[2]["voxels"], b[2]["voxels"])
    np.testing.assert_allclose(a[2]["index_to_world"], b[2]["index_to_world"], atol=1e-6)
    assert len(synced.grids) == len(fresh.grids) == 1


def test_volume_object_follows_viewport_edits(addon, stage, tmp_path):
    obj, principled = _smoke(stage, tmp_path)
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    _refined(engine, addon, ctx)
    _same(state.sync.scene, _fresh(stage, ctx, stage.lantern))
    before = _fresh(stage, ctx, stage.lantern)
    session = state.session
    image = _apply(addon, engine, ctx, lambda: setattr(obj, "location", (0.4, 0.2, 0.5)))
    assert np.isfinite(image).all()
    assert state.session is not session  # the box does not move alone: a new session
    fresh = _fresh(stage, ctx, stage.lantern)
    _same(state.sync.scene, fresh)
    assert not np.allclose(_volume(before)[2]["index_to_world"],
                           _volume(fresh)[2]["index_to_world"])   # control: it moved
    image = _apply(addon, engine, ctx,
                   lambda: setattr(principled.inputs["Density"], "default_value", 9.0))
    fresh = _fresh(stage, ctx, stage.lantern)
    _same(state.sync.scene, fresh)
    assert _volume(fresh)[0]["volume"]["sigma_s"][0] == pytest.approx(0.5 * 9.0)
    state.free()


def test_fire_grids_follow_viewport_edits(addon, stage, tmp_path):
    """A fire's temperature grid is synced as a fresh export holds it, and a Temperature edit
    reaches the synced medium (the value before the edit as control)."""
    import lantern._core as core
    obj, principled = _smoke(stage, tmp_path)
    path = os.path.join(str(tmp_path), "fire.vdb")
    c = np.linspace(-1, 1, 10)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    dens = np.ascontiguousarray(np.clip(1 - (x * x + y * y + z * z), 0, None).astype(np.float32))
    temp = np.ascontiguousarray((dens * 2.0 + 0.5 * (dens > 0)).astype(np.float32))
    core.vdb_write_grids(path, [("density", dens), ("temperature", temp)],
                         np.diag([0.1, 0.1, 0.1, 1.0]))
    obj.data.filepath = path
    principled.inputs["Blackbody Intensity"].default_value = 1.0
    principled.inputs["Temperature"].default_value = 1500.0
    bpy.context.view_layer.update()
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    _refined(engine, addon, ctx)
    synced, fresh = state.sync.scene, _fresh(stage, ctx, stage.lantern)
    for sc in (synced, fresh):
        mat = _volume(sc)[0]
        assert sc.grids[mat["temperature_grid"]]["name"].endswith(":temperature")
    a, b = _volume(synced)[0], _volume(fresh)[0]
    assert a["volume"] == b["volume"] and a["volume"]["temperature"] == pytest.approx(1500.0)
    np.testing.assert_array_equal(synced.grids[a["temperature_grid"]]["voxels"],
                                  fresh.grids[b["temperature_grid"]]["voxels"])
    image = _apply(addon, engine, ctx,
                   lambda: setattr(principled.inputs["Temperature"], "default_value", 2500.0))
    assert np.isfinite(image).all()
    a, b = _volume(state.sync.scene)[0], _volume(_fresh(stage, ctx, stage.lantern))[0]
    assert a["volume"] == b["volume"] and a["volume"]["temperature"] == pytest.approx(2500.0)
    state.free()


def test_volume_texture_coordinates_follow_the_viewport(addon, stage, tmp_path):
    """Object coordinates in a Volume object's density graph (volrules): the synced box carries
    the channel a fresh export gives it, the object-space position of each vertex (the world
    positions as control: they differ, the object is moved)."""
    obj, principled = _smoke(stage, tmp_path)
    nt = principled.id_data
    tc = nt.nodes.new("ShaderNodeTexCoord")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    add = nt.nodes.new("ShaderNodeMath")
    add.operation = "ADD"
    add.inputs[1].default_value = 1.0
    nt.links.new(tc.outputs["Object"], sep.inputs["Vector"])
    nt.links.new(sep.outputs["X"], add.inputs[0])
    nt.links.new(add.outputs[0], principled.inputs["Density"])
    bpy.context.view_layer.update()
    engine, ctx = _start(addon, stage)
    state = engine._lantern
    _refined(engine, addon, ctx)
    fresh = _fresh(stage, ctx, stage.lantern)
    synced = state.sync.scene
    a = next(m for m in synced.meshes if m["name"] == "Smoke")
    b = next(m for m in fresh.meshes if m["name"] == "Smoke")
    k = 3 * fresh.attribute_channels.index("object")
    np.testing.assert_allclose(a["attributes"], b["attributes"], atol=1e-6)
    world = np.asarray(b["positions"], np.float64)
    m = np.array(obj.matrix_world, np.float64)
    local = (np.c_[world, np.ones(len(world))] @ np.linalg.inv(m).T)[:, :3]
    np.testing.assert_allclose(b["attributes"][:, k:k + 3], local, atol=1e-5)
    assert not np.allclose(b["attributes"][:, k:k + 3], world, atol=1e-3)
    state.free()
