import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
# the checkout's lantern package when it has its own native core (else the installed one), as
# tests/cycles and tests/blender do
_SRC = os.path.join(ROOT, "python")
if any(f.startswith("_core") for f in os.listdir(os.path.join(_SRC, "lantern"))) and \
        _SRC not in sys.path:
    sys.path.insert(0, _SRC)

import render_compare  # noqa: E402


def pytest_terminal_summary(terminalreporter):
    """One line per Cycles comparison, in the CI log even without -s."""
    if render_compare.REPORT:
        terminalreporter.section("Lantern against Cycles")
        for line in render_compare.REPORT:
            terminalreporter.write_line(line)
