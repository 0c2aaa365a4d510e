"""Negative emission, which Lantern clamps to 0 where Cycles emits negative light (docs/nodes.md,
difftest D17), named in a warning: a constant Strength below 0, or a node graph on an emission
input that gives a value below -5 % of its largest (and -1e-4) at some probe point. The probe evaluates the compiled emission
program (colour x strength, node_light.evaluate: the native core outside a scene) at a fixed set
of points in the unit cube with varied normals, its UV, attribute (Generated, ...) and camera
inputs read as the point (outside a scene they read 0, where a Noise is 0 too). The unit cube is
the range of UV and Generated coordinates, so a graph of them is probed where it renders (points
in [-2, 2]^3 made a Blackbody of a coordinate warn). A graph negative only where the probe does
not reach goes unwarned: a warning means "can", its absence not "cannot"."""

import numpy as np

from . import node_eval as ne
from .node_light import evaluate

# inputs a probe point has no value for, read as the point's position instead
_AS_POSITION = (ne.IN_UV, ne.IN_ATTRIBUTE, ne.IN_CAMERA, ne.IN_WINDOW)

_N = 512


def _probe():
    rng = np.random.default_rng(17)   # fixed: the same export warns the same way every time
    pts = rng.uniform(0.0, 1.0, (_N, 3))
    nrm = rng.normal(size=(_N, 3))
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    return pts.astype(np.float32), nrm.astype(np.float32)


_POINTS, _NORMALS = _probe()


def _probe_program(prog):
    code = []
    for w in prog["code"]:
        w = list(w)
        if (w[0] & 0xFF) == ne.OP["input"] and ((w[0] >> 8) & 0xFF) in _AS_POSITION:
            w[0] = (w[0] & ~0xFF00) | (ne.IN_POSITION << 8)
            w[3] = 0
        code.append(w)
    return dict(prog, code=code)


def check_constant(report, where, socket_name, strength):
    """Warn where a constant emission strength is negative (it is read as 0)."""
    try:
        v = float(strength)
    except (TypeError, ValueError):
        return
    if v < 0.0:
        report.warn(f"{where}: '{socket_name}' is negative ({v:.4g}); Lantern emits no light "
                    "there (read as 0), Cycles emits negative light")


def check_program(report, where, prog):
    """Warn where the emission program prog (material_compile's dict) is negative at a probe
    point; nothing without the native core."""
    if prog is None:
        return
    try:
        vals = evaluate(_probe_program(prog), _POINTS, _NORMALS)
    except (ValueError, RuntimeError):
        return
    if vals is None or not (vals < 0.0).any():
        return
    # dips under 5 % of the graph's largest value, or under 1e-4, are not named: float rounding
    # (a Layer Weight's -1e-7 where all else is 0), a smooth minimum's overshoot (Voronoi Smooth
    # F1, -0.005), Blackbody's fit at its coldest (-0.018): test_nodes.py's node outputs
    neg = vals < -max(0.05 * float(np.abs(vals).max()), 1e-4)
    if not neg.any():
        return
    frac = float(neg.any(axis=1).mean())
    report.warn(f"{where}: the node graph on its emission gives negative values (at "
                f"{100.0 * frac:.0f} % of probe points, down to {float(vals.min()):.4g}); "
                "Lantern clamps emission to 0 there, Cycles emits negative light")
