"""Blender materials -> Lantern materials (this milestone: diffuse + emission).

The full node translation (Principled layers, textures) is a later issue. Here: Principled BSDF
base color and emission, Diffuse BSDF, Emission; anything else renders a documented fallback
(grey 0.8 diffuse) with a warning naming the material and the node."""

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
    if node.type == "BSDF_PRINCIPLED":
        out["base_color"] = _constant_color(node.inputs["Base Color"], material, report)
        strength = _constant_float(node.inputs["Emission Strength"], material, report)
        if strength != 0.0:
            col = _constant_color(node.inputs["Emission Color"], material, report)
            out["emission"] = [c * strength for c in col]
    elif node.type == "BSDF_DIFFUSE":
        out["base_color"] = _constant_color(node.inputs["Color"], material, report)
    elif node.type == "EMISSION":
        strength = _constant_float(node.inputs["Strength"], material, report)
        col = _constant_color(node.inputs["Color"], material, report)
        out["base_color"] = [0.0, 0.0, 0.0]
        out["emission"] = [c * strength for c in col]
    else:
        report.warn(f"Material '{material.name}': shader node '{node.name}' ({node.type}) is not "
                    "supported yet; rendering grey diffuse instead")
    return out


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
