"""Block statistics and error metrics of images: the layer under lantern/agreement.py.

Images are float arrays (H, W) or (H, W, C). Block statistics crop the image to whole blocks
(the last H % block rows and W % block columns are ignored). Callers import these through
lantern.metrics, which also carries the comparison every render test uses (compare_renders /
assert_agreement, lantern/agreement.py, tests/README.md); this module imports neither."""

import math
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np

from . import student_t


def _as3(img):
    arr = np.asarray(img, dtype=np.float64)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3:
        raise ValueError(f"expected an image (H, W) or (H, W, C), got shape {arr.shape}")
    return arr


def block_means(img, block=8):
    """Mean of each `block` x `block` tile: (H // block, W // block, C) (or without C for a
    2-D input). Partial tiles at the right and bottom edges are dropped."""
    if block < 1:
        raise ValueError(f"block must be >= 1, got {block}")
    squeeze = np.ndim(img) == 2
    arr = _as3(img)
    h, w, c = arr.shape
    bh, bw = h // block, w // block
    if bh == 0 or bw == 0:
        raise ValueError(f"image {h}x{w} is smaller than one {block}x{block} block")
    tiles = arr[:bh * block, :bw * block].reshape(bh, block, bw, block, c)
    means = tiles.mean(axis=(1, 3))
    return means[:, :, 0] if squeeze else means


def _mask3(mask, shape):
    if mask is None:
        return np.ones(shape, dtype=bool)
    m = np.asarray(mask, dtype=bool)
    if m.ndim == 2:
        m = np.broadcast_to(m[:, :, None], shape)
    if m.shape != shape:
        raise ValueError(f"mask shape {np.shape(mask)} does not match image {shape[:2]}")
    return m


def relative_rmse(a, ref, mask=None, eps=1e-2):
    """sqrt(mean((a - ref)^2 / (ref^2 + eps))) over all pixels and channels (or those where
    `mask`, (H, W) or (H, W, C), is true). `eps` keeps dark pixels from dominating."""
    a, ref = _as3(a), _as3(ref)
    if a.shape != ref.shape:
        raise ValueError(f"shapes differ: {a.shape} vs {ref.shape}")
    m = _mask3(mask, a.shape)
    if not m.any():
        raise ValueError("mask selects no pixels")
    err = (a - ref) ** 2 / (ref ** 2 + eps)
    return float(math.sqrt(err[m].mean()))


def rmse(a, ref, mask=None):
    a, ref = _as3(a), _as3(ref)
    if a.shape != ref.shape:
        raise ValueError(f"shapes differ: {a.shape} vs {ref.shape}")
    m = _mask3(mask, a.shape)
    return float(math.sqrt(((a - ref) ** 2)[m].mean()))


def mean_relative_difference(a, ref, mask=None):
    """(mean(a) - mean(ref)) / mean(ref) over the selected pixels: the overall brightness
    bias of `a` against `ref` (0 = same mean; 0.01 = 1 % brighter)."""
    a, ref = _as3(a), _as3(ref)
    if a.shape != ref.shape:
        raise ValueError(f"shapes differ: {a.shape} vs {ref.shape}")
    m = _mask3(mask, a.shape)
    denom = ref[m].mean()
    if denom == 0:
        raise ValueError("reference mean is zero; relative difference undefined")
    return float((a[m].mean() - denom) / denom)


def z_threshold(n_tests, alpha=1e-3, dof=None):
    """|z| a fair comparison of `n_tests` independent z-scores exceeds with probability
    `alpha` in all (Bonferroni: the 1 - alpha / (2 n) quantile). With `dof`, the z-scores use
    estimated standard errors and are Student-t distributed: the exact t quantile
    (lantern.student_t; dof may be fractional, e.g. Welch-Satterthwaite)."""
    if n_tests < 1:
        raise ValueError("n_tests must be >= 1")
    if dof is None:
        return NormalDist().inv_cdf(1.0 - alpha / (2.0 * n_tests))
    if dof < 1:
        raise ValueError("dof must be >= 1")
    return float(student_t.quantile(alpha / n_tests, dof))


def t_tail(t, dof):
    """P(|T| > t) for Student's t with `dof` degrees of freedom."""
    return float(student_t.two_sided_tail(t, dof))


def binomial_bound(n, p, alpha=1e-3):
    """Smallest m with P(Binomial(n, p) > m) <= alpha."""
    total, m = 0.0, 0
    while True:
        total += math.comb(n, m) * p ** m * (1 - p) ** (n - m)
        if 1.0 - total <= alpha:
            return m
        m += 1


def agreement(renders_a, renders_b, block=8, alpha=1e-3):
    """The former cross-integrator rule, kept for callers: two sets of independent renders
    agree when every block passes Bonferroni at `alpha` (Welch dof) and no more blocks exceed
    |z| = 3 than a fair comparison gives (binomial bound at `alpha` on the t tail at the
    conservative dof). Returns (passed, Comparison, over3, allowed). New tests use
    compare_renders, which also tests the image mean."""
    cmp = compare_sets(renders_a, renders_b, block=block)
    allowed = binomial_bound(cmp.n, t_tail(3.0, cmp.dof), alpha)
    over3 = int(np.sum(np.abs(cmp.z) > 3.0))
    return cmp.passed(alpha) and over3 <= allowed, cmp, over3, allowed


@dataclass
class Comparison:
    """Per-block z-scores of a - b: `z` (Bh, Bw, C); `mean_a`, `mean_b`, `se` alike; `dof`
    the conservative degrees of freedom of the estimated standard errors, min(K) - 1 (None:
    known variances); `dof_eff` per block, Welch-Satterthwaite (None: use `dof`)."""
    z: np.ndarray
    mean_a: np.ndarray
    mean_b: np.ndarray
    se: np.ndarray
    dof: int = None
    dof_eff: np.ndarray = None
    n_compared: int = None  # blocks x channels tested (None: all of z)
    bias_cap: float = 0.0   # a relative difference tolerated before p is computed

    @property
    def z_excess(self):
        """z beyond the tolerated difference: sign(z) max(|a - b| - cap |b|, 0) / se."""
        if not self.bias_cap:
            return self.z
        d = np.maximum(np.abs(self.mean_a - self.mean_b) - self.bias_cap * np.abs(self.mean_b),
                       0.0)
        return np.where(self.z == 0, 0.0, np.sign(self.z) * np.abs(_z(d, self.se)))

    @property
    def worst(self):
        """Largest |z| (0 where the standard error is zero and the means agree)."""
        return float(np.max(np.abs(self.z))) if self.z.size else 0.0

    @property
    def worst_index(self):
        return np.unravel_index(int(np.argmax(np.abs(np.nan_to_num(self.z, nan=np.inf)))),
                                self.z.shape)

    @property
    def n(self):
        return int(self.z.size if self.n_compared is None else self.n_compared)

    @property
    def p(self):
        """Two-sided p-value of each block's z beyond the cap (Student t with `dof_eff`, else
        `dof`)."""
        dof = self.dof_eff if self.dof_eff is not None else (
            np.inf if self.dof is None else self.dof)
        return student_t.two_sided_tail(self.z_excess, dof)

    def threshold(self, alpha=1e-3):
        """Bonferroni |z| threshold at the conservative `dof` (worst < threshold implies
        passed(); passed() itself uses each block's own dof)."""
        return z_threshold(self.n, alpha, self.dof)

    def passed(self, alpha=1e-3):
        """True when every block's p-value is above alpha / n (Bonferroni); NaN fails."""
        p = self.p
        return bool(p.size == 0 or (np.all(np.isfinite(p)) and p.min() * self.n > alpha))

    def __str__(self):
        by, bx, c = self.worst_index
        return (f"worst |z| = {self.worst:.2f} at block ({by}, {bx}) channel {c} "
                f"(a = {self.mean_a[by, bx, c]:.6g}, b = {self.mean_b[by, bx, c]:.6g}, "
                f"se = {self.se[by, bx, c]:.3g}, p x n = {self.p[by, bx, c] * self.n:.2g}); "
                f"threshold(1e-3) = {self.threshold():.2f} over {self.n} blocks")


def _z(diff, se):
    with np.errstate(divide="ignore", invalid="ignore"):
        z = diff / se
    z = np.where(se > 0, z, np.where(diff == 0, 0.0, np.copysign(np.inf, diff)))
    return z


def seed_blocks(renders, block=8):
    """K independent renders (list or (K, H, W[, C]) array) -> their block means, one
    (K, Bh, Bw, C) float64 array: what every comparison below works on."""
    if isinstance(renders, SeedBlocks):
        return renders.blocks
    return np.stack([block_means(_as3(r), block) for r in renders])


@dataclass
class SeedBlocks:
    """Per-seed block means (K, Bh, Bw, C) stored in place of the images (e.g. a Cycles
    reference, tests/render/refs/*.npz "seed_block_means"); accepted wherever renders are."""
    blocks: np.ndarray

    def __post_init__(self):
        self.blocks = np.asarray(self.blocks, dtype=np.float64)
        if self.blocks.ndim == 3:
            self.blocks = self.blocks[..., None]
        if self.blocks.ndim != 4:
            raise ValueError(f"expected (K, Bh, Bw, C) block means, got {self.blocks.shape}")

    def __len__(self):
        return len(self.blocks)


def block_stats(renders, block=8):
    """K independent renders (K, H, W[, C]) -> (mean, standard error) of each block's mean,
    both (Bh, Bw, C). The standard error is the sample standard deviation of the K block
    means over sqrt(K): exact whatever the correlation between pixels (filters)."""
    stack = seed_blocks(renders, block)
    k = len(stack)
    if k < 2:
        raise ValueError(f"need at least 2 independent renders, got {k}")
    return stack.mean(axis=0), stack.std(axis=0, ddof=1) / math.sqrt(k)


def _exact_blocks(ref, single_ndim, shape, block):
    """An exact reference (scalar, per channel, or one image) as block means, or None."""
    if isinstance(ref, SeedBlocks):
        return None
    if not isinstance(ref, (list, tuple)) or all(np.ndim(x) == 0 for x in ref):
        ref = np.asarray(ref)
    if isinstance(ref, np.ndarray) and ref.ndim <= 1:  # an exact value, scalar or per channel
        return np.broadcast_to(ref.astype(np.float64), shape).copy()
    if isinstance(ref, np.ndarray) and ref.ndim == single_ndim:  # one exact image
        return block_means(_as3(ref), block)
    return None


def compare_sets(renders_a, renders_b, block=8, se_floor=0.0, rel_floor=0.0):
    """Two sets of independent renders (same scene, different seeds; may differ in size) ->
    per-block z = (mean_a - mean_b) / sqrt(se_a^2 + se_b^2), with Welch-Satterthwaite degrees
    of freedom per block (`dof_eff`; `dof` = min(K) - 1, the conservative bound). `renders_b`
    may instead be one exact reference image (or a scalar/RGB value): then its standard error
    is zero. `se_floor` (absolute) and `rel_floor` (times |mean_b|) are added in quadrature to
    the standard error: an allowance for float rounding where an estimator has (almost) no
    variance. Either side may be a SeedBlocks (stored per-seed block means)."""
    sa = seed_blocks(renders_a, block)
    ka = len(sa)
    if ka < 2:
        raise ValueError(f"need at least 2 independent renders, got {ka}")
    mean_a, se_a = sa.mean(axis=0), sa.std(axis=0, ddof=1) / math.sqrt(ka)
    single_ndim = 3 if isinstance(renders_a, SeedBlocks) else np.ndim(renders_a[0])
    mean_b = _exact_blocks(renders_b, single_ndim, mean_a.shape, block)
    if mean_b is not None:
        se_b, kb = np.zeros_like(mean_a), None
    else:
        sb = seed_blocks(renders_b, block)
        kb = len(sb)
        if kb < 2:
            raise ValueError(f"need at least 2 independent renders, got {kb}")
        mean_b, se_b = sb.mean(axis=0), sb.std(axis=0, ddof=1) / math.sqrt(kb)
    if mean_a.shape != mean_b.shape:
        raise ValueError(f"block grids differ: {mean_a.shape} vs {mean_b.shape}")
    dof = ka - 1 if kb is None else min(ka, kb) - 1
    floor2 = float(se_floor) ** 2 + (float(rel_floor) * np.abs(mean_b)) ** 2
    se = np.sqrt(se_a ** 2 + se_b ** 2 + floor2)
    dof_eff = np.maximum(student_t.welch_dof(se_a ** 2, ka, se_b ** 2, kb), dof)
    return Comparison(_z(mean_a - mean_b, se), mean_a, mean_b, se, dof, dof_eff)


def compare_to_reference(img_a, var_a, img_b, var_b, block=8):
    """Per-block z-scores of two mean images with per-pixel variances of those means.

    `img_a`, `img_b`: mean images (H, W[, C]). `var_a`, `var_b`: the variance of each pixel's
    mean estimate (the squared standard error: sample variance of the samples / N), same shape,
    or None / 0 for an exact reference. Pixels are taken as independent, so a block mean's
    variance is sum(var) / n^2 over its n pixels; with a reconstruction filter wider than a
    pixel neighbours correlate and this underestimates the variance (use `compare_sets` with
    independent renders where that matters). Returns a `Comparison`: `z` per block and channel,
    `worst` the largest |z|, `passed(alpha)` against the Bonferroni threshold."""
    a, b = _as3(img_a), _as3(img_b)
    if a.shape != b.shape:
        raise ValueError(f"shapes differ: {a.shape} vs {b.shape}")

    def block_var(var):
        if var is None:
            return np.zeros((a.shape[0] // block, a.shape[1] // block, a.shape[2]))
        v = np.broadcast_to(_as3(var) if np.ndim(var) >= 2 else np.asarray(var, float),
                            a.shape)
        if (np.asarray(v) < 0).any():
            raise ValueError("variances must be >= 0")
        return block_means(v, block) / (block * block)

    mean_a, mean_b = block_means(a, block), block_means(b, block)
    se = np.sqrt(block_var(var_a) + block_var(var_b))
    return Comparison(_z(mean_a - mean_b, se), mean_a, mean_b, se)
