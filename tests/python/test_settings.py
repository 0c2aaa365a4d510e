"""Session settings and the behaviour without the native module (no _core needed)."""
import subprocess
import sys

import pytest

import lantern
from lantern import scenes, session


def test_defaults(monkeypatch):
    monkeypatch.setattr(session, "_native_has_cuda", lambda: False)  # a CPU-only core
    monkeypatch.delenv("LANTERN_THREADS", raising=False)  # tools/test.sh sets it
    settings, warnings = session.resolve_settings({})
    assert settings == {"integrator": "auto", "backend": "cpu", "spp_per_iteration": 1,
                        "max_depth": 16, "seed": 0, "threads": 0, "rr_depth": 4,
                        "sort": None, "connections": 5, "candidates": 10,
                        "light_path_fraction": 1.0, "cis_target": "contribution", "naive_ris": False,
                        "naive_map": False, "connection_allocation": None,
                        "cache_budget_mb": 0, "light_candidates": 1,
                        "adaptive_threshold": 0.0, "adaptive_min_samples": 0,
                        "adaptive_step": 4, "instancing": False, "auto_keep_pilot": False,
                        "auto_media": True, "moment_channels": False,
                        "soft_visibility": True}
    assert warnings == []


def test_threads_from_the_environment(monkeypatch):
    """LANTERN_THREADS caps `threads` 0 (every core); an explicit count wins; a value that is
    not a count is named in a warning and ignored."""
    monkeypatch.setenv("LANTERN_THREADS", "1")
    assert session.resolve_settings({})[0]["threads"] == 1
    assert session.resolve_settings({"threads": 3})[0]["threads"] == 3
    for bad in ("two", "-1", "5000"):
        monkeypatch.setenv("LANTERN_THREADS", bad)
        settings, warnings = session.resolve_settings({})
        assert settings["threads"] == 0
        assert any("LANTERN_THREADS" in w and bad in w for w in warnings), warnings
    monkeypatch.setenv("LANTERN_THREADS", " ")
    assert session.resolve_settings({})[0]["threads"] == 0


def test_unknown_setting_lists_valid_ones():
    with pytest.raises(TypeError, match=r"unknown setting\(s\) 'max_bounces'.*max_depth"):
        session.resolve_settings({"max_bounces": 3})


@pytest.mark.parametrize("name", ["bdpt", "lvc", "cis"])
def test_bidirectional_integrators_resolve(name):
    settings, warnings = session.resolve_settings({"integrator": name, "connections": 8,
                                                   "candidates": 16, "sort": False})
    assert settings["integrator"] == name and settings["connections"] == 8
    assert settings["candidates"] == 16 and settings["sort"] is False and warnings == []


@pytest.mark.parametrize("settings, exc, message", [
    ({"integrator": "mlt"}, ValueError, "integrator"),
    ({"backend": "metal"}, ValueError, "backend"),
    ({"spp_per_iteration": 0}, ValueError, r"spp_per_iteration.*\[1, 4096\]"),
    ({"spp_per_iteration": 4097}, ValueError, "spp_per_iteration"),
    ({"max_depth": 0}, ValueError, r"max_depth.*\[1, 1024\]"),
    ({"max_depth": 1025}, ValueError, "max_depth"),
    ({"max_depth": 2.0}, TypeError, "max_depth.*integer"),
    ({"seed": -1}, ValueError, "seed"),
    ({"threads": True}, TypeError, "threads"),
    ({"rr_depth": -1}, ValueError, "rr_depth"),
    ({"connections": 0}, ValueError, r"connections.*\[1, 64\]"),
    ({"candidates": 65}, ValueError, "candidates"),
    ({"sort": "yes"}, TypeError, "sort"),
    ({"cis_target": "luminance"}, ValueError, "cis_target"),
    ({"naive_ris": 1}, TypeError, "naive_ris"),
])
def test_bad_values(settings, exc, message):
    with pytest.raises(exc, match=message):
        session.resolve_settings(settings)


def test_backend_fallback_warns(monkeypatch):
    # a core without cuda_info() (built before the CUDA backend): cuda and auto mean the CPU
    monkeypatch.setattr(session, "_native_has_cuda", lambda: False)
    settings, warnings = session.resolve_settings({"backend": "cuda"})
    assert settings["backend"] == "cpu"
    assert any("CUDA" in w for w in warnings)
    settings, warnings = session.resolve_settings({"backend": "auto"})
    assert settings["backend"] == "cpu" and warnings == []


class _CudaCore:
    """A stand-in core with the CUDA backend's interface: cuda_info() and Session.backend; its
    GPU is unusable, so "cuda" falls back to the CPU with a warning, as the native core does."""
    calls = []

    @staticmethod
    def cuda_info():
        return {"compiled": True, "available": False, "reason": "no CUDA driver (test)",
                "name": "", "memory_bytes": 0, "compute_capability": ""}

    class Session:
        def __init__(self, scene, settings):
            _CudaCore.calls.append(settings)
            self.backend = "cpu"
            self._asked = settings["backend"]

        def warnings(self):
            return (["CUDA backend unavailable (no CUDA driver); rendering on the CPU"]
                    if self._asked == "cuda" else [])


def test_backend_passes_to_a_core_with_cuda(monkeypatch):
    monkeypatch.setattr(session, "_core", _CudaCore)
    monkeypatch.setattr(session, "_core_error", None)
    _CudaCore.calls.clear()
    for asked in ("cuda", "auto", "cpu"):
        s = lantern.Session(scenes.furnace_sphere(subdivisions=1, width=4, height=4),
                            backend=asked, integrator="pt")
        assert _CudaCore.calls[-1]["backend"] == asked  # the core decides, not Python
        assert s.backend == "cpu"
        assert any("CUDA" in w for w in s.warnings) == (asked == "cuda"), s.warnings
    assert session.resolve_settings({})[0]["backend"] == "auto"
    assert lantern.cuda_info()["compiled"] is True
    assert "no CUDA driver (test)" in session.backend_unavailable("cuda")
    assert session.backend_unavailable("cpu") is None


def test_cuda_info_without_cuda(monkeypatch):
    monkeypatch.setattr(session, "_core", object())  # a core without cuda_info
    monkeypatch.setattr(session, "_core_error", None)
    info = lantern.cuda_info()
    assert info["compiled"] is False and info["available"] is False
    assert "no CUDA backend" in session.backend_unavailable("cuda")
    assert "unknown backend" in session.backend_unavailable("metal")


def test_settings_checked_before_native(monkeypatch):
    # a bad setting is reported as such even when the native module is missing
    monkeypatch.setattr(session, "_core", None)
    monkeypatch.setattr(session, "_core_error", "ImportError: simulated")
    with pytest.raises(TypeError, match="unknown setting"):
        lantern.Session(lantern.Scene(), bounces=3, integrator="pt")


def test_missing_native_module_is_explained(monkeypatch):
    monkeypatch.setattr(session, "_core", None)
    monkeypatch.setattr(session, "_core_error", None)
    monkeypatch.setitem(sys.modules, "lantern._core", None)  # import fails
    assert not lantern.native_available()
    assert "ModuleNotFoundError" in lantern.native_error()
    with pytest.raises(RuntimeError, match=r"lantern\._core.*pip install --no-build-isolation"):
        lantern.Session(scenes.furnace_sphere(subdivisions=1), integrator="pt")
    with pytest.raises(RuntimeError, match="native module"):
        lantern.render(lantern.Scene(), spp=1, integrator="pt")


def test_import_survives_broken_native_module(tmp_path):
    # a _core that raises on import: `import lantern` and the pure-Python parts still work
    code = r"""
import sys, types, importlib.abc, importlib.machinery
class Broken(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    def find_spec(self, name, path=None, target=None):
        if name == "lantern._core":
            return importlib.machinery.ModuleSpec(name, self)
    def create_module(self, spec):
        return None
    def exec_module(self, module):
        raise OSError("undefined symbol: rtcNewDevice")
sys.meta_path.insert(0, Broken())
import lantern
from lantern import scenes, imageio, metrics
s = scenes.furnace_sphere(subdivisions=1)
s.save(sys.argv[1])
lantern.load_scene(sys.argv[1])
assert not lantern.native_available()
try:
    lantern.Session(s)
except RuntimeError as e:
    print("ERR", e)
"""
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "s.lantern")],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "ERR" in out.stdout and "undefined symbol" in out.stdout
    assert "pip install" in out.stdout


def test_render_argument_checks():
    with pytest.raises(ValueError, match="spp"):
        lantern.render(lantern.Scene(), spp=0, integrator="pt")
    with pytest.raises(ValueError, match="time_limit"):
        lantern.render(lantern.Scene(), spp=1, time_limit=0, integrator="pt")
