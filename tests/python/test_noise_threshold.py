"""addon/final_render.py's noise-threshold stop (Cycles' error measure) on synthetic sample
streams: the error it computes is Cycles' formula, its size follows the noise as theory says
(E|I - A| = sigma * sqrt(2 / pi) / sqrt(n) per channel for Gaussian samples), and the frame
converges once n passes the sample count that threshold implies. Loaded without bpy."""

import importlib.util
import math
from pathlib import Path

import numpy as np

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


def test_error_follows_the_noise():
    rng = np.random.default_rng(1)
    mu, sigma, n = 0.5, 0.2, 64
    check = final_render.NoiseCheck(1e-9, min_samples=n)
    errors = []
    for image, spp in _stream(rng, mu, sigma, n):
        check.add(image, spp)
        if spp == n:
            half = check._half_sum / check._half_spp
            diff = np.abs(image - half).sum(axis=2)
            errors = diff / (1e-4 + final_render.error_norm(image.sum(axis=2)))
    expect = 3 * sigma * math.sqrt(2 / math.pi) / math.sqrt(n) / (3 * mu)  # 3 mu > 1
    # 4096 pixels: the mean error is known to about 1%
    assert abs(errors.mean() / expect - 1) < 0.05
    assert math.isclose(check.error, float(errors.max()), rel_tol=1e-6)


def test_converges_when_the_noise_is_low_enough():
    rng = np.random.default_rng(2)
    mu, sigma = 0.3, 0.1  # R + G + B = 0.9 < 1: its square root normalises
    check = final_render.NoiseCheck(0.05, min_samples=4)
    stopped = None
    for image, spp in _stream(rng, mu, sigma, 400, shape=(16, 16, 3)):
        if check.add(image, spp):
            stopped = spp
            break
    assert stopped is not None
    # max over 256 pixels of |N| ~ 3 sigma-equivalents: per-pixel error ~ 3 * sigma * 1.8 /
    # sqrt(n) / sqrt(0.9): below 0.05 from n ~ 130; never before the noise allows it
    assert 30 < stopped < 300
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
