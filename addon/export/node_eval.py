"""What each shader node compiles to (material_compile): NodeContext follows a socket's links
(node_graph), converts between socket types and calls the handler of each node type
(node_handlers.NODE_HANDLERS), which emits the node's instructions (opcodes in node_ops) and
returns the Val of the output asked for."""

from . import node_graph as ng
from .node_handlers import NODE_HANDLERS
from .node_ops import (  # noqa: F401 (read as node_eval.X by the compilers)
    BLEND_MODES, GRADIENT_TYPES, IN_ATTRIBUTE, IN_BACKFACING, IN_CAMERA, IN_INCOMING,
    IN_NORMAL, IN_POSITION, IN_REFLECTION, IN_TRUE_NORMAL, IN_UV, IN_WINDOW, MAP_RANGE_MODES,
    MATH_OPS, NOISE_TYPES, OP, TABLE_SIZE, VECTOR_OPS, _width)
from .program_builder import Unsupported, Val


class NodeContext:
    """Compiles values of one program: links through node_graph, conversions between socket
    types, a memo per node output and cycle detection."""

    def __init__(self, compiler, builder):
        self.c, self.b, self.Val, self.Unsupported = compiler, builder, Val, Unsupported
        self.memo, self.visiting = {}, set()

    # ---- values ----
    def const(self, vals, kind):
        return self.Val(const=tuple(vals), width=len(vals), kind=kind)

    def reg(self, reg, width, kind):
        return self.Val(reg=reg, width=width, kind=kind)

    def convert(self, v, kind):
        """v as a value of socket type kind (Blender's implicit conversions)."""
        w = _width(kind)
        if v.width == w:
            return self.Val(const=v.const, reg=v.reg, width=w, kind=kind)
        if w == 3:   # value -> vector / colour: repeated
            if v.const is not None:
                return self.const(v.const * 3, kind)
            return self.reg(self.b.block([v, v, v]), 3, kind)
        if v.const is not None:   # 3 -> 1: luminance of a colour, mean of a vector
            x = v.const
            if v.kind == "RGBA":
                return self.const((0.2126 * x[0] + 0.7152 * x[1] + 0.0722 * x[2],), kind)
            return self.const(((x[0] + x[1] + x[2]) / 3.0,), kind)
        if v.kind == "RGBA":
            out, _ = self.emit_node("rgb_to_bw", [v], 1)
            return self.reg(out, 1, kind)
        third = self.const((1.0 / 3.0,) * 3, "VECTOR")
        out, _ = self.emit_node("vector_math", [v, third, self.const((0, 0, 0), "VECTOR"),
                                                self.const((0,), "VALUE")], 4,
                                mode=VECTOR_OPS.index("DOT_PRODUCT"))
        return self.reg(out + 3, 1, kind)

    def input_value(self, socket, path, kind=None):
        """The value feeding input `socket` (of a node in the tree of `path`), as `kind`."""
        kind = kind or socket.type
        got = ng.source(socket, path, self.c.report, self.c.where)
        if got[0] == "value":
            v = got[1]
            if v is None:
                raise self.Unsupported(f"'{socket.name}' has no value")
            v = tuple(x if x == x else 0.0 for x in v)   # NaN -> 0
            return self.convert(self.const(v, "RGBA" if len(v) == 3 and socket.type == "RGBA"
                                           else socket.type), kind)
        _, node, out, npath = got
        return self.convert(self.node_output(node, out, npath), kind)

    def inp(self, node, name, path, kind=None, identifier=False):
        sock = ng.enabled_input(node, name) if identifier else ng.named_input(node, name)
        if sock is None:
            raise self.Unsupported(f"node '{node.name}' has no input '{name}'")
        return self.input_value(sock, path, kind or sock.type)

    def node_output(self, node, out, path):
        key = (ng.node_key(node, path), out.identifier)
        if key in self.memo:
            return self.memo[key]
        if key[0] in self.visiting:
            self.c.warn(f"the node graph has a cycle through '{node.name}'; "
                        f"'{out.name}' reads its default value")
            return self.fallback(out)
        handler = NODE_HANDLERS.get(node.type)
        if handler is None:
            what = node.bl_idname if node.type in ("", "CUSTOM") else node.type
            self.c.warn(f"node '{node.name}' ({what}) is not supported by Lantern; its "
                        f"output '{out.name}' reads its default value")
            return self.fallback(out)
        self.visiting.add(key[0])
        try:
            v = handler(self, node, out, path)
        finally:
            self.visiting.discard(key[0])
        self.memo[key] = v
        return v

    def fallback(self, out):
        v = ng.socket_value(out)
        if v is None:
            v = (0.0,) if _width(out.type) == 1 else (0.0, 0.0, 0.0)
        return self.const(v, out.type)

    def emit_node(self, op, inputs, out_width, mode=0, flags=0, dim=0, aux=0, aux2=0):
        """Emits op over an input block of `inputs`; returns the output block's register."""
        src = self.b.block(inputs)
        out = self.b.alloc(out_width)
        idx = self.b.emit(OP[op], mode=mode, flags=flags, dim=dim, src=src, out=out, aux=aux,
                          aux2=aux2)
        self.b.release(src, sum(v.width for v in inputs))   # spent once the op has run
        return out, idx

    def geometry(self, mode, aux=0):
        key = ("input", mode, aux)
        if key not in self.memo:
            out = self.b.alloc(3)
            self.b.emit(OP["input"], mode=mode, out=out, aux=aux)
            self.memo[key] = self.reg(out, 3, "VECTOR")
        return self.memo[key]

    def attribute(self, name):
        ch = self.c.attributes.channel(name)
        return self.geometry(IN_ATTRIBUTE, ch)

    def texture_vector(self, node, path, default="generated"):
        sock = ng.named_input(node, "Vector")
        if sock is not None and sock.is_linked:
            return self.input_value(sock, path, "VECTOR")
        return self.geometry(IN_UV) if default == "uv" else self.attribute("generated")

