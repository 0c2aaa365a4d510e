"""Test the package in this checkout (python/lantern) when it has a native module, not an
installed copy (as tests/python/conftest.py does): the node tests need this checkout's core."""
import glob
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SRC = os.path.join(ROOT, "python")
if glob.glob(os.path.join(SRC, "lantern", "_core*")) and SRC not in sys.path:
    sys.path.insert(0, SRC)
