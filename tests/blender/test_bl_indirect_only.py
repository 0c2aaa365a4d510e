"""Export of Indirect Only collections (addon/export/visibility.py camera_visible): as Cycles'
object sync, an object whose instancer (itself when it is no instance) is Indirect Only in the
view layer loses Camera ray visibility only (its other ray flags and Cast Shadow stay); a
holdout keeps it; an instance of a collection follows its instancer, not the source's flags.
Pixels against Cycles: tests/cycles/test_indirect_only.py."""

import bpy
import pytest


def export(addon):
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    return scene, report


def _cube(name, collection, location=(0, 0, 0)):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    obj = bpy.data.objects.new(name, mesh)
    collection.objects.link(obj)
    obj.location = location
    return obj


def _collection(scene, name):
    col = bpy.data.collections.new(name)
    scene.collection.children.link(col)
    return col, bpy.context.view_layer.layer_collection.children[name]


def _meshes(scene):
    return {m["name"]: m for m in scene.meshes}


@pytest.mark.parametrize("indirect", [True, False])
def test_indirect_only_clears_camera_only(addon, empty, indirect):
    col, lc = _collection(empty, "Bounce")
    _cube("Inside", col)
    _cube("Outside", empty.collection, (3, 0, 0))
    lc.indirect_only = indirect
    scene, report = export(addon)
    by = _meshes(scene)
    assert by["Inside"]["visible_camera"] is (not indirect)  # the control: False only if set
    assert by["Outside"]["visible_camera"] is True
    for m in by.values():  # no other ray kind changes
        assert m["cast_shadow"] is True
        assert not [k for k in m if k.startswith("visible_") and k != "visible_camera"], m
    assert not [w for w in report.messages if "Indirect Only" in w], report.messages


def test_holdout_keeps_camera(addon, empty):
    col, lc = _collection(empty, "Bounce")
    obj = _cube("Masked", col)
    lc.indirect_only = True
    obj.is_holdout = True
    scene, _ = export(addon)
    assert _meshes(scene)["Masked"]["visible_camera"] is True
    obj.is_holdout = False
    lc.holdout = True  # the collection's holdout flag too
    scene, _ = export(addon)
    assert _meshes(scene)["Masked"]["visible_camera"] is True
    lc.holdout = False
    scene, _ = export(addon)
    assert _meshes(scene)["Masked"]["visible_camera"] is False


def test_object_camera_flag_still_read(addon, empty):
    _cube("Hidden", empty.collection).visible_camera = False
    scene, _ = export(addon)
    assert _meshes(scene)["Hidden"]["visible_camera"] is False


@pytest.mark.parametrize("indirect", [True, False])
def test_instance_follows_its_instancer(addon, empty, indirect):
    source = bpy.data.collections.new("Source")  # not in the scene: seen only as instances
    _cube("Part", source)
    col, lc = _collection(empty, "Bounce")
    inst = bpy.data.objects.new("Instancer", None)
    inst.instance_type = "COLLECTION"
    inst.instance_collection = source
    col.objects.link(inst)
    lc.indirect_only = indirect
    scene, _ = export(addon)
    parts = [m for n, m in _meshes(scene).items() if "Part" in n]
    assert len(parts) == 1, list(_meshes(scene))
    assert parts[0]["visible_camera"] is (not indirect)
