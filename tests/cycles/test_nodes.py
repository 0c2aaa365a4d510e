"""Shader nodes against Cycles, node by node: each case drives an emission-only material with
one node (or a short chain), rendered with one bounce by Lantern (pt) and by Cycles
(node_stage.py), each at 1 spp through the pixel centres: Cycles' sample 0 goes through the
centre (its filter sample is (0.5, 0.5), in every seed), and Lantern's pixel filter is narrowed
to FILTER_PX. So both images are the node's output at the pixel centres, with no filter
footprint left to straddle the node's discontinuities (checker edges, stepped ramps, saw
waves) and no noise: every pixel channel must agree within TOL (relative, 0.05 floor for values
near 0), none allowed beyond, and Lantern's image 1 % brighter or darker, or 5 % brighter on
one 8x8 block, must fail that (negative controls, tests/README.md). The sphere cases leave out
the silhouette ring (grazing normals there are the interpolation's, differently rounded).
Every case must vary over the image (a constant would pass anything) and export without a
warning. Voronoi hashes its integer cells with PCG (measured), White Noise the float bits of
its input (its cases use floored coordinates, which both renderers compute bit-exactly).
Blackbody and Wavelength are held to an independent computation (Planck and the CIE observer
integrated here, not with the exporter's code), Cycles' own blackbody being a fit."""

import math

import numpy as np
import pytest

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


def test_observer_table_gives_illuminant_a():
    """The observer's data (node_cie1931): CIE illuminant A, a Planckian radiator whose
    relative spectrum CIE 15 defines with c2 = 1.435e-2 m K at 2848 K, summed over the 5 nm
    rows from 380 to 780 nm, has the published chromaticity x, y = 0.44757, 0.40745 (CIE
    15:2004), here within the fifth digit's rounding; x-bar 1 % higher must miss it."""
    lam, cmf = _observer()
    rows = (lam >= 380.0) & (lam <= 780.0)
    s_a = 100.0 * (560.0 / lam[rows]) ** 5 * np.expm1(1.435e7 / (2848.0 * 560.0)) / \
        np.expm1(1.435e7 / (2848.0 * lam[rows]))

    def xy(obs):
        xyz = (s_a[:, None] * obs[rows]).sum(axis=0)
        return xyz[:2] / xyz.sum()

    tol = 1e-5
    got = xy(cmf)
    assert np.abs(got - (0.44757, 0.40745)).max() <= tol, got
    assert np.abs(xy(cmf * (1.01, 1.0, 1.0)) - (0.44757, 0.40745)).max() > tol


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


# ---- cases: (shape, builder) ----
def texcoord(out, scale=1.0):
    def build(nt, emit):
        nt.links.new(_abs(nt, _coord(nt, out), scale), emit.inputs["Color"])
    return build


def mapping(kind):
    def build(nt, emit):
        m = nt.nodes.new("ShaderNodeMapping")
        m.vector_type = kind
        for name, v in (("Location", (0.3, -0.2, 0.1)), ("Rotation", (0.2, 0.3, 0.7)),
                        ("Scale", (1.5, 0.8, 1.2))):
            if name in m.inputs:   # Vector and Normal mappings have no Location
                m.inputs[name].default_value = v
        nt.links.new(_coord(nt), m.inputs["Vector"])
        c = _node(nt, "ShaderNodeTexChecker", Scale=3.0)
        nt.links.new(m.outputs[0], c.inputs["Vector"]) if kind != "NORMAL" else \
            nt.links.new(_abs(nt, m.outputs[0]), emit.inputs["Color"])
        if kind != "NORMAL":
            _link(nt, c, "Color", emit)
    return build


def math_chain(ops):
    def build(nt, emit):
        x = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(_coord(nt), x.inputs[0])
        prev = x.outputs["X"]
        for op, b, c in ops:
            m = _node(nt, "ShaderNodeMath")
            m.operation = op
            nt.links.new(prev, m.inputs[0])
            m.inputs[1].default_value, m.inputs[2].default_value = b, c
            prev = m.outputs[0]
        nt.links.new(prev, emit.inputs["Strength"])
    return build


def vector_math(op):
    def build(nt, emit):
        m = nt.nodes.new("ShaderNodeVectorMath")
        m.operation = op
        nt.links.new(_coord(nt), m.inputs[0])
        m.inputs[1].default_value = (0.3, 0.7, 0.4)
        m.inputs[2].default_value = (0.5, 0.2, 0.9)
        m.inputs[3].default_value = 0.7
        out = m.outputs["Value"] if op in ("DOT_PRODUCT", "DISTANCE", "LENGTH") else \
            m.outputs["Vector"]
        nt.links.new(_abs(nt, out), emit.inputs["Color"])
    return build


def mix_color(blend):
    def build(nt, emit):
        m = nt.nodes.new("ShaderNodeMix")
        m.data_type = "RGBA"
        m.blend_type = blend
        # (clamped where the result can leave [0, 1]: Lantern's emission is never negative)
        m.clamp_result = blend in ("DODGE", "ADD", "SUBTRACT", "LINEAR_LIGHT")
        nt.links.new(_coord(nt), _ident(m, "A_Color"))
        g = _node(nt, "ShaderNodeTexChecker", Scale=2.3)   # (not 2: the plane's Generated z
        # is 0.5, at scale 2 a checker edge, where each pixel's side is float rounding's)
        g.inputs["Color1"].default_value = (0.9, 0.3, 0.6, 1.0)
        g.inputs["Color2"].default_value = (0.2, 0.8, 0.1, 1.0)
        nt.links.new(g.outputs["Color"], _ident(m, "B_Color"))
        _ident(m, "Factor_Float").default_value = 0.7
        out = next(s for s in m.outputs if s.identifier == "Result_Color")
        nt.links.new(out, emit.inputs["Color"])
    return build


def color_op(idname, inputs):
    def build(nt, emit):
        n = _node(nt, idname, **inputs)
        nt.links.new(_coord(nt), n.inputs["Color"])
        _link(nt, n, "Color", emit)
    return build


def ramp(interp):
    def build(nt, emit):
        r = nt.nodes.new("ShaderNodeValToRGB")
        r.color_ramp.interpolation = interp
        r.color_ramp.elements[0].color = (0.1, 0.2, 0.8, 1.0)
        e = r.color_ramp.elements.new(0.4)
        e.color = (0.9, 0.5, 0.1, 1.0)
        x = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(_coord(nt), x.inputs[0])
        nt.links.new(x.outputs["X"], r.inputs[0])
        _link(nt, r, "Color", emit)
    return build


def texture(idname, out="Color", props=None, absolute=False, **inputs):
    def build(nt, emit):
        n = _node(nt, idname, props, **inputs)
        if absolute:   # signed outputs (Lantern's emission is never negative)
            nt.links.new(_abs(nt, n.outputs[out]), emit.inputs["Color"])
        else:
            _link(nt, n, out, emit)
    return build


def white_noise(dim):
    def build(nt, emit):
        n = nt.nodes.new("ShaderNodeTexWhiteNoise")
        n.noise_dimensions = dim
        nt.links.new(_floored(nt), n.inputs["Vector"])
        if dim in ("1D", "4D"):
            _ident(n, "W").default_value = 2.0
        _link(nt, n, "Color", emit)
    return build


def spectral(idname, socket, lo, hi, into="Color"):
    """Blackbody / Wavelength over a range of its input along Generated X, on the emission's
    `into` (Strength: the colour's luminance)."""
    def build(nt, emit):
        x = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(_coord(nt), x.inputs[0])
        m = _node(nt, "ShaderNodeMapRange")
        nt.links.new(x.outputs["X"], m.inputs["Value"])
        m.inputs["To Min"].default_value, m.inputs["To Max"].default_value = lo, hi
        n = nt.nodes.new(idname)
        nt.links.new(m.outputs[0], n.inputs[socket])
        _link(nt, n, "Color", emit, into)
    return build


def camera_data(out, lo, hi):
    """A Camera Data output mapped from [lo, hi] to [0, 1] (signed outputs stay visible)."""
    def build(nt, emit):
        c = nt.nodes.new("ShaderNodeCameraData")
        m = _node(nt, "ShaderNodeMapRange", {"data_type": "FLOAT_VECTOR"} if out == "View Vector"
                  else None)
        src = c.outputs[out]
        if out == "View Vector":
            nt.links.new(src, _ident(m, "Vector"))
            _ident(m, "From_Min_FLOAT3").default_value = (lo, lo, lo)
            _ident(m, "From_Max_FLOAT3").default_value = (hi, hi, hi)
            nt.links.new(next(s for s in m.outputs if s.identifier == "Vector"),
                         emit.inputs["Color"])
        else:
            nt.links.new(src, m.inputs["Value"])
            m.inputs["From Min"].default_value, m.inputs["From Max"].default_value = lo, hi
            nt.links.new(m.outputs[0], emit.inputs["Strength"])
    return build


def normal_dot(nt, emit):
    """Normal node: Dot of the sphere's normal with its own direction, mapped to [0, 1]."""
    n = nt.nodes.new("ShaderNodeNormal")
    n.outputs["Normal"].default_value = (0.6, -1.6, 1.0)   # not unit: Blender normalises it
    nt.links.new(nt.nodes.new("ShaderNodeNewGeometry").outputs["Normal"], n.inputs["Normal"])
    m = _node(nt, "ShaderNodeMapRange")
    m.inputs["From Min"].default_value = -1.0
    nt.links.new(n.outputs["Dot"], m.inputs["Value"])
    nt.links.new(m.outputs[0], emit.inputs["Strength"])


def geometry_normal(displacement):
    """What Geometry > Normal reads on a bumped material, as the emission |N| of a black
    Principled BSDF (no light: the image is the emission) whose Normal a Bump node bends, or
    with the Material Output's Displacement as bump. Cycles: the Bump node leaves N alone, the
    Displacement bends it. The height is linear in space (a Gradient), where the two
    renderers' finite differences are exact (a Noise height differs by up to 3% in |N|: Cycles
    differences it over a tenth of a pixel, docs/nodes.md)."""
    def build(nt, emit):
        n = _abs(nt, nt.nodes.new("ShaderNodeNewGeometry").outputs["Normal"])
        h = nt.nodes.new("ShaderNodeTexGradient")
        out = nt.nodes["Material Output"]
        if displacement:
            d = _node(nt, "ShaderNodeDisplacement", Midlevel=0.5, Scale=0.8)
            nt.links.new(h.outputs["Fac"], d.inputs["Height"])
            nt.links.new(d.outputs[0], out.inputs["Displacement"])
            nt.links.new(n, emit.inputs["Color"])
            return
        p = _node(nt, "ShaderNodeBsdfPrincipled", **{"Base Color": (0.0, 0.0, 0.0, 1.0),
                                                     "Emission Strength": 1.0})
        nt.links.new(n, p.inputs["Emission Color"])
        b = _node(nt, "ShaderNodeBump", Distance=0.8)
        nt.links.new(h.outputs["Fac"], b.inputs["Height"])
        nt.links.new(b.outputs[0], p.inputs["Normal"])
        nt.links.new(p.outputs[0], out.inputs["Surface"])
    return build


def view_dependent(idname, out, **inputs):
    def build(nt, emit):
        _link(nt, _node(nt, idname, **inputs), out, emit)
    return build


def _image(name="grid", w=8, h=6):
    """An 8 x 6 float image of distinct colours (float: no 8-bit rounding on either side)."""
    img = bpy.data.images.new(name, w, h, float_buffer=True)
    y, x = np.mgrid[0:h, 0:w]
    px = np.stack([(x + 0.5) / w, (y + 0.5) / h, ((x * 7 + y * 3) % 5) / 4.0,
                   np.ones_like(x, float)], axis=-1)
    img.pixels.foreach_set(px.astype(np.float32).ravel())
    img.pack()
    return img


def image(projection="FLAT", extension="REPEAT", interpolation="Closest", vector="UV",
          scale=1.0):
    def build(nt, emit):
        n = nt.nodes.new("ShaderNodeTexImage")
        n.image = _image()
        n.projection, n.extension, n.interpolation = projection, extension, interpolation
        m = nt.nodes.new("ShaderNodeMapping")
        m.inputs["Location"].default_value = (-0.2, 0.1, 0.0)
        m.inputs["Scale"].default_value = (scale, scale, 1.0)
        nt.links.new(_coord(nt, vector), m.inputs["Vector"])
        nt.links.new(m.outputs[0], n.inputs["Vector"])
        _link(nt, n, "Color", emit)
    return build


def image_box(blend):
    """Box projection on a turned sphere (its sides come from the object-space normal, not
    the world's), Object coordinates mapped into the image."""
    def build(nt, emit):
        bpy.data.objects["Sphere"].rotation_euler = (0.4, 0.0, 0.7)
        n = nt.nodes.new("ShaderNodeTexImage")
        n.image = _image()
        n.projection, n.projection_blend, n.interpolation = "BOX", blend, "Linear"
        m = nt.nodes.new("ShaderNodeMapping")
        m.inputs["Location"].default_value = (0.5, 0.5, 0.5)
        m.inputs["Scale"].default_value = (0.45, 0.45, 0.45)
        nt.links.new(_coord(nt, "Object"), m.inputs["Vector"])
        nt.links.new(m.outputs[0], n.inputs["Vector"])
        _link(nt, n, "Color", emit)
    return build


def color_attribute(domain):
    def build(nt, emit):
        obj = bpy.data.objects["Plane"]
        attr = obj.data.color_attributes.new("Col", "FLOAT_COLOR", domain)
        n = len(attr.data)
        vals = np.array([[0.9, 0.1, 0.2, 1], [0.1, 0.8, 0.3, 1], [0.2, 0.3, 0.9, 1],
                         [0.7, 0.7, 0.1, 1]], np.float32)[np.arange(n) % 4]
        attr.data.foreach_set("color", vals.ravel())
        n = nt.nodes.new("ShaderNodeVertexColor")
        n.layer_name = "Col"
        _link(nt, n, "Color", emit)
    return build


def mix_vector(nonuniform):
    def build(nt, emit):
        m = nt.nodes.new("ShaderNodeMix")
        m.data_type = "VECTOR"
        m.factor_mode = "NON_UNIFORM" if nonuniform else "UNIFORM"
        nt.links.new(_coord(nt), _ident(m, "A_Vector"))
        _ident(m, "B_Vector").default_value = (0.9, 0.1, 0.5)
        if nonuniform:
            nt.links.new(_coord(nt, "UV"), _ident(m, "Factor_Vector"))
        else:
            _ident(m, "Factor_Float").default_value = 0.35
        out = next(o for o in m.outputs if o.identifier == "Result_Vector")
        nt.links.new(out, emit.inputs["Color"])
    return build


def mix_float_converted(nt, emit):
    """A float Mix fed by a colour and a vector (difftest seed 627, D32): Blender converts the
    colour to its luminance and the vector to its mean before mixing; Lantern took the first
    channel of each."""
    m = nt.nodes.new("ShaderNodeMix")
    m.data_type = "FLOAT"
    comb = nt.nodes.new("ShaderNodeCombineColor")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(_coord(nt), sep.inputs[0])
    nt.links.new(sep.outputs["X"], comb.inputs[0])   # red along x, green along y, blue 0.8
    nt.links.new(sep.outputs["Y"], comb.inputs[1])
    comb.inputs[2].default_value = 0.8
    nt.links.new(comb.outputs[0], _ident(m, "A_Float"))
    swap = _node(nt, "ShaderNodeCombineXYZ", Z=0.6)   # the vector (y, x, 0.6)
    nt.links.new(sep.outputs["Y"], swap.inputs["X"])
    nt.links.new(sep.outputs["X"], swap.inputs["Y"])
    nt.links.new(swap.outputs[0], _ident(m, "B_Float"))
    _ident(m, "Factor_Float").default_value = 0.35
    out = next(o for o in m.outputs if o.identifier == "Result_Float")
    nt.links.new(out, emit.inputs["Strength"])


def brick_zero_width(nt, emit):
    """Bricks of Width 0 are all mortar in Cycles (difftest D36): the Mortar colour, here
    Generated so that the image varies; Lantern's core reads them as all brick (Color1)."""
    b = _node(nt, "ShaderNodeTexBrick", **{"Brick Width": 0.0})
    nt.links.new(_coord(nt), b.inputs["Mortar"])
    nt.links.new(_coord(nt), b.inputs["Vector"])
    _link(nt, b, "Color", emit)


def brick_computed_size(socket, scale, offset):
    """Bricks whose width or row height a graph computes (not a constant the export could
    fold) as <= 0: Cycles runs its arithmetic on them, so they are all mortar (difftest D36);
    the core read them as all brick. Mortar Generated, so that the image varies."""
    def build(nt, emit):
        x = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(_coord(nt), x.inputs[0])
        m = _node(nt, "ShaderNodeMath", {"operation": "MULTIPLY_ADD"})
        nt.links.new(x.outputs["X"], m.inputs[0])
        m.inputs[1].default_value, m.inputs[2].default_value = scale, offset
        b = _node(nt, "ShaderNodeTexBrick", Scale=3.0)
        nt.links.new(m.outputs[0], b.inputs[socket])
        nt.links.new(_coord(nt), b.inputs["Mortar"])
        nt.links.new(_coord(nt), b.inputs["Vector"])
        _link(nt, b, "Color", emit)
    return build


def _sep(nt, comp):
    x = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(_coord(nt), x.inputs[0])
    return x.outputs[comp]


def _math(nt, op, a, b=None, c=None):
    """A Math node of sockets or constants."""
    m = _node(nt, "ShaderNodeMath", {"operation": op})
    for i, v in enumerate((a, b, c)):
        if v is None:
            continue
        if isinstance(v, (int, float)):
            m.inputs[i].default_value = v
        else:
            nt.links.new(v, m.inputs[i])
    return m.outputs[0]


def power_of_zero(vector, constant):
    """Power of a zero base and a negative exponent (difftest D35), read through a Minimum so
    that +inf and 0 differ: at render time (a base the graph computes: floor(5x) / 2 - 1, so
    -1, -0.5, 0, 0.5, 1 along x; the exponent -1.6 .. 1.4 along y) Cycles gives 0, as for a
    negative base to a fractional power; a Power of constants it folds on the host to +inf
    (Minimum with 2x then reads 2x). Plus x, so that the image varies."""
    def build(nt, emit):
        x, y = _sep(nt, "X"), _sep(nt, "Y")
        if constant:
            base, expo = 0.0, -1.0
        else:
            base = _math(nt, "MULTIPLY", _math(nt, "FLOOR", _math(nt, "MULTIPLY", x, 5.0)), 0.5)
            base = _math(nt, "SUBTRACT", base, 1.0)
            expo = _math(nt, "SUBTRACT", _math(nt, "MULTIPLY", y, 3.0), 1.6)
        if vector:
            vb, ve = (_node(nt, "ShaderNodeCombineXYZ") for _ in range(2))
            for k in range(3):
                for node, v in ((vb, base), (ve, expo)):
                    if isinstance(v, float):
                        node.inputs[k].default_value = v
                    else:
                        nt.links.new(v, node.inputs[k])
            p = _node(nt, "ShaderNodeVectorMath", {"operation": "POWER"})
            nt.links.new(vb.outputs[0], p.inputs[0])
            nt.links.new(ve.outputs[0], p.inputs[1])
            sx = nt.nodes.new("ShaderNodeSeparateXYZ")
            nt.links.new(p.outputs["Vector"], sx.inputs[0])
            r = sx.outputs["Y"]
        else:
            r = _math(nt, "POWER", base, expo)
        cap = _math(nt, "MULTIPLY", x, 2.0) if constant else 2.0
        nt.links.new(_math(nt, "ADD", _math(nt, "MINIMUM", r, cap), x), emit.inputs["Strength"])
    return build


def log_base_one(nt, emit):
    """Logarithm to a base the graph computes as 1: log(a) / log(1) is 0 in Cycles (its safe
    division), where Lantern divided by 0 (+-inf, NaN at a = 1); clamped to [-2, 2], plus
    2 + x."""
    x, y = _sep(nt, "X"), _sep(nt, "Y")
    one = _math(nt, "ADD", _math(nt, "FLOOR", x), 1.0)
    lg = _math(nt, "LOGARITHM", _math(nt, "MULTIPLY_ADD", y, 2.0, 0.1), one)
    v = _math(nt, "MAXIMUM", _math(nt, "MINIMUM", lg, 2.0), -2.0)
    nt.links.new(_math(nt, "ADD", _math(nt, "ADD", v, 2.0), x), emit.inputs["Strength"])


def map_range_vector(build_type):
    def build(nt, emit):
        m = nt.nodes.new("ShaderNodeMapRange")
        m.data_type = "FLOAT_VECTOR"
        m.interpolation_type = build_type
        nt.links.new(_coord(nt), _ident(m, "Vector"))
        _ident(m, "From_Min_FLOAT3").default_value = (0.2, 0.1, 0.0)
        _ident(m, "To_Max_FLOAT3").default_value = (0.8, 1.0, 0.6)
        _ident(m, "Steps_FLOAT3").default_value = (4.0, 3.0, 2.0)
        out = next(o for o in m.outputs if o.identifier == "Vector")
        nt.links.new(out, emit.inputs["Color"])
    return build


def curves(kind):
    def build(nt, emit):
        if kind == "rgb":
            c = nt.nodes.new("ShaderNodeRGBCurve")
            c.mapping.curves[3].points.new(0.4, 0.7)
            c.mapping.curves[0].points.new(0.5, 0.2)
            c.mapping.update()
            nt.links.new(_coord(nt), c.inputs["Color"])
            _link(nt, c, "Color", emit)
        else:
            c = nt.nodes.new("ShaderNodeFloatCurve")
            c.mapping.curves[0].points.new(0.3, 0.8)
            c.mapping.update()
            x = nt.nodes.new("ShaderNodeSeparateXYZ")
            nt.links.new(_coord(nt), x.inputs[0])
            nt.links.new(x.outputs["Y"], c.inputs["Value"])
            nt.links.new(c.outputs[0], emit.inputs["Strength"])
    return build


def separate_combine_hsv(nt, emit):
    sep = nt.nodes.new("ShaderNodeSeparateColor")
    sep.mode = "HSV"
    nt.links.new(_coord(nt), sep.inputs[0])
    comb = nt.nodes.new("ShaderNodeCombineColor")
    comb.mode = "HSL"
    nt.links.new(sep.outputs[0], comb.inputs[1])
    nt.links.new(sep.outputs[1], comb.inputs[2])
    nt.links.new(sep.outputs[2], comb.inputs[0])
    _link(nt, comb, "Color", emit)


CASES = {
    "mix_vector_uniform": ("plane", mix_vector(False)),
    "mix_vector_nonuniform": ("plane", mix_vector(True)),
    "mix_float_converted": ("plane", mix_float_converted),
    "brick_zero_width": ("plane", brick_zero_width),
    "brick_computed_zero_row_height": ("plane", brick_computed_size("Row Height", 0.0, 0.0)),
    "brick_computed_negative_width": ("plane", brick_computed_size("Brick Width", -0.3, -0.05)),
    "math_power_of_zero": ("plane", power_of_zero(False, False)),
    "vector_power_of_zero": ("plane", power_of_zero(True, False)),
    "math_power_of_zero_folded": ("plane", power_of_zero(False, True)),
    "vector_power_of_zero_folded": ("plane", power_of_zero(True, True)),
    "math_log_base_one": ("plane", log_base_one),
    "map_range_vector_stepped": ("plane", map_range_vector("STEPPED")),
    "map_range_vector_smootherstep": ("plane", map_range_vector("SMOOTHERSTEP")),
    "rgb_curves": ("plane", curves("rgb")),
    "float_curve": ("plane", curves("float")),
    "separate_combine_hsv_hsl": ("plane", separate_combine_hsv),
    "image_flat_repeat": ("plane", image(scale=1.7)),
    "image_flat_extend_linear": ("plane", image(extension="EXTEND", interpolation="Linear",
                                                scale=1.5)),
    "image_flat_mirror": ("plane", image(extension="MIRROR", scale=2.5)),
    "image_flat_clip": ("plane", image(extension="CLIP", scale=1.4)),
    "image_sphere_projection": ("sphere", image("SPHERE", vector="Generated")),
    "image_tube_projection": ("sphere", image("TUBE", vector="Generated")),
    "image_box_projection": ("sphere", image_box(0.0)),
    "image_box_projection_blend": ("sphere", image_box(0.35)),
    "color_attribute_corner": ("plane", color_attribute("CORNER")),
    "color_attribute_point": ("plane", color_attribute("POINT")),
    "texcoord_generated": ("plane", texcoord("Generated")),
    "texcoord_uv": ("plane", texcoord("UV")),
    "texcoord_object": ("plane", texcoord("Object")),
    "texcoord_camera": ("plane", texcoord("Camera", 0.3)),
    "texcoord_window": ("plane", texcoord("Window")),
    "texcoord_normal_sphere": ("sphere", texcoord("Normal")),
    "texcoord_reflection_sphere": ("sphere", texcoord("Reflection")),
    "mapping_point": ("plane", mapping("POINT")),
    "mapping_texture": ("plane", mapping("TEXTURE")),
    "mapping_vector": ("plane", mapping("VECTOR")),
    "mapping_normal": ("plane", mapping("NORMAL")),
    "math_arith": ("plane", math_chain([("MULTIPLY", 3.0, 0), ("POWER", 1.7, 0),
                                        ("SUBTRACT", 0.4, 0), ("ABSOLUTE", 0, 0)])),
    "math_periodic": ("plane", math_chain([("MULTIPLY", 9.0, 0), ("SINE", 0, 0),
                                           ("ADD", 1.2, 0)])),
    "math_wrap_smooth": ("plane", math_chain([("PINGPONG", 0.3, 0), ("SMOOTH_MAX", 0.1, 0.2),
                                              ("WRAP", 0.25, 0.02)])),
    "vector_cross": ("plane", vector_math("CROSS_PRODUCT")),
    "vector_reflect": ("plane", vector_math("REFLECT")),
    "vector_refract": ("plane", vector_math("REFRACT")),
    "vector_distance": ("plane", vector_math("DISTANCE")),
    "vector_project": ("plane", vector_math("PROJECT")),
    "vector_wrap": ("plane", vector_math("WRAP")),
    "ramp_linear": ("plane", ramp("LINEAR")),
    "ramp_ease": ("plane", ramp("EASE")),
    "ramp_bspline": ("plane", ramp("B_SPLINE")),
    "ramp_cardinal": ("plane", ramp("CARDINAL")),
    "ramp_constant": ("plane", ramp("CONSTANT")),
    "hsv": ("plane", color_op("ShaderNodeHueSaturation", {"Hue": 0.3, "Saturation": 1.4,
                                                          "Value": 0.8})),
    "bright_contrast": ("plane", color_op("ShaderNodeBrightContrast", {"Bright": 0.1,
                                                                       "Contrast": 0.4})),
    "gamma": ("plane", color_op("ShaderNodeGamma", {"Gamma": 2.2})),
    "invert": ("plane", color_op("ShaderNodeInvert", {"Fac": 0.8})),
    "checker": ("plane", texture("ShaderNodeTexChecker", Scale=3.0)),
    "gradient_radial": ("plane", texture("ShaderNodeTexGradient", props={"gradient_type":
                                                                         "RADIAL"})),
    "gradient_quadratic_sphere": ("plane", texture("ShaderNodeTexGradient", props={
        "gradient_type": "QUADRATIC_SPHERE"})),
    "noise_fbm": ("plane", texture("ShaderNodeTexNoise", Scale=4.0, Detail=3.5)),
    "noise_distorted": ("plane", texture("ShaderNodeTexNoise", Scale=3.0, Distortion=1.5)),
    "noise_ridged": ("plane", texture("ShaderNodeTexNoise", out="Fac", props={
        "noise_type": "RIDGED_MULTIFRACTAL"}, Scale=3.0, Detail=4.0)),
    "noise_hetero": ("plane", texture("ShaderNodeTexNoise", out="Fac", props={
        "noise_type": "HETERO_TERRAIN"}, absolute=True, Scale=3.0, Detail=3.0)),
    "noise_hybrid": ("plane", texture("ShaderNodeTexNoise", out="Fac", props={
        "noise_type": "HYBRID_MULTIFRACTAL"}, absolute=True, Scale=3.0, Detail=3.0)),
    "noise_multifractal": ("plane", texture("ShaderNodeTexNoise", out="Fac", props={
        "noise_type": "MULTIFRACTAL"}, Scale=3.0, Detail=3.0)),
    "noise_4d": ("plane", texture("ShaderNodeTexNoise", props={"noise_dimensions": "4D"},
                                  Scale=3.0, W=0.7)),
    "noise_2d": ("plane", texture("ShaderNodeTexNoise", props={"noise_dimensions": "2D"},
                                  Scale=3.0)),
    "noise_1d": ("plane", texture("ShaderNodeTexNoise", props={"noise_dimensions": "1D"},
                                  Scale=3.0, W=0.35)),
    "white_noise_2d": ("plane", white_noise("2D")),
    "white_noise_3d": ("plane", white_noise("3D")),
    "white_noise_4d": ("plane", white_noise("4D")),
    "wave_bands": ("plane", texture("ShaderNodeTexWave", Scale=1.0)),
    "wave_rings_saw": ("plane", texture("ShaderNodeTexWave", props={
        "wave_type": "RINGS", "wave_profile": "SAW"}, Scale=1.5, Distortion=2.0)),
    "magic": ("plane", texture("ShaderNodeTexMagic", Scale=2.0)),
    "voronoi_grid_f1": ("plane", texture("ShaderNodeTexVoronoi", out="Distance", Scale=4.0,
                                         Randomness=0.0)),
    "voronoi_f1_color": ("plane", texture("ShaderNodeTexVoronoi", Scale=4.0)),
    "voronoi_f1_distance": ("plane", texture("ShaderNodeTexVoronoi", out="Distance", Scale=4.0)),
    "voronoi_f1_position": ("plane", texture("ShaderNodeTexVoronoi", out="Position",
                                             absolute=True, Scale=3.0)),
    "voronoi_f2_manhattan": ("plane", texture("ShaderNodeTexVoronoi", out="Distance", props={
        "feature": "F2", "distance": "MANHATTAN"}, Scale=3.0, Randomness=0.8)),
    "voronoi_smooth_f1": ("plane", texture("ShaderNodeTexVoronoi", props={
        "feature": "SMOOTH_F1"}, Scale=3.0, Smoothness=0.6)),
    "voronoi_2d_chebychev": ("plane", texture("ShaderNodeTexVoronoi", props={
        "voronoi_dimensions": "2D", "distance": "CHEBYCHEV"}, Scale=4.0)),
    "voronoi_2d_minkowski_distance": ("plane", texture("ShaderNodeTexVoronoi", out="Distance",
                                                       props={"voronoi_dimensions": "2D",
                                                              "distance": "MINKOWSKI"},
                                                       Scale=4.0, Exponent=1.5)),
    "brick": ("plane", texture("ShaderNodeTexBrick", Scale=3.0)),
    "brick_fac_smooth": ("plane", texture("ShaderNodeTexBrick", out="Fac", **{
        "Scale": 2.0, "Mortar Size": 0.05, "Mortar Smooth": 0.6})),
    # a negative Mortar Smooth: no mortar anywhere in Cycles (its smoothstep of a negative
    # ratio), the bricks' colours alone (difftest D18: Lantern drew the mortar)
    "brick_negative_mortar_smooth": ("plane", texture("ShaderNodeTexBrick", **{
        "Scale": 3.0, "Mortar Size": 0.08, "Mortar Smooth": -0.4})),
    "brick_offset_squash": ("plane", texture("ShaderNodeTexBrick", props={
        "offset": 0.3, "offset_frequency": 3, "squash": 0.6, "squash_frequency": 2}, **{
        "Scale": 2.5, "Bias": 0.3, "Brick Width": 0.4, "Row Height": 0.2, "Mortar Size": 0.06,
        "Mortar Smooth": 0.0})),   # (a smooth band narrower than a pixel would be an edge)
    "blackbody": ("plane", spectral("ShaderNodeBlackbody", "Temperature", *BLACKBODY_K)),
    "blackbody_luminance": ("plane", spectral("ShaderNodeBlackbody", "Temperature",
                                              *BLACKBODY_LOW_K, into="Strength")),
    "wavelength": ("plane", spectral("ShaderNodeWavelength", "Wavelength", *WAVELENGTH_NM)),
    # past both ends of the table (difftest D26): black there in Cycles; 330-830 nm puts no
    # pixel centre at 375-380 nm, where Cycles extrapolates and Lantern reads the 380 nm row
    "wavelength_out_of_range": ("plane", spectral("ShaderNodeWavelength", "Wavelength", 330.0,
                                                  830.0)),
    "camera_view_vector_sphere": ("sphere", camera_data("View Vector", -0.5, 1.0)),
    "camera_z_depth_sphere": ("sphere", camera_data("View Z Depth", 2.5, 4.5)),
    "camera_distance_sphere": ("sphere", camera_data("View Distance", 2.5, 4.5)),
    "normal_dot_sphere": ("sphere", normal_dot),
    "geometry_normal_under_bump_sphere": ("sphere", geometry_normal(False)),
    "geometry_normal_displacement_sphere": ("sphere", geometry_normal(True)),
    "fresnel_sphere": ("sphere", view_dependent("ShaderNodeFresnel", "Fac", IOR=1.45)),
    "layer_weight_facing_sphere": ("sphere", view_dependent("ShaderNodeLayerWeight", "Facing",
                                                            Blend=0.3)),
    "layer_weight_fresnel_sphere": ("sphere", view_dependent("ShaderNodeLayerWeight",
                                                             "Fresnel", Blend=0.6)),
}
# Texture nodes with their Vector unlinked on the sphere: Blender reads Generated (UV for Image
# Texture), here varying in all three axes (the plane's cases above read a constant z of 0.5)
UNLINKED = {
    "checker": ("ShaderNodeTexChecker", "Color", None, {"Scale": 3.3}),
    "noise_3d": ("ShaderNodeTexNoise", "Color", None, {"Scale": 3.0, "Detail": 3.0}),
    "noise_4d": ("ShaderNodeTexNoise", "Fac", {"noise_dimensions": "4D"},
                 {"Scale": 2.5, "W": 0.4}),
    "noise_ridged": ("ShaderNodeTexNoise", "Fac", {"noise_type": "RIDGED_MULTIFRACTAL"},
                     {"Scale": 2.0, "Detail": 3.0}),
    "magic": ("ShaderNodeTexMagic", "Color", {"turbulence_depth": 3}, {"Scale": 2.5}),
    # (a sharp mortar: a smooth one's band is so steep that Generated's float rounding on
    # the sphere, 5e-7 between the two, moves its pixels by 4e-4)
    "brick": ("ShaderNodeTexBrick", "Color", None, {
        "Scale": 3.0, "Mortar": (0.1, 0.2, 0.3, 1.0), "Mortar Size": 0.05,
        "Mortar Smooth": 0.0}),
    "image_uv": ("ShaderNodeTexImage", "Color", None, {}),
    "voronoi_f1_distance": ("ShaderNodeTexVoronoi", "Distance", None, {"Scale": 5.0}),
    "voronoi_f1_color": ("ShaderNodeTexVoronoi", "Color", None, {"Scale": 5.0}),
    "voronoi_f1_position": ("ShaderNodeTexVoronoi", "Position", None, {"Scale": 3.0}),
    "voronoi_f2_chebychev": ("ShaderNodeTexVoronoi", "Distance", {
        "feature": "F2", "distance": "CHEBYCHEV"}, {"Scale": 4.0, "Randomness": 0.7}),
    "voronoi_f1_manhattan": ("ShaderNodeTexVoronoi", "Distance", {"distance": "MANHATTAN"},
                             {"Scale": 4.0}),
    "voronoi_smooth_f1_minkowski": ("ShaderNodeTexVoronoi", "Color", {
        "feature": "SMOOTH_F1", "distance": "MINKOWSKI"},
        {"Scale": 3.0, "Smoothness": 0.5, "Exponent": 0.8}),
    "voronoi_2d": ("ShaderNodeTexVoronoi", "Distance", {"voronoi_dimensions": "2D"},
                   {"Scale": 5.0}),
    # (every distance above 8, where Lantern's search used to start: 684 of 2496 channels off;
    # its Distance, (sum |d|^0.3)^(1/0.3), carries float rounding up to 4.8e-4: Color only)
    "voronoi_minkowski_exponent_0_3": ("ShaderNodeTexVoronoi", "Color", {
        "distance": "MINKOWSKI"}, {"Scale": 3.0, "Exponent": 0.3}),
}
for _g in ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL", "QUADRATIC_SPHERE",
           "RADIAL"):
    UNLINKED[f"gradient_{_g.lower()}"] = ("ShaderNodeTexGradient", "Color",
                                          {"gradient_type": _g}, {})
for _t, _dirs in (("BANDS", ("X", "Y", "Z", "DIAGONAL")), ("RINGS", ("X", "Y", "Z",
                                                                      "SPHERICAL"))):
    for _d, _profile in zip(_dirs, ("SIN", "SAW", "TRI", "SIN")):
        UNLINKED[f"wave_{_t.lower()}_{_d.lower()}_{_profile.lower()}"] = (
            "ShaderNodeTexWave", "Color", {"wave_type": _t, f"{_t.lower()}_direction": _d,
                                           "wave_profile": _profile},
            {"Scale": 1.3, "Distortion": 1.5, "Detail": 2.0})


def unlinked(idname, out, props, inputs):
    def build(nt, emit):
        n = _node(nt, idname, props, **inputs)
        if idname == "ShaderNodeTexImage":
            n.image = _image()
        assert not n.inputs["Vector"].is_linked
        if out == "Position":   # signed
            nt.links.new(_abs(nt, n.outputs[out], 0.5), emit.inputs["Color"])
        else:
            _link(nt, n, out, emit)
    return build


for _name, _spec in UNLINKED.items():
    CASES[f"{_name}_unlinked_sphere"] = ("sphere", unlinked(*_spec))


def white_noise_unlinked(dim, vector=None):
    """White Noise with its Vector unlinked: Cycles reads the socket's value there (no
    implicit Generated), so the case varies through W (4D: floored Generated X) alone."""
    def build(nt, emit):
        n = nt.nodes.new("ShaderNodeTexWhiteNoise")
        n.noise_dimensions = dim
        if vector is not None:
            n.inputs["Vector"].default_value = vector
        x = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(_floored(nt), x.inputs[0])
        nt.links.new(x.outputs["X"], _ident(n, "W"))
        assert not n.inputs["Vector"].is_linked
        _link(nt, n, "Color", emit)
    return build


def deform(kind):
    """Deforms the sphere (modifiers, a shape key): Generated stays on the undeformed mesh."""
    obj = bpy.data.objects["Sphere"]
    if kind == "twist":
        m = obj.modifiers.new("Twist", "SIMPLE_DEFORM")
        m.deform_method, m.angle = "TWIST", 0.8
    elif kind == "displace":   # no texture: along the normals by strength x (1 - midlevel)
        obj.modifiers.new("Displace", "DISPLACE").strength = 0.3
    elif kind == "shape_key":
        obj.shape_key_add(name="Basis")
        key = obj.shape_key_add(name="Lean")
        co = np.empty(3 * len(key.data), np.float32)
        key.data.foreach_get("co", co)
        co = co.reshape(-1, 3)
        co[:, 0] *= 1.0 + 0.4 * co[:, 2]
        key.data.foreach_set("co", co.ravel())
        key.value = 0.7
    elif kind == "subsurf_bend":   # builds, then deforms
        obj.modifiers.new("Subdivision", "SUBSURF").render_levels = 1
        m = obj.modifiers.new("Bend", "SIMPLE_DEFORM")
        m.deform_method, m.angle = "BEND", 0.8
    else:
        raise ValueError(kind)


def deformed(kind, build):
    def run(nt, emit):
        deform(kind)
        build(nt, emit)
    return run


def voronoi_dims(dim, feature, metric, out, **inputs):
    """1D and 4D Voronoi on the sphere: 4D with its Vector unlinked and W set, 1D over W
    linked to 2.7 x Generated X (1D reads no vector). The W output as emission strength."""
    def build(nt, emit):
        n = _node(nt, "ShaderNodeTexVoronoi", {"voronoi_dimensions": dim, "feature": feature,
                                               "distance": metric}, **inputs)
        if dim == "1D":
            x = nt.nodes.new("ShaderNodeSeparateXYZ")
            nt.links.new(_coord(nt), x.inputs[0])
            m = _node(nt, "ShaderNodeMath", {"operation": "MULTIPLY"})
            nt.links.new(x.outputs["X"], m.inputs[0])
            m.inputs[1].default_value = 2.7
            nt.links.new(m.outputs[0], _ident(n, "W"))
        else:
            _ident(n, "W").default_value = 0.7
        if out == "W":
            nt.links.new(n.outputs["W"], emit.inputs["Strength"])
        elif out == "Position":
            nt.links.new(_abs(nt, n.outputs[out], 0.5), emit.inputs["Color"])
        else:
            _link(nt, n, out, emit)
    return build


def voronoi_linked_randomness(value):
    """Randomness from a link, outside [0, 1]: Cycles clamps it there."""
    def build(nt, emit):
        n = _node(nt, "ShaderNodeTexVoronoi", Scale=4.0)
        v = nt.nodes.new("ShaderNodeValue")
        v.outputs[0].default_value = value
        nt.links.new(v.outputs[0], n.inputs["Randomness"])
        _link(nt, n, "Color", emit)
    return build


for _dim, _feature, _metric, _out in (
        ("4D", "F1", "EUCLIDEAN", "Color"), ("4D", "F2", "MANHATTAN", "Distance"),
        ("4D", "SMOOTH_F1", "EUCLIDEAN", "Color"), ("4D", "F1", "CHEBYCHEV", "Position"),
        ("4D", "F1", "MINKOWSKI", "W"), ("1D", "F1", "EUCLIDEAN", "Color"),
        ("1D", "F2", "EUCLIDEAN", "Distance"), ("1D", "SMOOTH_F1", "EUCLIDEAN", "Distance"),
        ("1D", "F1", "EUCLIDEAN", "W")):
    CASES[f"voronoi_{_dim.lower()}_{_feature.lower()}_{_metric.lower()}_{_out.lower()}"] = (
        "sphere", voronoi_dims(_dim, _feature, _metric, _out, Scale=3.0, Exponent=1.5,
                               Smoothness=0.6, Randomness=0.9))
CASES["voronoi_randomness_linked_above_one"] = ("plane", voronoi_linked_randomness(1.6))
CASES["voronoi_randomness_linked_below_zero"] = ("plane", voronoi_linked_randomness(-0.3))
CASES["texcoord_generated_twisted_sphere"] = ("sphere", deformed("twist",
                                                                 texcoord("Generated")))
CASES["voronoi_f1_unlinked_displaced_sphere"] = ("sphere", deformed(
    "displace", unlinked(*UNLINKED["voronoi_f1_distance"])))
CASES["wave_unlinked_shape_key_sphere"] = ("sphere", deformed(
    "shape_key", unlinked(*UNLINKED["wave_bands_x_sin"])))
CASES["white_noise_4d_unlinked_sphere"] = ("sphere", white_noise_unlinked("4D"))
CASES["white_noise_4d_unlinked_vector_set"] = ("plane", white_noise_unlinked(
    "4D", (0.3, -1.7, 2.25)))
for _blend in ("MIX", "DARKEN", "MULTIPLY", "BURN", "LIGHTEN", "SCREEN", "DODGE", "ADD",
               "OVERLAY", "SOFT_LIGHT", "LINEAR_LIGHT", "DIFFERENCE", "EXCLUSION", "SUBTRACT",
               "DIVIDE", "HUE", "SATURATION", "COLOR", "VALUE"):
    CASES[f"mix_{_blend.lower()}"] = ("plane", mix_color(_blend))


@pytest.fixture(scope="module", autouse=True)
def _addon():
    st.addon()


def _covered(shape, img_c):
    """The compared pixels: all of the plane; the sphere without its silhouette ring."""
    if shape != "sphere":
        return np.ones(img_c.shape[:2], bool)
    hit = img_c.max(axis=2) > 0
    covered = np.zeros_like(hit)
    covered[1:-1, 1:-1] = hit[1:-1, 1:-1] & hit[:-2, 1:-1] & hit[2:, 1:-1] & \
        hit[1:-1, :-2] & hit[1:-1, 2:]
    return covered


@pytest.mark.parametrize("case", sorted(CASES))
def test_node_output_matches_cycles(case, tmp_path):
    shape, build = CASES[case]
    sc, nt, emit = st.stage(shape)
    build(nt, emit)
    img_l, warnings = render_lantern()
    img_c = render_cycles(sc, tmp_path / "cycles.exr")
    assert warnings == []
    covered = _covered(shape, img_c)
    assert np.std(img_c[covered]) > 0.01, "the case does not vary: it would test nothing"
    if case in SPECTRAL_CYCLES:   # against the independent computation; Cycles within its bound
        expected = SPECTRAL_EXPECTED[case](img_c.shape[1])
        assert_exact(case, img_l, np.broadcast_to(expected, img_l.shape).copy(),
                     tol=SPECTRAL_TOL[case])
        tol, floor = SPECTRAL_CYCLES[case]
        if case == "wavelength":   # Cycles' own table and matrix: with the controls too
            assert_exact(case, img_l, img_c, tol=tol, floor=floor)
        else:   # Cycles' fit: a bound
            err = st.relative_error(img_l, img_c, floor).max()
            assert err <= tol, f"{case}: worst error against Cycles {err:.4f} > {tol}"
        return
    assert_exact(case, img_l, img_c, covered, *CASE_TOL.get(case, (TOL, 0.05)))


# ---- Generated through a final render: its depsgraph computes Blender's undeformed
# coordinates (ORCO) for every mesh, carried through the modifiers that build (Array,
# Subdivision) but not those that deform, which no viewport depsgraph without a 3D view has, so
# test_node_output_matches_cycles never reads them. The engine's own export is rendered at the
# pixel centres (the F12 it ran is discarded).
@pytest.mark.parametrize("stack", ["array_twist", "subsurf_bend"])
def test_generated_through_final_render(stack, tmp_path, monkeypatch):
    import importlib
    sc, nt, emit = st.stage("sphere")
    obj = bpy.data.objects["Sphere"]
    if stack == "array_twist":
        a = obj.modifiers.new("Array", "ARRAY")
        a.count, a.relative_offset_displace = 2, (0.5, 0.0, 0.0)
        m = obj.modifiers.new("Twist", "SIMPLE_DEFORM")
        m.deform_method, m.angle = "TWIST", 0.8
    else:
        deform("subsurf_bend")
    texcoord("Generated")(nt, emit)
    export = importlib.import_module("lantern_blender.export")
    captured = []

    def capture(depsgraph, **kw):   # kw: the engine's frame_set (motion blur's steps)
        captured.append((depsgraph.mode, *export_scene(depsgraph, **kw)))
        return captured[-1][1:]

    export_scene = export.export_scene
    monkeypatch.setattr(export, "export_scene", capture)
    sc.render.engine = "LANTERN"
    sc.lantern.samples, sc.lantern.max_depth, sc.lantern.integrator = 1, 1, "pt"
    sc.render.filepath = str(tmp_path / "f12.exr")
    bpy.ops.render.render(write_still=False)
    monkeypatch.undo()
    assert [c[0] for c in captured] == ["RENDER"], "the engine's export did not run"
    _, scene, report = captured[0]
    assert list(report.messages) == []
    scene.film["filter_width"] = FILTER_PX
    img_l = np.asarray(lantern.render(scene, spp=1, integrator="pt", max_depth=1, seed=1),
                       np.float64)
    img_c = render_cycles(sc, tmp_path / "cycles.exr")
    covered = _covered("sphere", img_c)
    assert np.std(img_c[covered]) > 0.01
    assert_exact(f"generated_final_render_{stack}", img_l, img_c, covered)
    # and the viewport depsgraph's export, which has no ORCO here, says what it cannot do
    _, warnings = render_lantern()
    assert any("Generated coordinates follow the deformed mesh" in w for w in warnings), warnings


# ---- Bump: a diffuse plane under a sun straight above, one bounce: each pixel is
# albedo / pi x E x cos(bumped normal), so the image is the bumped normal's z. Under an oblique
# sun Cycles also applies its bump shadowing term (the GGX masking of the normal's tilt at the
# sun's angle to the unbent normal, docs/nodes.md "Bump and displacement"), as Lantern does:
# bump_linear_oblique_sun (slope 0.5, sun 60 deg off the plane's normal) is 2.2 % darker than
# the cosine, which a Lantern without the term puts off in every pixel. Its sun is on the side
# the normal tilts towards (the term is the same either way): tilted away, the pixels read
# 0.045 of the unbent 0.38, where the normal's float rounding (BENT_TOL) is 1 % of them.
def _bump_stage(height_idname, inputs, distance, strength=1.0, invert=False, chain=False,
                displacement=False, sun_deg=0.0):
    sc, nt, emit = st.stage("plane")
    nt.nodes.remove(emit)
    d = _node(nt, "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
    nt.links.new(d.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    h = _node(nt, height_idname, **inputs)
    if displacement:
        disp = _node(nt, "ShaderNodeDisplacement", Midlevel=0.5, Scale=distance)
        nt.links.new(h.outputs[0], disp.inputs["Height"])
        nt.links.new(disp.outputs[0], nt.nodes["Material Output"].inputs["Displacement"])
    else:
        b = _node(nt, "ShaderNodeBump", {"invert": invert}, Distance=distance,
                  Strength=strength)
        nt.links.new(h.outputs[0], b.inputs["Height"])
        nt.links.new(b.outputs[0], d.inputs["Normal"])
        if chain:   # a second bump under the first
            w = _node(nt, "ShaderNodeTexWave", {"bands_direction": "Y"}, Scale=1.5)
            b2 = _node(nt, "ShaderNodeBump", Distance=0.05)
            nt.links.new(w.outputs["Fac"], b2.inputs["Height"])
            nt.links.new(b2.outputs[0], b.inputs["Normal"])
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, 0.0
    sun.rotation_euler = (0.0, math.radians(sun_deg), 0.0)
    sc.collection.objects.link(sun)
    return sc


# Noise and Wave heights: Cycles differences them over the ray differentials (0.1 px, the
# Bump's Filter Width), Lantern over its 2e-4 offsets, and a height that bends within a pixel
# has another slope over each (docs/nodes.md "Bump and displacement"): per pixel the measured
# worst (3.5e-3, 7.1e-3, 1.8e-3 on the unbent value), which a 1 % bias of either sign still
# exceeds where the differences have that sign, and the image mean within 2e-4, where they
# cancel (measured 5.8e-6, 4.2e-5, 5.0e-6)
BUMP_TOL = {"bump_noise": (5e-3, 2e-4), "bump_wave_chained": (1e-2, 2e-4),
            "displacement_as_bump": (2.5e-3, 2e-4)}

BUMPS = {
    "bump_linear": ("ShaderNodeTexGradient", {}, {"distance": 0.5}),
    "bump_linear_oblique_sun": ("ShaderNodeTexGradient", {}, {"distance": 1.0, "sun_deg": -60.0}),
    "bump_linear_inverted_half": ("ShaderNodeTexGradient", {}, {"distance": 1.0,
                                                                 "invert": True,
                                                                 "strength": 0.5}),
    "bump_noise": ("ShaderNodeTexNoise", {"Scale": 3.0}, {"distance": 0.3, "strength": 0.7}),
    "bump_wave_chained": ("ShaderNodeTexWave", {"Scale": 2.0}, {"distance": 0.05,
                                                                "chain": True}),
    "displacement_as_bump": ("ShaderNodeTexNoise", {"Scale": 2.0}, {"distance": 0.3,
                                                                    "displacement": True}),
}


@pytest.mark.parametrize("case", sorted(BUMPS))
def test_bump_matches_cycles(case, tmp_path):
    idname, inputs, kw = BUMPS[case]
    sc = _bump_stage(idname, inputs, **kw)
    img_l, warnings = render_lantern(max_depth=2)
    img_c = render_cycles(sc, tmp_path / "cycles.exr", bounces=0)
    assert warnings == []
    flat = 0.8 / math.pi * 3.0 * math.cos(math.radians(kw.get("sun_deg", 0.0)))
    # the normal moved (a plain plane renders `flat` everywhere)
    assert np.abs(img_c - flat).max() > 0.01 * flat, "no bump: the case would test nothing"
    tol, mean_tol = BUMP_TOL.get(case, (BENT_TOL, None))
    assert_exact(case, img_l, img_c, tol=tol, floor=flat, mean_tol=mean_tol)


# ---- Normal Map fed by a node graph (its Color a mix of two colours along x, Strength 0.8),
# on a diffuse plane under an oblique sun turned about both axes, so that both tilt
# directions show; the tilts stay under 0.25, where Cycles' bump shadowing term (docs/nodes.md
# "Bump and displacement", which Lantern applies too) is under 0.3%. World and object spaces on a turned
# plane (its uv tangent frame turns with it), object space also unevenly scaled (the normal
# matrix is the inverse transpose); Blender's own spaces flip y and z. Measured controls:
# Lantern rendering the world case as tangent space puts 73% of the pixel channels off, the
# object case as world space 52%, Blender World as World 95%.
# Tangent space: Cycles applies Strength to the mapped vector before normalising it (the
# colour's 2c - 1 in the tangent frame, of length 0.95-1.05 here), Lantern to the normalised
# one (pt.h normal_from_tangent_color); with Strength 0.8 the images differ by up to 1.7e-3
# on the unbent value, a model of Cycles' order reproduces Cycles to 1e-5 (docs/nodes.md);
# the Object and World spaces normalise first in both
NORMAL_MAP_TOL = {"TANGENT": 2.5e-3}
NORMAL_MAP_COLORS = {"TANGENT": ((0.38, 0.6, 1.0), (0.62, 0.42, 0.95)),
                     "WORLD": ((0.38, 0.6, 1.0), (0.62, 0.42, 0.95)),
                     "OBJECT": ((0.4, 0.58, 1.0), (0.6, 0.45, 0.95)),
                     "BLENDER_WORLD": ((0.38, 0.4, 0.0), (0.62, 0.58, 0.05))}


def _normal_map_stage(space):
    sc, nt, emit = st.stage("plane")
    nt.nodes.remove(emit)
    obj = bpy.data.objects["Plane"]
    if space != "TANGENT":   # turned: world, object and tangent frames all differ
        obj.rotation_euler = (0.0, 0.0, 0.8)
    if space == "OBJECT":
        obj.scale = (1.4, 0.7, 1.0)
    d = _node(nt, "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
    nt.links.new(d.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    x = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(_coord(nt), x.inputs[0])
    m = nt.nodes.new("ShaderNodeMix")
    m.data_type = "RGBA"
    nt.links.new(x.outputs["X"], _ident(m, "Factor_Float"))
    a, b = NORMAL_MAP_COLORS[space]
    _ident(m, "A_Color").default_value = a + (1.0,)
    _ident(m, "B_Color").default_value = b + (1.0,)
    nm = _node(nt, "ShaderNodeNormalMap", {"space": space}, Strength=0.8)
    nt.links.new(next(s for s in m.outputs if s.identifier == "Result_Color"), nm.inputs["Color"])
    nt.links.new(nm.outputs[0], d.inputs["Normal"])
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, 0.0
    sun.rotation_euler = (0.5, 0.6, 0.0)
    sc.collection.objects.link(sun)
    return sc


@pytest.mark.parametrize("space", sorted(NORMAL_MAP_COLORS))
def test_normal_map_from_a_graph_matches_cycles(space, tmp_path):
    sc = _normal_map_stage(space)
    img_l, warnings = render_lantern(max_depth=2)
    img_c = render_cycles(sc, tmp_path / "cycles.exr", bounces=0)
    assert warnings == []
    assert np.std(img_c) > 0.01 * img_c.mean(), "the map bends nothing: it would test nothing"
    assert_exact(space, img_l, img_c, tol=NORMAL_MAP_TOL.get(space, BENT_TOL),
                 floor=0.8 / math.pi * 3.0)


# ---- A node graph on Roughness: the image must not depend on the socket's hidden value.
# Cycles computes the multiple-scattering compensation (and the Principled layer's albedo) at
# each hit's roughness. Lantern did so at the material's constant roughness, which for a
# graph-driven input is the socket's own (hidden) value; measured before the fix (bench/
# textured_roughness_cycles.py): a metal sphere in a white world whose Roughness is a Voronoi
# Distance rendered 5.5 % darker than Cycles, a Wave Fac 8 % darker, hidden values 0 and 1 from
# -15 % to +66 %. Now a material with a per-hit roughness reads its tables from rows at
# roughness j / 32 interpolated at the hit's (scene/scene_materials.cpp fill_lobe_tables, bsdf/
# multiscatter.h ms_rough). Noise-free checks, same seed: a graph whose value is 0.3 everywhere
# (not constant-folded) renders the same image whatever the hidden value (TOL: only float
# rounding may differ), and matches the constant 0.3 within ROWS_TOL, the rows' interpolation
# (the tables' quadrature varies by up to 1e-3 from one roughness to the next, about what
# Cycles' own 32 x 32 tables carry; measured worst pixel 8.1e-4 metal, 4.1e-4 dielectric).
ROWS_TOL = 2e-3


def _graph_roughness_sphere(hidden, graph_value, metallic):
    sc, nt, emit = st.stage("sphere", size=24)
    sc.world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    nt.nodes.remove(emit)
    p = _node(nt, "ShaderNodeBsdfPrincipled", **{"Base Color": (0.9, 0.6, 0.3, 1.0),
                                                 "Metallic": metallic, "Roughness": hidden})
    nt.links.new(p.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    if graph_value is not None:   # graph_value + 0 x Generated X
        x = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(_coord(nt), x.inputs[0])
        m = _node(nt, "ShaderNodeMath", {"operation": "MULTIPLY_ADD"})
        nt.links.new(x.outputs["X"], m.inputs[0])
        m.inputs[1].default_value, m.inputs[2].default_value = 0.0, graph_value
        nt.links.new(m.outputs[0], p.inputs["Roughness"])
    img, warnings = render_lantern(max_depth=4, seed=3)
    assert warnings == []
    return img


@pytest.mark.parametrize("metallic", [1.0, 0.0])
def test_graph_roughness_matches_the_constant(metallic):
    ref = _graph_roughness_sphere(0.3, None, metallic)
    assert_exact(f"graph_roughness_control_{metallic}", _graph_roughness_sphere(0.3, 0.3, metallic),
                 ref, ref.max(axis=2) < 1.0, tol=ROWS_TOL)


@pytest.mark.parametrize("hidden", [0.9, 0.0])
@pytest.mark.parametrize("metallic", [1.0, 0.0])
def test_graph_roughness_ignores_the_hidden_value(metallic, hidden):
    ref = _graph_roughness_sphere(0.3, 0.3, metallic)
    assert_exact(f"graph_roughness_hidden_{hidden}_{metallic}",
                 _graph_roughness_sphere(hidden, 0.3, metallic), ref, ref.max(axis=2) < 1.0)
