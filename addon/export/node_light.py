"""Node trees outside materials: a light's (Emission colour x strength into the Light
Output, which multiplies the light's own colour and power, as in Cycles) and, through
compile_socket / evaluate, the world's (world_nodes.py). A graph is compiled as a material's
(material_compile), then evaluated by the core outside a scene (lantern._core
.evaluate_program): a light's at its centre, facing along its axis; a graph that varies over
the light (textures, geometry) is named in a warning and that one value is used."""

import numpy as np

from . import node_eval as ne
from . import node_graph as ng
from .material_compile import Builder, Unsupported
from .node_eval import NodeContext

# ops whose value depends on the point (not constant over a light)
_VARYING = {ne.OP["input"], ne.OP["image"], ne.OP["fresnel"], ne.OP["layer_weight"]}


class _NoAttributes:
    def channel(self, name):
        return -1


class _NoTextures:
    def add_raw(self, node, where):
        return None


class OwnerCompiler:
    """What NodeContext needs of its compiler, for a tree that is not a material's."""

    def __init__(self, where, report):
        self.where, self.report = where, report
        self.textures, self.attributes = _NoTextures(), _NoAttributes()

    def warn(self, msg):
        self.report.warn(f"{self.where}: {msg}")


def compile_socket(compiler, socket, post=None, context=NodeContext):
    """The program (material_compile's dict, target 'emission') of a colour on socket, or
    None (a warning says why)."""
    b = Builder()
    ctx = context(compiler, b)
    try:
        v = ctx.input_value(socket, (), "RGBA")
        if post is not None:
            v = post(ctx, v)
        return b.finish(v, "emission")
    except Unsupported as e:
        compiler.warn(f"the node graph on '{socket.name}' is not rendered ({e})")
        return None


def varies(prog):
    return any((w[0] & 0xFF) in _VARYING for w in prog["code"])


def evaluate(prog, points, normals):
    """The program's value (N x 3 float32) at points with normals (N x 3), or None without
    the native core."""
    try:
        from lantern import _core
    except ImportError:
        return None
    code = [int(x) & 0xFFFFFFFF for w in prog["code"] for x in w]
    pts = np.ascontiguousarray(points, np.float32).reshape(-1)
    nrm = np.ascontiguousarray(normals, np.float32).reshape(-1)
    out = _core.evaluate_program(code, [float(c) for c in prog["consts"]],
                                 int(prog["num_const"]), int(prog["result"]), pts.tolist(),
                                 nrm.tolist())
    return np.asarray(out, np.float32).reshape(-1, 3)


def times_strength(strength):
    def post(ctx, v):
        k = ctx.input_value(strength, (), "VECTOR")
        r, _ = ctx.emit_node("vector_math", [ctx.convert(v, "VECTOR"), k,
                                             ctx.const((0, 0, 0), "VECTOR"),
                                             ctx.const((0,), "VALUE")], 4, mode=2)
        return ctx.reg(r, 3, "RGBA")
    return post


def _emission_node(tree, compiler):
    outs = [n for n in tree.nodes if n.type == "OUTPUT_LIGHT"]
    active = [n for n in outs if getattr(n, "is_active_output", False)] or outs
    if not active:
        return None
    surface = active[0].inputs.get("Surface")
    if surface is None or not surface.is_linked:
        return "black"
    got = ng.source(surface, (), compiler.report, compiler.where)
    if got[0] != "node":
        return "black"
    node = got[1]
    if node.type != "EMISSION":
        compiler.warn(f"'{node.name}' ({node.type}) on the Light Output is not rendered (an "
                      "Emission node is); the light uses its Color and Power")
        return None
    return node


def light_factor(obj, matrix_world, report):
    """The light node tree's colour x strength (3 floats) that multiplies obj's light, or
    None without a tree (or one Lantern cannot read: a warning)."""
    light = obj.data
    tree = getattr(light, "node_tree", None)
    if tree is None or not getattr(light, "use_nodes", False):
        return None
    compiler = OwnerCompiler(f"Light '{obj.name}'", report)
    node = _emission_node(tree, compiler)
    if node is None:
        return None
    if node == "black":
        return [0.0, 0.0, 0.0]
    color, strength = node.inputs["Color"], node.inputs["Strength"]
    prog = compile_socket(compiler, color, times_strength(strength))
    if prog is None:
        return None
    m = np.array(matrix_world, dtype=np.float64)
    axis = -m[:3, 2] / max(float(np.linalg.norm(m[:3, 2])), 1e-30)
    value = evaluate(prog, [m[:3, 3]], [axis])
    if value is None:
        compiler.warn("the light node tree needs Lantern's native core; the light uses its "
                      "Color and Power")
        return None
    if varies(prog):
        compiler.warn("the light node tree varies over the light (textures or geometry "
                      "inputs), which Lantern does not render; its value at the light's "
                      "centre is used")
    v = [float(x) if np.isfinite(x) else 0.0 for x in value[0]]
    return [max(x, 0.0) for x in v]
