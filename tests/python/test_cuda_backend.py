"""The CUDA backend at the native level (`_core.Session(..., {"backend": ...})`).

Everywhere: what `cuda_info()` reports, and that a session asked for "cuda" where no GPU can
be used renders on the CPU (the same bits as a "cpu" session) with a warning that says why,
while "auto" falls back quietly. With a usable GPU (skipped otherwise): CUDA images against
CPU images of the same scenes for every integrator, with the comparison of every render test
(lantern.metrics.assert_agreement, tests/README.md: Welch t per block with Bonferroni,
image-mean z-tests, 1 % / 5 % negative controls) on paired seeds, plus finiteness,
repeatability of pt on the GPU and cancellation. The old rule (|z| > 3 in at most max(2, 1 %)
blocks) failed a correct GPU in about 59 % of runs over its 12 cases; this one in about
12 x 2e-3.

Paired seeds: the CPU runs the same wavefront as the GPU (one algorithm, its stages written
once for both), so seed k traces the same random numbers on both backends, and the images
differ only where float rounding (another BVH, fused multiply-adds, the order of atomic
splats) sends a path elsewhere. E[cuda_k - cpu_k] = 0 is tested as cuda_k - cpu_k + mean(cpu)
against mean(cpu): the noise is the spread of the differences. Where paths decorrelate the
pairs' noise grows to that of independent sets (which, at 16 x 64 spp, resolved only 1.9-3.0 %
cpu vs cpu): a test that then cannot see its 1 % / 5 % controls fails saying so."""
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes
from lantern.session import DEFAULT_SETTINGS

K = 16
GPU_CONTROLS = (0.01, 0.05)   # whole image, one block (paired seeds; independent sets of
                              # 16 x 64 spp resolved 1.9-3.0 % cpu vs cpu and stated 4 % / 10 %)


@pytest.fixture(scope="module")
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    from lantern import _core
    if not hasattr(_core, "cuda_info"):
        pytest.skip("this lantern._core predates the CUDA backend")
    return _core


def _cpu_usable(core):
    return not hasattr(core, "embree_available") or core.embree_available()


def native_session(core, scene, **settings):
    st = dict(DEFAULT_SETTINGS)
    st.update(settings)
    return core.Session(scene.to_native(), st)


def render(core, scene, steps=2, **settings):
    s = native_session(core, scene, **settings)
    for _ in range(steps):
        s.step()
    return s, s.image()


def test_cuda_info_reports_why(core):
    info = core.cuda_info()
    assert set(info) >= {"compiled", "available", "reason", "name", "memory_bytes",
                         "compute_capability"}
    assert isinstance(info["available"], bool) and isinstance(info["compiled"], bool)
    if not info["compiled"]:
        assert not info["available"]
    if info["available"]:
        assert info["name"] and info["memory_bytes"] > 0 and info["reason"] == ""
    else:
        assert len(info["reason"]) > 10, info
    backends = core.build_info()["backends"]
    assert ("cuda" in backends) == info["compiled"]


def test_disable_variable_hides_the_gpu(core):
    # the child finds lantern as this process did (conftest.py sets PYTHONPATH where needed)
    code = ("from lantern import _core; "
            "i = _core.cuda_info(); print(i['available'], '|', i['reason'])")
    env = dict(os.environ, LANTERN_DISABLE_CUDA="1")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    available, reason = out.stdout.strip().split("|")
    assert available.strip() == "False"
    if core.cuda_info()["compiled"]:
        assert "LANTERN_DISABLE_CUDA" in reason


def test_cuda_without_gpu_renders_on_the_cpu(core):
    if core.cuda_info()["available"]:
        pytest.skip("a GPU is usable here: the fallback is not taken")
    if not _cpu_usable(core):
        pytest.skip("no CPU backend either (Embree missing)")
    scene = scenes.cornell_box(width=24, height=24)
    s_cuda, img_cuda = render(core, scene, integrator="pt", backend="cuda", seed=3)
    s_cpu, img_cpu = render(core, scene, integrator="pt", backend="cpu", seed=3)
    assert s_cuda.backend == "cpu" and s_cuda.stats()["backend"] == "cpu"
    warn = " ".join(s_cuda.warnings())
    assert "CUDA backend is not available" in warn and core.cuda_info()["reason"] in warn
    assert np.isfinite(img_cuda).all() and img_cuda.mean() > 0
    assert np.array_equal(img_cuda, img_cpu)  # the same CPU render, bit for bit
    s_auto, img_auto = render(core, scene, integrator="pt", backend="auto", seed=3)
    assert s_auto.backend == "cpu"
    assert not any("CUDA" in w for w in s_auto.warnings())
    assert np.array_equal(img_auto, img_cpu)


def test_unknown_backend_is_refused(core):
    with pytest.raises(ValueError, match="backend"):
        native_session(core, scenes.cornell_box(width=8, height=8), backend="vulkan")


# ---- on a GPU -------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def gpu(core):
    info = core.cuda_info()
    if not info["available"]:
        pytest.skip(f"no usable GPU: {info['reason']}")
    if not _cpu_usable(core):
        pytest.skip("no CPU backend to compare against")
    return info


def _renders(core, scene, backend, integrator, seed0, spp=64, **settings):
    out = []
    for k in range(K):
        s = native_session(core, scene, integrator=integrator, backend=backend, seed=seed0 + k,
                           max_depth=8, spp_per_iteration=spp // 4, **settings)
        for _ in range(4):
            s.step()
        assert s.backend == backend, s.warnings()
        img = s.image()
        assert np.isfinite(img).all(), f"{backend} {integrator}: non-finite pixels"
        out.append(img)
    return out


def _agree_paired(name, a, b):
    """a, b: the same seeds on two backends; paired (module docstring)."""
    paired, level = metrics.paired_sets(a, b)
    metrics.assert_agreement(name + ", paired seeds", paired, level, block=8,
                             image_bias=GPU_CONTROLS[0], block_bias=GPU_CONTROLS[1])


CASES = [("pt", {}), ("lt", {}), ("bdpt", {}), ("lvc", {}), ("cis", {}), ("cis", {"sort": False})]


@pytest.mark.parametrize("integrator,settings", CASES,
                         ids=[i + ("-unsorted" if s else "") for i, s in CASES])
@pytest.mark.parametrize("scene_name", ["cornell", "features"])
def test_cuda_matches_cpu(core, gpu, integrator, settings, scene_name):
    make = {"cornell": scenes.cornell_box, "features": scenes.features_box}[scene_name]
    scene = make(width=32, height=32)
    a = _renders(core, scene, "cuda", integrator, 100, **settings)
    b = _renders(core, scene, "cpu", integrator, 100, **settings)
    _agree_paired(f"{scene_name} {integrator} {settings}", a, b)


def test_gpu_pt_is_repeatable_and_reports_itself(core, gpu):
    scene = scenes.cornell_box(width=32, height=32)
    s1, a = render(core, scene, integrator="pt", backend="cuda", seed=5)
    _, b = render(core, scene, integrator="pt", backend="cuda", seed=5)
    assert np.array_equal(a, b)  # pt has no atomics: the same bits every run
    st = s1.stats()
    assert st["backend"] == "cuda" and st["device"] == gpu["name"]
    assert st["device_memory_peak"] > 0 and st["rays_camera"] == 2 * 32 * 32


def test_gpu_cancel_keeps_the_last_iteration(core, gpu):
    scene = scenes.cornell_box(width=256, height=256)
    s = native_session(core, scene, integrator="cis", backend="cuda", spp_per_iteration=64)
    s.step()
    before = s.image()
    t = threading.Timer(0.01, s.cancel)
    t.start()
    finished = s.step()
    t.join()
    after = s.image()
    if not finished:
        assert s.spp == 64 and np.array_equal(before, after)
    assert np.isfinite(after).all()
