"""World -> constant background radiance (color * strength of the Background node)."""

import bpy


def _socket_color(socket):
    v = socket.default_value
    return [float(v[0]), float(v[1]), float(v[2])]


def export_world(world, report):
    if world is None:
        return {"color": [0.0, 0.0, 0.0]}
    tree = world.node_tree
    if bpy.app.version < (5, 0, 0) and not world.use_nodes:  # always nodes from 5.0
        tree = None
    if tree is None:
        return {"color": [float(c) for c in world.color[:3]]}
    output = next((n for n in tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
    if output is None:
        output = next((n for n in tree.nodes if n.type == "OUTPUT_WORLD"), None)
    surface = output.inputs["Surface"] if output else None
    if surface is None or not surface.is_linked:
        return {"color": [0.0, 0.0, 0.0]}
    node = surface.links[0].from_node
    if node.type != "BACKGROUND":
        report.warn(f"World '{world.name}': node '{node.name}' ({node.type}) is not supported; "
                    "the world renders black")
        return {"color": [0.0, 0.0, 0.0]}
    color_in, strength_in = node.inputs["Color"], node.inputs["Strength"]
    if color_in.is_linked or strength_in.is_linked:
        report.warn(f"World '{world.name}': only a constant Background color is supported; "
                    "textures and linked inputs use the socket's own value")
    s = float(strength_in.default_value)
    return {"color": [c * s for c in _socket_color(color_in)]}
