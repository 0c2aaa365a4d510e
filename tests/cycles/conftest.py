"""The checkout's lantern package when it has its own native core (else the installed one);
every test here needs bpy (with Cycles) and that core, so the folder is skipped, with the
reason, where either is missing (each test file once checked this itself)."""

import sys
from pathlib import Path

import pytest

_SRC = Path(__file__).resolve().parents[2] / "python"
if list((_SRC / "lantern").glob("_core*")) and str(_SRC) not in sys.path:
    sys.path.insert(0, str(_SRC))

pytest.importorskip("bpy")
_lantern = pytest.importorskip("lantern")
if not _lantern.native_available():
    pytest.skip(f"native core unavailable: {_lantern.native_error()}", allow_module_level=True)


def pytest_terminal_summary(terminalreporter):
    """The comparisons' measured numbers (render_compare.REPORT), in the CI log even without -s."""
    rc = sys.modules.get("render_compare")
    if rc is not None and rc.REPORT:
        terminalreporter.section("Lantern against Cycles")
        for line in rc.REPORT:
            terminalreporter.write_line(line)
