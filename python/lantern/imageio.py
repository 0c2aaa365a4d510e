"""Image files: `.exr` (linear float32 or half RGB), `.png` (8-bit sRGB, for viewing), `.npy`.

OpenImageIO is used when it imports; otherwise (or with LANTERN_NO_OIIO=1, or
`backend="builtin"`) a small built-in codec: scanline OpenEXR (exr.py, which also keeps named
channels and header metadata; write: none/zip/zips; read: none/rle/zip/zips, half/float/uint
channels) and PNG (8-bit, non-interlaced). OpenImageIO is imported only inside these
functions: bpy ships its own OpenImageIO libraries in the same process."""

import os
import struct
import zlib
from pathlib import Path

import numpy as np

from .exr import read_exr, write_exr

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


def write_image(path, rgb, half=False, compression="zip", backend=None, metadata=None):
    """Write linear RGB (H, W, 3). `.exr`: float32 (or `half=True`) with `compression` in
    none/zip/zips, and `metadata` (name -> str/int/float) in its header (the samples and scene
    of a render-farm chunk: merge.py); `.png`: 8-bit sRGB, clamped; `.npy`: float32 array."""
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
    if ext == ".exr":
        _exr_write(path, img, half, compression, metadata, oiio)
    elif oiio is not None:
        _oiio_write_png(oiio, path, img)
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

def _oiio_write_png(oiio, path, img):
    h, w, _ = img.shape
    out = oiio.ImageOutput.create(str(path))
    if out is None:
        raise OSError(f"{path}: OpenImageIO cannot write this format: {oiio.geterror()}")
    spec = oiio.ImageSpec(w, h, 3, "uint8")
    spec.attribute("oiio:ColorSpace", "sRGB")
    spec.channelnames = ("R", "G", "B")
    if not out.open(str(path), spec):
        raise OSError(f"{path}: cannot open for writing: {out.geterror()}")
    ok = out.write_image(to_png8(img))
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


# ---- Built-in OpenEXR (exr.py) ----

def _exr_write(path, img, half, compression, metadata=None, oiio=None):
    write_exr(path, {c: img[:, :, k] for k, c in enumerate("RGB")}, metadata, half, compression,
              oiio)


def _exr_read(path):
    image = read_exr(path)
    return _pick_rgb(np.stack(list(image.channels.values()), axis=2), list(image.channels), path)


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
