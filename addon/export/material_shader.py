"""One shader node (Principled, Diffuse, Emission, Glossy, Metallic, Translucent, Glass,
Refraction BSDF; not a mix) -> a Lantern material dict (material.py's docstring lists how each
maps), with the Principled inputs rendered by a fallback warned and the anisotropy tangent (a UV
map's, or Cycles' radial tangent as a program)."""

import math

from . import negative_emission
from . import node_eval as ne
from .material_compile import GraphCompiler, attach
from .material_inputs import (DEFAULT, _constant_color, _constant_float, _image_source, _Inputs,
                              _ior, _socket_default, _source, _turns, _unit, _weight)


def _convert_shader(node, material, report, textures):
    """One shader node (not a mix) -> a Lantern material dict."""
    out = dict(DEFAULT, name=material.name)
    name = material.name
    inputs = _Inputs(node, material, report, textures)
    color, value = inputs.color, inputs.value

    # GGX energy compensation: Blender's "Multiscatter GGX" (the default); plain "GGX" has none
    if getattr(node, "distribution", "MULTI_GGX") in ("GGX", "BECKMANN", "ASHIKHMIN_SHIRLEY"):
        out["multiscatter"] = False
        if node.distribution != "GGX":
            report.warn(f"Material '{name}': {node.distribution} distribution rendered as GGX")
    if node.type in ("BSDF_PRINCIPLED", "BSDF_DIFFUSE", "BSDF_GLOSSY", "BSDF_METALLIC",
                     "BSDF_GLASS", "BSDF_REFRACTION", "BSDF_TRANSLUCENT"):
        inputs.normal_map(out)
    if node.type == "BSDF_PRINCIPLED":
        base = inputs.base(out, "base_color", "Base Color")
        if not inputs.emission_graph(out, "Emission Color", "Emission Strength"):
            negative_emission.check_constant(report, inputs.where, "Emission Strength",
                                             value("Emission Strength"))
            strength = _weight(value("Emission Strength"), 1e30)
            if strength != 0.0:
                inputs.emission(out, "Emission Color", strength)
        roughness = inputs.scalar(out, "roughness", "Roughness", _unit)
        if "Diffuse Roughness" in node.inputs:   # Blender >= 4.3: Oren-Nayar base
            out["diffuse_roughness"] = _weight(value("Diffuse Roughness"))
        metallic = inputs.scalar(out, "metallic", "Metallic", _weight)
        # a texture or a node graph drives Metallic: the principled type whatever the
        # socket's own value (the conductor has no metallic input)
        metal_tex = "metallic_texture" in out or \
            any(p["target"] == "metallic" for p in out.get("programs", []))
        inputs.scalar(out, "alpha", "Alpha", lambda v: min(max(v, 0.0), 1.0) if v == v else 1.0)
        aniso = _weight(value("Anisotropic"))
        if aniso > 0.0:
            out.update(anisotropy=aniso,
                       anisotropic_rotation=_turns(value("Anisotropic Rotation")),
                       tangent=_tangent_mode(node, material, report, out, textures))
        transmission = _weight(value("Transmission Weight"))
        level = value("Specular IOR Level")
        level = 0.5 if level != level else min(max(level, 0.0), 1e3)
        film = _weight(value("Thin Film Thickness"), 1e5) \
            if "Thin Film Thickness" in node.inputs else 0.0   # Blender >= 4.2
        if film > 0.0:   # on the specular layer and the metal (not the glass)
            out.update(thin_film_thickness=film,
                       thin_film_ior=max(_ior(value("Thin Film IOR")), 1.0))
        if not (metallic > 0.0 or metal_tex or transmission > 0.0):
            # no metal or glass reads the base colour: an albedo alone, which Cycles does not
            # clamp above 1 (the core keeps it: kAlbedoBase)
            sock = node.inputs["Base Color"]
            if any(p["target"] == "base_color" for p in out.get("programs", [])):
                base = [max(x, 0.0) for x in _socket_default(sock, base, False)]
            elif "base_color_texture" not in out and _image_source(sock)[0] is None:
                base = color("Base Color", clamp=False)
            out["base_color"] = base
        coat = _weight(value("Coat Weight"))
        sheen = _weight(value("Sheen Weight"), 1e3)
        layered = coat > 0.0 or sheen > 0.0   # the simpler types have no coat or sheen
        sss = min(_weight(value("Subsurface Weight")), 1.0) \
            if "Subsurface Weight" in node.inputs else 0.0
        if metallic >= 0.999 and not metal_tex and not layered:  # the metal lobe alone: the
            out.pop("metallic")                                  # cheaper conductor
            out.update(type="conductor", base_color=base,
                       specular_tint=color("Specular Tint"), roughness=roughness)
        elif level > 0.0 or metallic > 0.0 or transmission > 0.0 or metal_tex or layered or \
                sss > 0.0:
            out.update(type="principled", base_color=base,
                       specular_tint=color("Specular Tint"), roughness=roughness,
                       ior=_ior(value("IOR")), metallic=metallic, transmission=transmission,
                       specular_level=min(level, 1e3))
            if coat > 0.0:
                out.update(coat_weight=coat, coat_roughness=_unit(value("Coat Roughness")),
                           coat_ior=max(_ior(value("Coat IOR")), 1.0),
                           coat_tint=color("Coat Tint"))
                inputs.normal_map(out, "Coat Normal", "coat_normal")
            if sheen > 0.0:
                out.update(sheen_weight=sheen, sheen_roughness=_unit(value("Sheen Roughness")),
                           sheen_tint=color("Sheen Tint"))
            if sss > 0.0:   # random-walk subsurface (docs/subsurface.md)
                out.update(_subsurface(node, sss, value, color))
        else:  # Specular IOR Level 0, no metal, no glass: exactly Lambert (the diffuse type)
            out.pop("roughness_texture", None)
            out.pop("metallic")
        _principled_unsupported(node, material, report)
    elif node.type == "BSDF_DIFFUSE":
        inputs.base(out, "base_color", "Color", clamp=False)
        out["diffuse_roughness"] = _weight(value("Roughness"))
    elif node.type == "EMISSION":
        out["base_color"] = [0.0, 0.0, 0.0]
        if not inputs.emission_graph(out, "Color", "Strength"):
            negative_emission.check_constant(report, inputs.where, "Strength", value("Strength"))
            inputs.emission(out, "Color", _weight(value("Strength"), 1e30))
    elif node.type == "BSDF_GLOSSY":
        # Cycles' Glossy has no Fresnel: a constant reflectance Color at every angle, which is
        # the conductor of index 0 + 1i (F = 1) scaled by the colour
        inputs.base(out, "base_color", "Color")
        out.update(type="conductor", eta=[0.0, 0.0, 0.0], k=[1.0, 1.0, 1.0])
        inputs.scalar(out, "roughness", "Roughness", _unit)
        _glossy_anisotropy(node, out, inputs, material, report)
    elif node.type == "BSDF_METALLIC":
        out.update(type="conductor")
        inputs.scalar(out, "roughness", "Roughness", _unit)
        _glossy_anisotropy(node, out, inputs, material, report)
        if getattr(node, "fresnel_type", "F82") == "F82":
            inputs.base(out, "base_color", "Base Color")
            out.update(specular_tint=color("Edge Tint"))
        else:
            n = _constant_color(node.inputs["IOR"], material, report)
            k = _constant_color(node.inputs["Extinction"], material, report)
            f0 = [((a - 1) ** 2 + b * b) / ((a + 1) ** 2 + b * b) for a, b in zip(n, k)]
            out.update(base_color=[min(max(f, 0.0), 1.0) for f in f0],
                       specular_tint=[1.0, 1.0, 1.0])
            report.warn(f"Material '{name}': Metallic BSDF in physical-conductor mode is "
                        f"approximated by its normal-incidence reflectance (F82 tint white)")
    elif node.type == "BSDF_TRANSLUCENT":
        out["type"] = "translucent"
        inputs.base(out, "base_color", "Color", clamp=False)
    elif node.type in ("BSDF_GLASS", "BSDF_REFRACTION"):
        inputs.base(out, "base_color", "Color")
        # Glass: Color tints reflection and transmission (Cycles), Refraction: transmission
        out.update(type="dielectric", ior=_ior(value("IOR")),
                   tint_reflection=node.type == "BSDF_GLASS")
        inputs.scalar(out, "roughness", "Roughness", _unit)
        if node.type == "BSDF_REFRACTION":
            report.warn(f"Material '{name}': Refraction BSDF rendered as glass (its Fresnel "
                        f"reflection included)")
    elif node.type == "BSDF_HAIR_PRINCIPLED":  # export/hair_material.py
        from .hair_material import principled_hair
        principled_hair(node, out, inputs, report)
    else:
        report.warn(f"Material '{name}': shader node '{node.name}' ({node.type}) is not "
                    "supported yet; rendering grey diffuse instead")
    return out


def _subsurface_radius(node, value, color):
    """Radius x Scale in metres (negative and NaN entries 0)."""
    sock = node.inputs.get("Subsurface Radius")
    rgb = list(sock.default_value)[:3] if sock is not None else [1.0, 0.2, 0.1]
    scale = value("Subsurface Scale")
    scale = scale if scale == scale and scale > 0.0 else 0.0
    return [float(x) * scale if x == x and x > 0.0 else 0.0 for x in rgb]


def _subsurface(node, weight, value, color):
    """The Principled BSDF's subsurface inputs -> the material dict's subsurface_* keys."""
    method = getattr(node, "subsurface_method", "RANDOM_WALK")
    # Cycles: Random Walk enters with the material's IOR, Skin with Subsurface IOR
    key = "Subsurface IOR" if method == "RANDOM_WALK_SKIN" else "IOR"
    ior = value(key) if key in node.inputs else 1.4
    g = value("Subsurface Anisotropy") if "Subsurface Anisotropy" in node.inputs else 0.0
    return {"subsurface_weight": weight,
            "subsurface_radius": [min(x, 1e30) for x in _subsurface_radius(node, value, color)],
            "subsurface_ior": min(max(ior, 1.01), 3.8) if ior == ior else 1.4,
            "subsurface_anisotropy": min(max(g, 0.0), 0.9) if g == g else 0.0,
            "subsurface_method": "random_walk_skin" if method == "RANDOM_WALK_SKIN"
            else "random_walk"}


def _principled_unsupported(node, material, report):
    """Warnings for the Principled inputs Lantern renders by a documented fallback."""
    name = material.name

    def val(key):
        sock = node.inputs.get(key)
        if sock is None:
            return 0.0
        v = _constant_float(sock, material, report) if not sock.is_linked else 1.0
        return v if math.isfinite(v) else 0.0
    if val("Subsurface Weight") > 0.0:
        if getattr(node, "subsurface_method", "RANDOM_WALK") == "BURLEY":
            report.warn(f"Material '{name}': Christensen-Burley subsurface is rendered as "
                        "Random Walk")
        for key in ("Subsurface Weight", "Subsurface Radius", "Subsurface Scale",
                    "Subsurface IOR", "Subsurface Anisotropy"):
            sock = node.inputs.get(key)
            if sock is not None and sock.is_linked:
                report.warn(f"Material '{name}': {key} driven by a node is rendered with "
                            "the socket's constant value")
        radius = _subsurface_radius(node, lambda k: val(k), None)
        if max(radius) <= 0.0:
            report.warn(f"Material '{name}': Subsurface Radius x Scale is 0: rendered as the "
                        "diffuse base, as Cycles does")
    if val("Thin Film Thickness") > 0.0 and val("Transmission Weight") > 0.0 and \
            val("Metallic") < 1.0:
        report.warn(f"Material '{name}': Thin Film is rendered on the specular layer and the "
                    "metal, not on the glass part (it refracts and reflects without interference)")


def _tangent_mode(node, material, report, out=None, textures=None):
    """The anisotropy tangent of a shader node: the UV map's (MikkTSpace) for a Tangent node
    in UV Map mode (meshes without UVs: each triangle's first minus third vertex); Cycles'
    radial tangent for an unlinked Tangent input (its default: radial about the object's Z
    axis) and for a Tangent node in Radial mode, as a "tangent" program attached to out."""
    sock = node.inputs.get("Tangent")
    src = None
    if sock is not None and sock.is_linked:
        src, _ = _source(sock)
    if src is not None and src.type == "TANGENT" and src.direction_type == "UV_MAP":
        if getattr(src, "uv_map", ""):
            report.warn(f"Material '{material.name}': Tangent node '{src.name}' names UV map "
                        f"'{src.uv_map}'; the active render UV map is used")
        return "uv"
    axis = None
    if src is None:
        axis = "Z"
    elif src.type == "TANGENT" and src.direction_type == "RADIAL":
        axis = src.axis
    if axis is not None and out is not None and textures is not None:
        prog = _radial_tangent(GraphCompiler(material, report, textures, textures.attributes),
                               axis)
        if prog is not None:
            attach(out, prog)
            return "uv"
    report.warn(f"Material '{material.name}': '{getattr(src, 'name', '?')}' on Tangent is not "
                "supported (a Tangent node in UV Map mode is); the UV tangent is used")
    return "uv"


def _radial_tangent(compiler, axis):
    """Cycles' radial tangent (its Tangent node, and an unlinked Tangent input: axis Z): the
    object-space direction about `axis` through the point's Generated coordinates less 1/2,
    axis x (g - 1/2) (Cycles' own up to sign, which anisotropy does not see), taken to the
    world by the object's normal matrix (per-instance attribute channels, as
    node_bump.world_normal_map); the core projects it onto the shading plane."""
    from .material_compile import Builder, NodeContext
    ops = ne.VECTOR_OPS
    b = Builder()
    ctx = NodeContext(compiler, b)
    zero, nil = ctx.const((0.0, 0.0, 0.0), "VECTOR"), ctx.const((0.0,), "VALUE")
    a = ctx.const(tuple(1.0 if c == axis else 0.0 for c in "XYZ"), "VECTOR")
    r, _ = ctx.emit_node("vector_math", [ctx.attribute("generated"),
                                         ctx.const((0.5, 0.5, 0.5), "VECTOR"), zero, nil], 4,
                         mode=ops.index("SUBTRACT"))
    r, _ = ctx.emit_node("vector_math", [a, ctx.reg(r, 3, "VECTOR"), zero, nil], 4,
                         mode=ops.index("CROSS_PRODUCT"))
    t = ctx.reg(r, 3, "VECTOR")
    rows = []
    for c in "xyz":   # world component = the normal matrix's row . t
        d, _ = ctx.emit_node("vector_math", [ctx.attribute(f"object_normal_{c}"), t, zero, nil],
                             4, mode=ops.index("DOT_PRODUCT"))
        rows.append(ctx.reg(d + 3, 1, "VALUE"))
    c, _ = ctx.emit_node("combine", rows, 3, mode=0)
    return b.finish(ctx.reg(c, 3, "VECTOR"), "tangent")


def _glossy_anisotropy(node, out, inputs, material, report):
    """Glossy / Metallic BSDF Anisotropy in [-1, 1]: positive stretches highlights across the
    tangent, negative along it (Blender's manual). Expressed in the Principled convention
    Lantern stores (alpha_x / alpha_y = 1 / (1 - 0.9 b) along the tangent): the same alpha
    ratio 1 / (1 - |a|)^2, the tangent turned a quarter for positive values. The magnitude
    mapping is Lantern's reading of Cycles' Glossy anisotropy, to be checked against Cycles
    renders (docs/materials.md)."""
    if "Anisotropy" not in node.inputs:
        return
    a = inputs.value("Anisotropy")
    if not math.isfinite(a) or abs(a) < 1e-4:
        return
    a = min(max(a, -0.99), 0.99)
    b = min((1.0 - (1.0 - abs(a)) ** 2) / 0.9, 1.0)
    rotation = _turns(inputs.value("Rotation")) + (0.25 if a > 0 else 0.0)
    out.update(anisotropy=b, anisotropic_rotation=rotation % 1.0,
               tangent=_tangent_mode(node, material, report, out, inputs.textures))
