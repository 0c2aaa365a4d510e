"""The node cases of test_nodes.py: a builder per case (it wires one node or a short chain
into an emission-only material) and CASES, name -> (shape, builder); test_nodes.py adds the
unlinked-vector, deformed and Voronoi cases."""

import numpy as np

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

from nodes_common import (BLACKBODY_K, BLACKBODY_LOW_K, WAVELENGTH_NM, _abs, _coord, _floored,
    _ident, _link, _node)  # noqa: E402


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
