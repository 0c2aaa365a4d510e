"""Image files: `.exr` (linear float32 or half RGB), `.png` (8-bit sRGB, for viewing), `.npy`.

OpenImageIO is used when it imports; otherwise (or with LANTERN_NO_OIIO=1, or
`backend="builtin"`) a small built-in codec: scanline OpenEXR (write: none/zip/zips; read:
none/rle/zip/zips, half/float/uint channels) and PNG (8-bit, non-interlaced). OpenImageIO is imported
only inside these functions: bpy ships its own OpenImageIO libraries in the same process."""

import os
import struct
import zlib
from pathlib import Path

import numpy as np

BACKENDS = (None, "oiio", "builtin")


def _want_oiio(backend):
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")
    if backend == "builtin":
        return None
    if backend is None and os.environ.get("LANTERN_NO_OIIO", "") not in ("", "0"):
        return None
    try:
        import OpenImageIO as oiio
    except ImportError:
        if backend == "oiio":
            raise RuntimeError("OpenImageIO was requested but does not import") from None
        return None
    return oiio


def _as_rgb(rgb):
    arr = np.asarray(rgb)
    if arr.ndim == 2:
        arr = np.repeat(arr[:, :, None], 3, axis=2)
    if arr.ndim != 3 or arr.shape[2] not in (3, 4):
        raise ValueError(f"expected an image of shape (H, W, 3), got {arr.shape}")
    arr = arr[:, :, :3]
    if arr.shape[0] < 1 or arr.shape[1] < 1:
        raise ValueError(f"empty image {arr.shape}")
    return np.ascontiguousarray(arr, dtype=np.float32)


def srgb_encode(linear):
    """Linear -> sRGB-encoded in [0, 1] (clamped), the IEC 61966-2-1 curve."""
    x = np.clip(np.nan_to_num(np.asarray(linear, dtype=np.float64), nan=0.0), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def srgb_decode(encoded):
    """sRGB-encoded in [0, 1] -> linear."""
    x = np.asarray(encoded, dtype=np.float64)
    return np.where(x <= 0.04045, x / 12.92, np.power((x + 0.055) / 1.055, 2.4))


def to_png8(rgb):
    """Linear float RGB -> uint8 sRGB (clamped, rounded)."""
    return np.round(srgb_encode(rgb) * 255.0).astype(np.uint8)


def write_image(path, rgb, half=False, compression="zip", backend=None):
    """Write linear RGB (H, W, 3). `.exr`: float32 (or `half=True`) with `compression` in
    none/zip/zips; `.png`: 8-bit sRGB, clamped; `.npy`: float32 array."""
    path = Path(path)
    ext = path.suffix.lower()
    img = _as_rgb(rgb)
    if ext == ".npy":
        np.save(path, img, allow_pickle=False)
        return
    if ext not in (".exr", ".png"):
        raise ValueError(f"{path}: unsupported image extension {ext!r} (.exr, .png, .npy)")
    if compression not in ("none", "zip", "zips"):
        raise ValueError(f"compression must be none, zip or zips, got {compression!r}")
    oiio = _want_oiio(backend)
    if oiio is not None:
        _oiio_write(oiio, path, img, half, compression)
    elif ext == ".exr":
        _exr_write(path, img, half, compression)
    else:
        _png_write(path, to_png8(img))


def read_image(path, backend=None):
    """Read an image as linear float32 (H, W, 3). PNGs are decoded from sRGB to linear."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"image not found: {path}")
    ext = path.suffix.lower()
    if ext == ".npy":
        return _as_rgb(np.load(path, allow_pickle=False))
    if ext not in (".exr", ".png"):
        raise ValueError(f"{path}: unsupported image extension {ext!r} (.exr, .png, .npy)")
    oiio = _want_oiio(backend)
    if oiio is not None:
        data = _oiio_read(oiio, path)
    elif ext == ".exr":
        return _exr_read(path)
    else:
        data = _png_read(path)
    if ext == ".png":
        return srgb_decode(data).astype(np.float32)
    return data


# ---- OpenImageIO ----

def _oiio_write(oiio, path, img, half, compression):
    h, w, _ = img.shape
    out = oiio.ImageOutput.create(str(path))
    if out is None:
        raise OSError(f"{path}: OpenImageIO cannot write this format: {oiio.geterror()}")
    if path.suffix.lower() == ".png":
        data = to_png8(img)
        spec = oiio.ImageSpec(w, h, 3, "uint8")
        spec.attribute("oiio:ColorSpace", "sRGB")
    else:
        with np.errstate(over="ignore"):  # beyond half range -> inf, as OpenEXR does
            data = img.astype(np.float16) if half else img
        spec = oiio.ImageSpec(w, h, 3, "half" if half else "float")
        spec.attribute("compression", compression)
    spec.channelnames = ("R", "G", "B")
    if not out.open(str(path), spec):
        raise OSError(f"{path}: cannot open for writing: {out.geterror()}")
    ok = out.write_image(data)
    out.close()
    if not ok:
        raise OSError(f"{path}: write failed: {out.geterror()}")


def _oiio_read(oiio, path):
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise OSError(f"{path}: cannot read: {oiio.geterror()}")
    try:
        spec = inp.spec()
        eight_bit = str(spec.format) == "uint8"
        data = inp.read_image(0, 0, 0, spec.nchannels, "uint8" if eight_bit else "float")
        if data is None:
            raise OSError(f"{path}: cannot read: {inp.geterror()}")
        names = list(spec.channelnames)
    finally:
        inp.close()
    data = np.asarray(data).reshape(spec.height, spec.width, spec.nchannels)
    # same arithmetic as the built-in reader, so both agree bit for bit
    data = data.astype(np.float32) / 255.0 if eight_bit else data.astype(np.float32)
    return _pick_rgb(data, names, path)


def _pick_rgb(data, names, path):
    """(H, W, C) with channel names -> (H, W, 3) RGB."""
    upper = [n.split(".")[-1].upper() for n in names]
    if all(c in upper for c in "RGB"):
        return np.ascontiguousarray(np.stack([data[:, :, upper.index(c)] for c in "RGB"],
                                             axis=2), dtype=np.float32)
    if "Y" in upper or len(names) == 1:
        y = data[:, :, upper.index("Y") if "Y" in upper else 0]
        return np.ascontiguousarray(np.repeat(y[:, :, None], 3, axis=2), dtype=np.float32)
    if data.shape[2] >= 3:
        return np.ascontiguousarray(data[:, :, :3], dtype=np.float32)
    raise ValueError(f"{path}: no RGB channels (channels: {names})")


# ---- Built-in OpenEXR (scanline, single part) ----

EXR_MAGIC = 20000630
EXR_COMPRESSIONS = {0: "none", 1: "rle", 2: "zips", 3: "zip", 4: "piz", 5: "pxr24",
                    6: "b44", 7: "b44a", 8: "dwaa", 9: "dwab", 10: "htj2k256", 11: "htj2k32"}
EXR_LINES_PER_CHUNK = {0: 1, 1: 1, 2: 1, 3: 16}  # what the built-in codec handles
EXR_PIXEL_TYPES = {0: np.dtype("<u4"), 1: np.dtype("<f2"), 2: np.dtype("<f4")}


def _exr_attr(name, type_name, payload):
    return (name.encode() + b"\0" + type_name.encode() + b"\0"
            + struct.pack("<i", len(payload)) + payload)


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


def _exr_write(path, img, half, compression):
    h, w, _ = img.shape
    ptype = 1 if half else 2
    dtype = EXR_PIXEL_TYPES[ptype]
    comp = {"none": 0, "zips": 2, "zip": 3}[compression]
    lines = EXR_LINES_PER_CHUNK[comp]
    chlist = b""
    for name in "BGR":  # channels are stored in alphabetical order
        chlist += name.encode() + b"\0" + struct.pack("<iB3xii", ptype, 0, 1, 1)
    chlist += b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (struct.pack("<ii", EXR_MAGIC, 2)
              + _exr_attr("channels", "chlist", chlist)
              + _exr_attr("compression", "compression", bytes([comp]))
              + _exr_attr("dataWindow", "box2i", box)
              + _exr_attr("displayWindow", "box2i", box)
              + _exr_attr("lineOrder", "lineOrder", b"\0")
              + _exr_attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + _exr_attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + _exr_attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + b"\0")
    with np.errstate(over="ignore"):  # beyond half range -> inf, as OpenEXR does
        planes = img[:, :, ::-1].astype(dtype)  # B, G, R
    chunks = []
    for y0 in range(0, h, lines):
        block = planes[y0:y0 + lines]  # (n, W, 3) -> per line, per channel, the pixels
        raw = np.ascontiguousarray(block.transpose(0, 2, 1)).tobytes()
        data = raw
        if comp in (2, 3):
            packed = zlib.compress(_zip_predict(raw), 6)
            if len(packed) < len(raw):
                data = packed
        chunks.append(struct.pack("<ii", y0, len(data)) + data)
    table_start = len(header)
    offsets = []
    pos = table_start + 8 * len(chunks)
    for c in chunks:
        offsets.append(pos)
        pos += len(c)
    with open(path, "wb") as f:
        f.write(header)
        f.write(struct.pack(f"<{len(offsets)}Q", *offsets))
        for c in chunks:
            f.write(c)


def _exr_read(path):
    buf = Path(path).read_bytes()
    if len(buf) < 8 or struct.unpack_from("<i", buf, 0)[0] != EXR_MAGIC:
        raise ValueError(f"{path}: not an OpenEXR file")
    flags = struct.unpack_from("<I", buf, 4)[0]
    if flags & 0x200:
        raise ValueError(f"{path}: tiled OpenEXR is not supported by the built-in reader; "
                         f"install OpenImageIO to read it")
    if flags & 0x1800:
        raise ValueError(f"{path}: deep or multi-part OpenEXR is not supported by the built-in "
                         f"reader; install OpenImageIO to read it")
    pos = 8
    attrs = {}
    while buf[pos] != 0:
        end = buf.index(b"\0", pos)
        name = buf[pos:end].decode()
        tend = buf.index(b"\0", end + 1)
        tname = buf[end + 1:tend].decode()
        size = struct.unpack_from("<i", buf, tend + 1)[0]
        attrs[name] = (tname, buf[tend + 5:tend + 5 + size])
        pos = tend + 5 + size
    pos += 1
    for key in ("channels", "compression", "dataWindow"):
        if key not in attrs:
            raise ValueError(f"{path}: OpenEXR header lacks {key!r}")
    comp = attrs["compression"][1][0]
    if comp not in EXR_LINES_PER_CHUNK:
        name = EXR_COMPRESSIONS.get(comp, f"unknown ({comp})")
        raise ValueError(f"{path}: OpenEXR compression {name.upper()} is not supported by the "
                         f"built-in reader (it reads NONE, RLE, ZIP, ZIPS); install OpenImageIO "
                         f"to read it")
    channels = []
    cl = attrs["channels"][1]
    p = 0
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
    nchunks = (h + lines - 1) // lines
    offsets = struct.unpack_from(f"<{nchunks}Q", buf, pos)
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
                nbytes = dt.itemsize * w
                out[row0 + r, :, c] = np.frombuffer(data, dtype=dt, count=w, offset=p)
                p += nbytes
    return _pick_rgb(out, [c for c, _ in channels], path)


# ---- Built-in PNG (8-bit, non-interlaced) ----

def _png_chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


def _png_write(path, rgb8):
    h, w, _ = rgb8.shape
    rows = np.concatenate([np.zeros((h, 1), dtype=np.uint8), rgb8.reshape(h, w * 3)], axis=1)
    png = (b"\x89PNG\r\n\x1a\n"
           + _png_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + _png_chunk(b"sRGB", b"\0")
           + _png_chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
           + _png_chunk(b"IEND", b""))
    Path(path).write_bytes(png)


def _png_read(path):
    """8-bit gray/RGB/RGBA PNG -> sRGB-encoded float32 (H, W, 3) in [0, 1]."""
    buf = Path(path).read_bytes()
    if buf[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    pos, idat, ihdr = 8, [], None
    while pos < len(buf):
        length, kind = struct.unpack_from(">I4s", buf, pos)
        data = buf[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", data)
        elif kind == b"IDAT":
            idat.append(data)
        elif kind == b"IEND":
            break
        pos += 12 + length
    w, h, depth, ctype, _, _, interlace = ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(ctype)
    if depth != 8 or channels is None or interlace:
        raise ValueError(f"{path}: the built-in PNG reader handles 8-bit non-interlaced "
                         f"gray/RGB/RGBA only; install OpenImageIO")
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), dtype=np.uint8)
    stride = w * channels
    raw = raw.reshape(h, stride + 1)
    img = np.zeros((h, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        ftype, line = raw[y, 0], raw[y, 1:].astype(np.int32)
        if ftype == 0:
            cur = line
        elif ftype == 1:  # Sub: running sum per channel
            cur = np.cumsum(line.reshape(w, channels), axis=0).reshape(-1) & 0xFF
        elif ftype == 2:
            cur = (line + prev) & 0xFF
        elif ftype in (3, 4):
            cur = np.zeros(stride, dtype=np.int32)
            for x in range(stride):
                a = cur[x - channels] if x >= channels else 0
                b = prev[x]
                if ftype == 3:
                    pred = (a + b) // 2
                else:
                    c = prev[x - channels] if x >= channels else 0
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + pred) & 0xFF
        else:
            raise ValueError(f"{path}: bad PNG filter type {ftype}")
        img[y] = cur
        prev = cur.astype(np.int32)
    img = img.reshape(h, w, channels).astype(np.float32) / 255.0
    if channels in (1, 2):
        return np.repeat(img[:, :, :1], 3, axis=2)
    return np.ascontiguousarray(img[:, :, :3])
