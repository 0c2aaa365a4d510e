"""Test the package in this checkout (python/lantern), not a stale installed copy. When the
checkout has no native module but an installed lantern does, borrow that `_core`."""
import glob
import importlib.util
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SRC = os.path.join(ROOT, "python")


def _installed_package_dir():
    spec = importlib.util.find_spec("lantern")
    if spec is None or not spec.submodule_search_locations:
        return None
    return list(spec.submodule_search_locations)[0]


def _has_core(path):
    return bool(path) and bool(glob.glob(os.path.join(path, "_core*")))


_installed = _installed_package_dir()
_here = os.path.join(SRC, "lantern")
if SRC not in sys.path:
    sys.path.insert(0, SRC)
    # child interpreters (subprocess tests) see the checkout too, unless only the installed
    # copy has the native module
    if _has_core(_here) or not _has_core(_installed):
        os.environ["PYTHONPATH"] = os.pathsep.join(
            [SRC] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])

import lantern  # noqa: E402  (after the path fix on purpose)

if (_installed and os.path.realpath(_installed) != os.path.realpath(_here)
        and not _has_core(_here) and _has_core(_installed)):
    lantern.__path__.append(_installed)
