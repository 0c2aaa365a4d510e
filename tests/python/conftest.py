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


# ---- Backends ----
# Tests that take a `backend` argument run once per backend in LANTERN_TEST_BACKENDS (comma
# separated, default "cpu", e.g. "cpu,cuda"). A backend this build or machine cannot use is
# skipped with the reason from lantern.cuda_info(); LANTERN_TEST_BACKENDS_STRICT=1 (the GPU
# check) turns those skips into failures, so a broken CUDA build cannot pass as all-skipped.
import pytest  # noqa: E402


def test_backends():
    names = [b.strip() for b in os.environ.get("LANTERN_TEST_BACKENDS", "cpu").split(",")]
    return [b for b in names if b] or ["cpu"]


test_backends.__test__ = False  # not a test


def pytest_generate_tests(metafunc):
    if "backend" in metafunc.fixturenames and not any(
            "backend" in m.args[0] for m in metafunc.definition.iter_markers("parametrize")):
        metafunc.parametrize("backend", test_backends(), indirect=True)


@pytest.fixture
def backend(request):
    from lantern import session
    name = request.param
    reason = session.backend_unavailable(name)
    if reason:
        if os.environ.get("LANTERN_TEST_BACKENDS_STRICT") == "1":
            pytest.fail(f"backend {name!r} was asked for but is unavailable: {reason}")
        pytest.skip(f"backend {name!r}: {reason}")
    return name


# ---- The native core ----
# A test (or a module, by `pytestmark = pytest.mark.usefixtures("core")`) that needs the native
# module takes `core`: lantern._core, or a skip naming why it is not there. A module may define
# its own (test_cuda_backend.py's also wants the CUDA entry points).
@pytest.fixture(scope="module")
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()}); build with "
                    f"`.venv/bin/pip install --no-build-isolation --no-deps .`")
    from lantern import _core
    return _core  # without Embree the CPU backend uses its built-in BVH
