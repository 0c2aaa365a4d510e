"""Rendering through the native core: determinism, seeds, cancel, analytic furnaces.

Skipped with a reason when `lantern._core` is not built. Tests taking `backend` run on each
backend in LANTERN_TEST_BACKENDS (conftest.py); bit-for-bit determinism is a CPU promise."""
import math
import threading
import time

import numpy as np
import pytest

import lantern
from lantern import cli, imageio, metrics, scenes


@pytest.fixture(scope="module")
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()}); build with "
                    f"`.venv/bin/pip install --no-build-isolation --no-deps .`")
    from lantern import _core
    return _core  # without Embree the CPU backend uses its built-in BVH


def test_build_info(core):
    assert isinstance(core.build_info(), dict)
    assert isinstance(core.embree_version(), str)


def test_session_interface(core, backend):
    scene = scenes.cornell_box(width=16, height=12)
    s = lantern.Session(scene, seed=1, threads=1, spp_per_iteration=2, backend=backend)
    assert s.spp == 0
    s.step()
    assert s.spp == 2
    img = s.image()
    assert img.dtype == np.float32 and img.shape == (12, 16, 3)
    assert np.isfinite(img).all() and img.mean() > 0
    stats = s.stats
    assert isinstance(stats, dict)
    assert isinstance(s.warnings, list)


def test_empty_scene_shows_world(core, backend):
    black = lantern.render(lantern.Scene(), spp=1, backend=backend)
    assert black.shape == (64, 64, 3) and not black.any()
    scene = lantern.Scene()
    scene.film.update(width=8, height=8)
    scene.world["color"] = [0.2, 0.5, 1.5]
    img = lantern.render(scene, spp=2, backend=backend)
    assert np.allclose(img, [0.2, 0.5, 1.5], rtol=1e-5)


def test_same_seed_same_bits(core):
    scene = scenes.cornell_box(width=32, height=32)
    a = lantern.render(scene, spp=4, seed=7, threads=0, backend="cpu")
    b = lantern.render(scene, spp=4, seed=7, threads=0, backend="cpu")
    assert a.tobytes() == b.tobytes()


def test_thread_count_does_not_change_the_image(core):
    scene = scenes.cornell_box(width=24, height=16)
    a = lantern.render(scene, spp=3, seed=11, threads=1, backend="cpu")
    b = lantern.render(scene, spp=3, seed=11, threads=2, backend="cpu")
    assert a.tobytes() == b.tobytes()


def test_different_seeds_differ(core, backend):
    scene = scenes.cornell_box(width=32, height=32)
    a = lantern.render(scene, spp=2, seed=1, backend=backend)
    b = lantern.render(scene, spp=2, seed=2, backend=backend)
    assert not np.array_equal(a, b)
    # but they agree on average
    assert abs(metrics.mean_relative_difference(a, b)) < 0.2


def test_progress_and_time_limit(core):
    calls = []
    scene = scenes.cornell_box(width=16, height=16)
    lantern.render(scene, spp=4, spp_per_iteration=2, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(2, 4), (4, 4)]
    start = time.monotonic()
    lantern.render(scene, spp=10 ** 6, time_limit=0.5)
    assert time.monotonic() - start < 10


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_cancel_from_another_thread(core, integrator, backend):
    scene = scenes.cornell_box(width=64, height=64)
    probe = lantern.Session(scene, seed=3, integrator=integrator, backend=backend)
    probe.step()  # the first iteration may pay for set-up
    t0 = time.monotonic()
    probe.step()
    per_spp = max(time.monotonic() - t0, 1e-4)
    spi = int(min(4096, max(1, math.ceil(1.5 / per_spp))))  # an iteration of ~1.5 s
    s = lantern.Session(scene, seed=3, spp_per_iteration=spi, integrator=integrator,
                        backend=backend)
    t0 = time.monotonic()
    s.step()
    t_iter = time.monotonic() - t0
    before = s.spp
    done = {}

    def worker():
        start = time.monotonic()
        s.step()
        done["seconds"] = time.monotonic() - start

    th = threading.Thread(target=worker)
    th.start()
    time.sleep(0.1 * t_iter)
    s.cancel()
    th.join(timeout=10 * t_iter + 5)
    assert not th.is_alive(), "step() did not return after cancel()"
    assert done["seconds"] <= t_iter * 1.5 + 0.5, (done, t_iter)
    assert s.spp in (before, before + spi)
    img = s.image()
    assert np.isfinite(img).all() and img.mean() > 0


def test_furnace_direct(core, backend):
    # depth 1: every camera ray hits the emitter: exactly Le, no noise
    scene = scenes.furnace_sphere(albedo=0.5, emission=[1.0, 2.0, 0.5], subdivisions=2,
                                  width=16, height=16)
    img = lantern.render(scene, spp=4, max_depth=1, backend=backend)
    assert np.allclose(img, [1.0, 2.0, 0.5], rtol=1e-5)


@pytest.mark.parametrize("max_depth", [4, 16])
def test_furnace(core, backend, max_depth):
    # closed diffuse sphere, albedo a, emission Le: every pixel -> Le * sum_{k<D} a^k
    albedo, le = 0.5, 1.0
    expected = scenes.furnace_expected(le, albedo, max_depth)
    scene = scenes.furnace_sphere(albedo=albedo, emission=le, subdivisions=3,
                                  width=16, height=16)
    k = 8
    renders = [lantern.render(scene, spp=128, seed=100 + i, max_depth=max_depth,
                              backend=backend) for i in range(k)]
    stack = np.stack(renders).astype(np.float64)
    assert np.isfinite(stack).all()
    mean = stack.mean(axis=0)
    # standard error of the image mean from the spread of the independent renders
    image_means = stack.mean(axis=(1, 2))  # (K, 3)
    se = image_means.std(axis=0, ddof=1) / math.sqrt(k)
    rel = np.abs(image_means.mean(axis=0) - expected) / expected
    assert (rel < 0.005).all(), (image_means.mean(axis=0), expected, se)
    rounding = 1e-5 * expected  # float32 accumulation where the estimator has no variance
    tol = metrics.z_threshold(3, 1e-3, dof=k - 1) * np.sqrt(se ** 2 + rounding ** 2)
    assert (np.abs(image_means.mean(axis=0) - expected) <= tol).all(), (se, tol)
    # per block: consistent with the exact value given the measured noise
    cmp = metrics.compare_sets(renders, expected, block=4, se_floor=float(rounding[0]))
    assert cmp.passed(1e-3), str(cmp)
    # every pixel within 0.5 % once its own noise allows it
    pixel_se = stack.std(axis=0, ddof=1) / math.sqrt(k)
    z_pixel = metrics.z_threshold(mean.size, 1e-3, dof=k - 1)
    bad = np.abs(mean - expected) > np.maximum(0.005 * expected,
                                               z_pixel * np.sqrt(pixel_se ** 2 + rounding ** 2))
    assert not bad.any(), f"{bad.sum()} pixels off"


def test_integrating_sphere_direct(core, backend):
    # depth 2 (direct light only) from a point light at the centre: (a / pi) P / (4 pi R^2);
    # the tessellated sphere is closer than R at facet centres: allow 2 %
    power = 4 * math.pi ** 2
    scene = scenes.integrating_sphere(albedo=0.5, power=power, subdivisions=4,
                                      width=16, height=16)
    img = lantern.render(scene, spp=8, max_depth=2, backend=backend)
    expected = scenes.integrating_sphere_expected(0.5, power, 1.0, 2)
    assert abs(metrics.mean_relative_difference(img, np.broadcast_to(expected, img.shape))) \
        < 0.02


def test_cli_render(core, tmp_path, capsys):
    path = tmp_path / "box.lantern"
    scenes.cornell_box(width=16, height=16).save(path)
    out = tmp_path / "box.exr"
    code = cli.main(["render", str(path), "-o", str(out), "--spp", "4", "--seed", "5",
                     "--png", str(tmp_path / "box.png")])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "4/4 spp" in err
    img = imageio.read_image(out)
    ref = lantern.render(lantern.load_scene(path), spp=4, seed=5)
    assert np.array_equal(img, ref)
    assert (tmp_path / "box.png").exists()
