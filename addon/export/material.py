"""Blender materials -> Lantern materials: diffuse, conductor (GGX metal) or dielectric (glass).

Layered materials (a Principled BSDF's specular layer over its diffuse base, coat, sheen) and
textures are a later issue. Here, by the shader node at the Material Output's Surface:

- Principled BSDF -> principled (bsdf/principled.h: metal, glass, a dielectric specular layer
  of IOR / Specular IOR Level / Specular Tint over a Lambertian Base Color, Roughness); Metallic
  1 -> conductor (the same lobe, cheaper); Specular IOR Level 0 without metal or glass ->
  diffuse (exactly Lambert). Coat (weight, roughness, IOR, tint) over everything; sheen and
  subsurface are not rendered yet (a warning).
  Emission Color x Strength in every case.
- Diffuse BSDF -> diffuse; Emission -> emission; Glossy BSDF -> conductor with Color as F0 and
  tint (Cycles' Glossy has no Fresnel: a constant Color reflectance); Metallic BSDF (F82) ->
  conductor (Base Color, Edge Tint), physical-conductor mode -> its normal-incidence
  reflectance as F0, with a warning; Glass BSDF -> dielectric; Refraction BSDF -> dielectric
  (its reflection included), with a warning.
- Anything else: grey 0.8 diffuse, with a warning naming the material and the node."""

import bpy

DEFAULT = {"name": "Lantern Default", "type": "diffuse", "base_color": [0.8, 0.8, 0.8],
           "emission": [0.0, 0.0, 0.0]}


def _constant_color(socket, material, report):
    """A color socket's value: its default, or a constant RGB/Value node feeding it."""
    if socket.is_linked:
        src = socket.links[0].from_node
        if src.type == "RGB":
            v = src.outputs[0].default_value
            return [float(v[0]), float(v[1]), float(v[2])]
        if src.type == "VALUE":
            v = float(src.outputs[0].default_value)
            return [v, v, v]
        report.warn(f"Material '{material.name}': node '{src.name}' ({src.type}) feeding "
                    f"'{socket.name}' is not supported yet; its constant value is used")
    v = socket.default_value
    if isinstance(v, float):
        return [v, v, v]
    return [float(v[0]), float(v[1]), float(v[2])]


def _constant_float(socket, material, report):
    if socket.is_linked:
        src = socket.links[0].from_node
        if src.type == "VALUE":
            return float(src.outputs[0].default_value)
        report.warn(f"Material '{material.name}': node '{src.name}' ({src.type}) feeding "
                    f"'{socket.name}' is not supported yet; its constant value is used")
    return float(socket.default_value)


def convert_material(material, report):
    out = dict(DEFAULT, name=material.name)
    tree = material.node_tree
    if bpy.app.version < (5, 0, 0) and not material.use_nodes:  # always nodes from 5.0
        tree = None
    if tree is None:
        return out
    output = next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output),
                  None) or next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL"), None)
    if output is None or not output.inputs["Surface"].is_linked:
        out["base_color"] = [0.0, 0.0, 0.0]  # no surface shader: black, as in Cycles
        return out
    node = output.inputs["Surface"].links[0].from_node
    name = material.name

    def color(socket):
        return [min(max(c, 0.0), 1.0) for c in _constant_color(node.inputs[socket], material,
                                                                   report)]

    def value(socket):
        return _constant_float(node.inputs[socket], material, report)

    # GGX energy compensation: Blender's "Multiscatter GGX" (the default); plain "GGX" has none
    if getattr(node, "distribution", "MULTI_GGX") in ("GGX", "BECKMANN", "ASHIKHMIN_SHIRLEY"):
        out["multiscatter"] = False
        if node.distribution != "GGX":
            report.warn(f"Material '{name}': {node.distribution} distribution rendered as GGX")
    if node.type == "BSDF_PRINCIPLED":
        out["base_color"] = _constant_color(node.inputs["Base Color"], material, report)
        strength = value("Emission Strength")
        if strength != 0.0:
            col = _constant_color(node.inputs["Emission Color"], material, report)
            out["emission"] = [c * strength for c in col]
        metallic = min(max(value("Metallic"), 0.0), 1.0)
        transmission = min(max(value("Transmission Weight"), 0.0), 1.0)
        level = max(value("Specular IOR Level"), 0.0)
        level = 0.5 if level != level else level
        if metallic >= 0.999:  # the metal lobe alone: the cheaper conductor type
            out.update(type="conductor", base_color=color("Base Color"),
                       specular_tint=color("Specular Tint"), roughness=_unit(value("Roughness")))
        elif level > 0.0 or metallic > 0.0 or transmission > 0.0:
            out.update(type="principled", base_color=color("Base Color"),
                       specular_tint=color("Specular Tint"), roughness=_unit(value("Roughness")),
                       ior=_ior(value("IOR")), metallic=metallic, transmission=transmission,
                       specular_level=min(level, 1e3))
            coat = min(max(value("Coat Weight"), 0.0), 1.0)
            if coat > 0.0:
                out.update(coat_weight=coat, coat_roughness=_unit(value("Coat Roughness")),
                           coat_ior=max(_ior(value("Coat IOR")), 1.0),
                           coat_tint=color("Coat Tint"))
            sheen = max(value("Sheen Weight"), 0.0)
            if sheen > 0.0:
                out.update(sheen_weight=sheen, sheen_roughness=_unit(value("Sheen Roughness")),
                           sheen_tint=color("Sheen Tint"))
            unsupported = [s for s in ("Subsurface Weight",) if value(s) > 0.0]
            if unsupported:
                report.warn(f"Material '{name}': {', '.join(unsupported)} not rendered yet "
                            f"(Lantern's Principled has metal, glass, specular and base layers)")
        # else: Specular IOR Level 0, no metal, no glass: exactly Lambert (the diffuse type)
    elif node.type == "BSDF_DIFFUSE":
        out["base_color"] = _constant_color(node.inputs["Color"], material, report)
    elif node.type == "EMISSION":
        strength = _constant_float(node.inputs["Strength"], material, report)
        col = _constant_color(node.inputs["Color"], material, report)
        out["base_color"] = [0.0, 0.0, 0.0]
        out["emission"] = [c * strength for c in col]
    elif node.type == "BSDF_GLOSSY":
        c = color("Color")
        out.update(type="conductor", base_color=c, specular_tint=c,
                   roughness=_unit(value("Roughness")))
    elif node.type == "BSDF_METALLIC":
        out.update(type="conductor", roughness=_unit(value("Roughness")))
        if getattr(node, "fresnel_type", "F82") == "F82":
            out.update(base_color=color("Base Color"), specular_tint=color("Edge Tint"))
        else:
            n = _constant_color(node.inputs["IOR"], material, report)
            k = _constant_color(node.inputs["Extinction"], material, report)
            f0 = [((a - 1) ** 2 + b * b) / ((a + 1) ** 2 + b * b) for a, b in zip(n, k)]
            out.update(base_color=[min(max(f, 0.0), 1.0) for f in f0],
                       specular_tint=[1.0, 1.0, 1.0])
            report.warn(f"Material '{name}': Metallic BSDF in physical-conductor mode is "
                        f"approximated by its normal-incidence reflectance (F82 tint white)")
    elif node.type in ("BSDF_GLASS", "BSDF_REFRACTION"):
        out.update(type="dielectric", base_color=color("Color"),
                   roughness=_unit(value("Roughness")), ior=_ior(value("IOR")))
        if node.type == "BSDF_REFRACTION":
            report.warn(f"Material '{name}': Refraction BSDF rendered as glass (its Fresnel "
                        f"reflection included)")
    else:
        report.warn(f"Material '{name}': shader node '{node.name}' ({node.type}) is not "
                    "supported yet; rendering grey diffuse instead")
    return out


def _unit(v):
    """Roughness: NaN -> 0.5, clamped to [0, 1]."""
    return 0.5 if v != v else min(max(float(v), 0.0), 1.0)


def _ior(v):
    """IOR: NaN or <= 0 -> 1.5; clamped to [0.01, 100] (below 1 is legal: bubbles)."""
    return 1.5 if not (v > 0.0) else min(max(float(v), 0.01), 100.0)


class MaterialTable:
    """Unique Lantern materials by Blender material; index 0 is the default material."""

    def __init__(self, report):
        self.report = report
        self.materials = [dict(DEFAULT)]
        self._index = {}

    def index(self, material):
        if material is None:
            return 0
        key = material.name_full
        if key not in self._index:
            self._index[key] = len(self.materials)
            self.materials.append(convert_material(material, self.report))
        return self._index[key]
