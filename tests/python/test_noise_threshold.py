"""addon/final_render.py's noise-threshold stop (Cycles' error measure) on synthetic sample
streams: the error it computes is Cycles' formula, its size follows the noise as theory says
(E|I - A| = sigma * sqrt(2 / pi) / sqrt(n) per channel for Gaussian samples), and the frame
converges once n passes the sample count that threshold implies. Loaded without bpy."""

import importlib.util
import math
from pathlib import Path

import numpy as np

from lantern import metrics

_path = Path(__file__).resolve().parents[2] / "addon" / "final_render.py"
_spec = importlib.util.spec_from_file_location("lantern_final_render", _path)
final_render = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(final_render)


def _stream(rng, mean, sigma, steps, shape=(64, 64, 3)):
    """Running means after each one-sample step, as Session.image() returns them."""
    total = np.zeros(shape)
    for n in range(1, steps + 1):
        total += mean + sigma * rng.standard_normal(shape)
        yield (total / n).astype(np.float32), n


def test_error_is_cycles_formula():
    check = final_render.NoiseCheck(0.01, min_samples=2)
    a = np.array([[[1.0, 2.0, 3.0]]], dtype=np.float32)
    b = np.array([[[3.0, 2.0, 1.0]]], dtype=np.float32)
    imgs = [a, a, b, b]             # samples 2 and 3 are the "A" half (odd bits' parity)
    for n in range(1, 5):
        check.add((sum(imgs[:n]) / n).astype(np.float32), n)
    mean, half = (a + b) / 2, b
    # R + G + B = 6 > 1: Cycles divides by the intensity itself, not its square root
    want = np.abs(mean - half).sum() / (1e-4 + mean.sum())
    assert math.isclose(check.error, float(want), rel_tol=1e-6)
    dim = final_render.NoiseCheck(0.01, min_samples=2)
    for n in range(1, 5):
        dim.add((sum(imgs[:n]) / n / 20).astype(np.float32), n)
    want = np.abs(mean - half).sum() / 20 / (1e-4 + math.sqrt(mean.sum() / 20))
    assert math.isclose(dim.error, float(want), rel_tol=1e-5)


def _expected_error(mu, sigma, n, channels=3):
    """E[error] for Gaussian samples of mean mu, deviation sigma, at n samples (n a multiple
    of 4, so that half A holds n / 2): I - A = (S_B - S_A) / n ~ N(0, sigma^2 / n) per
    channel, so E|I - A|_1 = channels sigma sqrt(2 / pi) / sqrt(n); the normaliser's argument
    R + G + B ~ N(channels mu, channels sigma^2 / n) is independent of it (S_A + S_B against
    S_B - S_A, equal halves), so E[1 / (1e-4 + norm)] is integrated over that normal
    (Gauss-Hermite, 40 nodes: its curvature adds ~0.1 % at the settings below)."""
    x, w = np.polynomial.hermite_e.hermegauss(40)
    total = channels * mu + math.sqrt(channels / n) * sigma * x
    norm = np.where(total < 1.0, np.sqrt(np.maximum(total, 0.0)), total)
    inv = float((w / (1e-4 + norm)).sum() / w.sum())
    return channels * sigma * math.sqrt(2 / math.pi) / math.sqrt(n) * inv


def _mean_test(errors, expect, z_max):
    """|mean(errors) / expect - 1| within z_max standard errors (the pixels are independent)."""
    se = errors.std(ddof=1) / math.sqrt(errors.size)
    return abs(errors.mean() - expect) <= z_max * se, (errors.mean() - expect) / se


def test_error_follows_the_noise():
    rng = np.random.default_rng(1)
    mu, sigma, n = 0.5, 0.2, 64
    # 256 x 256 independent pixels: the mean error's standard error is 0.436 / 256 = 0.17 %
    # of it (the sum of three half-normals has a relative deviation 0.755 / sqrt(3)), so a
    # 1 % error in the formula reads 5.9 se against the 3.29 that fails
    check = final_render.NoiseCheck(1e-9, min_samples=n)
    errors = []
    for image, spp in _stream(rng, mu, sigma, n, shape=(256, 256, 3)):
        check.add(image, spp)
        if spp == n:
            half = check._half_sum / check._half_spp
            diff = np.abs(image - half).sum(axis=2)
            errors = diff / (1e-4 + final_render.error_norm(image.sum(axis=2)))
    expect = _expected_error(mu, sigma, n)
    z_max = metrics.z_threshold(1, 1e-3)           # two-sided, alpha 1e-3
    ok, z = _mean_test(errors, expect, z_max)
    print(f"mean error {errors.mean():.6g} expected {expect:.6g}: z {z:+.2f} (max {z_max:.2f})")
    assert ok, (errors.mean(), expect, z)
    # negative controls: an expectation 1 % off either way is told apart
    for bias in (0.01, -0.01):
        assert not _mean_test(errors, expect * (1 + bias), z_max)[0], bias
    assert math.isclose(check.error, float(errors.max()), rel_tol=1e-6)


def test_converges_when_the_noise_is_low_enough():
    """The frame stops at the first check where every pixel's error, recomputed here from the
    stream (Cycles' formula written out again), is below the threshold; not one step before."""
    rng = np.random.default_rng(2)
    mu, sigma = 0.3, 0.1  # R + G + B = 0.9 < 1: its square root normalises
    check = final_render.NoiseCheck(0.05, min_samples=4)
    stopped, total, half, n_half, first = None, 0.0, 0.0, 0, None
    for image, spp in _stream(rng, mu, sigma, 400, shape=(16, 16, 3)):
        sample = image.astype(np.float64) * spp - total
        total = total + sample
        if final_render.half_a(spp - 1, 1):
            half, n_half = half + sample, n_half + 1
        if first is None and spp >= 4 and 0 < n_half < spp:
            i = total / spp
            s = i.sum(axis=2)
            err = np.abs(i - half / n_half).sum(axis=2) / (1e-4 + np.where(s < 1, np.sqrt(s), s))
            if err.max() < 0.05:
                first = spp
        if check.add(image, spp):
            stopped = spp
            break
    assert stopped is not None and stopped == first, (stopped, first)
    assert check.error < 0.05


def test_halves_alternate_in_blocks_of_four():
    """Not every other sample: the parity of the index's odd bits (Cycles' split), so each
    half of the QMC points is spread over the pixel; steps of several samples go whole."""
    a = [final_render.half_a(k, 1) for k in range(32)]
    assert a[:8] == [False, False, True, True, False, False, True, True]
    assert all(sum(a[k:k + 4]) == 2 for k in range(0, 32, 4))
    assert a[8:16] == [not x for x in a[:8]]
    assert [final_render.half_a(16 * k, 16) for k in range(4)] == [False, False, True, True]


def test_automatic_min_samples_as_cycles():
    assert final_render.auto_min_samples(0.01) == 64
    assert final_render.auto_min_samples(0.1) == 32
    assert final_render.NoiseCheck(0.01).min_samples == 64
