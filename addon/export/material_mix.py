"""Mix / Add Shader trees -> one Lantern material: Transparent BSDF leaves become its alpha,
emission-only leaves its emission, the other leaves (up to 4) a "mix" material whose leaves
add_leaf appends; a factor texture or node graph on the top Mix Shader of two shaders is kept
(a mix texture, an alpha texture or a program), deeper factors count as their mean."""

import math

from . import node_bump
from .material_compile import GraphCompiler, attach
from .material_inputs import DEFAULT, _constant_color, _constant_float, _image_source, \
    _source, is_graph
from .material_shader import _convert_shader


def _mix_leaves(socket, weight, material, report, depth=0):
    """Flatten Mix / Add Shader nodes below a shader socket: [(node, weight)], the weights
    multiplied down the tree (a Mix Shader's factor texture counts as its mean here)."""
    node, _ = _source(socket)
    if node is None or weight <= 0.0:
        return []   # an unlinked shader input is black
    if depth > 16:
        report.warn(f"Material '{material.name}': shader mixes nested too deep; cut")
        return []
    if node.type == "MIX_SHADER":
        f = _mix_factor(node, material, report)
        if is_graph(node.inputs["Fac"]):
            report.warn(f"Material '{material.name}': the node graph on the factor of nested "
                        f"Mix Shader '{node.name}' is not rendered; its own value {f:.3g} is "
                        "used (graph factors drive the top Mix Shader of two shaders)")
        return (_mix_leaves(node.inputs[1], weight * (1.0 - f), material, report, depth + 1) +
                _mix_leaves(node.inputs[2], weight * f, material, report, depth + 1))
    if node.type == "ADD_SHADER":
        return (_mix_leaves(node.inputs[0], weight, material, report, depth + 1) +
                _mix_leaves(node.inputs[1], weight, material, report, depth + 1))
    return [(node, weight)]


def _one_minus(ctx, v):
    from .node_eval import MATH_OPS
    r, _ = ctx.emit_node("math", [ctx.const((1.0,), "VALUE"), v, ctx.const((0.0,), "VALUE")],
                         1, mode=MATH_OPS.index("SUBTRACT"), flags=1)
    return ctx.reg(r, 1, "VALUE")


def _lerp_colors(ctx, f, a, b):
    """a + clamp(f, 0, 1) (b - a) for constant colours a, b: a program's colour."""
    from .node_eval import MATH_OPS, VECTOR_OPS
    f = ctx.convert(f, "VALUE")   # the program's width-3 value of the Fac socket
    r, _ = ctx.emit_node("math", [f, ctx.const((1.0,), "VALUE"), ctx.const((0.0,), "VALUE")],
                         1, mode=MATH_OPS.index("MULTIPLY"), flags=1)
    f = ctx.convert(ctx.reg(r, 1, "VALUE"), "VECTOR")
    r, _ = ctx.emit_node("vector_math", [f, ctx.const([y - x for x, y in zip(a, b)], "VECTOR"),
                                         ctx.const(a, "VECTOR"), ctx.const((0.0,), "VALUE")], 4,
                         mode=VECTOR_OPS.index("MULTIPLY_ADD"))
    return ctx.reg(r, 3, "RGBA")


def _unit_clamp(ctx, v):
    return v   # the core clamps factors and alpha to [0, 1]


def _mix_factor(node, material, report, textures=None):
    sock = node.inputs["Fac"]
    if is_graph(sock):   # a graph factor: programs where the mix allows (_convert_mix)
        v = sock.default_value
        return 0.5 if v != v else min(max(float(v), 0.0), 1.0)
    img, output = _image_source(sock)
    if img is not None and textures is not None:
        mean = textures.mean(img, output, f"Material '{material.name}'")
        if mean is not None:
            v = mean[0] if output != "color" else 0.2126 * mean[0] + 0.7152 * mean[1] + \
                0.0722 * mean[2]
            return min(max(v, 0.0), 1.0)
    v = _constant_float(sock, material, report) if img is None else 0.5
    return 0.5 if v != v else min(max(v, 0.0), 1.0)


def _convert_mix(top, material, report, textures, add_leaf):
    """Mix / Add Shader trees: Transparent BSDF leaves become the material's alpha (coverage),
    emission-only leaves its emission, the other leaves (up to 4) a "mix" material. A Mix
    Shader's image-texture factor is kept when it mixes two single shaders (or Transparent and
    one shader: an alpha texture); deeper in the tree its mean is used."""
    name = material.name
    where = f"Material '{name}'"
    if top.type == "BSDF_TRANSPARENT":
        leaves = [(top, 1.0)]
    elif top.type == "MIX_SHADER":
        f = _mix_factor(top, material, report, textures)
        leaves = (_mix_leaves(top.inputs[1], 1.0 - f, material, report, 1) +
                  _mix_leaves(top.inputs[2], f, material, report, 1))
    else:
        leaves = _mix_leaves(top.inputs[0], 1.0, material, report, 1) + \
            _mix_leaves(top.inputs[1], 1.0, material, report, 1)
    # a factor texture on the top Mix Shader between two single shaders
    fac_tex = None
    if top.type == "MIX_SHADER":
        img, output = _image_source(top.inputs["Fac"])
        a, _ = _source(top.inputs[1])
        b, _ = _source(top.inputs[2])
        single = a is not None and b is not None and \
            a.type not in ("MIX_SHADER", "ADD_SHADER") and \
            b.type not in ("MIX_SHADER", "ADD_SHADER")
        if img is None and not single and is_graph(top.inputs["Fac"]):
            report.warn(f"{where}: the node graph on the factor of Mix Shader '{top.name}' is "
                        "not rendered (graph factors mix two single shaders); its own value "
                        "is used")
        if img is None and single and is_graph(top.inputs["Fac"]) and \
                not (a.type == "BSDF_TRANSPARENT" and b.type == "BSDF_TRANSPARENT"):
            # a node graph on the factor (Fresnel, Layer Weight, noise, ...): a program
            if b.type == "BSDF_TRANSPARENT":   # Mix(X, Transparent): alpha = 1 - fac
                prog = GraphCompiler(material, report, textures, textures.attributes).program(
                    top.inputs["Fac"], "alpha", 1, post=_one_minus)
            else:
                prog = GraphCompiler(material, report, textures, textures.attributes).program(
                    top.inputs["Fac"], "alpha" if a.type == "BSDF_TRANSPARENT"
                    else "mix_factor", 1, post=_unit_clamp)
            if prog is not None:
                fac_tex = ("program", prog, a.type == "BSDF_TRANSPARENT" or
                           b.type == "BSDF_TRANSPARENT")
        if img is not None:
            if single and b.type != "BSDF_TRANSPARENT":
                tid = textures.add(img, output, where)
                fac_tex = (tid, a.type == "BSDF_TRANSPARENT")
            else:
                report.warn(f"{where}: the image texture on Mix Shader '{top.name}' Fac is "
                            "used as its mean value (textured factors mix two shaders, or "
                            "Transparent first and one shader)")
    # a graph factor between two shaders, neither Transparent: both stay leaves of a
    # two-leaf mix in order (an Emission leaf as a black one) and the emission is a program
    graph_mix = fac_tex is not None and fac_tex[0] == "program" and not fac_tex[2]
    transparent, emission, bsdf = 0.0, [0.0, 0.0, 0.0], []
    leaf_emission = []   # (unweighted emission of each leaf in order): graph_mix's program
    shader_emits = False  # an Emission shader of its own in the mix (not under any coat)
    for node, w in leaves:
        if node.type == "BSDF_TRANSPARENT":
            c = [x if math.isfinite(x) else 0.0 for x in
                 _constant_color(node.inputs["Color"], material, report)]
            if max(c) - min(c) > 1e-3:
                report.warn(f"{where}: Transparent BSDF '{node.name}' is tinted; Lantern's "
                            "transparency is untinted (its luminance is used)")
            t = min(max(0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2], 0.0), 1.0)
            transparent += w * t
            if t < 1.0:   # the untransmitted part of a grey Transparent BSDF is black
                bsdf.append(({"name": f"{name}/black", "type": "diffuse",
                              "base_color": [0.0, 0.0, 0.0]}, w * (1.0 - t)))
            continue
        leaf = _convert_shader(node, material, report, textures)
        progs = leaf.get("programs", [])
        if any(p["target"] == "emission" for p in progs):
            report.warn(f"{where}: the node graph on the emission of '{node.name}' inside a "
                        "shader mix is not rendered; its strength is used")
            leaf["programs"] = [p for p in progs if p["target"] != "emission"]
        if "emission_texture" in leaf:   # a mix's emission is constant: the image's mean
            report.warn(f"{where}: the emission image of '{node.name}' inside a shader mix is "
                        "used as its mean value")
            leaf["emission"] = leaf.pop("_emission_mean")
            leaf.pop("emission_texture")
        leaf.pop("_emission_mean", None)
        leaf_emission.append(list(leaf.get("emission", [0.0, 0.0, 0.0])))
        if node.type == "EMISSION":
            shader_emits = shader_emits or max(leaf["emission"]) > 0.0
            emission = [e + w * x for e, x in zip(emission, leaf["emission"])]
            if graph_mix:   # its share of the BSDF is black
                bsdf.append(({"name": f"{name}/black", "type": "diffuse",
                              "base_color": [0.0, 0.0, 0.0]}, w))
            continue
        emission = [e + w * x for e, x in zip(emission, leaf.get("emission", [0, 0, 0]))]
        leaf["emission"] = [0.0, 0.0, 0.0]
        if leaf.get("alpha", 1.0) < 1.0 or "alpha_texture" in leaf:
            report.warn(f"{where}: Alpha of '{node.name}' inside a shader mix is ignored "
                        "(use a Mix Shader with a Transparent BSDF)")
        leaf.pop("alpha", None)
        leaf.pop("alpha_texture", None)
        leaf["name"] = f"{name}/{node.name}"
        bsdf.append((leaf, w))
    alpha = min(max(1.0 - transparent, 0.0), 1.0)
    opaque = sum(w for _, w in bsdf)
    if fac_tex is None and transparent > 1.0 - 1e-6 and opaque > 1e-6:
        # Transparent BSDF weight t >= 1 beside BSDFs of weight W (an Add Shader): Cycles
        # passes rays with weight t and scatters W, more than one surface can (t + W > 1).
        # Coverage passes rays with weight 1 only, so the surface is normalised to t + W: the
        # share t / (t + W) of rays passes and the rest scatters the BSDFs at their own
        # weights (scale below). Passed light is then 1 / (t + W) of Cycles'; where alpha
        # would be 0 the BSDFs were dropped before (difftest D8: black, -100 %). Exact needs
        # a pass weight in the core's alpha test (docs/materials.md).
        alpha = opaque / (transparent + opaque)
        report.warn(f"{where}: Transparent BSDF of weight {transparent:.3g} added to shaders "
                    f"of weight {opaque:.3g}: light passing the surface is rendered "
                    f"{1.0 / (transparent + opaque):.3g} x as bright (Lantern's transparency "
                    "passes at most all rays)")
    prog = None
    if fac_tex is not None and fac_tex[0] == "program":   # a node-graph factor
        prog, transparent_leaf = fac_tex[1], fac_tex[2]
        fac_tex = None
        if transparent_leaf:    # the program is the alpha; what stops a ray is all X
            alpha = 1.0
            bsdf = [(leaf, 1.0) for leaf, _ in bsdf]
    if fac_tex is not None and fac_tex[1]:  # Mix(Transparent, X, fac): alpha = fac, textured;
        alpha = 1.0                         # where it stops a ray, the surface is all X
        bsdf = [(leaf, 1.0) for leaf, _ in bsdf]
    out = dict(DEFAULT, name=name)
    if len(bsdf) > 4:
        report.warn(f"{where}: {len(bsdf)} shaders mixed; Lantern keeps the 4 of largest weight")
        bsdf = sorted(bsdf, key=lambda lw: -lw[1])[:4]
    scale = 1.0 / alpha if alpha > 0.0 else 0.0   # what stops a ray carries the whole surface
    normals = [leaf for leaf, _ in bsdf if "normal_texture" in leaf]
    if len(normals) > 1 and len({(x["normal_texture"], x.get("normal_strength", 1.0))
                                 for x in normals}) > 1:
        report.warn(f"{where}: mixed shaders with different normal maps; the first is used")
    if not bsdf:
        out.update(base_color=[0.0, 0.0, 0.0])
    elif len(bsdf) == 1 and abs(bsdf[0][1] * scale - 1.0) < 1e-6 and \
            (fac_tex is None or fac_tex[1]) and \
            not (shader_emits and _layered(bsdf[0][0])):
        # one shader: no mix needed (but an Emission shader beside a Principled with a coat or
        # sheen stays a mix of one leaf: the core dims a Principled's own emission under its
        # layers, and Cycles does not dim a separate Emission closure; difftest ci seed 16)
        out = dict(bsdf[0][0], name=name)
    else:
        if add_leaf is None:
            raise ValueError("convert_material: a shader mix needs add_leaf")
        out = {"name": name, "type": "mix",
               "mix": [[add_leaf(leaf), w * scale] for leaf, w in bsdf]}
        if fac_tex is not None and not fac_tex[1] and len(bsdf) == 2:
            out["mix_texture"] = fac_tex[0]
            out["mix"] = [[out["mix"][0][0], 0.5], [out["mix"][1][0], 0.5]]
    if prog is not None:
        if prog["target"] == "mix_factor" and out.get("type") == "mix" and len(out["mix"]) == 2:
            out["mix"] = [[out["mix"][0][0], 0.5], [out["mix"][1][0], 0.5]]
            attach(out, prog)
            if len(leaf_emission) == 2 and any(max(e) > 0.0 for e in leaf_emission):
                # the leaves' emission mixed by the same factor, (1 - f) E_a + f E_b (Cycles
                # clamps the factor to [0, 1]); the constant, for light selection only, is
                # their mean, so that a leaf that emits anywhere makes the mesh a light
                ea, eb = leaf_emission
                attach(out, GraphCompiler(material, report, textures, textures.attributes)
                       .program(top.inputs["Fac"], "emission", 3,
                                post=lambda ctx, v: _lerp_colors(ctx, v, ea, eb)))
                emission = [0.5 * (x + y) for x, y in zip(ea, eb)]
        elif prog["target"] == "alpha":
            attach(out, prog)
        else:   # an emission leaf takes its share of the factor's own value
            report.warn(f"{where}: the node graph on the factor of Mix Shader '{top.name}' is "
                        "not rendered (graph factors mix two BSDFs, or a BSDF and "
                        "Transparent); its own value is used")
    node_bump.hoist(out, [leaf for leaf, _ in bsdf], report, where)
    if normals:
        out["normal_texture"] = normals[0]["normal_texture"]
        out["normal_strength"] = normals[0].get("normal_strength", 1.0)
    out["emission"] = [e * scale for e in emission]
    out["alpha"] = alpha
    if fac_tex is not None and fac_tex[1]:
        out["alpha_texture"] = fac_tex[0]
    return out


def _layered(leaf):
    """A Principled leaf with a coat or sheen: its own emission is under them."""
    return leaf.get("type") == "principled" and (leaf.get("coat_weight", 0.0) > 0.0 or
                                                 leaf.get("sheen_weight", 0.0) > 0.0)
