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
    value, color, where = inputs.value, inputs.color, inputs.where
    model = getattr(node, "model", "CHIANG")
    if model != "CHIANG":
        report.warn(f"{where}: Principled Hair model '{model}' is rendered with the Chiang model")
    for name in ("Random Color", "Random Roughness"):
        if name in node.inputs and value(name) != 0.0:
            report.warn(f"{where}: Principled Hair '{name}' is not rendered yet (no per-strand "
                        "random number); 0 is used")
    param = PARAMETRIZATIONS.get(getattr(node, "parametrization", "COLOR"), "color")
    unit = lambda v: min(max(v, 0.0), 1.0) if math.isfinite(v) else 0.0  # noqa: E731
    absorption = _socket_default(node.inputs["Absorption Coefficient"], [0.245531, 0.52, 1.365],
                                 color=False)
    out.update(type="hair", hair_parametrization=param,
               base_color=[unit(c) for c in color("Color")],
               melanin=unit(value("Melanin")), melanin_redness=unit(value("Melanin Redness")),
               hair_tint=[unit(c) for c in color("Tint")],
               absorption=[max(a, 0.0) for a in absorption],
               roughness=unit(value("Roughness")),
               radial_roughness=unit(value("Radial Roughness")),
               hair_coat=unit(value("Coat")),
               ior=min(max(value("IOR"), 1.0001), 100.0) if math.isfinite(value("IOR")) else 1.55,
               hair_offset=min(max(value("Offset"), -1.5707963), 1.5707963)
               if math.isfinite(value("Offset")) else 0.034906585)
    return out
