import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))

import render_compare  # noqa: E402


def pytest_terminal_summary(terminalreporter):
    """One line per Cycles comparison, in the CI log even without -s."""
    if render_compare.REPORT:
        terminalreporter.section("Lantern against Cycles")
        for line in render_compare.REPORT:
            terminalreporter.write_line(line)
