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
    # Student t, two-sided 5 % and 0.1 % (tables: Abramowitz & Stegun 26.10), small dof
    # included, where a Cornish-Fisher expansion is several per cent off
    for dof, t05, t001 in ((1, 12.7062, 636.619), (2, 4.30265, 31.5991), (3, 3.18245, 12.9240),
                           (5, 2.57058, 6.86883), (7, 2.36462, 5.40788), (10, 2.22814, 4.58689),
                           (30, 2.04227, 3.64600)):
        assert math.isclose(metrics.z_threshold(1, alpha=0.05, dof=dof), t05, rel_tol=1e-4)
        assert math.isclose(metrics.z_threshold(1, alpha=1e-3, dof=dof), t001, rel_tol=1e-4)
        assert math.isclose(metrics.t_tail(t05, dof), 0.05, rel_tol=1e-3)
    # fractional dof (Welch) lie between their neighbours; Bonferroni grows with n
    assert metrics.z_threshold(1, 0.05, 7) > metrics.z_threshold(1, 0.05, 7.5) > \
        metrics.z_threshold(1, 0.05, 8)
    assert metrics.z_threshold(100) > metrics.z_threshold(10)
    assert math.isclose(metrics.z_threshold(48, 1e-3, dof=7), 10.04, rel_tol=1e-3)


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


def _rate_bounds(trials, alpha, level=1e-4):
    """(lo, hi): a fair rate alpha gives a count outside [lo, hi] with probability < 2 level."""
    hi = metrics.binomial_bound(trials, alpha, level)
    cdf, lo = 0.0, 0
    while True:
        cdf += math.comb(trials, lo) * alpha ** lo * (1 - alpha) ** (trials - lo)
        if cdf > level:
            return lo, hi
        lo += 1


def test_false_alarm_rate_is_near_alpha():
    """Bonferroni over independent blocks is close to exact: the rate must sit in the
    binomial interval around alpha (an infinite threshold, or one far too low, fails)."""
    rng = np.random.default_rng(14)
    trials, alpha = 400, 0.1
    fails = sum(not metrics.compare_sets(noisy_set(rng, 8, 0.0, 1.0, (16, 16)), 0.0,
                                         block=4).passed(alpha) for _ in range(trials))
    lo, hi = _rate_bounds(trials, alpha * 0.95)  # 1 - (1 - a/n)^n is a little under a
    assert lo <= fails <= hi, (fails, lo, hi)


def test_welch_false_alarm_rate_with_unequal_sets():
    """4 noisy seeds against 32 quiet ones: the Welch dof (near 3, not min(K) - 1 = 3 for all
    cases) keeps the rate at alpha; a z-test with normal quantiles would alarm far more."""
    rng = np.random.default_rng(15)
    trials, alpha = 300, 0.1
    fails = 0
    for _ in range(trials):
        a = noisy_set(rng, 4, 0.0, 2.0, (8, 8, 1))
        b = noisy_set(rng, 32, 0.0, 0.5, (8, 8, 1))
        cmp = metrics.compare_sets(a, b, block=4)
        assert cmp.dof == 3 and (cmp.dof_eff >= 3).all()
        fails += not cmp.passed(alpha)
    lo, hi = _rate_bounds(trials, alpha * 0.95)
    assert lo <= fails <= hi, (fails, lo, hi)


def test_compare_renders_null_and_controls():
    rng = np.random.default_rng(16)
    tint = np.array([1.0, 0.7, 0.4])
    a = [tint * (1 + 0.05 * rng.standard_normal((32, 32, 3))) for _ in range(16)]
    b = [tint * (1 + 0.05 * rng.standard_normal((32, 32, 3))) for _ in range(12)]
    res = metrics.compare_renders(a, b, block=8)
    assert res.passed, str(res)
    assert res.blocks.n == 48 and res.detectable_bias() < 0.01
    controls = dict(metrics.negative_controls(a, b, block=8))
    assert len(controls) == 5 and not any(c.passed for c in controls.values())
    # a grey image has no channel swap to try; a mask leaves blocks out of both parts
    grey = [np.repeat(x[..., :1], 3, axis=2) for x in a]
    assert len(metrics.negative_controls(grey, 1.0, block=8)) == 4
    mask = np.ones((4, 4), bool)
    mask[0, 0] = False
    off = [x.copy() for x in a]
    for x in off:
        x[:8, :8] *= 3.0
    assert not metrics.compare_renders(off, b).passed
    masked = metrics.compare_renders(off, b, mask=mask)
    assert masked.passed and masked.blocks.n == 45, str(masked)
    # the bias cap: 0.15 % off with almost no noise passes under the 0.2 % cap, 0.3 % fails
    quiet = [tint * (1 + 1e-5 * rng.standard_normal((32, 32, 3))) for _ in range(8)]
    assert metrics.compare_renders([x * 1.0015 for x in quiet], tint).passed
    assert not metrics.compare_renders([x * 1.003 for x in quiet], tint).passed
    assert "DIFFER" in str(metrics.compare_renders([x * 1.003 for x in quiet], tint))


def test_compare_renders_mean_false_alarm_rate():
    """The image-mean test alone, cap 0: its false-alarm rate is alpha (exact t)."""
    rng = np.random.default_rng(17)
    trials, alpha = 300, 0.1
    fails = sum(not metrics.compare_renders(noisy_set(rng, 6, 1.0, 0.5, (8, 8, 1)),
                                            noisy_set(rng, 10, 1.0, 0.2, (8, 8, 1)),
                                            block=8, alpha=alpha, bias_cap=0.0).mean_passed
                for _ in range(trials))
    lo, hi = _rate_bounds(trials, alpha)
    assert lo <= fails <= hi, (fails, lo, hi)


def test_block_weighted_mean_weights_by_noise():
    """Two of 16 blocks 10x noisier (an emitter, a caustic): the block-weighted mean weights
    blocks by their precision (floored at the median block's), so its standard error is well
    under the image mean's, and its false-alarm rate stays at alpha (16 seeds a side, and 16
    against an exact value); with fewer than PRECISION_SEEDS seeds the weights are equal."""
    from lantern import agreement
    rng = np.random.default_rng(20)
    sd = np.full((32, 32, 1), 0.3)
    sd[:8, :16] = 3.0

    def hetero(k):
        return [1.0 + sd * rng.standard_normal(sd.shape) for _ in range(k)]
    trials, alpha = 400, 0.1
    for other in (16, None):
        fails, ratio = 0, []
        for _ in range(trials):
            res = metrics.compare_renders(hetero(16), hetero(other) if other else 1.0, block=8,
                                          alpha=alpha, bias_cap=0.0)
            fails += res.mean_p[1, 0] < alpha
            ratio.append(res.rel_se[1, 0] / res.rel_se[0, 0])
        lo, hi = _rate_bounds(trials, alpha)
        assert lo <= fails <= hi, (other, fails, lo, hi)
        assert np.median(ratio) < 0.5, (other, np.median(ratio))
    few = metrics.compare_renders(hetero(agreement.PRECISION_SEEDS - 1), 1.0, block=8)
    # equal weights over the 16 blocks: the weighted mean is the image mean here
    assert abs(few.rel[1, 0] - few.rel[0, 0]) < 1e-12
