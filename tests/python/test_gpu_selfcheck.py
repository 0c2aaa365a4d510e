"""The GPU self-check of backend "auto" (lantern/gpu_selfcheck.py, issue 30), on a machine
without a GPU: `session.cuda_info` is replaced by a GPU that says it is usable, and the child
process stands a test double in for the GPU renderer (gpu_selfcheck_run.gpu_renderer): one that
renders correctly (the CPU with other seeds), 25 % too bright, with a NaN, one that hangs and
one that aborts. The session must then render on the CPU and say why, naming the case; a
passing double's verdict is cached and not run again."""

import json

import numpy as np
import pytest

import lantern
from lantern import gpu_selfcheck, scenes, session

if not lantern.native_available():
    pytest.skip(f"native core unavailable: {lantern.native_error()}", allow_module_level=True)

FAKE_GPU = {"compiled": True, "available": True, "reason": "", "name": "Test Double GPU",
            "memory_bytes": 8 << 30, "compute_capability": "9.0", "driver_version": 13000}
CASE = "envmap/pt"   # the quickest case of the set (about a second a side)


@pytest.fixture
def fake_gpu(monkeypatch, tmp_path):
    monkeypatch.setattr(session, "cuda_info", lambda: dict(FAKE_GPU))
    monkeypatch.setenv("LANTERN_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("LANTERN_GPU_SELFCHECK", raising=False)
    monkeypatch.setattr(gpu_selfcheck, "CASES", (CASE,))
    monkeypatch.setattr(gpu_selfcheck, "_memo", {})
    return tmp_path


def small_session(**settings):
    return lantern.Session(scenes.cornell_box(16, 16), backend="auto", threads=1,
                           spp_per_iteration=2, **settings)


def cached_verdicts(folder):
    with open(folder / "gpu_selfcheck.json") as f:
        return list(json.load(f).values())


def no_child(*args, **kwargs):
    raise AssertionError("the self-check ran again instead of using its cached verdict")


def assert_cpu_render_with(s, *words):
    assert s.settings["backend"] == "cpu"
    report = " ".join(s.warnings)
    for w in words:
        assert w in report, report
    s.step()
    assert s.backend == "cpu"
    assert np.isfinite(s.image()).all() and s.image().mean() > 0


@pytest.mark.parametrize("double, words", [
    ("fail", ["differs from the CPU's"]),
    ("nan", ["non-finite"]),
    ("crash", ["killed by signal"]),
])
def test_a_faulty_gpu_renders_on_the_cpu_and_names_the_case(fake_gpu, monkeypatch, double,
                                                            words):
    monkeypatch.setattr(gpu_selfcheck, "DOUBLE", double)
    s = small_session()
    assert_cpu_render_with(s, f"'{CASE}'", "rendering on the CPU", *words)
    [v] = cached_verdicts(fake_gpu)
    assert v["ok"] is False and CASE in v["reason"]
    # the next session reads the verdict: no second check
    monkeypatch.setattr(gpu_selfcheck, "run_check", no_child)
    monkeypatch.setattr(gpu_selfcheck, "_memo", {})
    assert_cpu_render_with(small_session(), "(cached verdict)", *words)


def test_a_hanging_gpu_times_out(fake_gpu, monkeypatch):
    monkeypatch.setattr(gpu_selfcheck, "DOUBLE", "hang")
    monkeypatch.setattr(gpu_selfcheck, "TIMEOUT_S", 8.0)
    s = small_session()
    assert_cpu_render_with(s, "timed out after 8 s", f"in case '{CASE}'")


def test_a_passing_gpu_is_trusted_once_checked(fake_gpu, monkeypatch):
    monkeypatch.setattr(gpu_selfcheck, "DOUBLE", "pass")
    s = small_session()
    assert s.settings["backend"] == "auto"
    assert not any("self-check" in w for w in s.warnings), s.warnings
    [v] = cached_verdicts(fake_gpu)
    assert v["ok"] is True
    monkeypatch.setattr(gpu_selfcheck, "run_check", no_child)
    monkeypatch.setattr(gpu_selfcheck, "_memo", {})
    assert small_session().settings["backend"] == "auto"
    # another driver is another key: checked again
    monkeypatch.setattr(session, "cuda_info", lambda: dict(FAKE_GPU, driver_version=13010))
    with pytest.raises(AssertionError, match="ran again"):
        small_session()


def test_forcing_the_gpu_or_switching_the_check_off_skips_it(fake_gpu, monkeypatch):
    monkeypatch.setattr(gpu_selfcheck, "run_check", no_child)
    s = lantern.Session(scenes.cornell_box(8, 8), backend="cuda", threads=1, integrator="pt")
    assert not any("self-check" in w for w in s.warnings)
    monkeypatch.setenv("LANTERN_GPU_SELFCHECK", "off")
    assert small_session().settings["backend"] == "auto"


def test_the_check_needs_a_usable_gpu(monkeypatch, tmp_path):
    """Without a usable GPU "auto" renders on the CPU anyway: nothing to check."""
    monkeypatch.setenv("LANTERN_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(session, "cuda_info", lambda: dict(FAKE_GPU, available=False))
    monkeypatch.setattr(gpu_selfcheck, "run_check", no_child)
    small_session()
    assert not (tmp_path / "gpu_selfcheck.json").exists()


def test_the_command_line_check(fake_gpu, monkeypatch, capsys):
    from lantern import cli
    monkeypatch.setattr(gpu_selfcheck, "DOUBLE", "pass")
    assert cli.main(["gpu-check"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["ok"] is True and out["cached"] is False and "Test Double GPU" in out["key"]
    monkeypatch.setattr(session, "cuda_info", lambda: dict(FAKE_GPU, available=False,
                                                           reason="no CUDA-capable GPU found"))
    assert cli.main(["gpu-check"]) == cli.EXIT_ERROR
    assert "no CUDA-capable GPU found" in capsys.readouterr().err


def test_the_set_has_strands_and_motion_blur():
    """The strand and motion-blur cases really hold what the GPU must agree on: strands, a mesh
    and a strand set moving with their object's matrices (the two-level BVH, the strands'
    moving set); the moving one renders on the CPU."""
    from lantern import gpu_selfcheck_run as run
    assert {"hair/pt", "motion/pt", "hair/cis", "motion/cis"} <= set(run.CASES)
    hair, moving = run.scene_for("hair"), run.scene_for("motion")
    assert len(hair.curves) == 1 and "motion" not in hair.curves[0]
    assert len(moving.meshes[0]["motion"]) == 3 and len(moving.curves[0]["motion"]) == 3
    s = lantern.Session(moving, backend="cpu", threads=1, spp_per_iteration=1, max_depth=3)
    s.step()
    assert np.isfinite(s.image()).all() and s.image().mean() > 0


@pytest.mark.parametrize("double, ok", [("pass", True), ("fail", False)])
def test_the_strand_and_motion_cases_judge_the_gpu(fake_gpu, monkeypatch, double, ok):
    """The doubles on the new cases: a GPU that renders them as the CPU does passes, one 25 %
    too bright fails, named by the case."""
    monkeypatch.setattr(gpu_selfcheck, "DOUBLE", double)
    monkeypatch.setattr(gpu_selfcheck, "CASES", ("motion/pt",) if not ok
                        else ("hair/pt", "motion/pt"))
    v = gpu_selfcheck.verdict(dict(FAKE_GPU))
    assert v["ok"] is ok, v
    if not ok:
        assert "'motion/pt'" in v["reason"] and "differs from the CPU's" in v["reason"]


def test_cuda_takes_strand_and_motion_scenes():
    """The CUDA backend traces strands and moving meshes now (accel/scene_query.h): a session
    asking for it on such a scene no longer hands it to the CPU for them; without a GPU here it
    says only that none is available (the C++ session's own cuda_info)."""
    from lantern import gpu_selfcheck_run as run
    s = lantern.Session(run.scene_for("motion", 8), backend="cuda", threads=1,
                        spp_per_iteration=1, max_depth=2)
    report = " ".join(s.warnings)
    assert "strands yet" not in report and "motion blur yet" not in report, report
    if not lantern._core.cuda_info()["available"]:
        assert "CUDA backend is not available" in report, report
