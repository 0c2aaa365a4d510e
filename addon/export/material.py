"""Blender materials -> Lantern materials (docs/materials.md), by the shader node at the
Material Output's Surface:

- Principled BSDF -> principled (bsdf/principled.h): sheen and coat over metal, glass and a
  dielectric specular layer (IOR, Specular IOR Level, Specular Tint, Roughness) over a diffuse
  Base Color (Lambert, or Oren-Nayar with Diffuse Roughness). Metallic 1 -> conductor (the
  same lobe, cheaper); Specular IOR Level 0 without metal or glass -> diffuse; either only
  without coat and sheen (they would be lost: difftest D16). Subsurface is
  not rendered (a warning). Emission Color x Strength in every case.
- Diffuse BSDF -> diffuse (Roughness > 0: Blender's energy-preserving Oren-Nayar);
  Translucent BSDF -> translucent; Emission -> emission; Glossy BSDF -> conductor of constant
  reflectance Color (Cycles' Glossy has no Fresnel: eta 0, k 1 scaled by Color); Metallic BSDF
  (F82) -> conductor (Base Color, Edge Tint), physical-conductor mode -> its normal-incidence
  reflectance as F0, with a warning; Glass BSDF -> dielectric (Color tints reflection and
  transmission, as Cycles); Refraction BSDF -> dielectric (its reflection included, untinted),
  with a warning.
- Mix Shader, Add Shader -> mix (Transparent BSDF leaves -> alpha); see _convert_mix.
- Anything else: grey 0.8 diffuse, with a warning naming the material and the node.
- Negative or non-finite colours read as 0, non-finite weights as 0 (a warning).

Textures (texture.py): an Image Texture feeding Base Color / Color, Roughness, Metallic or Alpha
(directly, through a Separate Color channel, or its Alpha output) is rendered as a texture; a
Normal Map node (tangent space) on Normal (and Coat Normal) as a normal map. On other inputs (emission colour,
coat, sheen, ...) the image's mean value is used, with a warning. A missing image is magenta.
Alpha < 1 (constant or textured) lets rays pass the surface (docs/materials.md)."""

import math

import bpy

from .holdout import holdout_material
from . import node_bump
from . import negative_emission
from . import node_eval as ne
from .material_compile import GraphCompiler, attach
from .texture import MAGENTA, TextureTable

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


def convert_material(material, report, textures=None, add_leaf=None):
    """The Lantern material of a Blender material. A Mix / Add Shader tree becomes a "mix" of
    leaf materials, which add_leaf(dict) -> id appends to the scene (MaterialTable does)."""
    textures = textures if textures is not None else TextureTable(report)
    out = dict(DEFAULT, name=material.name)
    tree = material.node_tree
    if bpy.app.version < (5, 0, 0) and not material.use_nodes:  # always nodes from 5.0
        tree = None
    if tree is None:
        return out
    output = next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output),
                  None) or next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL"), None)
    # Displacement and Volume outputs are named once per render by export/unsupported.py
    if output is None or not output.inputs["Surface"].is_linked:
        out["base_color"] = [0.0, 0.0, 0.0]  # no surface shader: black, as in Cycles
        return out
    node, _ = _source(output.inputs["Surface"])
    if node is None:
        out["base_color"] = [0.0, 0.0, 0.0]
        return out
    if node.type == "HOLDOUT":  # export/holdout.py
        return holdout_material(material)
    if node.type in ("MIX_SHADER", "ADD_SHADER", "BSDF_TRANSPARENT"):
        out = _convert_mix(node, material, report, textures, add_leaf)
    else:
        out = _convert_shader(node, material, report, textures)
        out.pop("_emission_mean", None)
    disp = node_bump.displacement(GraphCompiler(material, report, textures,
                                                textures.attributes), material, output)
    if disp is not None:   # the displaced surface first, then the shader's own Bump nodes
        out.setdefault("programs", []).insert(0, disp)
    return out


def _mix_leaves(socket, weight, material, report, depth=0):
    """Flatten Mix / Add Shader nodes below a shader socket: [(node, weight)], the weights
    multiplied down the tree (a Mix Shader's factor texture counts as its mean here)."""
    node, _ = _source(socket)
    if node is None or weight <= 0.0:
        return []   # an unlinked shader input is black
    if depth > 16:
        report.warn(f"Material '{material.name}': shader mixes nested too deep; cut")
        return []
    if node.type == "MIX_SHADER":
        f = _mix_factor(node, material, report)
        if is_graph(node.inputs["Fac"]):
            report.warn(f"Material '{material.name}': the node graph on the factor of nested "
                        f"Mix Shader '{node.name}' is not rendered; its own value {f:.3g} is "
                        "used (graph factors drive the top Mix Shader of two shaders)")
        return (_mix_leaves(node.inputs[1], weight * (1.0 - f), material, report, depth + 1) +
                _mix_leaves(node.inputs[2], weight * f, material, report, depth + 1))
    if node.type == "ADD_SHADER":
        return (_mix_leaves(node.inputs[0], weight, material, report, depth + 1) +
                _mix_leaves(node.inputs[1], weight, material, report, depth + 1))
    return [(node, weight)]


def _one_minus(ctx, v):
    from .node_eval import MATH_OPS
    r, _ = ctx.emit_node("math", [ctx.const((1.0,), "VALUE"), v, ctx.const((0.0,), "VALUE")],
                         1, mode=MATH_OPS.index("SUBTRACT"), flags=1)
    return ctx.reg(r, 1, "VALUE")


def _lerp_colors(ctx, f, a, b):
    """a + clamp(f, 0, 1) (b - a) for constant colours a, b: a program's colour."""
    from .node_eval import MATH_OPS, VECTOR_OPS
    f = ctx.convert(f, "VALUE")   # the program's width-3 value of the Fac socket
    r, _ = ctx.emit_node("math", [f, ctx.const((1.0,), "VALUE"), ctx.const((0.0,), "VALUE")],
                         1, mode=MATH_OPS.index("MULTIPLY"), flags=1)
    f = ctx.convert(ctx.reg(r, 1, "VALUE"), "VECTOR")
    r, _ = ctx.emit_node("vector_math", [f, ctx.const([y - x for x, y in zip(a, b)], "VECTOR"),
                                         ctx.const(a, "VECTOR"), ctx.const((0.0,), "VALUE")], 4,
                         mode=VECTOR_OPS.index("MULTIPLY_ADD"))
    return ctx.reg(r, 3, "RGBA")


def _unit_clamp(ctx, v):
    return v   # the core clamps factors and alpha to [0, 1]


def _mix_factor(node, material, report, textures=None):
    sock = node.inputs["Fac"]
    if is_graph(sock):   # a graph factor: programs where the mix allows (_convert_mix)
        v = sock.default_value
        return 0.5 if v != v else min(max(float(v), 0.0), 1.0)
    img, output = _image_source(sock)
    if img is not None and textures is not None:
        mean = textures.mean(img, output, f"Material '{material.name}'")
        if mean is not None:
            v = mean[0] if output != "color" else 0.2126 * mean[0] + 0.7152 * mean[1] + \
                0.0722 * mean[2]
            return min(max(v, 0.0), 1.0)
    v = _constant_float(sock, material, report) if img is None else 0.5
    return 0.5 if v != v else min(max(v, 0.0), 1.0)


def _convert_mix(top, material, report, textures, add_leaf):
    """Mix / Add Shader trees: Transparent BSDF leaves become the material's alpha (coverage),
    emission-only leaves its emission, the other leaves (up to 4) a "mix" material. A Mix
    Shader's image-texture factor is kept when it mixes two single shaders (or Transparent and
    one shader: an alpha texture); deeper in the tree its mean is used."""
    name = material.name
    where = f"Material '{name}'"
    if top.type == "BSDF_TRANSPARENT":
        leaves = [(top, 1.0)]
    elif top.type == "MIX_SHADER":
        f = _mix_factor(top, material, report, textures)
        leaves = (_mix_leaves(top.inputs[1], 1.0 - f, material, report, 1) +
                  _mix_leaves(top.inputs[2], f, material, report, 1))
    else:
        leaves = _mix_leaves(top.inputs[0], 1.0, material, report, 1) + \
            _mix_leaves(top.inputs[1], 1.0, material, report, 1)
    # a factor texture on the top Mix Shader between two single shaders
    fac_tex = None
    if top.type == "MIX_SHADER":
        img, output = _image_source(top.inputs["Fac"])
        a, _ = _source(top.inputs[1])
        b, _ = _source(top.inputs[2])
        single = a is not None and b is not None and \
            a.type not in ("MIX_SHADER", "ADD_SHADER") and \
            b.type not in ("MIX_SHADER", "ADD_SHADER")
        if img is None and not single and is_graph(top.inputs["Fac"]):
            report.warn(f"{where}: the node graph on the factor of Mix Shader '{top.name}' is "
                        "not rendered (graph factors mix two single shaders); its own value "
                        "is used")
        if img is None and single and is_graph(top.inputs["Fac"]) and \
                not (a.type == "BSDF_TRANSPARENT" and b.type == "BSDF_TRANSPARENT"):
            # a node graph on the factor (Fresnel, Layer Weight, noise, ...): a program
            if b.type == "BSDF_TRANSPARENT":   # Mix(X, Transparent): alpha = 1 - fac
                prog = GraphCompiler(material, report, textures, textures.attributes).program(
                    top.inputs["Fac"], "alpha", 1, post=_one_minus)
            else:
                prog = GraphCompiler(material, report, textures, textures.attributes).program(
                    top.inputs["Fac"], "alpha" if a.type == "BSDF_TRANSPARENT"
                    else "mix_factor", 1, post=_unit_clamp)
            if prog is not None:
                fac_tex = ("program", prog, a.type == "BSDF_TRANSPARENT" or
                           b.type == "BSDF_TRANSPARENT")
        if img is not None:
            if single and b.type != "BSDF_TRANSPARENT":
                tid = textures.add(img, output, where)
                fac_tex = (tid, a.type == "BSDF_TRANSPARENT")
            else:
                report.warn(f"{where}: the image texture on Mix Shader '{top.name}' Fac is "
                            "used as its mean value (textured factors mix two shaders, or "
                            "Transparent first and one shader)")
    # a graph factor between two shaders, neither Transparent: both stay leaves of a
    # two-leaf mix in order (an Emission leaf as a black one) and the emission is a program
    graph_mix = fac_tex is not None and fac_tex[0] == "program" and not fac_tex[2]
    transparent, emission, bsdf = 0.0, [0.0, 0.0, 0.0], []
    leaf_emission = []   # (unweighted emission of each leaf in order): graph_mix's program
    shader_emits = False  # an Emission shader of its own in the mix (not under any coat)
    for node, w in leaves:
        if node.type == "BSDF_TRANSPARENT":
            c = [x if math.isfinite(x) else 0.0 for x in
                 _constant_color(node.inputs["Color"], material, report)]
            if max(c) - min(c) > 1e-3:
                report.warn(f"{where}: Transparent BSDF '{node.name}' is tinted; Lantern's "
                            "transparency is untinted (its luminance is used)")
            t = min(max(0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2], 0.0), 1.0)
            transparent += w * t
            if t < 1.0:   # the untransmitted part of a grey Transparent BSDF is black
                bsdf.append(({"name": f"{name}/black", "type": "diffuse",
                              "base_color": [0.0, 0.0, 0.0]}, w * (1.0 - t)))
            continue
        leaf = _convert_shader(node, material, report, textures)
        progs = leaf.get("programs", [])
        if any(p["target"] == "emission" for p in progs):
            report.warn(f"{where}: the node graph on the emission of '{node.name}' inside a "
                        "shader mix is not rendered; its strength is used")
            leaf["programs"] = [p for p in progs if p["target"] != "emission"]
        if "emission_texture" in leaf:   # a mix's emission is constant: the image's mean
            report.warn(f"{where}: the emission image of '{node.name}' inside a shader mix is "
                        "used as its mean value")
            leaf["emission"] = leaf.pop("_emission_mean")
            leaf.pop("emission_texture")
        leaf.pop("_emission_mean", None)
        leaf_emission.append(list(leaf.get("emission", [0.0, 0.0, 0.0])))
        if node.type == "EMISSION":
            shader_emits = shader_emits or max(leaf["emission"]) > 0.0
            emission = [e + w * x for e, x in zip(emission, leaf["emission"])]
            if graph_mix:   # its share of the BSDF is black
                bsdf.append(({"name": f"{name}/black", "type": "diffuse",
                              "base_color": [0.0, 0.0, 0.0]}, w))
            continue
        emission = [e + w * x for e, x in zip(emission, leaf.get("emission", [0, 0, 0]))]
        leaf["emission"] = [0.0, 0.0, 0.0]
        if leaf.get("alpha", 1.0) < 1.0 or "alpha_texture" in leaf:
            report.warn(f"{where}: Alpha of '{node.name}' inside a shader mix is ignored "
                        "(use a Mix Shader with a Transparent BSDF)")
        leaf.pop("alpha", None)
        leaf.pop("alpha_texture", None)
        leaf["name"] = f"{name}/{node.name}"
        bsdf.append((leaf, w))
    alpha = min(max(1.0 - transparent, 0.0), 1.0)
    opaque = sum(w for _, w in bsdf)
    if fac_tex is None and transparent > 1.0 - 1e-6 and opaque > 1e-6:
        # Transparent BSDF weight t >= 1 beside BSDFs of weight W (an Add Shader): Cycles
        # passes rays with weight t and scatters W, more than one surface can (t + W > 1).
        # Coverage passes rays with weight 1 only, so the surface is normalised to t + W: the
        # share t / (t + W) of rays passes and the rest scatters the BSDFs at their own
        # weights (scale below). Passed light is then 1 / (t + W) of Cycles'; where alpha
        # would be 0 the BSDFs were dropped before (difftest D8: black, -100 %). Exact needs
        # a pass weight in the core's alpha test (docs/materials.md).
        alpha = opaque / (transparent + opaque)
        report.warn(f"{where}: Transparent BSDF of weight {transparent:.3g} added to shaders "
                    f"of weight {opaque:.3g}: light passing the surface is rendered "
                    f"{1.0 / (transparent + opaque):.3g} x as bright (Lantern's transparency "
                    "passes at most all rays)")
    prog = None
    if fac_tex is not None and fac_tex[0] == "program":   # a node-graph factor
        prog, transparent_leaf = fac_tex[1], fac_tex[2]
        fac_tex = None
        if transparent_leaf:    # the program is the alpha; what stops a ray is all X
            alpha = 1.0
            bsdf = [(leaf, 1.0) for leaf, _ in bsdf]
    if fac_tex is not None and fac_tex[1]:  # Mix(Transparent, X, fac): alpha = fac, textured;
        alpha = 1.0                         # where it stops a ray, the surface is all X
        bsdf = [(leaf, 1.0) for leaf, _ in bsdf]
    out = dict(DEFAULT, name=name)
    if len(bsdf) > 4:
        report.warn(f"{where}: {len(bsdf)} shaders mixed; Lantern keeps the 4 of largest weight")
        bsdf = sorted(bsdf, key=lambda lw: -lw[1])[:4]
    scale = 1.0 / alpha if alpha > 0.0 else 0.0   # what stops a ray carries the whole surface
    normals = [leaf for leaf, _ in bsdf if "normal_texture" in leaf]
    if len(normals) > 1 and len({(x["normal_texture"], x.get("normal_strength", 1.0))
                                 for x in normals}) > 1:
        report.warn(f"{where}: mixed shaders with different normal maps; the first is used")
    if not bsdf:
        out.update(base_color=[0.0, 0.0, 0.0])
    elif len(bsdf) == 1 and abs(bsdf[0][1] * scale - 1.0) < 1e-6 and \
            (fac_tex is None or fac_tex[1]) and \
            not (shader_emits and _layered(bsdf[0][0])):
        # one shader: no mix needed (but an Emission shader beside a Principled with a coat or
        # sheen stays a mix of one leaf: the core dims a Principled's own emission under its
        # layers, and Cycles does not dim a separate Emission closure; difftest ci seed 16)
        out = dict(bsdf[0][0], name=name)
    else:
        if add_leaf is None:
            raise ValueError("convert_material: a shader mix needs add_leaf")
        out = {"name": name, "type": "mix",
               "mix": [[add_leaf(leaf), w * scale] for leaf, w in bsdf]}
        if fac_tex is not None and not fac_tex[1] and len(bsdf) == 2:
            out["mix_texture"] = fac_tex[0]
            out["mix"] = [[out["mix"][0][0], 0.5], [out["mix"][1][0], 0.5]]
    if prog is not None:
        if prog["target"] == "mix_factor" and out.get("type") == "mix" and len(out["mix"]) == 2:
            out["mix"] = [[out["mix"][0][0], 0.5], [out["mix"][1][0], 0.5]]
            attach(out, prog)
            if len(leaf_emission) == 2 and any(max(e) > 0.0 for e in leaf_emission):
                # the leaves' emission mixed by the same factor, (1 - f) E_a + f E_b (Cycles
                # clamps the factor to [0, 1]); the constant, for light selection only, is
                # their mean, so that a leaf that emits anywhere makes the mesh a light
                ea, eb = leaf_emission
                attach(out, GraphCompiler(material, report, textures, textures.attributes)
                       .program(top.inputs["Fac"], "emission", 3,
                                post=lambda ctx, v: _lerp_colors(ctx, v, ea, eb)))
                emission = [0.5 * (x + y) for x, y in zip(ea, eb)]
        elif prog["target"] == "alpha":
            attach(out, prog)
        else:   # an emission leaf takes its share of the factor's own value
            report.warn(f"{where}: the node graph on the factor of Mix Shader '{top.name}' is "
                        "not rendered (graph factors mix two BSDFs, or a BSDF and "
                        "Transparent); its own value is used")
    node_bump.hoist(out, [leaf for leaf, _ in bsdf], report, where)
    if normals:
        out["normal_texture"] = normals[0]["normal_texture"]
        out["normal_strength"] = normals[0].get("normal_strength", 1.0)
    out["emission"] = [e * scale for e in emission]
    out["alpha"] = alpha
    if fac_tex is not None and fac_tex[1]:
        out["alpha_texture"] = fac_tex[0]
    return out


def _convert_shader(node, material, report, textures):
    """One shader node (not a mix) -> a Lantern material dict."""
    out = dict(DEFAULT, name=material.name)
    name = material.name
    inputs = _Inputs(node, material, report, textures)
    color, value = inputs.color, inputs.value

    # GGX energy compensation: Blender's "Multiscatter GGX" (the default); plain "GGX" has none
    if getattr(node, "distribution", "MULTI_GGX") in ("GGX", "BECKMANN", "ASHIKHMIN_SHIRLEY"):
        out["multiscatter"] = False
        if node.distribution != "GGX":
            report.warn(f"Material '{name}': {node.distribution} distribution rendered as GGX")
    if node.type in ("BSDF_PRINCIPLED", "BSDF_DIFFUSE", "BSDF_GLOSSY", "BSDF_METALLIC",
                     "BSDF_GLASS", "BSDF_REFRACTION", "BSDF_TRANSLUCENT"):
        inputs.normal_map(out)
    if node.type == "BSDF_PRINCIPLED":
        base = inputs.base(out, "base_color", "Base Color")
        if not inputs.emission_graph(out, "Emission Color", "Emission Strength"):
            negative_emission.check_constant(report, inputs.where, "Emission Strength",
                                             value("Emission Strength"))
            strength = _weight(value("Emission Strength"), 1e30)
            if strength != 0.0:
                inputs.emission(out, "Emission Color", strength)
        roughness = inputs.scalar(out, "roughness", "Roughness", _unit)
        if "Diffuse Roughness" in node.inputs:   # Blender >= 4.3: Oren-Nayar base
            out["diffuse_roughness"] = _weight(value("Diffuse Roughness"))
        metallic = inputs.scalar(out, "metallic", "Metallic", _weight)
        # a texture or a node graph drives Metallic: the principled type whatever the
        # socket's own value (the conductor has no metallic input)
        metal_tex = "metallic_texture" in out or \
            any(p["target"] == "metallic" for p in out.get("programs", []))
        inputs.scalar(out, "alpha", "Alpha", lambda v: min(max(v, 0.0), 1.0) if v == v else 1.0)
        aniso = _weight(value("Anisotropic"))
        if aniso > 0.0:
            out.update(anisotropy=aniso,
                       anisotropic_rotation=_turns(value("Anisotropic Rotation")),
                       tangent=_tangent_mode(node, material, report, out, textures))
        transmission = _weight(value("Transmission Weight"))
        level = value("Specular IOR Level")
        level = 0.5 if level != level else min(max(level, 0.0), 1e3)
        film = _weight(value("Thin Film Thickness"), 1e5) \
            if "Thin Film Thickness" in node.inputs else 0.0   # Blender >= 4.2
        if film > 0.0:   # on the specular layer and the metal (not the glass)
            out.update(thin_film_thickness=film,
                       thin_film_ior=max(_ior(value("Thin Film IOR")), 1.0))
        if not (metallic > 0.0 or metal_tex or transmission > 0.0):
            # no metal or glass reads the base colour: an albedo alone, which Cycles does not
            # clamp above 1 (the core keeps it: kAlbedoBase)
            sock = node.inputs["Base Color"]
            if any(p["target"] == "base_color" for p in out.get("programs", [])):
                base = [max(x, 0.0) for x in _socket_default(sock, base, False)]
            elif "base_color_texture" not in out and _image_source(sock)[0] is None:
                base = color("Base Color", clamp=False)
            out["base_color"] = base
        coat = _weight(value("Coat Weight"))
        sheen = _weight(value("Sheen Weight"), 1e3)
        layered = coat > 0.0 or sheen > 0.0   # the simpler types have no coat or sheen
        if metallic >= 0.999 and not metal_tex and not layered:  # the metal lobe alone: the
            out.pop("metallic")                                  # cheaper conductor
            out.update(type="conductor", base_color=base,
                       specular_tint=color("Specular Tint"), roughness=roughness)
        elif level > 0.0 or metallic > 0.0 or transmission > 0.0 or metal_tex or layered:
            out.update(type="principled", base_color=base,
                       specular_tint=color("Specular Tint"), roughness=roughness,
                       ior=_ior(value("IOR")), metallic=metallic, transmission=transmission,
                       specular_level=min(level, 1e3))
            if coat > 0.0:
                out.update(coat_weight=coat, coat_roughness=_unit(value("Coat Roughness")),
                           coat_ior=max(_ior(value("Coat IOR")), 1.0),
                           coat_tint=color("Coat Tint"))
                inputs.normal_map(out, "Coat Normal", "coat_normal")
            if sheen > 0.0:
                out.update(sheen_weight=sheen, sheen_roughness=_unit(value("Sheen Roughness")),
                           sheen_tint=color("Sheen Tint"))
        else:  # Specular IOR Level 0, no metal, no glass: exactly Lambert (the diffuse type)
            out.pop("roughness_texture", None)
            out.pop("metallic")
        _principled_unsupported(node, material, report)
    elif node.type == "BSDF_DIFFUSE":
        inputs.base(out, "base_color", "Color", clamp=False)
        out["diffuse_roughness"] = _weight(value("Roughness"))
    elif node.type == "EMISSION":
        out["base_color"] = [0.0, 0.0, 0.0]
        if not inputs.emission_graph(out, "Color", "Strength"):
            negative_emission.check_constant(report, inputs.where, "Strength", value("Strength"))
            inputs.emission(out, "Color", _weight(value("Strength"), 1e30))
    elif node.type == "BSDF_GLOSSY":
        # Cycles' Glossy has no Fresnel: a constant reflectance Color at every angle, which is
        # the conductor of index 0 + 1i (F = 1) scaled by the colour
        inputs.base(out, "base_color", "Color")
        out.update(type="conductor", eta=[0.0, 0.0, 0.0], k=[1.0, 1.0, 1.0])
        inputs.scalar(out, "roughness", "Roughness", _unit)
        _glossy_anisotropy(node, out, inputs, material, report)
    elif node.type == "BSDF_METALLIC":
        out.update(type="conductor")
        inputs.scalar(out, "roughness", "Roughness", _unit)
        _glossy_anisotropy(node, out, inputs, material, report)
        if getattr(node, "fresnel_type", "F82") == "F82":
            inputs.base(out, "base_color", "Base Color")
            out.update(specular_tint=color("Edge Tint"))
        else:
            n = _constant_color(node.inputs["IOR"], material, report)
            k = _constant_color(node.inputs["Extinction"], material, report)
            f0 = [((a - 1) ** 2 + b * b) / ((a + 1) ** 2 + b * b) for a, b in zip(n, k)]
            out.update(base_color=[min(max(f, 0.0), 1.0) for f in f0],
                       specular_tint=[1.0, 1.0, 1.0])
            report.warn(f"Material '{name}': Metallic BSDF in physical-conductor mode is "
                        f"approximated by its normal-incidence reflectance (F82 tint white)")
    elif node.type == "BSDF_TRANSLUCENT":
        out["type"] = "translucent"
        inputs.base(out, "base_color", "Color", clamp=False)
    elif node.type in ("BSDF_GLASS", "BSDF_REFRACTION"):
        inputs.base(out, "base_color", "Color")
        # Glass: Color tints reflection and transmission (Cycles), Refraction: transmission
        out.update(type="dielectric", ior=_ior(value("IOR")),
                   tint_reflection=node.type == "BSDF_GLASS")
        inputs.scalar(out, "roughness", "Roughness", _unit)
        if node.type == "BSDF_REFRACTION":
            report.warn(f"Material '{name}': Refraction BSDF rendered as glass (its Fresnel "
                        f"reflection included)")
    else:
        report.warn(f"Material '{name}': shader node '{node.name}' ({node.type}) is not "
                    "supported yet; rendering grey diffuse instead")
    return out


def _layered(leaf):
    """A Principled leaf with a coat or sheen: its own emission is under them."""
    return leaf.get("type") == "principled" and (leaf.get("coat_weight", 0.0) > 0.0 or
                                                 leaf.get("sheen_weight", 0.0) > 0.0)


def _principled_unsupported(node, material, report):
    """Warnings for the Principled inputs Lantern renders by a documented fallback."""
    name = material.name

    def val(key):
        sock = node.inputs.get(key)
        if sock is None:
            return 0.0
        v = _constant_float(sock, material, report) if not sock.is_linked else 1.0
        return v if math.isfinite(v) else 0.0
    if val("Subsurface Weight") > 0.0:
        report.warn(f"Material '{name}': Subsurface Weight is rendered as the diffuse base "
                    "(no subsurface scattering)")
    if val("Thin Film Thickness") > 0.0 and val("Transmission Weight") > 0.0 and \
            val("Metallic") < 1.0:
        report.warn(f"Material '{name}': Thin Film is rendered on the specular layer and the "
                    "metal, not on the glass part (it refracts and reflects without interference)")


def _turns(v):
    """A rotation in turns: NaN -> 0, wrapped into [0, 1)."""
    return float(v) % 1.0 if math.isfinite(v) else 0.0


def _tangent_mode(node, material, report, out=None, textures=None):
    """The anisotropy tangent of a shader node: the UV map's (MikkTSpace) for a Tangent node
    in UV Map mode (meshes without UVs: each triangle's first minus third vertex); Cycles'
    radial tangent for an unlinked Tangent input (its default: radial about the object's Z
    axis) and for a Tangent node in Radial mode, as a "tangent" program attached to out."""
    sock = node.inputs.get("Tangent")
    src = None
    if sock is not None and sock.is_linked:
        src, _ = _source(sock)
    if src is not None and src.type == "TANGENT" and src.direction_type == "UV_MAP":
        if getattr(src, "uv_map", ""):
            report.warn(f"Material '{material.name}': Tangent node '{src.name}' names UV map "
                        f"'{src.uv_map}'; the active render UV map is used")
        return "uv"
    axis = None
    if src is None:
        axis = "Z"
    elif src.type == "TANGENT" and src.direction_type == "RADIAL":
        axis = src.axis
    if axis is not None and out is not None and textures is not None:
        prog = _radial_tangent(GraphCompiler(material, report, textures, textures.attributes),
                               axis)
        if prog is not None:
            attach(out, prog)
            return "uv"
    report.warn(f"Material '{material.name}': '{getattr(src, 'name', '?')}' on Tangent is not "
                "supported (a Tangent node in UV Map mode is); the UV tangent is used")
    return "uv"


def _radial_tangent(compiler, axis):
    """Cycles' radial tangent (its Tangent node, and an unlinked Tangent input: axis Z): the
    object-space direction about `axis` through the point's Generated coordinates less 1/2,
    axis x (g - 1/2) (Cycles' own up to sign, which anisotropy does not see), taken to the
    world by the object's normal matrix (per-instance attribute channels, as
    node_bump.world_normal_map); the core projects it onto the shading plane."""
    from .material_compile import Builder, NodeContext
    ops = ne.VECTOR_OPS
    b = Builder()
    ctx = NodeContext(compiler, b)
    zero, nil = ctx.const((0.0, 0.0, 0.0), "VECTOR"), ctx.const((0.0,), "VALUE")
    a = ctx.const(tuple(1.0 if c == axis else 0.0 for c in "XYZ"), "VECTOR")
    r, _ = ctx.emit_node("vector_math", [ctx.attribute("generated"),
                                         ctx.const((0.5, 0.5, 0.5), "VECTOR"), zero, nil], 4,
                         mode=ops.index("SUBTRACT"))
    r, _ = ctx.emit_node("vector_math", [a, ctx.reg(r, 3, "VECTOR"), zero, nil], 4,
                         mode=ops.index("CROSS_PRODUCT"))
    t = ctx.reg(r, 3, "VECTOR")
    rows = []
    for c in "xyz":   # world component = the normal matrix's row . t
        d, _ = ctx.emit_node("vector_math", [ctx.attribute(f"object_normal_{c}"), t, zero, nil],
                             4, mode=ops.index("DOT_PRODUCT"))
        rows.append(ctx.reg(d + 3, 1, "VALUE"))
    c, _ = ctx.emit_node("combine", rows, 3, mode=0)
    return b.finish(ctx.reg(c, 3, "VECTOR"), "tangent")


def _glossy_anisotropy(node, out, inputs, material, report):
    """Glossy / Metallic BSDF Anisotropy in [-1, 1]: positive stretches highlights across the
    tangent, negative along it (Blender's manual). Expressed in the Principled convention
    Lantern stores (alpha_x / alpha_y = 1 / (1 - 0.9 b) along the tangent): the same alpha
    ratio 1 / (1 - |a|)^2, the tangent turned a quarter for positive values. The magnitude
    mapping is Lantern's reading of Cycles' Glossy anisotropy, to be checked against Cycles
    renders (docs/materials.md)."""
    if "Anisotropy" not in node.inputs:
        return
    a = inputs.value("Anisotropy")
    if not math.isfinite(a) or abs(a) < 1e-4:
        return
    a = min(max(a, -0.99), 0.99)
    b = min((1.0 - (1.0 - abs(a)) ** 2) / 0.9, 1.0)
    rotation = _turns(inputs.value("Rotation")) + (0.25 if a > 0 else 0.0)
    out.update(anisotropy=b, anisotropic_rotation=rotation % 1.0,
               tangent=_tangent_mode(node, material, report, out, inputs.textures))


def _weight(v, hi=1.0):
    """A weight or strength: NaN and infinities -> 0, clamped to [0, hi]."""
    return min(max(float(v), 0.0), hi) if math.isfinite(v) else 0.0


def _unit(v):
    """Roughness: NaN -> 0.5, clamped to [0, 1]."""
    return 0.5 if v != v else min(max(float(v), 0.0), 1.0)


def _ior(v):
    """IOR: NaN or <= 0 -> 1.5; clamped to [0.01, 100] (below 1 is legal: bubbles)."""
    return 1.5 if not (v > 0.0) else min(max(float(v), 0.01), 100.0)


class MaterialTable:
    """Unique Lantern materials by Blender material; index 0 is the default material (Blender's
    default surface, DEFAULT_SURFACE)."""

    def __init__(self, report, texture_cache=None):
        self.report = report
        self.materials = [dict(DEFAULT_SURFACE)]
        self._index = {}
        self.texture_table = TextureTable(report, texture_cache)

    @property
    def textures(self):
        return self.texture_table.textures

    @property
    def attributes(self):
        return self.texture_table.attributes

    def index(self, material):
        if material is None:
            return 0
        key = material.name_full
        if key not in self._index:
            slot = len(self.materials)
            self._index[key] = slot
            self.materials.append(None)   # the slot, before any mix leaves are appended
            self.materials[slot] = convert_material(material, self.report, self.texture_table,
                                                    self._add_leaf)
        return self._index[key]

    def _add_leaf(self, leaf):
        self.materials.append(leaf)
        return len(self.materials) - 1
