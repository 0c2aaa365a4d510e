"""tools/exr_passes.py for the tests here."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "tools"))
from exr_passes import read_passes, render_passes  # noqa: E402,F401
