"""The differential tester's sixth batch of features (tools/difftest_features6.py,
docs/difftest.md): drawn from a stream of its own, so a full case changes only where it gains a
tag; what it draws reaches Blender (an object's Diffuse / Glossy / Transmission / Volume Scatter
ray visibility and its Shadow, a lamp's ray visibility) and the add-on's export (the mesh and
light fields off); the shrinker takes each off. No render: bpy's data and the export only."""

import copy
import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import difftest_features as df  # noqa: E402
import difftest_features6 as f6  # noqa: E402
import difftest_scene as ds  # noqa: E402


def test_earlier_cases_draw_as_before(monkeypatch):
    """With the batch's draw a no-op (the generator before it), each of 60 full seeds draws
    the same case, or one with a tag of this batch it did not have; some draw the same, some
    gain one (the control that the comparison sees the batch)."""
    new = {s: ds.generate(s, "full") for s in range(60)}
    monkeypatch.setattr(f6, "draw", lambda key, case, *a: case)
    same = gained = 0
    for s in range(60):
        old = ds.generate(s, "full")
        if json.dumps(old, sort_keys=True) == json.dumps(new[s], sort_keys=True):
            same += 1
        else:
            assert (df.features(new[s]) - df.features(old)) & set(f6.FEATURES), s
            gained += 1
    assert same >= 15 and gained >= 10, (same, gained)
    assert not any(f6.features(ds.generate(s, "ci")) for s in range(20))


def _case_with(tags, seeds=range(20000, 20400)):
    for s in seeds:
        case = ds.generate(s, "full")
        if set(tags) <= df.features(case):
            return case
    raise AssertionError(f"no seed draws {tags}")


def test_visibility_reaches_blender_and_export():
    """The hidden kinds and the Shadow reach the bpy objects, and the add-on exports them as
    the mesh's and the light's fields off (the meshes and lights without them: none)."""
    import bpy
    import difftest
    import difftest_build as db
    case = _case_with({"object ray visibility", "lamp ray visibility"})
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
    case = _case_with({"object no shadow"})
    db.build(case)
    want = {f"{o['kind']}{i}" for i, o in enumerate(case["objects"])
            if o.get("cast_shadow") is False}
    assert want == {ob.name for ob in bpy.data.objects
                    if ob.type == "MESH" and not ob.visible_shadow}
    scene, _ = difftest.export_lantern()
    assert want == {m["name"] for m in scene.meshes if m.get("cast_shadow") is False}


def test_shrinker_takes_them_off():
    """Each of the batch's tags has a shrink edit whose case no longer has it."""
    for tag in ("object ray visibility", "lamp ray visibility", "object no shadow"):
        case = _case_with({tag})
        edits = [c for _, c in df.shrink_edits(copy.deepcopy(case))]
        assert any(tag not in df.features(c) for c in edits), tag
