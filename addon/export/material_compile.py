"""Node graphs -> register programs (native/src/scene/material_program.h), one per material
input a graph drives. The graph is read through node_graph.source (groups flattened, reroutes
and muted nodes removed); values are constants or registers; each node becomes one or a few
instructions whose inputs sit in one register block. The core folds what stays constant
(material_program.cpp). A node Lantern does not evaluate warns by name and its output reads
the socket's own value; a cycle warns and reads the input's value."""

from . import node_graph as ng
from .node_eval import NODE_HANDLERS, NodeContext
from .program_builder import REGS, Builder, Unsupported, Val  # noqa: F401 (imported from here)

TARGETS = ("base_color", "roughness", "metallic", "emission", "alpha", "mix_factor", "bump",
           "displacement", "normal_map", "normal_map_world", "tangent", "density",
           "volume_emission", "volume_color", "volume_emission_color",
           "volume_absorption_color")


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
