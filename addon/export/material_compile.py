"""Node graphs -> register programs (native/src/scene/material_program.h), one per material
input a graph drives. The graph is read through node_graph.source (groups flattened, reroutes
and muted nodes removed); values are constants or registers; each node becomes one or a few
instructions whose inputs sit in one register block. The core folds what stays constant
(material_program.cpp). A node Lantern does not evaluate warns by name and its output reads
the socket's own value; a cycle warns and reads the input's value."""

from . import node_graph as ng
from .node_eval import NODE_HANDLERS, NodeContext

REGS = 192          # kProgramRegs
TARGETS = ("base_color", "roughness", "metallic", "emission", "alpha", "mix_factor")


class Unsupported(Exception):
    pass


class Val:
    """A value in the program: a constant tuple, or `width` registers from `reg`; `kind` is the
    Blender socket type it carries (VALUE, VECTOR, RGBA)."""

    __slots__ = ("const", "reg", "width", "kind")

    def __init__(self, const=None, reg=None, width=1, kind="VALUE"):
        self.const, self.reg, self.width, self.kind = const, reg, width, kind


class Builder:
    """Registers, constants and instructions of one program."""

    def __init__(self):
        self.image = []          # register image: constants, 0 for temporaries
        self.const_top = 0       # registers below this are preloaded
        self.code = []           # [w0, w1, w2, w3]
        self.tables = []         # (instruction index, floats): appended after the image
        self._consts = {}

    def alloc(self, n):
        base = len(self.image)
        if base + n > REGS:
            raise Unsupported("the graph needs more registers than a program has")
        self.image.extend([0.0] * n)
        return base

    def const(self, vals):
        vals = tuple(float(v) for v in vals)
        if vals not in self._consts:
            base = self.alloc(len(vals))
            self.image[base:base + len(vals)] = list(vals)
            self.const_top = max(self.const_top, base + len(vals))
            self._consts[vals] = base
        return self._consts[vals]

    def emit(self, op, mode=0, flags=0, dim=0, src=0, out=0, aux=0, aux2=0):
        self.code.append([op | (mode << 8) | (flags << 16) | (dim << 24), src | (out << 16),
                          aux & 0xFFFFFFFF, aux2 & 0xFFFFFFFF])
        return len(self.code) - 1

    def block(self, vals):
        """One contiguous input block holding vals (each already of the width wanted)."""
        base = self.alloc(sum(v.width for v in vals))
        at = base
        for v in vals:
            if v.const is not None:
                self.image[at:at + v.width] = [float(x) for x in v.const]
                self.const_top = max(self.const_top, at + v.width)
            else:
                self.emit(0, dim=v.width, src=v.reg, out=at)
            at += v.width
        return base

    def table(self, instr, floats):
        self.tables.append((instr, [float(x) for x in floats]))

    def finish(self, result, target):
        if result.const is not None:
            reg = self.const(result.const if result.width == 3 else result.const * 3)
        elif result.width == 1:
            reg = self.block([result, result, result])
        else:
            reg = result.reg
        consts = self.image[:self.const_top]
        code = [list(w) for w in self.code]
        for instr, floats in self.tables:
            code[instr][2] = len(consts)       # the table's offset in the program's constants
            consts.extend(floats)
        return {"target": target, "code": code, "consts": consts, "num_const": self.const_top,
                "result": reg}


class GraphCompiler:
    """Compiles the graphs of one material; `textures` (TextureTable) and `attributes`
    (AttributeTable) are the scene's."""

    def __init__(self, material, report, textures, attributes):
        self.material, self.report = material, report
        self.textures, self.attributes = textures, attributes
        self.where = f"Material '{material.name}'"

    def warn(self, msg):
        self.report.warn(f"{self.where}: {msg}")

    def is_graph(self, socket):
        """True when a node (not a plain value) feeds socket through the graph."""
        return ng.source(socket)[0] == "node"

    def program(self, socket, target, width, post=None):
        """The program of `target` driven by `socket` (width 1 or 3 of the result), or None
        when the graph could not be compiled (a warning says why)."""
        b = Builder()
        ctx = NodeContext(self, b)
        try:
            v = ctx.input_value(socket, (), "RGBA" if width == 3 else "VALUE")
            if post is not None:
                v = post(ctx, v)
            return b.finish(v, target)
        except Unsupported as e:
            self.warn(f"the node graph on '{socket.name}' is not rendered ({e}); its own "
                      "value is used")
            return None


def attach(out, prog):
    if prog is not None:
        out.setdefault("programs", []).append(prog)


__all__ = ["GraphCompiler", "Builder", "Val", "Unsupported", "TARGETS", "NODE_HANDLERS",
           "attach"]
