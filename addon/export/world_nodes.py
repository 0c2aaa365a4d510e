"""Procedural worlds: a Background whose Color or Strength a node graph drives (Gradient,
Noise, Mix, Math, ... on the direction) is compiled as a material's graph (material_compile)
and evaluated by the core over the directions of an equirectangular map at export
(node_light.evaluate); the map then renders, and is importance-sampled, as an Environment
Texture world (world.py, scene/envmap*). As in Cycles' background, Generated, Object, Position
and Normal read the view direction (Normal and Incoming its reverse); an Environment or Sky
Texture anywhere in the graph leaves the world to world.py / sky*.py. The map's resolution
limits detail: a graph finer than BAKE_WIDTH / 360 degrees is blurred (docs/nodes.md)."""

import math

import numpy as np

from . import node_eval as ne
from . import node_graph as ng
from .node_eval import NodeContext
from .node_light import OwnerCompiler, compile_socket, evaluate, times_strength

BAKE_WIDTH, BAKE_HEIGHT = 1024, 512
_LEAVE = {"TEX_ENVIRONMENT", "TEX_SKY"}   # world.py's and the sky's own paths
_BAKED = {}   # program -> baked map


class WorldContext(NodeContext):
    """Texture coordinates of the background: the direction itself."""

    def attribute(self, name):
        if name in ("generated", "object"):
            return self.geometry(ne.IN_POSITION)
        if name == "object_normal":
            return self.geometry(ne.IN_NORMAL)
        self.c.warn(f"the attribute '{name}' has no value on the world; 0 is used")
        return self.const((0.0, 0.0, 0.0), "VECTOR")


def _upstream(socket, path=(), seen=None, depth=0):
    """{node key: node type} of the nodes feeding socket (through groups)."""
    seen = {} if seen is None else seen
    got = ng.source(socket, path) if socket is not None and socket.is_linked else ("value",)
    if got[0] != "node" or depth > 64:
        return seen
    _, node, _, npath = got
    key = ng.node_key(node, npath)
    if key in seen:
        return seen
    seen[key] = node.type
    for s in node.inputs:
        _upstream(s, npath, seen, depth + 1)
    return seen


def directions(width=BAKE_WIDTH, height=BAKE_HEIGHT):
    """World directions (H x W x 3) at texel centres of Lantern's equirectangular map
    (rows bottom to top; scene/envmap.h env_uv_to_direction)."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi = (0.5 - u)[None, :] * 2.0 * math.pi
    elev = (v - 0.5)[:, None] * math.pi
    c = np.cos(elev)
    return np.stack(np.broadcast_arrays(c * np.cos(phi), c * np.sin(phi), np.sin(elev)), -1)


def bake(world, background, out, report):
    """Fills out (world.py's dict) with the baked map of a procedural Background and returns
    True; False (nothing changed) for a constant, an image or a sky world."""
    color, strength = background.inputs["Color"], background.inputs["Strength"]
    if not (color.is_linked or strength.is_linked):
        return False
    found = _upstream(color)
    _upstream(strength, (), found)
    types = set(found.values())
    if types & _LEAVE or not types:
        return False
    compiler = OwnerCompiler(f"World '{world.name}'", report)
    prog = compile_socket(compiler, color, times_strength(strength), context=WorldContext)
    if prog is None:
        return False
    key = (tuple(tuple(w) for w in prog["code"]), tuple(prog["consts"]), prog["num_const"],
           prog["result"])
    rgb = _BAKED.get(key)
    if rgb is None:
        d = directions().reshape(-1, 3)
        rgb = evaluate(prog, d, -d)
        if rgb is None:
            return False
        rgb = np.nan_to_num(rgb, nan=0.0, posinf=0.0, neginf=0.0)
        rgb = np.maximum(rgb, 0.0).reshape(BAKE_HEIGHT, BAKE_WIDTH, 3)
        if len(_BAKED) >= 4:   # viewport syncs re-export the world: the last few bakes kept
            _BAKED.pop(next(iter(_BAKED)))
        _BAKED[key] = rgb
    out.update({"map": rgb.astype(np.float32, copy=True), "map_name": f"{world.name} "
                "(node graph)", "strength": [1.0, 1.0, 1.0], "projection": "equirectangular",
                "to_map": np.eye(3).tolist()})
    return True
