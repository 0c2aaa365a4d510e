"""The GPU self-check's feature cases (gpu_selfcheck.FEATURE_CASES), on a machine without a GPU
(test_gpu_selfcheck.py's fake GPU and doubles): under backend "auto" a scene with subsurface
scattering or participating media goes to the GPU only once that feature's cases passed there;
a feature whose case failed, crashed or did not run keeps its own scenes on the CPU, saying
which case, and no other scene. The "pass" double passes the new cases, the "fail" double
fails them."""

import numpy as np
import pytest

import lantern
from lantern import gpu_selfcheck, scenes, scenes_sss, session
from lantern import gpu_selfcheck_run as run

from test_gpu_selfcheck import FAKE_GPU, fake_gpu, no_child  # noqa: F401 (a fixture)

if not lantern.native_available():
    pytest.skip(f"native core unavailable: {lantern.native_error()}", allow_module_level=True)


FEATURE_CASES = tuple(c for cases in gpu_selfcheck.FEATURE_CASES.values() for c in cases)


def features(scene):
    return session.gpu_features(scene.to_native())


def test_the_features_of_a_scene():
    """What the core tests (subsurface_reason, media_reason), with controls: weight 0 or
    radius 0 is no subsurface, a world volume is a medium."""
    assert features(scenes_sss.lit_sphere()) == {"subsurface"}
    assert features(run.fog_box()) == {"media"}
    assert features(scenes.cornell_box(8, 8)) == set()
    assert features(run.scene_for("hair")) == set()
    off = scenes_sss.lit_sphere()
    off.materials[0]["subsurface_weight"] = 0.0
    assert features(off) == set()
    flat = scenes_sss.lit_sphere()
    flat.materials[0]["subsurface_radius"] = [0.0, 0.0, 0.0]
    assert features(flat) == set()
    fog = scenes.cornell_box(8, 8)
    fog.world["volume"] = {"sigma_s": [0.1] * 3}
    assert features(fog) == {"media"}


def test_the_set_has_the_feature_cases_after_the_core():
    assert list(run.CASES) == list(run.CORE_CASES) + list(FEATURE_CASES)
    assert {"skin/pt", "skin/cis", "skin/lt", "fog/pt", "fog/cis", "fog/lt"} == set(FEATURE_CASES)
    assert all(gpu_selfcheck.feature_of(c) is None for c in run.CORE_CASES)
    skin, fog = run.scene_for("skin"), run.scene_for("fog")
    assert skin.materials[0]["subsurface_method"] == "random_walk_skin"
    assert fog.grids and any(m.get("density_grid") is not None for m in fog.materials)


def verdict_for(monkeypatch, double, cases):
    monkeypatch.setattr(gpu_selfcheck, "DOUBLE", double)
    monkeypatch.setattr(gpu_selfcheck, "CASES", cases)
    return gpu_selfcheck.verdict(dict(FAKE_GPU))


def veto(*feats):
    return gpu_selfcheck.auto_backend_veto(dict(FAKE_GPU), set(feats))


def test_the_pass_double_passes_every_feature_case(fake_gpu, monkeypatch):
    """A GPU that renders as the CPU does (other seeds) passes the six new cases: both features
    go to the GPU."""
    v = verdict_for(monkeypatch, "pass", FEATURE_CASES)
    assert v["ok"] is True and [c["case"] for c in v["cases"]] == list(FEATURE_CASES), v
    assert all(c["ok"] for c in v["cases"]), v
    assert v["features"]["subsurface"]["ok"] and v["features"]["media"]["ok"], v
    assert veto("subsurface", "media") is None and veto() is None


@pytest.mark.long
@pytest.mark.parametrize("case", FEATURE_CASES)
def test_the_fail_double_fails_each_feature_case(case):
    """Each new case alone (in this process: the child's run_case) tells a GPU 25 % too bright
    from the CPU, confirmed with fresh seeds, and passes the correct one."""
    assert run.run_case(case, run.gpu_renderer("pass")) is None
    why = run.run_case(case, run.gpu_renderer("fail"))
    assert why and "differs from the CPU's" in why, why
    why = run.run_case(case, run.gpu_renderer("fail"), round_=1)
    assert why and "differs from the CPU's" in why, why


def test_a_faulty_feature_keeps_only_its_scenes_on_the_cpu(fake_gpu, monkeypatch):
    """The core set passes, the subsurface stages are wrong ("fail:skin"): a Skin sphere renders
    on the CPU naming 'skin/pt', the Cornell box and the fog box use the GPU; the verdict is
    cached and read by the next sessions."""
    v = verdict_for(monkeypatch, "fail:skin", ("envmap/pt", "skin/pt", "fog/pt"))
    assert v["ok"] is True and not v["features"]["subsurface"]["ok"], v
    assert v["features"]["media"]["ok"] and [c["ok"] for c in v["cases"]] == [True, False, True]
    monkeypatch.setattr(gpu_selfcheck, "run_check", no_child)
    monkeypatch.setattr(gpu_selfcheck, "_memo", {})
    sss = lantern.Session(scenes_sss.lit_sphere(8, 8), backend="auto", threads=1,
                          spp_per_iteration=1, max_depth=3)
    assert sss.settings["backend"] == "cpu"
    report = " ".join(sss.warnings)
    assert "'skin/pt'" in report and "subsurface scattering" in report, report
    assert "(cached verdict)" in report, report
    sss.step()
    assert sss.backend == "cpu" and np.isfinite(sss.image()).all()
    for scene in (scenes.cornell_box(8, 8), run.fog_box(8, 8)):
        s = lantern.Session(scene, backend="auto", threads=1, spp_per_iteration=1)
        assert s.settings["backend"] == "auto", s.warnings
        assert not any("self-check" in w for w in s.warnings), s.warnings


def test_a_crash_in_a_feature_case_keeps_the_core(fake_gpu, monkeypatch):
    """The child aborts in 'skin/pt' (a device fault in a walk kernel): the core set had passed,
    so only subsurface fails (the crash named) and media, never reached, is not checked."""
    v = verdict_for(monkeypatch, "crash:skin", ("envmap/pt", "skin/pt", "fog/pt"))
    assert v["ok"] is True and v["case"] == "skin/pt", v
    assert "killed by signal" in v["features"]["subsurface"]["reason"]
    assert "media" not in v["features"]
    assert veto() is None
    assert "killed by signal" in veto("subsurface") and "'skin/pt'" in veto("subsurface")
    assert "has not checked participating media" in veto("media")
    # a crash in a core case still fails the GPU for every scene
    monkeypatch.setattr(gpu_selfcheck, "DOUBLE", "crash:envmap")
    v = gpu_selfcheck.verdict(dict(FAKE_GPU), again=True)
    assert v["ok"] is False and v["case"] == "envmap/pt", v
    assert "'envmap/pt'" in veto() and "killed by signal" in veto()


def test_the_command_line_check_fails_on_a_feature(fake_gpu, monkeypatch, capsys):
    """`python -m lantern gpu-check` exits with an error when a feature's case failed (the
    JSON says the core passed)."""
    import json

    from lantern import cli
    monkeypatch.setattr(gpu_selfcheck, "DOUBLE", "fail:fog")
    monkeypatch.setattr(gpu_selfcheck, "CASES", ("fog/pt",))
    assert cli.main(["gpu-check"]) == cli.EXIT_ERROR
    out = json.loads(capsys.readouterr().out)
    assert out["ok"] is True and out["features"]["media"]["ok"] is False, out
    assert "'fog/pt'" in out["reason"], out


def test_a_hang_in_a_feature_case_times_out_that_feature(fake_gpu, monkeypatch):
    """The child hangs in 'fog/pt': the parent's timeout names the case and fails media only."""
    monkeypatch.setattr(gpu_selfcheck, "TIMEOUT_S", 6.0)
    v = verdict_for(monkeypatch, "hang:fog", ("fog/pt",))
    assert v["ok"] is True and not v["features"]["media"]["ok"], v
    assert "timed out after 6 s in case 'fog/pt'" in veto("media")
    assert veto() is None


def native_settings_of(monkeypatch, scene, **settings):
    """The settings python/lantern/session.py hands the core for `scene` (a stand-in core)."""
    seen = {}

    class Core:
        def Session(self, native_scene, native_settings):  # noqa: N802 (the core's name)
            seen.update(native_settings)
            return object()
    monkeypatch.setattr(session, "require_core", lambda: Core())
    monkeypatch.setattr(session, "camera_side_light_warnings", lambda *a: [])
    lantern.Session(scene, threads=1, **settings)
    return seen


def test_auto_on_the_gpu_reads_which_features_passed(fake_gpu, monkeypatch):
    """Integrator auto on a GPU chooses cis in a subsurface or media scene only where that
    feature's self-check cases passed there (session.cpp, SessionSettings::gpu_checked; its
    decision: tests/cpp/test_session_auto_gpu.cpp): session.py hands the core the features the
    cached verdict passed (bits 1 subsurface, 2 media), none for a forced "cuda" or the check
    off, and none where the scene went to the CPU. Host code only: never ran on a GPU."""
    assert gpu_selfcheck.features_passed({"ok": False, "features": {
        "media": {"ok": True}}}) == set()
    assert gpu_selfcheck.features_passed({"ok": True}) == set()
    assert gpu_selfcheck.features_passed({"ok": True, "features": {
        "subsurface": {"ok": False}, "media": {"ok": True}}}) == {"media"}
    assert session.gpu_checked_bits({"subsurface", "media"}) == 3
    verdict_for(monkeypatch, "fail:skin", ("envmap/pt", "skin/pt", "fog/pt"))
    monkeypatch.setattr(gpu_selfcheck, "run_check", no_child)
    assert gpu_selfcheck.passed_features(dict(FAKE_GPU)) == {"media"}
    fog, cornell = run.fog_box(8, 8), scenes.cornell_box(8, 8)
    assert native_settings_of(monkeypatch, fog, backend="auto")["gpu_checked"] == 2
    assert native_settings_of(monkeypatch, cornell, backend="auto")["gpu_checked"] == 2
    sss = native_settings_of(monkeypatch, scenes_sss.lit_sphere(8, 8), backend="auto")
    assert sss["backend"] == "cpu" and sss["gpu_checked"] == 0, sss
    assert native_settings_of(monkeypatch, fog, backend="cuda")["gpu_checked"] == 0
    monkeypatch.setenv("LANTERN_GPU_SELFCHECK", "off")
    assert native_settings_of(monkeypatch, fog, backend="auto")["gpu_checked"] == 0
    monkeypatch.delenv("LANTERN_GPU_SELFCHECK")
    monkeypatch.setattr(gpu_selfcheck, "_memo", {})
    monkeypatch.setattr(gpu_selfcheck, "run_check", lambda timeout=None: {
        "ok": True, "features": {f: {"ok": True} for f in gpu_selfcheck.FEATURE_CASES}})
    monkeypatch.setenv("LANTERN_GPU_SELFCHECK", "again")
    assert native_settings_of(monkeypatch, fog, backend="auto")["gpu_checked"] == 3
