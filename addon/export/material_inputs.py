"""What a shader node's inputs read for a material (material.py converts the node): constant
colours and values, the image or node graph feeding a socket (through reroutes and Separate
Color), and _Inputs, which turns each input into a constant, a texture id or a node-graph program
(material_compile). Also the material defaults and the clamps every converter applies."""

import math

from . import negative_emission
from . import node_bump
from .material_compile import GraphCompiler, attach
from .texture import MAGENTA


DEFAULT = {"name": "Lantern Default", "type": "diffuse", "base_color": [0.8, 0.8, 0.8],
           "emission": [0.0, 0.0, 0.0]}


# What Blender renders where an object has no material (no slot, or an empty one): its default
# surface material, a Principled BSDF at its defaults (measured with bpy 5.0.1: Cycles renders
# such an object exactly as one with a new material, not as its own Diffuse 0.8 default
# shader); this is convert_material of that Principled (tests/blender/test_bl_export.py)
DEFAULT_SURFACE = {"name": "Lantern Default", "type": "principled",
                   "base_color": [0.8, 0.8, 0.8], "emission": [0.0, 0.0, 0.0],
                   "roughness": 0.5, "diffuse_roughness": 0.0, "metallic": 0.0, "alpha": 1.0,
                   "specular_tint": [1.0, 1.0, 1.0], "ior": 1.5, "transmission": 0.0,
                   "specular_level": 0.5}


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


def _source(socket):
    """(node, output socket name) feeding `socket` through reroutes, or (None, None)."""
    seen = 0
    while socket.is_linked and seen < 16:
        seen += 1
        link = socket.links[0]
        node = link.from_node
        if node.type == "REROUTE":
            socket = node.inputs[0]
            continue
        return node, link.from_socket.name
    return None, None


def _image_source(socket):
    """(Image Texture node, output) when an image feeds `socket` directly (output "color" or
    "alpha") or through one Separate Color / Separate RGB channel ("red", "green", "blue")."""
    node, out = _source(socket)
    if node is None:
        return None, None
    if node.type == "TEX_IMAGE":
        return node, "alpha" if out == "Alpha" else "color"
    if node.type in ("SEPARATE_COLOR", "SEPRGB"):
        channel = {"Red": "red", "R": "red", "Green": "green", "G": "green", "Blue": "blue",
                   "B": "blue"}.get(out)
        mode = getattr(node, "mode", "RGB")
        inner, inner_out = _source(node.inputs[0])
        if channel and mode == "RGB" and inner is not None and inner.type == "TEX_IMAGE" \
                and inner_out == "Color":
            return inner, channel
    return None, None


class _Inputs:
    """Reads one shader node's inputs for a material: constants, or textures where Lantern
    can texture the input (`textured` names them), else the texture's mean with a warning."""

    def __init__(self, node, material, report, textures):
        self.node, self.material, self.report, self.textures = node, material, report, textures
        self.where = f"Material '{material.name}'"
        self.compiler = GraphCompiler(material, report, textures, textures.attributes)

    def graph(self, out, socket_name, target, width, post=None):
        """A node graph (not an image, RGB or Value node) on the input: compiled into a
        program of `target` on out (material_compile); True when it drives the input."""
        sock = self.node.inputs.get(socket_name)
        if not is_graph(sock):
            return False
        prog = self.compiler.program(sock, target, width, post)
        attach(out, prog)
        return prog is not None

    def texture(self, socket_name, as_color):
        """Texture id feeding the input, "missing" for an unreadable image, or None."""
        sock = self.node.inputs.get(socket_name)
        if sock is None:
            return None
        img, output = _image_source(sock)
        if img is None:
            return None
        if as_color and output != "color":
            return None  # a channel or alpha as a colour: the mean (below)
        tid = self.textures.add(img, output, self.where)
        return "missing" if tid is None else tid

    def color(self, socket_name, clamp=True):
        sock = self.node.inputs[socket_name]
        img, output = _image_source(sock)
        if img is not None:  # an input Lantern does not texture: the image's mean
            mean = self.textures.mean(img, output, self.where)
            self.report.warn(f"{self.where}: the image texture on '{socket_name}' is not "
                             f"rendered as a texture; its mean value is used")
            v = mean if mean is not None else MAGENTA
        else:
            v = _constant_color(sock, self.material, self.report)
        if not all(math.isfinite(c) and c >= 0.0 for c in v):
            self.report.warn(f"{self.where}: '{socket_name}' has negative or non-finite values "
                             f"{[round(c, 4) for c in v]}; read as 0 there")
            v = [c if math.isfinite(c) and c >= 0.0 else 0.0 for c in v]
        return [min(c, 1.0) for c in v] if clamp else v

    def value(self, socket_name, warn=True):
        sock = self.node.inputs[socket_name]
        img, output = _image_source(sock)
        if img is not None:
            mean = self.textures.mean(img, output, self.where)
            if warn:
                self.report.warn(f"{self.where}: the image texture on '{socket_name}' is not "
                                 f"rendered as a texture; its mean value is used")
            if mean is not None:
                return 0.2126 * mean[0] + 0.7152 * mean[1] + 0.0722 * mean[2]
        return _constant_float(sock, self.material, self.report)

    def emission_graph(self, out, color_name, strength_name):
        """Emission colour x strength where a node graph drives either: one emission program
        (the constant emission, for light selection only, is the strength's own value)."""
        color, strength = self.node.inputs[color_name], self.node.inputs[strength_name]
        if not (is_graph(color) or is_graph(strength)):
            return False

        def times_strength(ctx, v):
            # Strength is a float socket: a colour feeding it is its luminance there, as
            # Blender converts (not a per-channel scale)
            k = ctx.convert(ctx.input_value(strength, (), "VALUE"), "VECTOR")
            r, _ = ctx.emit_node("vector_math", [ctx.convert(v, "VECTOR"), k,
                                                 ctx.const((0, 0, 0), "VECTOR"),
                                                 ctx.const((0,), "VALUE")], 4, mode=2)
            return ctx.reg(r, 3, "RGBA")
        prog = self.compiler.program(color, "emission", 3, post=times_strength)
        if prog is None:
            return False
        negative_emission.check_program(self.report, self.where, prog)
        attach(out, prog)
        est = _weight(float(strength.default_value), 1e30) or 1.0
        out["emission"] = [est] * 3
        out["_emission_mean"] = [est] * 3
        return True

    def base(self, out, key, socket_name, clamp=True):
        """A colour input Lantern textures (base colour, glass colour): out[key + '_texture']
        and the image's mean as out[key], magenta for a missing image, a node-graph program
        (its constant: the socket's own value), else the constant. clamp=False: an albedo
        alone (Diffuse, Translucent BSDF), above 1 as Cycles uses it (the core keeps it)."""
        if key == "base_color" and self.graph(out, socket_name, "base_color", 3):
            v = _socket_default(self.node.inputs[socket_name], [0.8, 0.8, 0.8], clamp)
            out[key] = [max(x, 0.0) for x in v]
            return out[key]
        tid = self.texture(socket_name, as_color=True)
        if tid == "missing":
            out[key] = list(MAGENTA)
        elif tid is not None:
            out[key + "_texture"] = tid
            img, output = _image_source(self.node.inputs[socket_name])
            mean = self.textures.mean(img, output, self.where) or [0.8, 0.8, 0.8]
            out[key] = [min(max(c, 0.0), 1.0) for c in mean]
        else:
            out[key] = self.color(socket_name, clamp)
        return out[key]

    def scalar(self, out, key, socket_name, convert):
        """A value input Lantern textures (roughness, metallic, alpha): out[key + '_texture']
        and convert(mean) as out[key], a node-graph program, else convert(constant)."""
        if key in ("roughness", "metallic", "alpha") and self.graph(out, socket_name, key, 1):
            out[key] = convert(_socket_default(self.node.inputs[socket_name], [0.5], False)[0])
            return out[key]
        tid = self.texture(socket_name, as_color=False)
        if tid is not None and tid != "missing":
            out[key + "_texture"] = tid
        out[key] = convert(self.value(socket_name, warn=False))
        return out[key]

    def emission(self, out, socket_name, strength):
        """Emission colour x strength; an image on the colour: emission_texture, the strength
        its multiplier (the image's mean x strength is kept as "_emission_mean" for shader
        mixes, which cannot texture emission). Node graphs: emission_graph."""
        tid = self.texture(socket_name, as_color=True)
        if tid is not None and tid != "missing":
            out["emission_texture"] = tid
            out["emission"] = [strength] * 3
            img, output = _image_source(self.node.inputs[socket_name])
            mean = self.textures.mean(img, output, self.where) or [1.0, 1.0, 1.0]
            out["_emission_mean"] = [max(c, 0.0) * strength for c in mean]
            return
        col = list(MAGENTA) if tid == "missing" else self.color(socket_name, clamp=False)
        out["emission"] = [c * strength for c in col]

    def normal_map(self, out, socket_name="Normal", key="normal"):
        """A tangent-space Normal Map node on the Normal input -> normal_texture, or a
        "normal_map" program where a node graph drives its Color; Object and World spaces: a
        "normal_map_world" program (node_bump.world_normal_map). Coat Normal: socket_name
        "Coat Normal", key "coat_normal" -> coat_normal_texture, tangent-space images only."""
        sock = self.node.inputs.get(socket_name)
        if sock is None or not sock.is_linked:
            return
        if key == "normal" and node_bump.is_bump(sock):   # Bump nodes: programs
            for prog in node_bump.bump_chain(
                    self.compiler, self.node, normal_map=lambda owner: _Inputs(
                        owner, self.material, self.report, self.textures).normal_map(out)):
                attach(out, prog)
            return
        src, _ = _source(sock)
        if src is None:
            return
        if src.type != "NORMAL_MAP":
            self.report.warn(f"{self.where}: '{src.name}' ({src.type}) on {socket_name} is not "
                             "supported (Normal Map nodes in tangent space are); ignored")
            return
        if getattr(src, "space", "TANGENT") != "TANGENT":   # a program gives the normal
            if key != "normal":
                self.report.warn(f"{self.where}: Normal Map '{src.name}' in {src.space} space "
                                 f"on {socket_name} is not supported (tangent space is); ignored")
                return
            prog = node_bump.world_normal_map(self.compiler, src)
            if prog is not None:
                attach(out, prog)
                strength = _constant_float(src.inputs["Strength"], self.material, self.report)
                out[key + "_strength"] = min(max(strength, 0.0), 1e3) \
                    if strength == strength else 1.0
            return
        if getattr(src, "uv_map", ""):
            self.report.warn(f"{self.where}: Normal Map '{src.name}' names UV map "
                             f"'{src.uv_map}'; the active render UV map is used")
        color = src.inputs["Color"]
        img, output = _image_source(color)
        if is_graph(color):
            # a node graph drives the colour: a "normal_map" program (its result the
            # tangent-space colour), applied where the texture would be
            if key != "normal":
                self.report.warn(f"{self.where}: Normal Map '{src.name}' on {socket_name} is "
                                 "fed by a node graph (only an Image Texture is rendered "
                                 "there); ignored")
                return
            prog = self.compiler.program(color, "normal_map", 3)
            if prog is None:
                return
            attach(out, prog)
        elif img is None or output != "color":
            if color.is_linked:
                self.report.warn(f"{self.where}: Normal Map '{src.name}' is not fed by an "
                                 "Image Texture's Color or a node graph; ignored")
            return
        else:
            tid = self.textures.add(img, "color", self.where)
            if tid is None:
                return
            out[key + "_texture"] = tid
        strength = _constant_float(src.inputs["Strength"], self.material, self.report)
        out[key + "_strength"] = min(max(strength, 0.0), 1e3) if strength == strength else 1.0


def is_graph(sock):
    """A node other than an Image Texture (directly or through Separate Color), RGB or Value
    feeds sock: material_compile handles it."""
    if sock is None or not sock.is_linked:
        return False
    img, _ = _image_source(sock)
    if img is not None:
        return not _plain_image(img)
    src, _ = _source(sock)
    return src is not None and src.type not in ("RGB", "VALUE")


def _plain_image(node):
    """An Image Texture the texture path renders exactly: flat projection, its Vector the UV
    map directly or through Mapping nodes with constant inputs and no X/Y rotation."""
    if getattr(node, "projection", "FLAT") != "FLAT":
        return False
    sock = node.inputs.get("Vector")
    for _ in range(16):
        if sock is None or not sock.is_linked:
            return True
        link = sock.links[0]
        src = link.from_node
        if src.type == "REROUTE":
            sock = src.inputs[0]
        elif src.type == "UVMAP" or (src.type == "TEX_COORD" and link.from_socket.name == "UV"):
            return True
        elif src.type == "MAPPING" and src.vector_type in ("POINT", "TEXTURE", "VECTOR"):
            rot = src.inputs.get("Rotation")
            if any(s.is_linked for s in src.inputs[1:]) or \
                    (rot is not None and (abs(rot.default_value[0]) > 1e-6 or
                                          abs(rot.default_value[1]) > 1e-6)):
                return False
            sock = src.inputs.get("Vector")
        else:
            return False
    return False


def _socket_default(sock, fallback, color):
    v = getattr(sock, "default_value", None)
    try:
        vals = [float(x) for x in v] if not isinstance(v, float) else [float(v)] * 3
    except TypeError:
        return fallback
    vals = [x if math.isfinite(x) else 0.0 for x in vals[:3]]
    return [min(max(x, 0.0), 1.0) for x in vals] if color else vals


def _turns(v):
    """A rotation in turns: NaN -> 0, wrapped into [0, 1)."""
    return float(v) % 1.0 if math.isfinite(v) else 0.0


def _weight(v, hi=1.0):
    """A weight or strength: NaN and infinities -> 0, clamped to [0, hi]."""
    return min(max(float(v), 0.0), hi) if math.isfinite(v) else 0.0


def _unit(v):
    """Roughness: NaN -> 0.5, clamped to [0, 1]."""
    return 0.5 if v != v else min(max(float(v), 0.0), 1.0)


def _ior(v):
    """IOR: NaN or <= 0 -> 1.5; clamped to [0.01, 100] (below 1 is legal: bubbles)."""
    return 1.5 if not (v > 0.0) else min(max(float(v), 0.01), 100.0)
