"""Image Texture nodes -> Lantern textures (docs/materials.md, "Textures").

Pixels come from `Image.pixels.foreach_get` (never per pixel); 8-bit images stay 8-bit
(sRGB-encoded colour or linear data by the image's colour space), float images are scene
linear float32. An image is read once per export however many nodes use it. The node's
extension (repeat, extend, clip, mirror) and interpolation (Closest, or Linear; Cubic and Smart
render as Linear) travel with the texture, and so does a Mapping node on its Vector input
(2D: location, Z rotation, scale). An image that cannot be read renders magenta, as in Cycles."""

import math

import numpy as np

from .node_attributes import AttributeTable

MAGENTA = [1.0, 0.0, 1.0]

_LINEAR_SPACES = {"Non-Color", "Linear", "Linear Rec.709", "Raw", "Linear CIE-XYZ E",
                  "Linear CIE-XYZ D65", "Generic Data", "Utility - Raw"}
_EXTENSIONS = {"REPEAT": "repeat", "EXTEND": "extend", "CLIP": "clip", "MIRROR": "mirror"}
IDENTITY_UV = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))


def mapping_constant(node, name, where, report):
    """The constant value of a Mapping node's input `name` (None if it has none); a linked
    input is named in a warning and its own value used."""
    sock = node.inputs.get(name)
    if sock is None:
        return None
    if sock.is_linked:
        report.warn(f"{where}: the Mapping node '{node.name}' has a linked {name}; its "
                    "constant value is used")
    return [float(x) for x in sock.default_value]


def _mapping_transform(node, where, report):
    """The 2D affine uv transform of a Mapping node with constant inputs, or None."""
    def const(name):
        return mapping_constant(node, name, where, report)

    kind = getattr(node, "vector_type", "POINT")
    loc = const("Location") or [0.0, 0.0, 0.0]
    rot = const("Rotation") or [0.0, 0.0, 0.0]
    scale = const("Scale") or [1.0, 1.0, 1.0]
    if abs(rot[0]) > 1e-6 or abs(rot[1]) > 1e-6:
        report.warn(f"{where}: Mapping node '{node.name}' rotates about X or Y; only its Z "
                    "rotation applies to image textures")
    c, s = math.cos(rot[2]), math.sin(rot[2])
    sx, sy = scale[0], scale[1]
    if kind == "POINT":      # R (S v) + L
        return ((c * sx, -s * sy, loc[0]), (s * sx, c * sy, loc[1]))
    if kind == "VECTOR":     # R (S v)
        return ((c * sx, -s * sy, 0.0), (s * sx, c * sy, 0.0))
    if kind == "TEXTURE":    # the inverse of POINT: S^-1 R^-1 (v - L)
        if abs(sx) < 1e-12 or abs(sy) < 1e-12:
            report.warn(f"{where}: Mapping node '{node.name}' has a zero scale; ignored")
            return None
        a = ((c / sx, s / sx), (-s / sy, c / sy))
        return ((a[0][0], a[0][1], -(a[0][0] * loc[0] + a[0][1] * loc[1])),
                (a[1][0], a[1][1], -(a[1][0] * loc[0] + a[1][1] * loc[1])))
    report.warn(f"{where}: Mapping node '{node.name}' of type {kind} is not supported for "
                "image textures; ignored")
    return None


def _compose(outer, inner):
    """outer(inner(uv)) for 2x3 affine transforms."""
    o, i = outer, inner
    return tuple(tuple(o[r][0] * i[0][k] + o[r][1] * i[1][k] + (o[r][2] if k == 2 else 0.0)
                       for k in range(3)) for r in range(2))


def uv_transform(node, where, report):
    """The uv transform of an Image Texture node from what feeds its Vector input."""
    sock = node.inputs.get("Vector")
    xf = IDENTITY_UV
    seen = 0
    while sock is not None and sock.is_linked and seen < 8:
        seen += 1
        link = sock.links[0]
        src = link.from_node
        if src.type == "MAPPING":
            m = _mapping_transform(src, where, report)
            if m is not None:
                xf = _compose(xf, m)
            sock = src.inputs.get("Vector")
        elif src.type == "UVMAP":
            uv = getattr(src, "uv_map", "")
            if uv:
                report.warn(f"{where}: UV Map node '{src.name}' names '{uv}'; Lantern uses the "
                            "mesh's active render UV map")
            break
        elif src.type == "TEX_COORD" and link.from_socket.name == "UV":
            break
        elif src.type == "REROUTE":
            sock = src.inputs[0]
        else:
            report.warn(f"{where}: '{src.name}' ({src.type}) feeding the Vector input of "
                        f"'{node.name}' is not supported; the UV map is used")
            break
    return xf


class TextureTable:
    """Lantern textures of one export, deduplicated by image and sampling settings; pixels are
    read once per image."""

    def __init__(self, report, cache=None):
        self.report = report
        self.textures = []
        self._index = {}
        self._pixels = {}
        self.attributes = AttributeTable(report)   # what node graphs read per vertex
        # pixels kept between viewport exports: by image name, valid while the image's stamp
        # (size, format, colour space, file, dirty flag) is unchanged and no depsgraph update
        # named the image (engine.view_update drops those)
        self._cache = cache

    @staticmethod
    def _stamp(image):
        return (tuple(image.size), int(image.channels), bool(image.is_float),
                image.colorspace_settings.name, image.filepath_raw, image.source,
                getattr(image, "alpha_mode", ""), bool(image.is_dirty), bool(image.packed_file))

    def _read(self, image, where):
        """(pixels, colorspace) of a Blender image, or None when it cannot be read."""
        key = image.name_full
        if key in self._pixels:
            return self._pixels[key]
        if self._cache is not None:
            hit = self._cache.get(key)
            try:
                stamp = self._stamp(image)
            except (RuntimeError, ReferenceError):
                stamp = None
            if hit is not None and stamp is not None and hit[0] == stamp:
                self._pixels[key] = hit[1]
                return hit[1]
        result = None
        try:
            if image.source in {"MOVIE", "SEQUENCE"}:
                self.report.warn(f"{where}: image '{image.name}' is a {image.source.lower()}; "
                                 "its current frame is used")
            if image.source == "TILED":
                self.report.warn(f"{where}: image '{image.name}' has UDIM tiles; only its "
                                 "first tile is used")
            w, h = int(image.size[0]), int(image.size[1])
            ch = int(image.channels)
            if w > 0 and h > 0 and ch in (1, 2, 3, 4):
                buf = np.empty(w * h * ch, np.float32)
                image.pixels.foreach_get(buf)
                buf = buf.reshape(h, w, ch)
                if ch < 3:  # grey (+ alpha)
                    grey = buf[..., :1]
                    alpha = buf[..., 1:2] if ch == 2 else np.ones_like(grey)
                    buf = np.concatenate([grey, grey, grey, alpha], axis=2)
                elif ch == 3:
                    buf = np.concatenate([buf, np.ones((h, w, 1), np.float32)], axis=2)
                if getattr(image, "alpha_mode", "STRAIGHT") == "NONE":
                    buf[..., 3] = 1.0
                space = image.colorspace_settings.name
                if image.is_float:
                    result = (np.ascontiguousarray(buf, np.float32), "linear")
                else:
                    if space == "sRGB":
                        cs = "srgb"
                    elif space in _LINEAR_SPACES:
                        cs = "linear"
                    else:
                        cs = "srgb"
                        self.report.warn(f"{where}: image '{image.name}' is in colour space "
                                         f"'{space}'; read as sRGB")
                    q = np.rint(np.clip(np.nan_to_num(buf), 0.0, 1.0) * 255.0).astype(np.uint8)
                    result = (np.ascontiguousarray(q), cs)
        except (RuntimeError, ReferenceError, ValueError) as e:
            self.report.warn(f"{where}: image '{image.name}' could not be read ({e})")
            result = None
        self._pixels[key] = result
        if self._cache is not None and result is not None:
            try:
                self._cache[key] = (self._stamp(image), result)
            except (RuntimeError, ReferenceError):
                pass
        return result

    def add_raw(self, node, where):
        """Texture id of an Image Texture node for a node-graph program (material_compile):
        no uv transform (the program computes the coordinates), or None when missing."""
        return self.add(node, "color", where, raw=True)

    def add(self, node, output, where, raw=False):
        """Texture id for an Image Texture node read through `output` ("color", "alpha",
        "red", "green", "blue"), or None when its image is missing (a warning says so)."""
        image = node.image
        if image is None:
            self.report.warn(f"{where}: Image Texture '{node.name}' has no image; magenta")
            return None
        got = self._read(image, where)
        if got is None:
            self.report.warn(f"{where}: image '{image.name}' of '{node.name}' is missing or "
                             f"unreadable ({image.filepath or 'no file'}); magenta, as Cycles")
            return None
        pixels, colorspace = got
        interp = getattr(node, "interpolation", "Linear")
        if interp in ("Cubic", "Smart"):
            self.report.warn(f"{where}: '{node.name}' uses {interp} interpolation; rendered "
                             "as Linear")
        if getattr(node, "projection", "FLAT") != "FLAT" and not raw:
            self.report.warn(f"{where}: '{node.name}' uses {node.projection} projection; "
                             "rendered as Flat")
        wrap = _EXTENSIONS.get(getattr(node, "extension", "REPEAT"), "repeat")
        xf = IDENTITY_UV if raw else uv_transform(node, where, self.report)
        key = (image.name_full, wrap, interp == "Closest", output, xf)
        if key not in self._index:
            self._index[key] = len(self.textures)
            self.textures.append({
                "name": image.name, "pixels": pixels, "colorspace": colorspace, "wrap": wrap,
                "interpolation": "closest" if interp == "Closest" else "linear",
                "output": output, "uv_transform": [list(xf[0]), list(xf[1])]})
        return self._index[key]

    def mean(self, node, output, where):
        """The mean value of an Image Texture node's image (for inputs Lantern cannot texture):
        an RGB list, or None when the image is missing."""
        if node.image is None:
            return None
        got = self._read(node.image, where)
        if got is None:
            return None
        pixels, colorspace = got
        v = pixels.reshape(-1, 4).astype(np.float64)
        if pixels.dtype == np.uint8:
            v /= 255.0
            if colorspace == "srgb":
                v[:, :3] = np.where(v[:, :3] <= 0.04045, v[:, :3] / 12.92,
                                    ((v[:, :3] + 0.055) / 1.055) ** 2.4)
        m = v.mean(axis=0)
        if output == "alpha":
            return [float(m[3])] * 3
        return [float(m[0]), float(m[1]), float(m[2])]
