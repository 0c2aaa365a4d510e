"""Zip-level pieces of the scene fuzzer (tools/fuzz_mutate.py): writing members and `.npy`
arrays (also with arbitrary headers), the zip-structure mutations, and honest bombs: members
that inflate 1000:1, written in the time and memory of one chunk (`deflate_repeat`)."""

import io
import struct
import zipfile
import zlib

import numpy as np

from lantern.scene import fixed_time_member


def zip_bytes(members, method=zipfile.ZIP_DEFLATED):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=method) as zf:
        for name, data in members.items():
            zf.writestr(fixed_time_member(name, method), data)
    return buf.getvalue()


def npy_bytes(arr):
    buf = io.BytesIO()
    np.save(buf, arr, allow_pickle=False)
    return buf.getvalue()


def npy_raw(header, data=b"", version=(1, 0)):
    """A .npy member with an arbitrary header text (a dict literal, or anything)."""
    text = header.encode("latin1")
    pad = 16 - (10 + len(text) + 1) % 16
    text += b" " * pad + b"\n"
    size = struct.pack("<H", len(text)) if version == (1, 0) else struct.pack("<I", len(text))
    return b"\x93NUMPY" + bytes(version) + size + text + data


def _headers(data, sig):
    out, i = [], data.find(sig)
    while i >= 0:
        out.append(i)
        i = data.find(sig, i + 1)
    return out


def _patch(data, offset, fmt, value):
    data = bytearray(data)
    if offset + struct.calcsize(fmt) <= len(data):
        struct.pack_into(fmt, data, offset, value)
    return bytes(data)


# ---- Zip structure ----
def mutate_zip(seed, rng):
    members = dict(seed.members)
    data = zip_bytes(members)
    local, central = _headers(data, b"PK\x03\x04"), _headers(data, b"PK\x01\x02")
    op = rng.choice(["truncate", "flip", "declared_size", "crc", "method", "encrypted", "drop",
                     "duplicate", "rename", "stored", "prefix", "suffix", "garbage", "empty",
                     "json_bomb", "array_bomb", "liar"])
    if op == "truncate":
        return data[:rng.randrange(len(data))], op
    if op == "flip":
        data = bytearray(data)
        for _ in range(rng.randint(1, 8)):
            data[rng.randrange(len(data))] ^= 1 << rng.randrange(8)
        return bytes(data), op
    if op in ("declared_size", "crc", "method", "encrypted"):
        k = rng.randrange(len(central))
        value = {"declared_size": rng.choice([0, 1, 100, 2**31, 2**32 - 1]),
                 "crc": rng.randrange(2**32), "method": rng.choice([1, 12, 14, 99]),
                 "encrypted": 1}[op]
        field = {"declared_size": (24, 22, "<I"), "crc": (16, 14, "<I"),
                 "method": (10, 8, "<H"), "encrypted": (8, 6, "<H")}[op]
        data = _patch(data, central[k] + field[0], field[2], value)
        if rng.random() < 0.7 and k < len(local):
            data = _patch(data, local[k] + field[1], field[2], value)
        return data, f"{op}={value}"
    names = list(members)
    victim = rng.choice(names)
    if op == "drop":
        del members[victim]
    elif op == "duplicate":
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
            for n, b in members.items():
                zf.writestr(fixed_time_member(n), b)
            zf.writestr(fixed_time_member(victim), members[rng.choice(names)])
        return buf.getvalue(), op
    elif op == "rename":
        members[victim + rng.choice(["x", "/", " ", "\u00e9"])] = members.pop(victim)
    elif op == "stored":
        return zip_bytes(members, zipfile.ZIP_STORED), op
    elif op == "prefix":
        return rng.randbytes(rng.randint(1, 4096)) + data, op
    elif op == "suffix":
        return data + rng.randbytes(rng.randint(1, 4096)), op
    elif op == "garbage":
        return rng.randbytes(rng.randint(1, 10000)), op
    elif op == "empty":
        return b"", op
    elif op == "json_bomb":
        return _json_bomb(seed, rng), op
    elif op == "array_bomb":
        return _array_bomb(seed, rng), op
    elif op == "liar":  # declares its real size of scene.json small: zipfile stops there
        data = zip_bytes(members)
        k = names.index("scene.json")
        return _patch(_patch(data, central[k] + 24, "<I", 64), local[k] + 22, "<I", 64), op
    return zip_bytes(members), f"{op}:{victim}"


def deflate_repeat(prefix, chunk, count, suffix=b"", crc=True):
    """(raw deflate stream, crc32, size) of prefix + chunk * count + suffix, in time and
    memory of one chunk: after a full flush the compressor's output for a chunk repeats.
    crc=False skips the checksum (0) for members a reader must refuse before reading."""
    c = zlib.compressobj(9, zlib.DEFLATED, -15)
    head = c.compress(prefix) + c.flush(zlib.Z_FULL_FLUSH)
    block = c.compress(chunk) + c.flush(zlib.Z_FULL_FLUSH)
    tail = c.compress(suffix) + c.flush()
    value = 0
    if crc:
        value = zlib.crc32(prefix)
        for _ in range(count):
            value = zlib.crc32(chunk, value)
        value = zlib.crc32(suffix, value)
    return head + block * count + tail, value, len(prefix) + len(chunk) * count + len(suffix)


def raw_zip(members, bomb_name, bomb):
    """A zip of `members` (deflated by zipfile) plus one member from `deflate_repeat`."""
    data = bytearray(zip_bytes({n: b for n, b in members.items() if n != bomb_name}))
    with zipfile.ZipFile(io.BytesIO(bytes(data))) as zf:
        infos = zf.infolist()
    eocd = data.rfind(b"PK\x05\x06")
    cd_start = struct.unpack_from("<I", data, eocd + 16)[0]
    central = bytes(data[cd_start:eocd])
    stream, crc, size = bomb
    name = bomb_name.encode()
    offset = cd_start
    local = struct.pack("<4s5H3I2H", b"PK\x03\x04", 20, 0, 8, 0, 0x21, crc, len(stream), size,
                        len(name), 0) + name
    entry = struct.pack("<4s6H3I5H2I", b"PK\x01\x02", 20, 20, 0, 8, 0, 0x21, crc, len(stream),
                        size, len(name), 0, 0, 0, 0, 0, offset) + name
    body = bytes(data[:cd_start]) + local + stream
    cd = central + entry
    end = struct.pack("<4s4H2IH", b"PK\x05\x06", 0, 0, len(infos) + 1, len(infos) + 1, len(cd),
                      len(body), 0)
    return body + cd + end


def _array_bomb(seed, rng):
    """positions of the first mesh replaced by an honest .npy of zeros, 0.6-2 GiB inflated."""
    member = seed.doc["meshes"][0]["positions"]
    rows = rng.choice([50, 179]) << 20
    header = npy_raw(f"{{'descr': '<f4', 'fortran_order': False, 'shape': ({rows}, 3), }}")
    return raw_zip(seed.members, member, deflate_repeat(header, bytes(12 << 20), rows >> 20))


def _json_bomb(seed, rng):
    """scene.json padded with 70 MiB-2 GiB of spaces (honest sizes) in about 1/1000 of that."""
    text = seed.members["scene.json"]
    mib = rng.choice([70, 150, 2047])
    return raw_zip(seed.members, "scene.json",
                   deflate_repeat(text[:-1], b" " * (1 << 20), mib, b"}"))
