"""Shared by the shader-node tests against Cycles (test_nodes.py, test_nodes_shading.py and
nodes_cases.py): the tolerances, the two renders, the exact comparison with its negative
controls, Blackbody and Wavelength computed independently, node-graph helpers and the
sphere's compared pixels (test_nodes.py's docstring says how the comparison works)."""

import numpy as np

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import lantern  # noqa: E402

import node_stage as st  # noqa: E402


FILTER_PX = 1e-6   # Lantern's filter width (Blender's filter size), pixels: the centre
TOL = 1e-4   # relative per pixel channel (0.05 floor): the float rounding of two
# implementations, measured at most 3.4e-5 (noise_distorted; most cases under 1e-5)
BLOCK = 8    # the +5 % control's block
# Lantern's Bump and Displacement difference the height over offsets of 2e-4 relative to the
# point in float: the bent normal carries about 3e-4 of rounding (test_bl_nodes.py measures
# 8.5e-5 on a plane at the origin), so lit bumps are compared on the scale of the unbent
# value (the floor) and normals on their own (floor 1)
BENT_TOL = 6e-4
# (tol, floor) where a case is wider than TOL, each explained in docs/nodes.md
CASE_TOL = {
    # ColorRamp and the curves: both bake 256 entries of Blender's evaluation and step
    # linearly between them; Ease, Cardinal and curves differ by up to 2.2e-4 (not found)
    "ramp_ease": (4e-4, 0.05), "ramp_cardinal": (4e-4, 0.05), "rgb_curves": (4e-4, 0.05),
    "float_curve": (4e-4, 0.05),
    "geometry_normal_displacement_sphere": (BENT_TOL, 1.0),
    # Cycles' own table and matrix, as the in-range case's bound (SPECTRAL_CYCLES)
    "wavelength_out_of_range": (3e-4, 1.0),
}


def render_lantern(max_depth=1, seed=1):
    """Lantern's image at the pixel centres (1 spp, the exported filter narrowed to FILTER_PX)
    and the export's warnings."""
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    scene.film["filter_width"] = FILTER_PX
    img = lantern.render(scene, spp=1, integrator="pt", max_depth=max_depth, seed=seed)
    return np.asarray(img, np.float64), list(report.messages)


def render_cycles(sc, path, bounces=0, seed=0):
    """Cycles' image at the pixel centres: its sample 0 (1 spp) goes through them. No bounce:
    the Principled cases' specular would otherwise add a sampled reflection of the sphere.
    Nor is an emitting mesh a light: Cycles' next-event samples of the sphere reach its own
    surface through the inside, where a bumped normal turns the specular towards them (a few
    pixels of geometry_normal_under_bump_sphere, 1-5 % brighter, seed by seed)."""
    for mat in bpy.data.materials:
        mat.cycles.emission_sampling = "NONE"
    return st.render_cycles(sc, path, spp=1, bounces=bounces, seed=seed)


def _control_block(ref, mask):
    """(row, col) of the BLOCK x BLOCK block inside `mask` that is brightest in `ref`."""
    best, where = -1.0, None
    for i in range(0, ref.shape[0] - BLOCK + 1, BLOCK):
        for j in range(0, ref.shape[1] - BLOCK + 1, BLOCK):
            m = mask[i:i + BLOCK, j:j + BLOCK]
            v = ref[i:i + BLOCK, j:j + BLOCK][m].mean() if m.all() else -1.0
            if v > best:
                best, where = v, (i, j)
    assert where is not None, "no block inside the compared pixels for the +5 % control"
    return where


def assert_exact(name, img_l, ref, mask=None, tol=TOL, floor=0.05, mean_tol=None):
    """Every pixel channel of `mask` within `tol` of `ref` (relative, `floor` near 0), none
    beyond, and (where a per-pixel cap is wide: `mean_tol`) the image mean within `mean_tol`
    relative; Lantern's image x 1.01, x 0.99 and +5 % on one block must each fail that."""
    mask = np.ones(ref.shape[:2], bool) if mask is None else mask

    def off(img):
        """(worst pixel channel, the image mean's relative error)"""
        return (float(st.relative_error(img, ref, floor)[mask].max()),
                abs(float(img[mask].mean() / ref[mask].mean()) - 1.0))

    def fails(img):
        w, m = off(img)
        return w > tol or (mean_tol is not None and m > mean_tol)

    w, m = off(img_l)
    assert w <= tol, (f"{name}: worst pixel channel off by {w:.2e} > {tol:.0e} "
                      f"({int((st.relative_error(img_l, ref, floor)[mask] > tol).sum())} of "
                      f"{int(mask.sum()) * 3}; means {img_l[mask].mean():.4f} Lantern, "
                      f"{ref[mask].mean():.4f} reference)")
    assert mean_tol is None or m <= mean_tol, f"{name}: image mean off by {m:.2e}"
    i, j = _control_block(ref, mask)
    block = img_l.copy()
    block[i:i + BLOCK, j:j + BLOCK] *= 1.05
    for label, biased in (("x 1.01", img_l * 1.01), ("x 0.99", img_l * 0.99),
                          ("+5 % on one block", block)):
        assert fails(biased), (f"{name}: negative control {label} passed, so this "
                               "comparison cannot see it")
    return w, m


# ---- Blackbody and Wavelength, computed here: Planck's law from h, c and k, and the CIE 1931
# observer's 5 nm table (node_cie1931, the data: checked against illuminant A below) linearly
# interpolated and integrated by the trapezoid rule at 0.1 nm, taken to linear Rec.709 by the
# matrix of its primaries and the CIE's D65 white (X, Z = 0.95047, 1.08883). Not the exporter's
# code (its 1 nm sums, its matrix, its tables in the core are what is under test). Cycles' own
# blackbody is a fit (docs/nodes.md), so Cycles is held only to its bound there.
H_PLANCK, C_LIGHT, K_BOLTZMANN = 6.62607015e-34, 299792458.0, 1.380649e-23   # SI, exact
BLACKBODY_K, WAVELENGTH_NM = (1800.0, 11000.0), (400.0, 700.0)   # over Generated X
# below about 1900 K blue is negative in Rec.709, below 950 K green too: Cycles' node outputs
# max(colour, 0), which only a graph reading the colour as a value can see (its luminance: 1.15
# at 800 K, not 1; difftest seed 643, D33)
BLACKBODY_LOW_K = (800.0, 2400.0)
# per pixel channel against the computation above: Blackbody's 256 knots in 1/T interpolate
# within 2.9e-4 of the exact colour (the 1 nm sums 7e-5 from the 0.1 nm ones); Wavelength's
# knots are the observer's rows, so only float rounding is left
SPECTRAL_TOL = {"blackbody": 5e-4, "blackbody_luminance": 5e-4, "wavelength": 2e-5}
# against Cycles, (tol, floor), from the measured worst pixel channel: Blackbody 0.75 %
# relative at 1915 K, at most 0.06 % from 2835 K up (Cycles' blackbody is a fit); Wavelength
# 1.8e-4 absolute (floor 1; peak about 1): Cycles' observer table is rounded to 4 decimals
# (up to 1.05e-4 through the matrix) and its XYZ to Rec.709 matrix comes from OpenColorIO
SPECTRAL_CYCLES = {"blackbody": (0.01, 0.05), "blackbody_luminance": (0.01, 0.05),
                   "wavelength": (3e-4, 1.0)}


def _observer():
    from lantern_blender.export import node_cie1931 as cie
    lam = cie.LAMBDA_MIN + cie.LAMBDA_STEP * np.arange(len(cie.CMF_5NM))
    return lam, np.array(cie.CMF_5NM, np.float64)


def _xyz_to_rec709():
    xy = np.array([[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]])   # R, G, B
    prim = np.stack([xy[:, 0] / xy[:, 1], np.ones(3), (1.0 - xy.sum(axis=1)) / xy[:, 1]])
    white = np.array([0.95047, 1.0, 1.08883])
    return np.linalg.inv(prim * np.linalg.solve(prim, white))


def _centres(lo, hi, width):
    """The spectral cases' input at the pixel centres (Generated X = (j + 0.5) / width)."""
    return lo + (hi - lo) * (np.arange(width) + 0.5) / width


def blackbody_expected(width, kelvin=BLACKBODY_K):
    """(width, 3): a blackbody's linear Rec.709 colour at luminance 1, per column."""
    lam, cmf = _observer()
    fine = np.arange(360.0, 830.0 + 1e-9, 0.1)
    obs = np.stack([np.interp(fine, lam, cmf[:, k]) for k in range(3)], axis=1)
    m = fine * 1e-9
    out = []
    for t in _centres(*kelvin, width):
        b = 2.0 * H_PLANCK * C_LIGHT ** 2 / m ** 5 / np.expm1(H_PLANCK * C_LIGHT /
                                                             (m * K_BOLTZMANN * t))
        y = b[:, None] * obs
        xyz = ((y[1:] + y[:-1]) * 0.5 * np.diff(fine)[:, None]).sum(axis=0)
        out.append(_xyz_to_rec709() @ xyz / xyz[1])
    return np.array(out)


def wavelength_expected(width):
    """(width, 3): the observer at one wavelength in linear Rec.709, / 2.52 (Cycles' scale,
    which keeps every channel under 1), clamped at 0, per column."""
    lam, cmf = _observer()
    xyz = np.stack([np.interp(_centres(*WAVELENGTH_NM, width), lam, cmf[:, k])
                    for k in range(3)], axis=1)
    return np.maximum(xyz @ _xyz_to_rec709().T / 2.52, 0.0)


def blackbody_luminance_expected(width):
    """(width, 3): the luminance of the blackbody colour clamped at 0 (as Cycles' node
    outputs it), the grey an Emission Strength reads, per column."""
    rgb = np.maximum(blackbody_expected(width, BLACKBODY_LOW_K), 0.0)
    return np.repeat((rgb @ np.array([0.2126, 0.7152, 0.0722]))[:, None], 3, axis=1)


SPECTRAL_EXPECTED = {"blackbody": blackbody_expected, "wavelength": wavelength_expected,
                     "blackbody_luminance": blackbody_luminance_expected}


def _link(nt, node, out, emit, into="Color"):
    nt.links.new(node.outputs[out], emit.inputs[into])


def _node(nt, idname, props=None, **inputs):
    n = nt.nodes.new(idname)
    for k, v in (props or {}).items():   # first: they decide which inputs are available
        setattr(n, k, v)
    for k, v in inputs.items():
        _ident(n, k).default_value = v
    return n


def _ident(node, identifier):
    return next(s for s in node.inputs if s.identifier == identifier)


def _coord(nt, out="Generated"):
    return nt.nodes.new("ShaderNodeTexCoord").outputs[out]


def _abs(nt, socket, scale=1.0):
    """|v| * scale (emission is clamped at 0 in Lantern, signed in Cycles)."""
    a = nt.nodes.new("ShaderNodeVectorMath")
    a.operation = "ABSOLUTE"
    nt.links.new(socket, a.inputs[0])
    s = nt.nodes.new("ShaderNodeVectorMath")
    s.operation = "SCALE"
    s.inputs["Scale"].default_value = scale
    nt.links.new(a.outputs[0], s.inputs[0])
    return s.outputs[0]


def _floored(nt, scale=7.3):
    m = nt.nodes.new("ShaderNodeVectorMath")
    m.operation = "SCALE"
    m.inputs["Scale"].default_value = scale
    nt.links.new(_coord(nt), m.inputs[0])
    f = nt.nodes.new("ShaderNodeVectorMath")
    f.operation = "FLOOR"
    nt.links.new(m.outputs[0], f.inputs[0])
    return f.outputs[0]


def _covered(shape, img_c):
    """The compared pixels: all of the plane; the sphere without its silhouette ring."""
    if shape != "sphere":
        return np.ones(img_c.shape[:2], bool)
    hit = img_c.max(axis=2) > 0
    covered = np.zeros_like(hit)
    covered[1:-1, 1:-1] = hit[1:-1, 1:-1] & hit[:-2, 1:-1] & hit[2:, 1:-1] & \
        hit[1:-1, :-2] & hit[1:-1, 2:]
    return covered
