"""The differential tester's sixth batch of features (tools/difftest_features6.py,
docs/difftest.md): drawn from a stream of its own, so a full case changes only where it gains a
tag; what it draws reaches Blender (an object's Diffuse / Glossy / Transmission / Volume Scatter
ray visibility and its Shadow, a lamp's ray visibility) and the add-on's export (the mesh and
light fields off); the shrinker takes each off. No render: bpy's data and the export only."""

import difftest_batch as batch
import difftest_features6 as f6  # (difftest_batch puts tools/ on the path)
import difftest_scene as ds


def test_earlier_cases_draw_as_before(monkeypatch):
    """With the batch's draw a no-op (the generator before it), each of 60 full seeds draws
    the same case, or one with a tag of this batch it did not have; some draw the same, some
    gain one (the control that the comparison sees the batch)."""
    same, gained = batch.draws_as_before(monkeypatch, f6, gained_tags=f6.FEATURES)
    assert same >= 15 and gained >= 10, (same, gained)
    assert not any(f6.features(ds.generate(s, "ci")) for s in range(20))


def test_visibility_reaches_blender_and_export():
    """The hidden kinds and the Shadow reach the bpy objects, and the add-on exports them as
    the mesh's and the light's fields off (the meshes and lights without them: none)."""
    import bpy
    import difftest
    import difftest_build as db
    case = batch.case_with({"object ray visibility", "lamp ray visibility"})
    db.build(case)
    scene, _ = difftest.export_lantern()
    fields = [f"visible_{k}" for k in f6.RAY_KINDS]
    got = {m["name"]: {k for k in fields if m.get(k) is False}
           for m in list(scene.meshes) + list(scene.lights)}
    want = {f"{o['kind']}{i}": {f"visible_{k}" for k in o.get("rays_off", ())}
            for i, o in enumerate(case["objects"]) if o["kind"] in f6.MESHES}
    want.update({f"{lt['type'].lower()}{i}": {f"visible_{k}" for k in lt.get("rays_off", ())}
                 for i, lt in enumerate(case["lights"])})
    assert {k: v for k, v in got.items() if k in want} == want, (got, want)
    assert sum(bool(v) for v in want.values()) >= 2
    case = batch.case_with({"object no shadow"})
    db.build(case)
    want = {f"{o['kind']}{i}" for i, o in enumerate(case["objects"])
            if o.get("cast_shadow") is False}
    assert want == {ob.name for ob in bpy.data.objects
                    if ob.type == "MESH" and not ob.visible_shadow}
    scene, _ = difftest.export_lantern()
    assert want == {m["name"] for m in scene.meshes if m.get("cast_shadow") is False}


def test_shrinker_takes_them_off():
    """Each of the batch's tags has a shrink edit whose case no longer has it."""
    batch.assert_shrinker_takes_off(("object ray visibility", "lamp ray visibility",
                                     "object no shadow"))
