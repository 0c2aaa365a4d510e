"""A material's node tree as the compiler sees it: links followed through reroutes, muted
nodes (their internal links, else the output's default), node groups (flattened: a group's
output leads inside, a Group Input back out to the group node's input) and invalid or muted
links (the input's own value). Cycles in a graph are found by the compiler (material_compile)
on the flattened graph.

source(socket, path) -> ("value", v) or ("node", node, output_socket, path): `path` is the
tuple of group nodes from the material's tree down to the tree `node` lives in."""

MAX_HOPS = 256   # reroutes, groups and muted nodes followed for one link


def socket_value(socket):
    """A socket's own value as a tuple (1 or 3 floats; RGBA drops alpha), or None for sockets
    without one (shaders, geometry)."""
    v = getattr(socket, "default_value", None)
    if v is None:
        return None
    if isinstance(v, (bool, int, float)):
        return (float(v),)
    try:
        vals = [float(x) for x in v]
    except TypeError:
        return None
    if len(vals) >= 3:
        return tuple(vals[:3])
    if len(vals) == 2:
        return (vals[0], vals[1], 0.0)
    return (vals[0],) if vals else None


def _group_output(tree):
    nodes = [n for n in tree.nodes if n.type == "GROUP_OUTPUT"]
    for n in nodes:
        if getattr(n, "is_active_output", False):
            return n
    return nodes[0] if nodes else None


def _by_identifier(sockets, identifier):
    for s in sockets:
        if s.identifier == identifier:
            return s
    return None


def _live_link(socket):
    for link in socket.links:
        if getattr(link, "is_muted", False) or not getattr(link, "is_valid", True):
            continue
        return link
    return None


def source(socket, path=(), report=None, where=""):
    """What feeds input `socket` of a node in the tree reached through `path`."""
    hops = 0
    while True:
        hops += 1
        if hops > MAX_HOPS:
            if report:
                report.warn(f"{where}: links through reroutes and groups too deep (a loop?); "
                            f"'{socket.name}' uses its own value")
            return ("value", socket_value(socket))
        link = _live_link(socket) if socket.is_linked else None
        if link is None:
            if socket.is_linked and report and any(not getattr(lk, "is_valid", True)
                                                   for lk in socket.links):
                report.warn(f"{where}: the link into '{socket.name}' of "
                            f"'{socket.node.name}' is invalid (a cycle in the graph, or "
                            "mismatched sockets); the input's own value is used")
            return ("value", socket_value(socket))
        node, out = link.from_node, link.from_socket
        if node.type == "REROUTE":
            socket = node.inputs[0]
            continue
        if getattr(node, "mute", False):
            inner = next((lk.from_socket for lk in node.internal_links
                          if lk.to_socket == out), None)
            if inner is None:
                return ("value", socket_value(out))
            socket = inner
            continue
        if node.type == "GROUP":
            tree = node.node_tree
            gout = _group_output(tree) if tree is not None else None
            inner = _by_identifier(gout.inputs, out.identifier) if gout is not None else None
            if inner is None:
                if report:
                    report.warn(f"{where}: node group '{node.name}' has no output "
                                f"'{out.name}'; its default is used")
                return ("value", socket_value(out))
            socket, path = inner, path + (node,)
            continue
        if node.type == "GROUP_INPUT":
            if not path:
                return ("value", socket_value(out))
            group = path[-1]
            outer = _by_identifier(group.inputs, out.identifier)
            if outer is None:
                return ("value", socket_value(out))
            socket, path = outer, path[:-1]
            continue
        return ("node", node, out, path)


def node_key(node, path):
    """A key naming one node of the flattened graph (a group's nodes once per group use)."""
    return tuple(g.name for g in path) + (node.id_data.name_full, node.name)


def enabled_input(node, identifier):
    """An input by identifier (Blender 4+ nodes keep one socket per data type)."""
    return _by_identifier(node.inputs, identifier)


def named_input(node, name):
    """The first enabled input called `name` (or any, when none is enabled)."""
    first = None
    for s in node.inputs:
        if s.name == name:
            if getattr(s, "enabled", True):
                return s
            first = first or s
    return first
