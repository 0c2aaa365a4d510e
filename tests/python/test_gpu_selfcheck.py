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
