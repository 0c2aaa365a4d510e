"""Bump: a Bump node on a shader's Normal input and the Material Output's Displacement (as
bump), compiled into "bump" and "displacement" programs whose result is (height, strength,
signed distance); the core bends the shading normal by them (the displacement first: it is
the normal node graphs read, Cycles' N) (native/src/scene/material_program.h,
program_bump). A Bump fed by another Bump gives two programs, the inner first; a Normal Map
(tangent space, an image or a graph) under the innermost Bump is the material's normal map,
applied before them. Filter Width is not used (Lantern has no ray differentials: docs/nodes.md)."""

from . import node_graph as ng
from .material_compile import Builder, Unsupported
from . import node_eval as ne
from .node_eval import NodeContext

MAX_CHAIN = 8


def _program(compiler, parts, what, target="bump"):
    """A bump program from parts(ctx) -> (height, strength, distance) Vals; None for a
    constant height (it bends nothing) or a graph that does not compile (a warning)."""
    b = Builder()
    ctx = NodeContext(compiler, b)
    try:
        h, s, d = parts(ctx)
        if h.const is not None:
            return None
        reg = b.block([h, s, d])
        return b.finish(ctx.reg(reg, 3, "VECTOR"), target)
    except Unsupported as e:
        compiler.warn(f"the height graph of {what} is not rendered ({e}); no bump")
        return None


def _bump_node(compiler, node, path):
    def parts(ctx):
        h = ctx.inp(node, "Height", path, "VALUE")
        s = ctx.inp(node, "Strength", path, "VALUE")
        d = ctx.inp(node, "Distance", path, "VALUE")
        if getattr(node, "invert", False):
            if d.const is not None:
                d = ctx.const((-d.const[0],), "VALUE")
            else:
                r, _ = ctx.emit_node("math", [d, ctx.const((-1.0,), "VALUE"),
                                              ctx.const((0.0,), "VALUE")], 1, mode=2)
                d = ctx.reg(r, 1, "VALUE")
        return h, s, d
    return _program(compiler, parts, f"Bump '{node.name}'")


def bump_chain(compiler, owner, path=(), normal_map=None, depth=0):
    """Programs of the Bump nodes feeding owner's Normal input (innermost first).
    normal_map(node) is called for a Normal Map under the chain, with the node whose Normal
    input it feeds."""
    sock = ng.named_input(owner, "Normal")
    if sock is None or not sock.is_linked or depth > MAX_CHAIN:
        return []
    got = ng.source(sock, path, compiler.report, compiler.where)
    if got[0] != "node":
        return []
    _, node, _, npath = got
    if node.type == "NORMAL_MAP":
        if normal_map is not None and depth > 0:
            normal_map(owner)
        return []
    if node.type != "BUMP":
        compiler.warn(f"'{node.name}' ({node.type}) on the Normal of '{owner.name}' is not "
                      "supported (Bump and tangent-space Normal Map nodes are); ignored")
        return []
    progs = bump_chain(compiler, node, npath, normal_map, depth + 1)
    prog = _bump_node(compiler, node, npath)
    return progs + ([prog] if prog is not None else [])


def world_normal_map(compiler, node):
    """The "normal_map_world" program of an Object or World space Normal Map node: its colour
    decoded to a direction (2c - 1; Blender's own spaces flip y and z), object space taken to
    the world by the shaded object's normal matrix (per-instance attribute channels); None
    when the graph does not compile (a warning)."""
    space = node.space
    ctx_ops = ne.VECTOR_OPS

    def post(ctx, v):
        zero, nil = ctx.const((0.0, 0.0, 0.0), "VECTOR"), ctx.const((0.0,), "VALUE")
        flip = -1.0 if space.startswith("BLENDER_") else 1.0
        r, _ = ctx.emit_node("vector_math", [ctx.convert(v, "VECTOR"),
                                             ctx.const((2.0, 2.0 * flip, 2.0 * flip), "VECTOR"),
                                             ctx.const((-1.0, -flip, -flip), "VECTOR"), nil],
                             4, mode=ctx_ops.index("MULTIPLY_ADD"))
        n = ctx.reg(r, 3, "VECTOR")
        if not space.endswith("OBJECT"):
            return n
        rows = []
        for axis in "xyz":   # world component = the normal matrix's row . n
            d, _ = ctx.emit_node("vector_math", [ctx.attribute(f"object_normal_{axis}"), n,
                                                 zero, nil], 4,
                                 mode=ctx_ops.index("DOT_PRODUCT"))
            rows.append(ctx.reg(d + 3, 1, "VALUE"))
        c, _ = ctx.emit_node("combine", rows, 3, mode=0)
        return ctx.reg(c, 3, "VECTOR")
    return compiler.program(node.inputs["Color"], "normal_map_world", 3, post=post)


def is_bump(sock):
    """Whether a Bump node (through reroutes and groups) feeds sock."""
    if sock is None or not sock.is_linked:
        return False
    got = ng.source(sock)
    return got[0] == "node" and got[1].type == "BUMP"


def displacement(compiler, material, output):
    """The bump program of the Material Output's Displacement, or None (with a warning where
    Lantern cannot render what is linked there)."""
    sock = output.inputs.get("Displacement")
    if sock is None or not sock.is_linked:
        return None
    # (true displacement, a method other than Bump Only, is named by unsupported.py)
    got = ng.source(sock, (), compiler.report, compiler.where)
    if got[0] != "node":
        return None
    _, node, _, path = got
    if node.type != "DISPLACEMENT":
        compiler.warn(f"'{node.name}' ({node.type}) on the Displacement output is not "
                      "rendered (a Displacement node is, as bump)")
        return None
    n = ng.named_input(node, "Normal")
    if n is not None and n.is_linked:
        compiler.warn(f"Displacement '{node.name}': its Normal input is ignored (the shading "
                      "normal is used)")

    def parts(ctx):   # displaced by (height - midlevel) x scale along the normal
        h = ctx.inp(node, "Height", path, "VALUE")
        mid = ctx.inp(node, "Midlevel", path, "VALUE")
        scale = ctx.inp(node, "Scale", path, "VALUE")
        if h.const is not None:
            return h, h, h
        r, _ = ctx.emit_node("math", [h, mid, ctx.const((0.0,), "VALUE")], 1, mode=1)
        r2, _ = ctx.emit_node("math", [ctx.reg(r, 1, "VALUE"), scale,
                                       ctx.const((0.0,), "VALUE")], 1, mode=2)
        one = ctx.const((1.0,), "VALUE")
        return ctx.reg(r2, 1, "VALUE"), one, one
    return _program(compiler, parts, f"Displacement '{node.name}'", "displacement")


def hoist(out, leaves, report, where):
    """A shader mix bends one normal: the bump (and graph-fed normal map) programs of its first
    leaf that has any (a warning when leaves differ)."""
    found = [[p for p in leaf.get("programs", [])
              if p["target"] in ("bump", "displacement", "normal_map", "normal_map_world")]
             for leaf in leaves]
    found = [f for f in found if f]
    if not found:
        return
    if any(repr(f) != repr(found[0]) for f in found[1:]):
        report.warn(f"{where}: mixed shaders with different bumps; the first is used")
    if out.get("type") == "mix":
        out.setdefault("programs", []).extend(found[0])
        first = next(leaf for leaf in leaves if any(
            p["target"] in ("bump", "displacement", "normal_map", "normal_map_world")
            for p in leaf.get("programs", [])))
        if any(p["target"] in ("normal_map", "normal_map_world") for p in found[0]):
            out["normal_strength"] = first.get("normal_strength", 1.0)
