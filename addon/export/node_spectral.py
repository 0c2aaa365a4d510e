"""Blackbody and Wavelength: colours of a spectrum, computed here (numpy) into 256-entry tables
that the core's ColorRamp op interpolates (no op of their own). Spectra are integrated against
the tabulated CIE 1931 2-degree observer (node_cie1931; until 2026-12 the multi-lobe Gaussian
fit of Wyman, Sloan and Shirley, 3% off in the red tail), then taken to linear Rec.709 (D65).
Blackbody (Planck's law) is normalised to luminance Y = 1 over 800-12000 K (clamped outside),
as Blender defines it, and clamped at 0 after (Cycles does: blue is negative below 1900 K); the table runs in 1/T, where the colour changes smoothly. Wavelength
(380-780 nm) is the observer's own colour, scaled so that no channel exceeds 1 and clamped
at 0, as Cycles does (docs/nodes.md: measured against Cycles): its table has a knot at each of
the observer's 5 nm rows, unclamped, and the clamp follows the lookup, so the core's linear
steps are the observer's own linear interpolation (256 knots between the rows put it off by up
to 2.3e-4 at the 5 nm kinks)."""

import math

from . import node_cie1931 as cie
from . import node_ops as ne

T_MIN, T_MAX = 800.0, 12000.0
L_MIN, L_MAX = 380.0, 780.0
WAVELENGTH_SCALE = 1.0 / 2.52   # Cycles' empirical scale that keeps every channel <= 1
XYZ_TO_REC709 = ((3.2404542, -1.5371385, -0.4985314),
                 (-0.9692660, 1.8760108, 0.0415560),
                 (0.0556434, -0.2040259, 1.0572252))


def cie_xyz(lam):
    """The CIE 1931 colour matching functions at wavelength lam (nm): the tabulated observer
    (node_cie1931), linearly interpolated; 0 outside 360-830 nm."""
    u = (lam - cie.LAMBDA_MIN) / cie.LAMBDA_STEP
    i = int(math.floor(u))
    if i < 0 or i >= len(cie.CMF_5NM) - 1:
        return cie.CMF_5NM[-1] if i == len(cie.CMF_5NM) - 1 and u == i else (0.0, 0.0, 0.0)
    f = u - i
    a, b = cie.CMF_5NM[i], cie.CMF_5NM[i + 1]
    return tuple(a[k] + (b[k] - a[k]) * f for k in range(3))


def _rgb(xyz):
    return [sum(XYZ_TO_REC709[r][c] * xyz[c] for c in range(3)) for r in range(3)]


_CMF = [(float(lam), cie_xyz(float(lam))) for lam in range(360, 831)]   # 1 nm steps


def blackbody_rgb(t):
    """Linear Rec.709 colour of a blackbody at t kelvin, luminance 1."""
    t = min(max(float(t), T_MIN), T_MAX)
    c1, c2 = 3.741771852e-16, 1.438776877e-2   # 2 pi h c^2, h c / k (SI)
    acc = [0.0, 0.0, 0.0]
    for lam, xyz in _CMF:
        m = lam * 1e-9
        b = c1 / (m ** 5 * math.expm1(c2 / (m * t)))
        for k in range(3):
            acc[k] += b * xyz[k]
    return [c / acc[1] for c in _rgb(acc)]


def _observer_rgb(lam, clamp=True):
    """The Wavelength node's colour inside its table (380-780 nm; lam clamped to it)."""
    lam = min(max(float(lam), L_MIN), L_MAX)
    rgb = [c * WAVELENGTH_SCALE for c in _rgb(cie_xyz(lam))]
    return [max(c, 0.0) for c in rgb] if clamp else rgb


def wavelength_rgb(lam, clamp=True):
    """The Wavelength node as Cycles evaluates it: its row index (lam - 380) / 5 truncated to
    an integer, black outside rows 0-79 (lam <= 375 nm or >= 780 nm: difftest D26, where 0.35 nm
    read the 380 nm colour), rows 0 and 1 extrapolated for 375-380 nm."""
    lam = float(lam)
    if not (L_MIN - cie.LAMBDA_STEP < lam < L_MAX):
        return [0.0, 0.0, 0.0]
    if lam >= L_MIN:
        return _observer_rgb(lam, clamp)
    a, b = _observer_rgb(L_MIN, False), _observer_rgb(L_MIN + cie.LAMBDA_STEP, False)
    t = (lam - L_MIN) / cie.LAMBDA_STEP
    rgb = [x + (y - x) * t for x, y in zip(a, b)]
    return [max(c, 0.0) for c in rgb] if clamp else rgb


WAVELENGTH_KNOTS = int(round((L_MAX - L_MIN) / cie.LAMBDA_STEP)) + 1   # 81: the 5 nm rows


def _table(fn, us):
    floats = []
    for u in us:
        floats.extend(list(fn(u)) + [1.0])
    return floats


_TABLES = {}


def _blackbody_table():
    if "bb" not in _TABLES:   # uniform in 1/T from 1/T_MIN to 1/T_MAX
        a, b = 1.0 / T_MIN, 1.0 / T_MAX
        n = ne.TABLE_SIZE
        _TABLES["bb"] = _table(blackbody_rgb, [1.0 / (a + (b - a) * i / (n - 1))
                                               for i in range(n)])
    return _TABLES["bb"]


def _wavelength_table():
    if "wl" not in _TABLES:   # unclamped, at the observer's rows (clamped after the lookup)
        _TABLES["wl"] = _table(lambda lam: _observer_rgb(lam, clamp=False),
                               [L_MIN + cie.LAMBDA_STEP * i for i in range(WAVELENGTH_KNOTS)])
    return _TABLES["wl"]


def _math(ctx, op, a, b, c=0.0):
    vals = [a, ctx.const((b,), "VALUE") if isinstance(b, float) else b,
            ctx.const((c,), "VALUE")]
    r, _ = ctx.emit_node("math", vals, 1, mode=ne.MATH_OPS.index(op))
    return ctx.reg(r, 1, "VALUE")


def _ramp(ctx, fac, floats, size=ne.TABLE_SIZE):
    r, idx = ctx.emit_node("ramp", [fac], 4, flags=1, aux2=size)
    ctx.b.table(idx, floats)
    return ctx.reg(r, 3, "RGBA")


def h_blackbody(ctx, node, out, path):
    # Cycles' node outputs max(colour, 0): below about 1900 K blue is negative in Rec.709 (below
    # 950 K green too), which a graph that reads the colour as a value sees (difftest D33)
    t = ctx.inp(node, "Temperature", path, "VALUE")
    if t.const is not None:
        return ctx.const(tuple(max(c, 0.0) for c in blackbody_rgb(t.const[0])), "RGBA")
    a, b = 1.0 / T_MIN, 1.0 / T_MAX
    t = _math(ctx, "MAXIMUM", t, 1.0)
    inv = _math(ctx, "DIVIDE", ctx.const((1.0,), "VALUE"), t)       # 1/T
    u = _math(ctx, "MULTIPLY_ADD", inv, 1.0 / (b - a), -a / (b - a))  # 0 at T_MIN, 1 at T_MAX
    rgb = _ramp(ctx, u, _blackbody_table())   # unclamped knots, clamped after the lookup
    zero, one = ctx.const((0.0, 0.0, 0.0), "VECTOR"), ctx.const((1.0,), "VALUE")
    r, _ = ctx.emit_node("vector_math", [rgb, zero, zero, one], 4,
                         mode=ne.VECTOR_OPS.index("MAXIMUM"))
    return ctx.reg(r, 3, "RGBA")


def h_wavelength(ctx, node, out, path):
    lam = ctx.inp(node, "Wavelength", path, "VALUE")
    if lam.const is not None:
        return ctx.const(tuple(wavelength_rgb(lam.const[0])), "RGBA")
    u = _math(ctx, "MULTIPLY_ADD", lam, 1.0 / (L_MAX - L_MIN), -L_MIN / (L_MAX - L_MIN))
    rgb = _ramp(ctx, u, _wavelength_table(), WAVELENGTH_KNOTS)
    zero, one = ctx.const((0.0, 0.0, 0.0), "VECTOR"), ctx.const((1.0,), "VALUE")
    r, _ = ctx.emit_node("vector_math", [rgb, zero, zero, one], 4,
                         mode=ne.VECTOR_OPS.index("MAXIMUM"))
    # black outside Cycles' rows (wavelength_rgb); 375-380 nm reads the 380 nm row here, where
    # Cycles extrapolates (at most 0.002 apart)
    inside = _math(ctx, "MULTIPLY", _math(ctx, "GREATER_THAN", lam, L_MIN - cie.LAMBDA_STEP),
                   _math(ctx, "LESS_THAN", lam, L_MAX))
    r, _ = ctx.emit_node("vector_math", [ctx.reg(r, 3, "VECTOR"), zero, zero, inside], 4,
                         mode=ne.VECTOR_OPS.index("SCALE"))
    return ctx.reg(r, 3, "RGBA")


SPECTRAL_HANDLERS = {"BLACKBODY": h_blackbody, "WAVELENGTH": h_wavelength}
