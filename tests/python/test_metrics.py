"""Metrics on synthetic data with known answers."""
import math

import numpy as np
import pytest

from lantern import metrics


def test_block_means_known():
    img = np.arange(36, dtype=np.float64).reshape(6, 6)
    bm = metrics.block_means(img, 2)
    assert bm.shape == (3, 3)
    assert bm[0, 0] == (0 + 1 + 6 + 7) / 4 and bm[2, 2] == (28 + 29 + 34 + 35) / 4
    rgb = np.stack([img, 2 * img, 3 * img], axis=2)
    assert np.allclose(metrics.block_means(rgb, 3)[:, :, 2], 3 * metrics.block_means(img, 3))
    # partial blocks are dropped
    assert metrics.block_means(np.ones((10, 17, 3)), 8).shape == (1, 2, 3)
    with pytest.raises(ValueError, match="smaller than one"):
        metrics.block_means(np.ones((4, 4)), 8)


def test_relative_rmse_and_bias():
    ref = np.full((8, 8, 3), 2.0)
    a = ref * 1.1
    assert math.isclose(metrics.relative_rmse(a, ref, eps=0.0), 0.1, rel_tol=1e-12)
    assert math.isclose(metrics.relative_rmse(a, ref), 0.2 / math.sqrt(4.01), rel_tol=1e-12)
    assert metrics.relative_rmse(ref, ref) == 0.0
    assert math.isclose(metrics.mean_relative_difference(a, ref), 0.1, rel_tol=1e-12)
    assert math.isclose(metrics.rmse(a, ref), 0.2, rel_tol=1e-12)
    mask = np.zeros((8, 8), dtype=bool)
    mask[:2] = True
    b = ref.copy()
    b[:2] *= 1.5
    assert math.isclose(metrics.mean_relative_difference(b, ref, mask=mask), 0.5)
    assert metrics.mean_relative_difference(b, ref, mask=~mask) == 0.0
    with pytest.raises(ValueError, match="shapes differ"):
        metrics.relative_rmse(a, ref[:4])


def test_z_threshold():
    assert math.isclose(metrics.z_threshold(1, alpha=0.05), 1.959964, rel_tol=1e-5)
    # Student t, 10 dof, two-sided 5 %: 2.228
    assert abs(metrics.z_threshold(1, alpha=0.05, dof=10) - 2.228) < 0.01
    assert metrics.z_threshold(100) > metrics.z_threshold(10)


def noisy_set(rng, k, mean, sigma, shape=(32, 32, 3)):
    return [mean + sigma * rng.standard_normal(shape) for _ in range(k)]


def test_compare_sets_null_and_bias():
    rng = np.random.default_rng(11)
    a = noisy_set(rng, 16, 1.0, 0.2)
    b = noisy_set(rng, 12, 1.0, 0.2)
    same = metrics.compare_sets(a, b, block=8)
    assert same.z.shape == (4, 4, 3) and same.dof == 11
    assert same.passed(), str(same)
    # se of a block mean: 0.2 / 8 / sqrt(K)
    assert np.allclose(same.se.mean(), 0.2 / 8 * math.sqrt(1 / 16 + 1 / 12), rtol=0.2)
    shifted = metrics.compare_sets(a, [x + 0.05 for x in b], block=8)
    assert not shifted.passed() and shifted.worst > 5
    assert "worst |z|" in str(shifted)


def test_compare_sets_against_exact_value():
    rng = np.random.default_rng(12)
    a = noisy_set(rng, 16, 0.5, 0.1)
    assert metrics.compare_sets(a, 0.5).passed()
    assert metrics.compare_sets(a, [0.5, 0.5, 0.5]).passed()
    assert metrics.compare_sets(a, np.full((32, 32, 3), 0.5)).passed()
    assert not metrics.compare_sets(a, 0.52).passed()


def test_compare_to_reference_known_variance():
    rng = np.random.default_rng(13)
    n = 64  # samples per pixel
    samples = 1.0 + 0.5 * rng.standard_normal((n, 32, 32, 3))
    mean = samples.mean(axis=0)
    var_of_mean = samples.var(axis=0, ddof=1) / n
    c = metrics.compare_to_reference(mean, var_of_mean, np.ones_like(mean), None, block=8)
    assert c.passed(), str(c)
    # block se = sigma / sqrt(n * 64)
    assert np.allclose(c.se, 0.5 / math.sqrt(n * 64), rtol=0.1)
    biased = metrics.compare_to_reference(mean * 1.1, var_of_mean, np.ones_like(mean),
                                          var_of_mean)
    assert not biased.passed()
    exact = metrics.compare_to_reference(np.ones((8, 8)), 0.0, np.ones((8, 8)), None)
    assert exact.worst == 0.0
    off = metrics.compare_to_reference(np.ones((8, 8)), 0.0, np.zeros((8, 8)), None)
    assert off.worst == math.inf and not off.passed()


def test_false_alarm_rate_is_near_alpha():
    rng = np.random.default_rng(14)
    trials, alpha = 200, 0.1
    fails = sum(not metrics.compare_sets(noisy_set(rng, 8, 0.0, 1.0, (16, 16)), 0.0,
                                         block=4).passed(alpha) for _ in range(trials))
    assert fails / trials < 2.5 * alpha
