"""The one statistical comparison of renders (tests/README.md): per-block agreement plus a test
on the image mean, and the negative controls that prove a comparison can fail.

compare_renders(a, b): a, b are sets of independent renders (different seeds), stored per-seed
block means (metrics.SeedBlocks) or, for b, an exact value or image.
- blocks: z = (mean_a - mean_b) / se per block and channel, Student t with Welch-Satterthwaite
  dof per block; all must pass Bonferroni at `alpha` over the blocks compared (beyond the same
  tolerated relative difference `bias_cap` as the mean).
- the overall level, per channel, twice: the image mean, and the mean of the blocks relative to
  their reference level (each block with signal weighted by the inverse of its relative
  variance, floored at the median block's: _precision). Each passes when
  |relative difference| <= bias_cap + t(alpha / 2C, Welch dof) se, se from the spread of the
  seeds' values: a z-test that tolerates a stated systematic difference `bias_cap` (0.2 %).
False alarms: at most alpha for each of the two parts (2 alpha in all).
negative_controls(a, b): the same comparison with a known bias injected into a (1 % on the
whole image, +5 % on one block, two channels swapped); each must fail."""

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from . import blocks as stats, student_t

DEFAULT_ALPHA = 1e-3
DEFAULT_BIAS_CAP = 0.002    # a systematic image-mean difference tolerated (0.2 %)
POWER_Z = 2.33              # one-sided normal quantile for 99 % power ("detectable")
CONTROL_IMAGE_BIAS = 0.01
CONTROL_BLOCK_BIAS = 0.05


MEAN_TESTS = ("image mean", "block-weighted mean")
SIGNAL_FRACTION = 0.05      # blocks under this fraction of the mean stay out of the weighted mean
PRECISION_SEEDS = 12        # seeds a side from which the weighted mean weights blocks by noise


@dataclass
class Agreement:
    """The verdict of compare_renders: `blocks` (a metrics.Comparison; masked-out blocks have
    z = 0 and do not count) and two tests of the overall level, per channel, in relative
    terms (rows of `rel`, `rel_se`, `rel_dof`): the image mean, and the mean of each block
    relative to its reference level (every block with signal weighted by its precision, at most
    the median block's, so that a bright, noisy emitter does not hide a bias elsewhere).
    `mean_a`, `mean_b`: image means."""
    blocks: stats.Comparison
    mean_a: np.ndarray
    mean_b: np.ndarray
    rel: np.ndarray
    rel_se: np.ndarray
    rel_dof: np.ndarray
    alpha: float
    bias_cap: float
    mask: np.ndarray = None
    name: str = ""
    notes: list = field(default_factory=list)

    @property
    def mean_rel(self):
        """(mean_a - mean_b) / mean_b per channel: the image mean's relative difference."""
        return self.rel[0]

    @cached_property
    def mean_threshold(self):
        """t quantiles of the mean tests (Bonferroni over both tests and the channels)."""
        return student_t.quantile(self.alpha / self.rel.size, self.rel_dof)

    @property
    def mean_p(self):
        """P(a fair comparison exceeds the observed |difference| beyond the cap), per test
        and channel: the two-sided t tail of (|rel| - cap)+ / se (1 within the cap)."""
        z = stats._z(np.maximum(np.abs(self.rel) - self.bias_cap, 0.0), self.rel_se)
        return student_t.two_sided_tail(np.where(np.isnan(self.rel), np.nan, z), self.rel_dof)

    @property
    def mean_allowed(self):
        """The largest relative difference each mean test accepts (tests x channels)."""
        return self.bias_cap + self.mean_threshold * self.rel_se

    @property
    def mean_passed(self):
        p = self.mean_p
        return bool(np.all(np.isfinite(p)) and p.min() * p.size > self.alpha)

    @property
    def blocks_passed(self):
        return self.blocks.passed(self.alpha)

    @property
    def passed(self):
        return self.mean_passed and self.blocks_passed

    def __bool__(self):
        return self.passed

    def detectable_bias(self):
        """Smallest relative whole-image bias the mean tests flag with ~99 % probability:
        bias_cap + (threshold + 2.33) se, the better of the two tests (worst channel)."""
        r = self.bias_cap + (self.mean_threshold + POWER_Z) * self.rel_se
        return float(np.min(np.max(np.where(np.isfinite(r), r, np.inf), axis=1)))

    def block_resolution(self):
        """Per block and channel, the smallest relative bias of that block alone the block
        test flags with ~99 % probability (cap + (Bonferroni threshold + 2.33) se / |mean_b|)."""
        cmp = self.blocks
        thr = student_t.quantile(self.alpha / cmp.n, cmp.dof_eff)
        with np.errstate(divide="ignore", invalid="ignore"):
            r = self.bias_cap + (thr + POWER_Z) * cmp.se / np.abs(cmp.mean_b)
        return np.where(np.abs(cmp.mean_b) > 0, r, np.inf)

    def __str__(self):
        cmp = self.blocks
        tests = "; ".join(
            f"{label} rel. diff [{', '.join(f'{x:+.3%}' for x in self.rel[t])}] (allowed "
            f"{np.max(self.mean_allowed[t]):.3%})" for t, label in enumerate(MEAN_TESTS))
        head = f"{self.name}: " if self.name else ""
        return (f"{head}{'agree' if self.passed else 'DIFFER'}; {tests}: cap "
                f"{self.bias_cap:.2%} + t {np.max(self.mean_threshold):.2f} se, "
                f"{'ok' if self.mean_passed else 'FAIL'}; blocks ({cmp.n} compared, Welch dof >= "
                f"{np.min(cmp.dof_eff):.1f}): {cmp}; {'ok' if self.blocks_passed else 'FAIL'}; "
                f"detects a whole-image bias >= {self.detectable_bias():.2%}"
                + "".join(f"; {n}" for n in self.notes))


def _level_test(per_seed_a, per_seed_b, level):
    """Relative difference of two per-seed statistics (K, C) over `level` (C), its standard
    error and Welch dof; per_seed_b None: b is exactly `level`."""
    ka = len(per_seed_a)
    se2_a = per_seed_a.var(axis=0, ddof=1) / ka
    mean_a = per_seed_a.mean(axis=0)
    if per_seed_b is None:
        mean_b, se2_b, kb = level, np.zeros_like(mean_a), None
    else:
        kb = len(per_seed_b)
        mean_b, se2_b = per_seed_b.mean(axis=0), per_seed_b.var(axis=0, ddof=1) / kb
    dof = np.maximum(student_t.welch_dof(se2_a, ka, se2_b, kb),
                     (ka if kb is None else min(ka, kb)) - 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(mean_a == mean_b, 0.0, (mean_a - mean_b) / np.abs(level))
        se = np.where(level != 0, np.sqrt(se2_a + se2_b) / np.abs(level), np.inf)
    return rel, se, dof


def compare_renders(renders_a, renders_b, block=8, alpha=DEFAULT_ALPHA,
                    bias_cap=DEFAULT_BIAS_CAP, mask=None, se_floor=0.0, rel_floor=1e-5,
                    name=""):
    """Compare two sets of independent renders (module docstring). `mask` (Bh, Bw) bool
    selects the blocks compared (default all); `se_floor` (absolute) and `rel_floor` (times
    |mean_b|) are float-rounding allowances added in quadrature to every standard error."""
    sa = stats.seed_blocks(renders_a, block)
    b = _as_b(renders_b, block, sa.shape[1:])
    cmp = stats.compare_sets(stats.SeedBlocks(sa), b, block, se_floor=se_floor,
                               rel_floor=rel_floor)
    bh, bw, c = cmp.z.shape
    mask = np.ones((bh, bw), bool) if mask is None else np.asarray(mask, bool)
    if mask.shape != (bh, bw):
        raise ValueError(f"mask {mask.shape} does not match the block grid {(bh, bw)}")
    if not mask.any():
        raise ValueError("mask selects no blocks")
    cmp.z = np.where(mask[..., None], cmp.z, 0.0)
    cmp.n_compared = int(mask.sum()) * c
    cmp.bias_cap = float(bias_cap)
    sb = b.blocks if isinstance(b, stats.SeedBlocks) else None
    # ---- the image mean ----
    ma = sa[:, mask].mean(axis=1)
    mb = None if sb is None else sb[:, mask].mean(axis=1)
    level = cmp.mean_b[mask].mean(axis=0) if sb is None else mb.mean(axis=0)
    r0, s0, d0 = _level_test(ma, mb, level)
    # ---- every block with signal relative to its level, weighted by its precision ----
    ref = cmp.mean_b if sb is None else 0.5 * (cmp.mean_a + cmp.mean_b)
    signal = mask[..., None] & (np.abs(ref) >= SIGNAL_FRACTION * np.abs(ref[mask]).mean(axis=0))
    signal &= np.abs(ref) > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.where(signal, _precision(sa, sb, ref, signal) / np.abs(ref), 0.0)
        w /= np.maximum((w * np.abs(ref)).sum(axis=(0, 1)), 1e-300)
    wa = (sa * w).sum(axis=(1, 2))
    wb = None if sb is None else (sb * w).sum(axis=(1, 2))
    lw = (cmp.mean_b * w).sum(axis=(0, 1)) if sb is None else wb.mean(axis=0)
    r1, s1, d1 = _level_test(wa, wb, np.where(signal.any(axis=(0, 1)), 1.0, 0.0) if sb is None
                             else np.where(signal.any(axis=(0, 1)), lw, 0.0))
    floor = np.sqrt(se_floor ** 2 / mask.sum() / np.maximum(np.abs(level), 1e-300) ** 2
                    + rel_floor ** 2)
    rel_se = np.sqrt(np.stack([s0, s1]) ** 2 + floor ** 2)
    return Agreement(cmp, ma.mean(axis=0), level, np.stack([r0, r1]), rel_se,
                     np.stack([d0, d1]), alpha, bias_cap, mask, name)


def _precision(sa, sb, ref, signal):
    """Weights of the blocks in the block-weighted mean: the inverse of each block's relative
    variance (both sides, averaged over the channels), floored at the median block's and held
    within 16x of it, so that noisy blocks (an emitter, a caustic, a glossy highlight) count
    less and no block counts more than the median one. On the Cornell box this resolves a
    uniform bias with 0.6-0.8x the standard error of equal weights. Weights from the same
    seeds favour the blocks whose variance came out low; with the floor that keeps the
    false-alarm rate at alpha from 12 seeds a side (test_metrics.py); with fewer (6-10) it
    rose 1.3-1.6x, so below PRECISION_SEEDS, and where there is no noise, all weights are
    equal."""
    if min(len(sa), len(sa) if sb is None else len(sb)) < PRECISION_SEEDS:
        return np.ones(ref.shape)
    var = sa.var(axis=0, ddof=1) / len(sa)
    if sb is not None:
        var = var + sb.var(axis=0, ddof=1) / len(sb)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(signal, var / ref ** 2, np.nan)
    v = _nanmean_stack(np.moveaxis(rel, 2, 0))
    if not np.isfinite(v).any():
        return np.ones(ref.shape)
    med = float(np.nanmedian(v))
    if not med > 0:
        return np.ones(ref.shape)
    p = 1.0 / np.clip(np.nan_to_num(v, nan=med), med, 16.0 * med)
    return np.broadcast_to(p[..., None], ref.shape)


def _nanmean_stack(x):
    """Mean over axis 0 of the finite entries (NaN where there are none), without warnings."""
    n = np.isfinite(x).sum(axis=0)
    return np.where(n > 0, np.nansum(x, axis=0) / np.maximum(n, 1), np.nan)


def _as_b(renders_b, block, grid):
    """renders_b as SeedBlocks, or as it is when it is an exact value or image."""
    if isinstance(renders_b, stats.SeedBlocks):
        return renders_b
    if stats._exact_blocks(renders_b, 3, grid, block) is not None:
        return renders_b
    return stats.SeedBlocks(stats.seed_blocks(renders_b, block))


# ---- Negative controls ----

def control_block(agreement):
    """The block the +5 % control goes into: among the compared blocks carrying at least a
    tenth of the mean signal, the one with the median relative noise (a typical block)."""
    cmp = agreement.blocks
    lum = np.abs(cmp.mean_b).mean(axis=2)
    rel = (cmp.se.mean(axis=2) / np.where(lum > 0, lum, np.inf))
    ok = agreement.mask & (lum >= 0.1 * lum[agreement.mask].mean()) & (lum > 0)
    idx = np.argwhere(ok)
    order = np.argsort(rel[ok], kind="stable")
    by, bx = idx[order[len(order) // 2]]
    return int(by), int(bx)


def _swap_pair(mean_b):
    """The two channels whose image means differ most, when they differ by >= 2 %."""
    if len(mean_b) < 2:
        return None
    best, pair = 0.0, None
    for i in range(len(mean_b)):
        for j in range(i + 1, len(mean_b)):
            s = abs(mean_b[i]) + abs(mean_b[j])
            d = 2 * abs(mean_b[i] - mean_b[j]) / s if s > 0 else 0.0
            if d > best:
                best, pair = d, (i, j)
    return pair if best >= 0.02 else None


def negative_controls(renders_a, renders_b, block=8, image_bias=CONTROL_IMAGE_BIAS,
                      block_bias=CONTROL_BLOCK_BIAS, **kwargs):
    """[(label, Agreement)]: compare_renders(a', b) for a' = a with a known bias injected into
    every seed's block means: +-image_bias (1 %) on the whole image, +-block_bias (5 %) on one
    typical block (control_block), two channels swapped. The swap is left out where the
    reference's channel means are the same within 2 % (a grey image: it changes nothing)."""
    sa = stats.seed_blocks(renders_a, block)
    base = compare_renders(stats.SeedBlocks(sa), renders_b, block, **kwargs)
    by, bx = control_block(base)
    out = []
    for sign in (1.0, -1.0):  # both signs: a difference already there cannot mask one
        out.append((f"{sign * image_bias:+.1%} on the whole image",
                    stats.SeedBlocks(sa * (1.0 + sign * image_bias))))
        one = sa.copy()
        one[:, by, bx, :] *= 1.0 + sign * block_bias
        out.append((f"{sign * block_bias:+.0%} on block ({by}, {bx})",
                    stats.SeedBlocks(one)))
    pair = _swap_pair(base.mean_b)
    results = [(label, compare_renders(x, renders_b, block, **kwargs)) for label, x in out]
    if pair:
        sw = sa.copy()
        sw[..., [pair[0], pair[1]]] = sa[..., [pair[1], pair[0]]]
        results.append((f"channels {'RGBA'[pair[0]]} and {'RGBA'[pair[1]]} swapped",
                        compare_renders(stats.SeedBlocks(sw), renders_b, block, **kwargs)))
    return results


def paired_sets(renders_a, renders_b):
    """Renders of the same seeds on both sides (a_k and b_k trace the same random numbers), as
    a comparison of independent sets against an exact value (tests/README.md, "Paired seeds"):
    E[a_k - b_k] = 0 is tested as a_k - b_k + mean(b) against mean(b), so the noise is the
    spread of the per-seed differences. Returns (the K differences plus the level, the level),
    in float64, for compare_renders / assert_agreement."""
    level = np.mean(renders_b, axis=0, dtype=np.float64)
    paired = [np.asarray(a, np.float64) - b + level
              for a, b in zip(renders_a, renders_b, strict=True)]
    return paired, level


def assert_agreement(name, renders_a, renders_b, block=8, controls=True,
                     image_bias=CONTROL_IMAGE_BIAS, block_bias=CONTROL_BLOCK_BIAS, **kwargs):
    """compare_renders, printed; asserts agreement and, with `controls`, that every negative
    control fails (the comparison can see a 1 % image bias, +5 % on a typical block and a
    swapped channel; a test whose noise cannot afford that states larger `image_bias` /
    `block_bias`, and tests/README.md lists them). Returns the Agreement."""
    res = compare_renders(renders_a, renders_b, block, name=name, **kwargs)
    print(res)
    assert np.isfinite(res.blocks.mean_a).all(), f"{name}: non-finite pixels"
    assert res.passed, str(res)
    if controls:
        ctls = negative_controls(renders_a, renders_b, block, image_bias, block_bias, **kwargs)
        print(f"  negative controls caught: {', '.join(label for label, c in ctls if not c)}")
        for label, ctl in ctls:
            assert not ctl.passed, (f"{name}: negative control '{label}' passed, so this "
                                    f"comparison cannot see it: {ctl}")
    return res


def false_alarm_bound(trials, alpha, level=1e-3):
    """Largest number of false alarms in `trials` independent fair comparisons consistent with
    a rate <= alpha (binomial, one-sided at `level`)."""
    return stats.binomial_bound(trials, alpha, level)


