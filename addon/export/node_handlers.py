"""One handler per shader node type: handler(ctx, node, out, path) -> Val of output `out`.
Register layouts of the instructions are those documented at NodeOp in
native/src/scene/material_program_ops.h."""

from . import node_graph as ng
from . import node_ops as ne
from .node_spectral import SPECTRAL_HANDLERS
from .node_textures import TEXTURE_HANDLERS

OP = ne.OP


def _out_index(node, out):
    return [s.identifier for s in node.outputs].index(out.identifier)


def _v(ctx, node, name, path, kind="VALUE"):
    return ctx.inp(node, name, path, kind)


# ---- inputs ----
def h_value(ctx, node, out, path):
    return ctx.const(ng.socket_value(node.outputs[0]), "VALUE")


def h_rgb(ctx, node, out, path):
    return ctx.const(ng.socket_value(node.outputs[0]), "RGBA")


def _normalized(ctx, v):
    """v / |v|: the interpolated vertex normal is shorter than 1 inside a face (0.9957 at
    worst on a 48 x 24 UV sphere); Cycles' Normal coordinate is unit length."""
    zero, one = ctx.const((0.0, 0.0, 0.0), "VECTOR"), ctx.const((1.0,), "VALUE")
    r, _ = ctx.emit_node("vector_math", [v, zero, zero, one], 4,
                         mode=ne.VECTOR_OPS.index("NORMALIZE"))
    return ctx.reg(r, 3, "VECTOR")


def _facing_viewer(ctx, v):
    """v negated on back faces: Cycles' Normal coordinate is its shading normal N in object
    space, and N faces the incoming ray (difftest D19: back faces seen through alpha)."""
    b = ctx.geometry(ne.IN_BACKFACING)
    r, _ = ctx.emit_node("math", [ctx.reg(b.reg, 1, "VALUE"), ctx.const((-2.0,), "VALUE"),
                                  ctx.const((1.0,), "VALUE")], 1,
                         mode=ne.MATH_OPS.index("MULTIPLY_ADD"))
    zero = ctx.const((0.0, 0.0, 0.0), "VECTOR")
    r, _ = ctx.emit_node("vector_math", [v, zero, zero, ctx.reg(r, 1, "VALUE")], 4,
                         mode=ne.VECTOR_OPS.index("SCALE"))
    return ctx.reg(r, 3, "VECTOR")


def h_tex_coord(ctx, node, out, path):
    name = out.identifier
    if getattr(node, "object", None) is not None and name == "Object":
        ctx.c.warn(f"Texture Coordinate '{node.name}' names object '{node.object.name}'; the "
                   "shaded object's own coordinates are used")
    if getattr(node, "from_instancer", False):
        ctx.c.warn(f"Texture Coordinate '{node.name}': From Instancer is not supported")
    table = {"Generated": lambda: ctx.attribute("generated"),
             "Normal": lambda: _facing_viewer(ctx, _normalized(
                 ctx, ctx.attribute("object_normal"))),
             "UV": lambda: ctx.geometry(ne.IN_UV),
             "Object": lambda: ctx.attribute("object"),
             "Camera": lambda: ctx.geometry(ne.IN_CAMERA),
             "Window": lambda: ctx.geometry(ne.IN_WINDOW),
             "Reflection": lambda: ctx.geometry(ne.IN_REFLECTION)}
    if name not in table:
        return ctx.fallback(out)
    return table[name]()


def h_uvmap(ctx, node, out, path):
    if getattr(node, "uv_map", ""):
        ctx.c.warn(f"UV Map node '{node.name}' names '{node.uv_map}'; the active render UV "
                   "map is used")
    return ctx.geometry(ne.IN_UV)


def h_geometry(ctx, node, out, path):
    name = out.identifier
    m = {"Position": ne.IN_POSITION, "Normal": ne.IN_NORMAL, "True Normal": ne.IN_TRUE_NORMAL,
         "Incoming": ne.IN_INCOMING}
    if name in m:
        return ctx.geometry(m[name])
    if name == "Backfacing":
        g = ctx.geometry(ne.IN_BACKFACING)
        return ctx.reg(g.reg, 1, "VALUE")
    ctx.c.warn(f"Geometry '{node.name}' output '{out.name}' is not supported; 0 is used")
    return ctx.fallback(out)


def h_object_info(ctx, node, out, path):
    name = out.identifier
    if name == "Location":
        return ctx.attribute("object_location")
    if name in ("Random", "Object Index", "Material Index"):
        a = ctx.attribute("object_random")
        k = {"Random": 0, "Object Index": 1, "Material Index": 2}[name]
        return ctx.reg(a.reg + k, 1, "VALUE")
    if name == "Color":
        return ctx.attribute("object_color")
    if name == "Alpha":
        return ctx.const((1.0,), "VALUE")
    return ctx.fallback(out)


def h_camera_data(ctx, node, out, path):
    """Camera Data: the point in camera space (x right, y up, z forward): its direction, its
    depth along the view axis and its distance."""
    cam = ctx.geometry(ne.IN_CAMERA)
    zero, one = ctx.const((0.0, 0.0, 0.0), "VECTOR"), ctx.const((1.0,), "VALUE")
    if out.identifier == "View Z Depth":
        return ctx.reg(cam.reg + 2, 1, "VALUE")
    op = "NORMALIZE" if out.identifier == "View Vector" else "LENGTH"
    r, _ = ctx.emit_node("vector_math", [cam, zero, zero, one], 4, mode=ne.VECTOR_OPS.index(op))
    if op == "LENGTH":
        return ctx.reg(r + 3, 1, "VALUE")
    return ctx.reg(r, 3, "VECTOR")


def h_normal(ctx, node, out, path):
    """Normal: its own direction (the output socket's value), and Dot: that direction with
    the normalised input."""
    d = ng.socket_value(node.outputs[0]) or (0.0, 0.0, 1.0)
    length = sum(x * x for x in d) ** 0.5
    d = tuple(x / length for x in d) if length > 0 else (0.0, 0.0, 1.0)
    direction = ctx.const(d, "VECTOR")
    if out.identifier == "Normal":
        return direction
    zero, one = ctx.const((0.0, 0.0, 0.0), "VECTOR"), ctx.const((1.0,), "VALUE")
    n = ctx.input_value(node.inputs[0], path, "VECTOR")
    r, _ = ctx.emit_node("vector_math", [n, zero, zero, one], 4,
                         mode=ne.VECTOR_OPS.index("NORMALIZE"))
    r2, _ = ctx.emit_node("vector_math", [ctx.reg(r, 3, "VECTOR"), direction, zero, one], 4,
                          mode=ne.VECTOR_OPS.index("DOT_PRODUCT"))
    return ctx.reg(r2 + 3, 1, "VALUE")


def h_color_attribute(ctx, node, out, path):
    name = getattr(node, "layer_name", "")
    if out.identifier == "Alpha":
        ctx.c.warn(f"Color Attribute '{node.name}': its Alpha output reads 1")
        return ctx.const((1.0,), "VALUE")
    return ctx.reg(ctx.attribute(f"color:{name}").reg, 3, "RGBA")


def grid_register(ctx, name):
    """The first of the 4 registers (colour, Fac) of grid `name` at the point (kOpGrid), for a
    compiler with a `grids` table (volume_objects: the object's grids; its aux is the grid's
    place in that table until the export puts the scene's index there)."""
    key = ("grid", name)
    if key not in ctx.memo:
        out = ctx.b.alloc(4)
        ctx.b.emit(OP["grid"], out=out, aux=ctx.c.grids.index_of(name))
        ctx.memo[key] = out
    return ctx.memo[key]


def h_attribute(ctx, node, out, path):
    kind = getattr(node, "attribute_type", "GEOMETRY")
    if kind != "GEOMETRY":
        ctx.c.warn(f"Attribute '{node.name}' of type {kind} is not supported; 0 is used")
        return ctx.fallback(out)
    if getattr(ctx.c, "grids", None) is not None:
        # a Volume object's material: the attribute is a grid of its file (kOpGrid)
        r = grid_register(ctx, node.attribute_name)
        if out.identifier == "Fac":
            return ctx.reg(r + 3, 1, "VALUE")
        if out.identifier == "Alpha":
            return ctx.const((1.0,), "VALUE")
        return ctx.reg(r, 3, "RGBA" if out.identifier == "Color" else "VECTOR")
    a = ctx.attribute(f"attr:{node.attribute_name}")
    if out.identifier == "Fac":
        return ctx.convert(ctx.reg(a.reg, 3, "RGBA"), "VALUE")
    if out.identifier == "Alpha":
        return ctx.const((1.0,), "VALUE")
    return ctx.reg(a.reg, 3, "RGBA" if out.identifier == "Color" else "VECTOR")


# ---- utility ----
def h_math(ctx, node, out, path):
    op = ne.MATH_OPS.index(node.operation)
    ins = [ctx.input_value(s, path, "VALUE") for s in node.inputs[:3]]
    r, _ = ctx.emit_node("math", ins, 1, mode=op, flags=1 if node.use_clamp else 0)
    return ctx.reg(r, 1, "VALUE")


def h_vector_math(ctx, node, out, path):
    op = ne.VECTOR_OPS.index(node.operation)
    vecs = [ctx.input_value(s, path, "VECTOR") for s in node.inputs[:3]]
    scale = ctx.input_value(node.inputs[3], path, "VALUE")
    r, _ = ctx.emit_node("vector_math", vecs + [scale], 4, mode=op)
    if out.identifier == "Value":
        return ctx.reg(r + 3, 1, "VALUE")
    return ctx.reg(r, 3, "VECTOR")


def h_mix(ctx, node, out, path):
    dt = node.data_type
    if dt == "ROTATION":
        ctx.c.warn(f"Mix '{node.name}' of rotations is not supported")
        return ctx.fallback(out)
    suffix = {"FLOAT": "Float", "VECTOR": "Vector", "RGBA": "Color"}[dt]
    kind = {"FLOAT": "VALUE", "VECTOR": "VECTOR", "RGBA": "RGBA"}[dt]
    nonuniform = dt == "VECTOR" and node.factor_mode == "NON_UNIFORM"
    fac = ctx.inp(node, "Factor_Vector" if nonuniform else "Factor_Float", path,
                  "VECTOR" if nonuniform else "VALUE", identifier=True)
    if not nonuniform:
        fac = ctx.convert(fac, "VECTOR")
    # a float Mix converts what feeds A and B to a value first (a colour's luminance, a
    # vector's mean), then the op mixes the repeated value
    a, b = (ctx.convert(ctx.inp(node, f"{ab}_{suffix}", path, kind, identifier=True), "VECTOR")
            for ab in "AB")
    flags = (1 if node.clamp_factor else 0) | (4 if nonuniform else 0)
    mode = 255
    if dt == "RGBA":
        mode = ne.BLEND_MODES.index(node.blend_type)
        flags |= 2 if node.clamp_result else 0
    r, _ = ctx.emit_node("mix", [fac, a, b], 3, mode=mode, flags=flags)
    return ctx.reg(r, 1 if dt == "FLOAT" else 3, kind)


def h_mix_rgb(ctx, node, out, path):   # the legacy MixRGB node
    fac = ctx.convert(ctx.input_value(node.inputs[0], path, "VALUE"), "VECTOR")
    a = ctx.input_value(node.inputs[1], path, "RGBA")
    b = ctx.input_value(node.inputs[2], path, "RGBA")
    flags = 1 | (2 if node.use_clamp else 0)
    r, _ = ctx.emit_node("mix", [fac, a, b], 3, mode=ne.BLEND_MODES.index(node.blend_type),
                         flags=flags)
    return ctx.reg(r, 3, "RGBA")


def h_map_range(ctx, node, out, path):
    mode = ne.MAP_RANGE_MODES.index(node.interpolation_type)
    if node.data_type == "FLOAT_VECTOR":
        names = ["Vector", "From_Min_FLOAT3", "From_Max_FLOAT3", "To_Min_FLOAT3",
                 "To_Max_FLOAT3", "Steps_FLOAT3"]
        ins = [ctx.inp(node, n, path, "VECTOR", identifier=True) for n in names]
        r, _ = ctx.emit_node("map_range", ins, 3, mode=mode, flags=int(node.clamp), dim=3)
        return ctx.reg(r, 3, "VECTOR")
    names = ["Value", "From Min", "From Max", "To Min", "To Max", "Steps"]
    ins = [ctx.inp(node, n, path, "VALUE", identifier=True) for n in names]
    r, _ = ctx.emit_node("map_range", ins, 1, mode=mode, flags=int(node.clamp), dim=1)
    return ctx.reg(r, 1, "VALUE")


def h_clamp(ctx, node, out, path):
    ins = [ctx.input_value(s, path, "VALUE") for s in node.inputs[:3]]
    r, _ = ctx.emit_node("clamp", ins, 1, mode=0 if node.clamp_type == "MINMAX" else 1)
    return ctx.reg(r, 1, "VALUE")


def _color_op(op, names_kinds):
    def h(ctx, node, out, path):
        ins = [ctx.inp(node, n, path, k, identifier=True) for n, k in names_kinds]
        r, _ = ctx.emit_node(op, ins, 3)
        return ctx.reg(r, 3, "RGBA")
    return h


def h_separate(ctx, node, out, path):
    mode = {"RGB": 0, "HSV": 1, "HSL": 2}.get(getattr(node, "mode", "RGB"), 0)
    mode = 1 if node.type == "SEPHSV" else mode
    src = ctx.input_value(node.inputs[0], path, node.inputs[0].type)
    r, _ = ctx.emit_node("separate", [src], 3, mode=mode)
    return ctx.reg(r + _out_index(node, out), 1, "VALUE")


def h_combine(ctx, node, out, path):
    mode = {"RGB": 0, "HSV": 1, "HSL": 2}.get(getattr(node, "mode", "RGB"), 0)
    mode = 1 if node.type == "COMBHSV" else mode
    ins = [ctx.input_value(s, path, "VALUE") for s in node.inputs[:3]]
    r, _ = ctx.emit_node("combine", ins, 3, mode=mode)
    return ctx.reg(r, 3, out.type)


def h_rgb_to_bw(ctx, node, out, path):
    r, _ = ctx.emit_node("rgb_to_bw", [ctx.input_value(node.inputs[0], path, "RGBA")], 1)
    return ctx.reg(r, 1, "VALUE")


def _table_node(ctx, node, op, ins, floats, n, mode=0, flags=0, width=3):
    r, idx = ctx.emit_node(op, ins, 4, mode=mode, flags=flags, aux2=n)
    ctx.b.table(idx, floats)
    return r


def h_ramp(ctx, node, out, path):
    ramp = node.color_ramp
    floats = []
    for i in range(ne.TABLE_SIZE):
        floats.extend(float(x) for x in ramp.evaluate(i / (ne.TABLE_SIZE - 1)))
    fac = ctx.input_value(node.inputs[0], path, "VALUE")
    r = _table_node(ctx, node, "ramp", [fac], floats, ne.TABLE_SIZE,
                    flags=0 if ramp.interpolation == "CONSTANT" else 1)
    if out.identifier == "Alpha":
        return ctx.reg(r + 3, 1, "VALUE")
    return ctx.reg(r, 3, "RGBA")


def h_curves(ctx, node, out, path):
    mapping = node.mapping
    mapping.initialize()
    lo, hi = mapping.clip_min_x if mapping.use_clip else 0.0, \
        mapping.clip_max_x if mapping.use_clip else 1.0
    lo, hi = float(min(lo, 0.0)), float(max(hi, 1.0))
    curves = mapping.curves
    floats = []
    for i in range(ne.TABLE_SIZE):
        x = lo + (hi - lo) * i / (ne.TABLE_SIZE - 1)
        if node.type == "CURVE_FLOAT":
            floats.extend([mapping.evaluate(curves[0], x), 0.0, 0.0, 0.0])
        else:   # the combined curve first, then each channel's (Blender's order)
            row = [mapping.evaluate(curves[c], mapping.evaluate(curves[3], x)) for c in range(3)]
            floats.extend(row + [0.0])
    floats.extend([lo, hi, 0.0, 0.0])
    fac = ctx.input_value(node.inputs[0], path, "VALUE")
    if node.type == "CURVE_FLOAT":
        v = ctx.input_value(node.inputs[1], path, "VALUE")
        r = _table_node(ctx, node, "curves", [fac, v, v, v], floats, ne.TABLE_SIZE, mode=1)
        return ctx.reg(r, 1, "VALUE")
    c = ctx.input_value(node.inputs[1], path, "RGBA")
    r = _table_node(ctx, node, "curves", [fac, c], floats, ne.TABLE_SIZE)
    return ctx.reg(r, 3, "RGBA")


def _normal_in(ctx, node, path):
    sock = ng.named_input(node, "Normal")
    if sock is not None and sock.is_linked:
        return ctx.input_value(sock, path, "VECTOR")
    return ctx.geometry(ne.IN_NORMAL)


def h_fresnel(ctx, node, out, path):
    r, _ = ctx.emit_node("fresnel", [_v(ctx, node, "IOR", path), _normal_in(ctx, node, path)], 1)
    return ctx.reg(r, 1, "VALUE")


def h_layer_weight(ctx, node, out, path):
    r, _ = ctx.emit_node("layer_weight", [_v(ctx, node, "Blend", path),
                                          _normal_in(ctx, node, path)], 2)
    return ctx.reg(r + (1 if out.identifier == "Facing" else 0), 1, "VALUE")


def h_mapping(ctx, node, out, path):
    kinds = ("POINT", "TEXTURE", "VECTOR", "NORMAL")
    mode = kinds.index(node.vector_type)
    ins = []
    for name, default in (("Vector", (0.0, 0.0, 0.0)), ("Location", (0.0, 0.0, 0.0)),
                          ("Rotation", (0.0, 0.0, 0.0)), ("Scale", (1.0, 1.0, 1.0))):
        sock = node.inputs.get(name)   # Vector and Normal mappings have no Location
        ins.append(ctx.input_value(sock, path, "VECTOR")
                   if sock is not None and getattr(sock, "enabled", True)
                   else ctx.const(default, "VECTOR"))
    r, _ = ctx.emit_node("mapping", ins, 3, mode=mode)
    return ctx.reg(r, 3, "VECTOR")


def h_normalize_passthrough(ctx, node, out, path):
    return ctx.input_value(node.inputs[0], path, out.type)



NODE_HANDLERS = {
    "VALUE": h_value, "RGB": h_rgb, "TEX_COORD": h_tex_coord, "UVMAP": h_uvmap,
    "NEW_GEOMETRY": h_geometry, "OBJECT_INFO": h_object_info,
    "VERTEX_COLOR": h_color_attribute, "ATTRIBUTE": h_attribute, "CAMERA": h_camera_data,
    "NORMAL": h_normal,
    "MATH": h_math, "VECT_MATH": h_vector_math, "MIX": h_mix, "MIX_RGB": h_mix_rgb,
    "MAP_RANGE": h_map_range, "CLAMP": h_clamp,
    "INVERT": _color_op("invert", [("Fac", "VALUE"), ("Color", "RGBA")]),
    "GAMMA": _color_op("gamma", [("Color", "RGBA"), ("Gamma", "VALUE")]),
    "BRIGHTCONTRAST": _color_op("bright_contrast", [("Color", "RGBA"), ("Bright", "VALUE"),
                                                    ("Contrast", "VALUE")]),
    "HUE_SAT": _color_op("hsv", [("Hue", "VALUE"), ("Saturation", "VALUE"),
                                 ("Value", "VALUE"), ("Fac", "VALUE"), ("Color", "RGBA")]),
    "SEPARATE_COLOR": h_separate, "SEPRGB": h_separate, "SEPHSV": h_separate,
    "SEPXYZ": h_separate, "COMBINE_COLOR": h_combine, "COMBRGB": h_combine,
    "COMBXYZ": h_combine, "COMBHSV": h_combine, "RGBTOBW": h_rgb_to_bw, "VALTORGB": h_ramp,
    "CURVE_RGB": h_curves, "CURVE_FLOAT": h_curves, "FRESNEL": h_fresnel,
    "LAYER_WEIGHT": h_layer_weight, "MAPPING": h_mapping,
}
NODE_HANDLERS.update(TEXTURE_HANDLERS)
NODE_HANDLERS.update(SPECTRAL_HANDLERS)
