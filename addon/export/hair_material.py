"""The Principled Hair BSDF node -> a Lantern "hair" material (docs/curves.md; the core's
bsdf/hair.h, Chiang et al. 2016 as Cycles): its parametrisation (Melanin, Direct Coloring,
Absorption Coefficient), Roughness, Radial Roughness, Coat, IOR, Offset, each a constant (a
linked input: its constant value, warned by material_inputs). Not yet: the Huang model (rendered
as Chiang), Random Color and Random Roughness (a per-strand random number), both warned."""

import math

from .material_inputs import _socket_default

PARAMETRIZATIONS = {"MELANIN": "melanin", "COLOR": "color", "ABSORPTION": "absorption"}


def principled_hair(node, out, inputs, report):
    """Fill the material dict `out` from the node (inputs: material_inputs._Inputs)."""
    where = inputs.where

    # inputs of other parametrisations may be absent (unavailable sockets): their defaults
    def value(name, default=0.0):
        return inputs.value(name) if node.inputs.get(name) is not None else default

    def color(name, default):
        return inputs.color(name) if node.inputs.get(name) is not None else default

    model = getattr(node, "model", "CHIANG")
    if model != "CHIANG":
        report.warn(f"{where}: Principled Hair model '{model}' is rendered with the Chiang model")
    for name in ("Random Color", "Random Roughness"):
        if value(name) != 0.0:
            report.warn(f"{where}: Principled Hair '{name}' is not rendered yet (no per-strand "
                        "random number); 0 is used")
    param = PARAMETRIZATIONS.get(getattr(node, "parametrization", "COLOR"), "color")
    unit = lambda v: min(max(v, 0.0), 1.0) if math.isfinite(v) else 0.0  # noqa: E731
    sock = node.inputs.get("Absorption Coefficient")
    absorption = [0.245531, 0.52, 1.365] if sock is None else \
        _socket_default(sock, [0.245531, 0.52, 1.365], color=False)
    out.update(type="hair", hair_parametrization=param,
               base_color=[unit(c) for c in color("Color", [0.017513, 0.005763, 0.002059])],
               melanin=unit(value("Melanin", 0.8)),
               melanin_redness=unit(value("Melanin Redness", 1.0)),
               hair_tint=[unit(c) for c in color("Tint", [1.0, 1.0, 1.0])],
               absorption=[max(a, 0.0) for a in absorption],
               roughness=unit(value("Roughness", 0.3)),
               radial_roughness=unit(value("Radial Roughness", 0.3)),
               hair_coat=unit(value("Coat", 0.0)))
    ior, offset = value("IOR", 1.55), value("Offset", 0.034906585)
    out["ior"] = min(max(ior, 1.0001), 100.0) if math.isfinite(ior) else 1.55
    out["hair_offset"] = min(max(offset, -1.5707963), 1.5707963) if math.isfinite(offset) \
        else 0.034906585
    return out
