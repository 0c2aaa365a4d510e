"""Load addon/ into bpy 5.0.1 as the package `lantern_blender` and register it once."""

import importlib.util
import sys
from pathlib import Path

import pytest

# this checkout's package when it has a native module (as tests/python does), not an installed
# copy: the add-on under test and the core it drives must be the same checkout's
_SRC = Path(__file__).resolve().parents[2] / "python"
if any((_SRC / "lantern").glob("_core*")) and str(_SRC) not in sys.path:
    sys.path.insert(0, str(_SRC))

bpy = pytest.importorskip("bpy")

ADDON = Path(__file__).resolve().parents[2] / "addon"
# the checkout's lantern package when it has its own native core (else the installed one)
_SRC = Path(__file__).resolve().parents[2] / "python"
if list((_SRC / "lantern").glob("_core*")) and str(_SRC) not in sys.path:
    sys.path.insert(0, str(_SRC))


def _load_addon():
    if "lantern_blender" in sys.modules:
        return sys.modules["lantern_blender"]
    spec = importlib.util.spec_from_file_location(
        "lantern_blender", ADDON / "__init__.py", submodule_search_locations=[str(ADDON)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["lantern_blender"] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def addon():
    module = _load_addon()
    module.register()
    yield module
    module.unregister()


@pytest.fixture
def empty(addon):
    """An empty scene (factory settings), Lantern selected, a tiny resolution."""
    from blender_helpers import empty_scene
    return empty_scene()


@pytest.fixture
def default_scene(addon):
    """Blender's default scene: cube, light, camera."""
    bpy.ops.wm.read_factory_settings(use_empty=False)
    bpy.context.scene.render.engine = "LANTERN"
    return bpy.context.scene


@pytest.fixture
def errors(addon, monkeypatch):
    """Records every error and warning the engine reports (and still reports them)."""
    calls = []
    engine = addon.engine
    orig_error, orig_warn = engine._report_error, engine._report_warnings

    def report_error(eng, what, error):
        calls.append(("ERROR", f"{what}: {error}"))
        orig_error(eng, what, error)

    def report_warnings(eng, messages):
        calls.extend(("WARNING", m) for m in messages)
        orig_warn(eng, messages)

    monkeypatch.setattr(engine, "_report_error", report_error)
    monkeypatch.setattr(engine, "_report_warnings", report_warnings)
    return calls
