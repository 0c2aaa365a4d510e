"""The differential tester's fifth batch of features (tools/difftest_features5.py,
docs/difftest.md): drawn from a stream of its own, so a full case changes only where it gains a
tag; what it draws reaches Blender (a parent Empty that moves the child, the shutter's Position,
Motion Steps, Subsurface IOR); the shrinker takes each off. No render: bpy's data only.
(test_difftest.py checks, besides, that every tag is drawn within 300 seeds and exports without
a warning.)"""

import difftest_batch as batch
import difftest_features5 as f5  # (difftest_batch puts tools/ on the path)


def test_earlier_cases_draw_as_before(monkeypatch):
    """With the batch's draw a no-op (the generator before it), each of 60 full seeds draws
    the same case, or one with a tag it did not have; some draw the same, some gain one
    (the control that the comparison sees the batch)."""
    same, gained = batch.draws_as_before(monkeypatch, f5)
    assert same >= 15 and gained >= 15, (same, gained)


def test_parent_position_steps_reach_blender():
    """A parented mesh moves with its Empty over the shutter and sits where the case put it at
    frame 1; the Position and the Motion Steps are set; the Subsurface IOR reaches its
    socket."""
    import bpy
    import difftest_build as db
    case = batch.case_with({"parented motion", "shutter position", "motion steps"})
    db.build(case)
    sc = bpy.context.scene
    assert sc.render.motion_blur_position == case["shutter_position"]
    i = next(i for i, o in enumerate(case["objects"]) if "parent" in o)
    ob = next(o for o in bpy.data.objects if o.parent is not None)
    assert ob.name == f"{case['objects'][i]['kind']}{i}"
    where = {}
    for f in (0, 1, 2):
        sc.frame_set(f)
        where[f] = ob.matrix_world.translation.copy()
    assert (where[1] - type(where[1])(case["objects"][i]["location"])).length < 1e-4
    assert (where[0] - where[2]).length > 1e-3, "the child does not move with its parent"
    steps = [o.cycles.motion_steps for o in bpy.data.objects] + [sc.camera.cycles.motion_steps]
    assert max(steps) in (2, 3)
    case = batch.case_with({"subsurface ior"})
    db.build(case)
    want = [n["inputs"]["Subsurface IOR"] for g in case["materials"].values()
            for n in g["nodes"].values() if "Subsurface IOR" in n.get("inputs", {})]
    got = [s.default_value for m in bpy.data.materials if m.node_tree
           for n in m.node_tree.nodes if n.type == "BSDF_PRINCIPLED"
           for s in n.inputs if s.name == "Subsurface IOR"]
    assert want and all(any(abs(w - g) < 1e-5 for g in got) for w in want), (want, got)


def test_shrinker_takes_them_off():
    """Each of the batch's motion knobs has a shrink edit whose case no longer has its tag."""
    batch.assert_shrinker_takes_off(("parented motion", "shutter position", "motion steps",
                                     "camera rotation"))
