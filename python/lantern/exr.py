"""OpenEXR with named channels and header metadata, for render-farm chunks and multilayer files:
`write_exr(path, channels, metadata)` and `read_exr(path) -> ExrImage`.

Channels are (H, W) float arrays by name ("R", "G", "B", or Blender's multilayer
"ViewLayer.Combined.R", ...); metadata are header attributes (str, int or float; Lantern's own
start with "lantern."). OpenImageIO is used when it imports, else the built-in codec: scanline,
single part (write: none/zip/zips; read: none/rle/zip/zips, half/float/uint channels)."""

import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

EXR_MAGIC = 20000630
EXR_COMPRESSIONS = {0: "none", 1: "rle", 2: "zips", 3: "zip", 4: "piz", 5: "pxr24",
                    6: "b44", 7: "b44a", 8: "dwaa", 9: "dwab", 10: "htj2k256", 11: "htj2k32"}
EXR_LINES_PER_CHUNK = {0: 1, 1: 1, 2: 1, 3: 16}  # what the built-in codec handles
EXR_PIXEL_TYPES = {0: np.dtype("<u4"), 1: np.dtype("<f2"), 2: np.dtype("<f4")}
# header attributes every file has: not metadata
_STANDARD = {"channels", "compression", "dataWindow", "displayWindow", "lineOrder",
             "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth", "chunkCount",
             "openexr:lineOrder", "PixelAspectRatio", "oiio:subimages", "oiio:subimagename",
             "oiio:ColorSpace", "XResolution", "YResolution", "ResolutionUnit", "name",
             "DateTime"}


@dataclass
class ExrImage:
    """Channels in file order, (H, W) float32 each; metadata by attribute name."""
    channels: dict
    metadata: dict = field(default_factory=dict)

    @property
    def shape(self):
        first = next(iter(self.channels.values()))
        return first.shape


def _check_channels(channels):
    if not channels:
        raise ValueError("an EXR needs at least one channel")
    shapes = {np.shape(v) for v in channels.values()}
    if len(shapes) != 1 or len(next(iter(shapes))) != 2:
        raise ValueError(f"EXR channels must be (H, W) arrays of one shape, got {shapes}")
    h, w = next(iter(shapes))
    if h < 1 or w < 1:
        raise ValueError(f"empty image ({h}, {w})")
    return h, w


def _check_metadata(metadata):
    out = {}
    for k, v in (metadata or {}).items():
        if isinstance(v, (bool, np.bool_)):
            v = int(v)
        if isinstance(v, (np.integer, int)) and -2**31 <= int(v) < 2**31:
            out[str(k)] = int(v)
        elif isinstance(v, (np.floating, float)):
            out[str(k)] = float(v)
        else:  # large integers (64-bit seeds) and everything else as text
            out[str(k)] = str(v)
    return out


def write_exr(path, channels, metadata=None, half=False, compression="zip", oiio=None):
    """Write `channels` (name -> (H, W) array) with header `metadata`; `oiio`: the OpenImageIO
    module to write with, or None for the built-in codec."""
    h, w = _check_channels(channels)
    meta = _check_metadata(metadata)
    if compression not in ("none", "zip", "zips"):
        raise ValueError(f"compression must be none, zip or zips, got {compression!r}")
    names = list(channels)
    with np.errstate(over="ignore"):  # beyond half range -> inf, as OpenEXR does
        planes = [np.asarray(channels[n], np.float32).astype(np.float16 if half else np.float32)
                  for n in names]
    if oiio is None:
        _builtin_write(Path(path), names, planes, meta, half, compression)
        return
    spec = oiio.ImageSpec(w, h, len(names), "half" if half else "float")
    spec.channelnames = tuple(names)
    spec.attribute("compression", compression)
    for k, v in meta.items():
        spec.attribute(k, v)
    out = oiio.ImageOutput.create(str(path))
    if out is None:
        raise OSError(f"{path}: OpenImageIO cannot write this format: {oiio.geterror()}")
    if not out.open(str(path), spec):
        raise OSError(f"{path}: cannot open for writing: {out.geterror()}")
    ok = out.write_image(np.ascontiguousarray(np.stack(planes, axis=2)))
    out.close()
    if not ok:
        raise OSError(f"{path}: write failed: {out.geterror()}")


def read_exr(path, oiio=None):
    """Every channel and the metadata of an EXR's first part."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"image not found: {path}")
    if oiio is None:
        return _builtin_read(path)
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise OSError(f"{path}: cannot read: {oiio.geterror()}")
    try:
        spec = inp.spec()
        data = inp.read_image(0, 0, 0, spec.nchannels, "float")
        if data is None:
            raise OSError(f"{path}: cannot read: {inp.geterror()}")
        names = list(spec.channelnames)
        meta = {a.name: a.value for a in spec.extra_attribs if a.name not in _STANDARD}
    finally:
        inp.close()
    data = np.asarray(data, np.float32).reshape(spec.height, spec.width, spec.nchannels)
    return ExrImage({n: np.ascontiguousarray(data[:, :, c]) for c, n in enumerate(names)}, meta)


# ---- Built-in codec ----

def _attr(name, type_name, payload):
    return (name.encode() + b"\0" + type_name.encode() + b"\0"
            + struct.pack("<i", len(payload)) + payload)


def _meta_attr(name, value):
    if isinstance(value, int):
        return _attr(name, "int", struct.pack("<i", value))
    if isinstance(value, float):
        return _attr(name, "float", struct.pack("<f", value))
    return _attr(name, "string", value.encode())


def _zip_predict(raw):
    """OpenEXR's zip pre-filter: split even/odd bytes, then byte deltas (+128)."""
    b = np.frombuffer(raw, dtype=np.uint8)
    t = np.concatenate([b[0::2], b[1::2]])
    d = t.copy()
    d[1:] = (t[1:].astype(np.int16) - t[:-1].astype(np.int16) + 128).astype(np.uint8)
    return d.tobytes()


def _zip_unpredict(data):
    t = np.frombuffer(data, dtype=np.uint8).astype(np.uint64)
    if t.size:
        t[1:] -= 128
        t = (np.cumsum(t) & 0xFF).astype(np.uint8)
    else:
        t = t.astype(np.uint8)
    half = (t.size + 1) // 2
    out = np.empty(t.size, dtype=np.uint8)
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return out.tobytes()


def _rle_decode(data, expected):
    """OpenEXR RLE: a signed count byte; c < 0: -c literal bytes follow; else one byte
    repeated c + 1 times."""
    out = bytearray()
    src = memoryview(data)
    i, n = 0, len(src)
    while i < n:
        c = src[i] - 256 if src[i] > 127 else src[i]
        if c < 0:
            out += src[i + 1:i + 1 - c]
            i += 1 - c
        else:
            out += bytes([src[i + 1]]) * (c + 1)
            i += 2
        if len(out) > expected:
            break
    return bytes(out)


def _builtin_write(path, names, planes, meta, half, compression):
    h, w = planes[0].shape
    ptype = 1 if half else 2
    dtype = EXR_PIXEL_TYPES[ptype]
    comp = {"none": 0, "zips": 2, "zip": 3}[compression]
    lines = EXR_LINES_PER_CHUNK[comp]
    order = sorted(range(len(names)), key=lambda k: names[k].encode())  # stored sorted by name
    chlist = b"".join(names[k].encode() + b"\0" + struct.pack("<iB3xii", ptype, 0, 1, 1)
                      for k in order) + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (struct.pack("<ii", EXR_MAGIC, 2)
              + _attr("channels", "chlist", chlist)
              + _attr("compression", "compression", bytes([comp]))
              + _attr("dataWindow", "box2i", box)
              + _attr("displayWindow", "box2i", box)
              + _attr("lineOrder", "lineOrder", b"\0")
              + _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + _attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + _attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + b"".join(_meta_attr(k, v) for k, v in meta.items())
              + b"\0")
    stack = np.stack([planes[k].astype(dtype) for k in order], axis=1)  # (H, C, W)
    chunks = []
    for y0 in range(0, h, lines):
        raw = np.ascontiguousarray(stack[y0:y0 + lines]).tobytes()  # per line, per channel
        data = raw
        if comp in (2, 3):
            packed = zlib.compress(_zip_predict(raw), 6)
            if len(packed) < len(raw):
                data = packed
        chunks.append(struct.pack("<ii", y0, len(data)) + data)
    offsets, pos = [], len(header) + 8 * len(chunks)
    for c in chunks:
        offsets.append(pos)
        pos += len(c)
    with open(path, "wb") as f:
        f.write(header)
        f.write(struct.pack(f"<{len(offsets)}Q", *offsets))
        for c in chunks:
            f.write(c)


def _parse_header(buf, path):
    pos, attrs = 8, {}
    while buf[pos] != 0:
        end = buf.index(b"\0", pos)
        name = buf[pos:end].decode()
        tend = buf.index(b"\0", end + 1)
        tname = buf[end + 1:tend].decode()
        size = struct.unpack_from("<i", buf, tend + 1)[0]
        attrs[name] = (tname, buf[tend + 5:tend + 5 + size])
        pos = tend + 5 + size
    for key in ("channels", "compression", "dataWindow"):
        if key not in attrs:
            raise ValueError(f"{path}: OpenEXR header lacks {key!r}")
    return attrs, pos + 1


def _metadata(attrs):
    meta = {}
    for name, (tname, payload) in attrs.items():
        if name in _STANDARD:
            continue
        if tname == "string":
            meta[name] = payload.decode("utf-8", "replace")
        elif tname == "int" and len(payload) == 4:
            meta[name] = struct.unpack("<i", payload)[0]
        elif tname == "float" and len(payload) == 4:
            meta[name] = struct.unpack("<f", payload)[0]
    return meta


def _builtin_read(path):
    buf = path.read_bytes()
    if len(buf) < 8 or struct.unpack_from("<i", buf, 0)[0] != EXR_MAGIC:
        raise ValueError(f"{path}: not an OpenEXR file")
    flags = struct.unpack_from("<I", buf, 4)[0]
    if flags & 0x200:
        raise ValueError(f"{path}: tiled OpenEXR is not supported by the built-in reader; "
                         f"install OpenImageIO to read it")
    if flags & 0x1800:
        raise ValueError(f"{path}: deep or multi-part OpenEXR is not supported by the built-in "
                         f"reader; install OpenImageIO to read it")
    attrs, pos = _parse_header(buf, path)
    comp = attrs["compression"][1][0]
    if comp not in EXR_LINES_PER_CHUNK:
        name = EXR_COMPRESSIONS.get(comp, f"unknown ({comp})")
        raise ValueError(f"{path}: OpenEXR compression {name.upper()} is not supported by the "
                         f"built-in reader (it reads NONE, RLE, ZIP, ZIPS); install OpenImageIO "
                         f"to read it")
    channels, cl, p = [], attrs["channels"][1], 0
    while cl[p] != 0:
        end = cl.index(b"\0", p)
        cname = cl[p:end].decode()
        ptype, _plinear, xs, ys = struct.unpack_from("<iB3xii", cl, end + 1)
        if xs != 1 or ys != 1:
            raise ValueError(f"{path}: subsampled channel {cname!r} is not supported by the "
                             f"built-in reader")
        channels.append((cname, EXR_PIXEL_TYPES[ptype]))
        p = end + 17
    xmin, ymin, xmax, ymax = struct.unpack("<iiii", attrs["dataWindow"][1])
    w, h = xmax - xmin + 1, ymax - ymin + 1
    lines = EXR_LINES_PER_CHUNK[comp]
    offsets = struct.unpack_from(f"<{(h + lines - 1) // lines}Q", buf, pos)
    out = np.zeros((h, w, len(channels)), dtype=np.float32)
    line_bytes = sum(dt.itemsize for _, dt in channels) * w
    for off in offsets:
        y, size = struct.unpack_from("<ii", buf, off)
        data = buf[off + 8:off + 8 + size]
        row0 = y - ymin
        n = min(lines, h - row0)
        if row0 < 0 or n <= 0:
            raise ValueError(f"{path}: corrupt OpenEXR chunk (y = {y})")
        expected = line_bytes * n
        if comp in (2, 3) and size < expected:
            data = _zip_unpredict(zlib.decompress(data))
        elif comp == 1 and size < expected:
            data = _zip_unpredict(_rle_decode(data, expected))
        if len(data) != expected:
            raise ValueError(f"{path}: corrupt OpenEXR chunk at y = {y}")
        p = 0
        for r in range(n):
            for c, (_, dt) in enumerate(channels):
                out[row0 + r, :, c] = np.frombuffer(data, dtype=dt, count=w, offset=p)
                p += dt.itemsize * w
    return ExrImage({name: np.ascontiguousarray(out[:, :, c])
                     for c, (name, _) in enumerate(channels)}, _metadata(attrs))
