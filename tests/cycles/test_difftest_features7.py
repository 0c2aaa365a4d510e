"""The differential tester's seventh batch (tools/difftest_features7.py: a mesh volume that
casts no shadow) and its glossy-caustic guard (tools/difftest_run.py glossy_caustic, D59,
docs/difftest.md): the batch draws from a stream of its own, so a full case changes only where
it gains its tag; the volume's Shadow reaches Blender and the export; the shrinker takes it
off. The guard flags D59's case and not its variants, confirms a flagged case with Cycles at
CAUSTIC_CYCLES_FACTOR x the samples and calls it "not confirmed" only where that agrees. No
render: bpy's data, the export and a stubbed run_case."""

import copy
import json
import os

import pytest

import difftest_batch as batch
import difftest_features7 as f7  # (difftest_batch puts tools/ on the path)
import difftest_scene as ds

CASES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "difftest_cases")


def test_earlier_cases_draw_as_before(monkeypatch):
    """With the batch's draw a no-op, each of 200 full seeds draws the same case or one that
    gains "volume no shadow" (some do: the control); the ci profile draws none of it."""
    same, gained = batch.draws_as_before(monkeypatch, f7, gained_tags=f7.FEATURES,
                                         seeds=range(200))
    assert same >= 150 and gained >= 3, (same, gained)
    assert not any(f7.features(ds.generate(s, "ci")) for s in range(20))


def test_volume_shadow_reaches_blender_and_export():
    """The volume's object has Ray Visibility > Shadow off in bpy, and the add-on exports its
    mesh with cast_shadow False (no other mesh of the case has it)."""
    import bpy
    import difftest
    import difftest_build as db
    case = batch.case_with({"volume no shadow"})
    db.build(case)
    want = {f"{o['kind']}{i}" for i, o in enumerate(case["objects"])
            if o.get("cast_shadow") is False}
    assert want and all(case["objects"][int(n[-1])].get("volume") for n in want)
    assert want == {ob.name for ob in bpy.data.objects
                    if ob.type == "MESH" and not ob.visible_shadow}
    scene, _ = difftest.export_lantern()
    assert want == {m["name"] for m in scene.meshes if m.get("cast_shadow") is False}


def test_shrinker_takes_it_off():
    batch.assert_shrinker_takes_off(("volume no shadow",))


def _d59():
    with open(os.path.join(CASES, "d59_glossy_plane_point_lamp_bidir.json")) as f:
        return json.load(f)["case"]


def test_glossy_caustic_flag():
    """D59's case (a Radius-0 point lamp, a Glossy plane of Roughness 0.34) is flagged; with
    the lamp at Radius 0.2, or the plane at Roughness 0.8, it is not."""
    import difftest_run as dr
    case = _d59()
    assert dr.glossy_caustic(case)
    big = copy.deepcopy(case)
    big["lights"][0]["radius"] = 0.2
    rough = copy.deepcopy(case)
    rough["materials"]["m0"]["nodes"]["n0"]["inputs"]["Roughness"] = 0.8
    assert not dr.glossy_caustic(big) and not dr.glossy_caustic(rough)


@pytest.mark.parametrize("flagged,checked,verdict", [
    (True, "agree", "not confirmed"), (True, "differ", "confirmed"),
    (False, "agree", "not confirmed"), (False, "differ", "confirmed")])
def test_caustic_guard_confirms_with_more_cycles_samples(monkeypatch, tmp_path, flagged,
                                                         checked, verdict):
    """investigate (--no-shrink): a flagged case's one confirmation renders Cycles at
    CAUSTIC_CYCLES_FACTOR x the samples, an unflagged case's at the usual; the verdict follows
    that confirmation (the guard clears nothing that still differs)."""
    import difftest
    import difftest_run as dr
    calls = []

    def run_case(case, st, base=0, spp_factor=1, **kw):
        calls.append((st.cycles_spp, st.spp, spp_factor))
        return difftest.Result(checked)
    monkeypatch.setattr(dr, "run_case", run_case)
    monkeypatch.setattr(difftest, "save_case", lambda *a, **k: "replay")
    case = _d59()
    if not flagged:
        case["lights"][0]["radius"] = 0.2
    st = difftest.Settings(integrator="bdpt")
    info = dr.investigate(case, st, str(tmp_path), 0, shrink=False, say=lambda *a: None)
    assert info["verdict"].split(" (")[0] == verdict
    assert info.get("glossy_caustic", False) == (flagged and checked == "agree")
    factor = dr.CAUSTIC_CYCLES_FACTOR if flagged else 1
    assert calls == [(16 * factor, 16, 2)], calls
    assert factor >= 4 or not flagged   # Cycles' side well past Lantern's 2x
