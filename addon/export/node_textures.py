"""Handlers of the texture nodes (node_handlers): procedural textures and Image Texture.
An unlinked Vector reads Generated coordinates (UV for Image Texture), as in Blender; White
Noise's reads its socket's own value, (0, 0, 0) unless a script set it (Cycles gives its Vector
no implicit coordinates: on a mesh it is one colour)."""

from . import node_graph as ng
from . import node_ops as ne


def _vec(ctx, node, path, default="generated"):
    return ctx.texture_vector(node, path, default)


def _val(ctx, node, ident, path):
    return ctx.inp(node, ident, path, "VALUE", identifier=True)


def _color_fac(ctx, r, out, color_first=True):
    """Outputs laid out color(3), fac (color_first) or fac, color(3)."""
    if out.identifier in ("Fac", "Value", "Distance"):
        return ctx.reg(r + (3 if color_first else 0), 1, "VALUE")
    return ctx.reg(r + (0 if color_first else 1), 3, "RGBA")


def h_checker(ctx, node, out, path):
    ins = [_vec(ctx, node, path), ctx.inp(node, "Color1", path, "RGBA", identifier=True),
           ctx.inp(node, "Color2", path, "RGBA", identifier=True),
           _val(ctx, node, "Scale", path)]
    r, _ = ctx.emit_node("checker", ins, 4)
    return _color_fac(ctx, r, out)


def h_gradient(ctx, node, out, path):
    r, _ = ctx.emit_node("gradient", [_vec(ctx, node, path)], 4,
                         mode=ne.GRADIENT_TYPES.index(node.gradient_type))
    return _color_fac(ctx, r, out)


def _dim(node, attr):
    return int(getattr(node, attr, "3D")[0])


def h_noise(ctx, node, out, path):
    dim = _dim(node, "noise_dimensions")
    vec = _vec(ctx, node, path) if dim > 1 else ctx.const((0.0, 0.0, 0.0), "VECTOR")
    w = _val(ctx, node, "W", path) if dim in (1, 4) else ctx.const((0.0,), "VALUE")
    names = ("Scale", "Detail", "Roughness", "Lacunarity", "Offset", "Gain", "Distortion")
    ins = [vec, w] + [_val(ctx, node, n, path) for n in names]
    flags = (1 if getattr(node, "normalize", True) else 0) | (2 if out.identifier == "Fac" else 0)
    r, _ = ctx.emit_node("noise", ins, 4, mode=ne.NOISE_TYPES.index(node.noise_type),
                         dim=dim, flags=flags)   # 2: the value alone (no colour fractals)
    return _color_fac(ctx, r, out, color_first=False)


def h_white_noise(ctx, node, out, path):
    dim = _dim(node, "noise_dimensions")
    vec = ctx.inp(node, "Vector", path, "VECTOR", identifier=True) if dim > 1 else \
        ctx.const((0.0, 0.0, 0.0), "VECTOR")
    w = _val(ctx, node, "W", path) if dim in (1, 4) else ctx.const((0.0,), "VALUE")
    r, _ = ctx.emit_node("white_noise", [vec, w], 4, dim=dim)
    return _color_fac(ctx, r, out, color_first=False)


def h_voronoi(ctx, node, out, path):
    dim = _dim(node, "voronoi_dimensions")
    feature = {"F1": 0, "F2": 1, "SMOOTH_F1": 2}.get(node.feature)
    if feature is None:
        ctx.c.warn(f"Voronoi '{node.name}': {node.feature} is not supported (F1, F2, Smooth "
                   "F1 are); its default is used")
        return ctx.fallback(out)
    detail = ng.enabled_input(node, "Detail")
    if detail is not None and (detail.is_linked or detail.default_value != 0.0):
        ctx.c.warn(f"Voronoi '{node.name}': Detail above 0 is rendered as 0 (one octave)")
    if getattr(node, "normalize", False):
        ctx.c.warn(f"Voronoi '{node.name}': Normalize is not supported; ignored")
    metric = ("EUCLIDEAN", "MANHATTAN", "CHEBYCHEV", "MINKOWSKI").index(node.distance)
    names = ("Scale", "Smoothness", "Exponent", "Randomness")
    vec = _vec(ctx, node, path) if dim > 1 else ctx.const((0.0, 0.0, 0.0), "VECTOR")
    w = _val(ctx, node, "W", path) if dim in (1, 4) else ctx.const((0.0,), "VALUE")
    ins = [vec, w] + [_val(ctx, node, n, path) for n in names]
    r, _ = ctx.emit_node("voronoi", ins, 8, mode=feature, dim=dim, aux=metric)
    k = out.identifier
    if k == "Distance":
        return ctx.reg(r, 1, "VALUE")
    if k == "Color":
        return ctx.reg(r + 1, 3, "RGBA")
    if k == "Position":
        return ctx.reg(r + 4, 3, "VECTOR")
    if k == "W":
        return ctx.reg(r + 7, 1, "VALUE")
    ctx.c.warn(f"Voronoi '{node.name}': output '{out.name}' is not supported; 0 is used")
    return ctx.fallback(out)


def h_wave(ctx, node, out, path):
    t = 0 if node.wave_type == "BANDS" else 1
    d = node.bands_direction if t == 0 else node.rings_direction
    dirs = ("X", "Y", "Z", "DIAGONAL") if t == 0 else ("X", "Y", "Z", "SPHERICAL")
    names = ("Scale", "Distortion", "Detail", "Detail Scale", "Detail Roughness", "Phase Offset")
    ins = [_vec(ctx, node, path)] + [_val(ctx, node, n, path) for n in names]
    r, _ = ctx.emit_node("wave", ins, 4, mode=t, aux=dirs.index(d),
                         aux2=("SIN", "SAW", "TRI").index(node.wave_profile))
    return _color_fac(ctx, r, out)


def h_magic(ctx, node, out, path):
    ins = [_vec(ctx, node, path), _val(ctx, node, "Scale", path),
           _val(ctx, node, "Distortion", path)]
    r, _ = ctx.emit_node("magic", ins, 4, aux=int(node.turbulence_depth))
    return _color_fac(ctx, r, out)


def h_image(ctx, node, out, path):
    proj = ("FLAT", "BOX", "SPHERE", "TUBE").index(getattr(node, "projection", "FLAT"))
    tid = ctx.c.textures.add_raw(node, ctx.c.where)
    ins = [_vec(ctx, node, path, "uv")]
    if proj == 1:   # box: the sides by the object-space normal, blended by Projection Blend
        blend = float(getattr(node, "projection_blend", 0.0))
        ins += [ctx.attribute("object_normal"),
                ctx.const((min(max(blend, 0.0), 1.0) if blend == blend else 0.0,), "VALUE")]
    r, _ = ctx.emit_node("image", ins, 4, mode=proj, aux=-1 if tid is None else tid)
    if out.identifier == "Alpha":
        return ctx.reg(r + 3, 1, "VALUE")
    return ctx.reg(r, 3, "RGBA")


def h_brick(ctx, node, out, path):
    # bricks of no (or negative) width or height, constant or computed, are all mortar in
    # Cycles wherever Mortar Size > 0 (difftest D36): the core's op runs the same arithmetic
    colors = [ctx.inp(node, n, path, "RGBA", identifier=True)
              for n in ("Color1", "Color2", "Mortar")]
    names = ("Scale", "Mortar Size", "Mortar Smooth", "Bias", "Brick Width", "Row Height")
    ins = [_vec(ctx, node, path)] + colors + [_val(ctx, node, n, path) for n in names] + \
        [ctx.const((float(node.offset),), "VALUE"), ctx.const((float(node.squash),), "VALUE")]
    r, _ = ctx.emit_node("brick", ins, 4, aux=int(node.offset_frequency),
                         aux2=int(node.squash_frequency))
    return _color_fac(ctx, r, out)


TEXTURE_HANDLERS = {
    "TEX_CHECKER": h_checker, "TEX_GRADIENT": h_gradient, "TEX_NOISE": h_noise,
    "TEX_WHITE_NOISE": h_white_noise, "TEX_VORONOI": h_voronoi, "TEX_WAVE": h_wave,
    "TEX_MAGIC": h_magic, "TEX_IMAGE": h_image, "TEX_BRICK": h_brick,
}
