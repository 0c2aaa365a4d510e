"""Student's t distribution without scipy (the GPU machine has numpy only): the two-sided tail
P(|T| > t) through the regularized incomplete beta function, P = I_{v/(v+t^2)}(v/2, 1/2)
(Abramowitz & Stegun 26.7.1), evaluated by its continued fraction (modified Lentz; Numerical
Recipes 6.4), and its inverse by bisection. Vectorised over numpy arrays; the degrees of
freedom may be fractional (Welch-Satterthwaite) or infinite (a normal)."""

import math

import numpy as np

_lgamma = np.vectorize(math.lgamma, otypes=[np.float64])
_TINY = 1e-300


def _beta_cf(a, b, x, iters=400):
    """Continued fraction of I_x(a, b) (converges fast for x < (a + 1) / (a + b + 2))."""
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c = np.ones_like(x)
    d = 1.0 - qab * x / qap
    d = 1.0 / np.where(np.abs(d) < _TINY, _TINY, d)
    h = d.copy()
    for m in range(1, iters + 1):
        m2 = 2.0 * m
        for aa in (m * (b - m) * x / ((qam + m2) * (a + m2)),
                   -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))):
            d = 1.0 + aa * d
            d = 1.0 / np.where(np.abs(d) < _TINY, _TINY, d)
            c = 1.0 + aa / c
            c = np.where(np.abs(c) < _TINY, _TINY, c)
            step = d * c
            h = h * step
        if np.all(np.abs(step - 1.0) < 1e-14):
            break
    return h


def betainc(a, b, x):
    """Regularized incomplete beta function I_x(a, b), elementwise."""
    a, b, x = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (a, b, x)))
    out = np.where(x >= 1.0, 1.0, 0.0)
    inside = (x > 0.0) & (x < 1.0)
    if inside.any():
        ai, bi, xi = a[inside], b[inside], x[inside]
        front = np.exp(_lgamma(ai + bi) - _lgamma(ai) - _lgamma(bi)
                       + ai * np.log(xi) + bi * np.log1p(-xi))
        direct = xi < (ai + 1.0) / (ai + bi + 2.0)
        val = np.empty_like(xi)
        if direct.any():
            val[direct] = front[direct] * _beta_cf(ai[direct], bi[direct], xi[direct]) \
                / ai[direct]
        flip = ~direct
        if flip.any():
            val[flip] = 1.0 - front[flip] * _beta_cf(bi[flip], ai[flip], 1.0 - xi[flip]) \
                / bi[flip]
        out = out.astype(np.float64)
        out[inside] = val
    return out


def two_sided_tail(t, dof):
    """P(|T| > |t|) for Student's t with `dof` degrees of freedom (array-valued, dof may be
    fractional; dof = inf gives the normal tail). |t| = inf gives 0; NaN stays NaN."""
    t, dof = np.broadcast_arrays(np.abs(np.asarray(t, dtype=np.float64)),
                                 np.asarray(dof, dtype=np.float64))
    out = np.full(t.shape, np.nan)
    normal = ~np.isfinite(dof) | (dof > 1e7)
    ok = np.isfinite(t)
    if (normal & ok).any():
        erfc = np.vectorize(math.erfc, otypes=[np.float64])
        out[normal & ok] = erfc(t[normal & ok] / math.sqrt(2.0))
    sel = ~normal & ok
    if sel.any():
        v = dof[sel]
        out[sel] = betainc(0.5 * v, 0.5, v / (v + t[sel] ** 2))
    out[np.isinf(t)] = 0.0
    return out


def quantile(p_two_sided, dof):
    """t > 0 with P(|T| > t) = p (the inverse of two_sided_tail), by bisection on log t."""
    p, dof = np.broadcast_arrays(np.asarray(p_two_sided, dtype=np.float64),
                                 np.asarray(dof, dtype=np.float64))
    if ((p <= 0) | (p >= 1)).any():
        raise ValueError("p must be in (0, 1)")
    lo = np.full(p.shape, math.log(1e-4))
    hi = np.full(p.shape, math.log(1e9))
    for _ in range(48):
        mid = 0.5 * (lo + hi)
        above = two_sided_tail(np.exp(mid), dof) > p   # t too small
        lo = np.where(above, mid, lo)
        hi = np.where(above, hi, mid)
    return np.exp(0.5 * (lo + hi))


def welch_dof(se2_a, k_a, se2_b, k_b):
    """Welch-Satterthwaite degrees of freedom of a difference of two means whose squared
    standard errors se2_a, se2_b come from k_a and k_b samples (k_b = None: b exact). Where
    both are zero the result is inf (nothing estimated)."""
    se2_a = np.asarray(se2_a, dtype=np.float64)
    se2_b = np.zeros_like(se2_a) if k_b is None else np.asarray(se2_b, dtype=np.float64)
    num = (se2_a + se2_b) ** 2
    den = se2_a ** 2 / (k_a - 1)
    if k_b is not None:
        den = den + se2_b ** 2 / (k_b - 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        v = num / den
    return np.where(den > 0, v, np.inf)
