"""Mutations of valid `.lantern` files for tools/fuzz_scene.py: each takes a seed scene (its
members, decoded) and a `random.Random`, and returns the bytes of one hostile file and a short
label. Families: zip structure, JSON, .npy headers and data, values, whole-scene scale."""

import copy
import io
import json
import math
import struct
import zipfile
import zlib

import numpy as np

HOSTILE = [float("nan"), float("inf"), float("-inf"), 1e39, -1e39, 3e38, 1e300, 1e-45, 0, -1,
           2**31, 2**32, 2**63, 2**64, 10**30, True, None, "x", "", [], {}, [1, 2], 1.5,
           -1e19, 2e19, [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[0]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]],
           "y" * 100_000]
DTYPES = ["<f8", ">f4", "<f2", "<i4", "<u8", "<i8", "|u1", "|b1", "|O", "<c8", "|S4", "<U3",
          "|V12", "[('a', '<f4'), ('b', '<f4'), ('c', '<f4')]", "('<f4', (3,))", "<m8", "<M8"]
# every field a reader knows, for keys added where they do not belong
FIELDS = ["soft_falloff", "visible_camera", "cast_shadow", "radius", "to_world", "position",
          "direction", "size", "shape", "angle", "spot_size", "spot_blend", "power", "strength",
          "eta", "k", "mix", "mix_texture", "base_color_texture", "normal_texture", "pixels",
          "uv_transform", "type", "name", "screen", "clip", "color", "filter_width",
          "zz_unknown"]
SCALES = [1e-30, 1e-20, 1e-10, 1e-3, 1e3, 1e10, 1e15, 1e18, 1e19, 1e20, 1e30, 1e38, -1.0]
OFFSETS = [1e6, 1e10, 1e18, 2e19, 1e30]


class Seed:
    """A valid scene file, decoded: `members` (name -> bytes), `doc` (scene.json), `arrays`."""

    def __init__(self, name, data):
        self.name = name
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            self.members = {n: zf.read(n) for n in zf.namelist()}
        self.doc = json.loads(self.members["scene.json"])
        self.arrays = {n: np.load(io.BytesIO(b), allow_pickle=False)
                       for n, b in self.members.items() if n.endswith(".npy")}


def zip_bytes(members, method=zipfile.ZIP_DEFLATED):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=method) as zf:
        for name, data in members.items():
            zf.writestr(name, data)
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


def dump(doc):
    return json.dumps(doc, allow_nan=True).encode()


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
                zf.writestr(n, b)
            zf.writestr(victim, members[rng.choice(names)])
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


# ---- JSON ----
def _paths(value, prefix=()):
    yield prefix
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _paths(v, prefix + (i,))


def _set(doc, path, value):
    node = doc
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value


def mutate_json(seed, rng):
    members = dict(seed.members)
    doc = copy.deepcopy(seed.doc)
    paths = [p for p in _paths(doc) if p]
    op = rng.choice(["replace", "replace", "replace", "delete", "unknown_key", "unknown_key",
                     "list", "swap",
                     "text_truncate", "text_flip", "bad_utf8", "deep", "bom", "trailing"])
    text = None
    if op == "replace":  # a depth first, so shallow structure is hit as often as numbers
        depth = rng.choice(sorted({len(p) for p in paths}))
        path = rng.choice([p for p in paths if len(p) == depth])
        value = rng.choice(HOSTILE)
        _set(doc, path, value)
        op = f"replace {'/'.join(map(str, path))}={str(value)[:20]}"
    elif op == "delete":
        path = rng.choice(paths)
        node = doc
        for p in path[:-1]:
            node = node[p]
        del node[path[-1]]
        op = f"delete {'/'.join(map(str, path))}"
    elif op == "unknown_key":
        dicts = [p for p in _paths(doc) if isinstance(_get(doc, p), dict)]
        key, value = rng.choice(FIELDS), rng.choice(HOSTILE)
        _get(doc, rng.choice(dicts))[key] = value
        op = f"add {key}={str(value)[:20]}"
    elif op == "list":
        lists = [p for p in _paths(doc) if isinstance(_get(doc, p), list) and _get(doc, p)]
        lst = _get(doc, rng.choice(lists))
        how = rng.choice(["dup", "pop", "clear", "reverse", "extend"])
        {"dup": lambda: lst.append(copy.deepcopy(rng.choice(lst))), "pop": lst.pop,
         "clear": lst.clear, "reverse": lst.reverse,
         "extend": lambda: lst.extend([copy.deepcopy(lst[0])] * 50)}[how]()
        op = f"list {how}"
    elif op == "swap":  # one array field names another member
        refs = [p for p in paths if isinstance(_get(doc, p), str) and _get(doc, p) in members]
        if refs:
            _set(doc, rng.choice(refs), rng.choice(list(members)))
    else:
        raw = dump(doc)
        if op == "text_truncate":
            text = raw[:rng.randrange(len(raw))]
        elif op == "text_flip":
            text = bytearray(raw)
            for _ in range(rng.randint(1, 4)):
                text[rng.randrange(len(text))] = rng.randrange(256)
            text = bytes(text)
        elif op == "bad_utf8":
            i = rng.randrange(len(raw))
            text = raw[:i] + b"\xff\xfe" + raw[i:]
        elif op == "deep":
            depth = rng.choice([40, 900, 5000, 200_000])
            text = raw[:-1] + b', "deep": ' + b"[" * depth + b"]" * depth + b"}"
        elif op == "bom":
            text = b"\xef\xbb\xbf" + raw
        elif op == "trailing":
            text = raw + b" {}"
    members["scene.json"] = text if text is not None else dump(doc)
    return zip_bytes(members), op


def _get(doc, path):
    for p in path:
        doc = doc[p]
    return doc


# ---- .npy headers and data ----
def mutate_npy(seed, rng):
    members = dict(seed.members)
    name = rng.choice(sorted(seed.arrays))
    arr = seed.arrays[name]
    raw = members[name]
    hlen = struct.unpack("<H", raw[8:10])[0]
    header, body = raw[10:10 + hlen].decode("latin1").strip(), raw[10 + hlen:]
    descr, shape = arr.dtype.str, arr.shape
    op = rng.choice(["dtype", "shape", "fortran", "garbage_header", "magic", "version",
                     "hlen", "truncate", "extend", "flip", "retype", "reshape", "rows"])
    if op == "dtype":
        d = rng.choice(DTYPES)
        d = d if d.startswith(("[", "(")) else repr(d)
        out = npy_raw(f"{{'descr': {d}, 'fortran_order': False, 'shape': {shape}, }}", body)
        op = f"dtype {d}"
    elif op == "shape":
        new = rng.choice([(), (0,), (0, 3), (shape[0],), shape + (1,), (2**40, 3),
                          (2**62, 2**62), (-1, 3), (shape[0] + 1,) + shape[1:],
                          (max(shape[0] // 2, 1),) + shape[1:], (3, shape[0])])
        out = npy_raw(f"{{'descr': {descr!r}, 'fortran_order': False, 'shape': {new}, }}",
                      body)
        op = f"shape {new}"
    elif op == "fortran":
        out = npy_raw(header.replace("False", "True"), body)
    elif op == "garbage_header":
        out = npy_raw(rng.choice(["{}", "[1, 2]", "{'descr': '<f4'}", "(" * 300 + ")" * 300,
                                  "__import__('os')", "{'descr': '<f4', 'fortran_order': 1, "
                                  "'shape': (1.5,)}", "x" * 20000]), body)
    elif op == "magic":
        out = b"\x93NUMPZ" + raw[6:]
    elif op == "version":
        out = raw[:6] + bytes([rng.choice([0, 3, 9]), rng.choice([0, 1])]) + raw[8:]
    elif op == "hlen":
        out = raw[:8] + struct.pack("<H", rng.choice([0, 1, 65535])) + raw[10:]
    elif op == "truncate":
        out = raw[:rng.randrange(len(raw))]
    elif op == "extend":
        out = raw + rng.randbytes(rng.randint(1, 64))
    elif op == "flip":
        out = bytearray(raw)
        out[rng.randrange(len(out))] ^= 1 << rng.randrange(8)
        out = bytes(out)
    elif op == "retype":  # valid: another dtype holding the same values
        kinds = {"f": ["<f8", ">f4", "<f2"], "u": ["<i8", ">u4", "<u2", "|u1"],
                 "i": ["<i8", ">i4"]}[arr.dtype.kind]
        out = npy_bytes(arr.astype(rng.choice(kinds)))
    elif op == "reshape":
        out = npy_bytes(rng.choice([arr.reshape(-1), arr.T, np.asfortranarray(arr),
                                    arr[None]]))
    else:  # rows: drop or repeat rows
        out = npy_bytes(arr[: max(len(arr) - rng.randint(1, 3), 0)] if rng.random() < 0.5
                        else np.concatenate([arr, arr[:2]]))
    members[name] = out
    return zip_bytes(members), f"{name} {op}"


# ---- Values ----
def mutate_values(seed, rng):
    members = dict(seed.members)
    doc = copy.deepcopy(seed.doc)
    op = rng.choice(["array_values", "array_values", "film", "camera", "light", "material"])
    if op == "array_values":
        name = rng.choice(sorted(seed.arrays))
        arr = seed.arrays[name].copy()
        flat = arr.reshape(-1)
        if flat.size:
            n = rng.choice([1, 3, max(flat.size // 10, 1), flat.size])
            at = [rng.randrange(flat.size) for _ in range(n)]
            if arr.dtype.kind == "f":
                flat[at] = rng.choice([np.nan, np.inf, -np.inf, 1e19, -2e19, 3e38, 1e-40,
                                       -1.0, 0.0, 65504.0])
            else:
                top = np.iinfo(arr.dtype).max
                flat[at] = rng.choice([top, top // 2, 0, int(flat.max()) + 1, 1 << 24])
        members[name] = npy_bytes(arr)
        op = f"values {name}"
    elif op == "film":
        doc["film"]["width"], doc["film"]["height"] = rng.choice(
            [(1, 1), (0, 16), (4097, 1), (1, 20000), (65536, 65536), (100000, 8), (3, 65536)])
        doc["film"]["filter_width"] = rng.choice([0.0, 1e-9, 1.5, 100.0, 1e30])
        op = f"film {doc['film']}"
    elif op == "camera":
        cam = doc["camera"]
        how = rng.choice(["far", "screen", "clip", "ortho"])
        if how == "far":
            cam["to_world"][rng.randrange(3)][3] = rng.choice(OFFSETS)
        elif how == "screen":
            s = rng.choice([1e-20, 1e-6, 1e3, 1e20])
            cam["screen"] = [-s, s, -s, s]
        elif how == "clip":
            cam["clip"] = rng.choice([[0.0, 1e-30], [1e-30, 1e30], [0.0, 3e38], [1e10, 1e11]])
        else:
            cam["type"] = "orthographic"
            s = rng.choice([1e-20, 1.0, 1e20])
            cam["screen"] = [-s, s, -s, s]
        op = f"camera {how}"
    elif op == "light" and doc.get("lights"):
        light = rng.choice(doc["lights"])
        key, value = rng.choice([("power", [1e39] * 3), ("power", [1e30] * 3),
                                 ("power", [0, 0, 0]), ("power", [1e-40] * 3),
                                 ("radius", 1e30), ("radius", 1e-30), ("spot_size", 1e-9),
                                 ("size", [1e-30, 1e-30]), ("size", [1e30, 1e30]),
                                 ("angle", math.pi), ("strength", [1e39] * 3),
                                 ("position", [2e19, 0, 0]), ("to_world_far", 2e19)])
        if key == "to_world_far" and "to_world" in light:
            light["to_world"][0][3] = value
        else:
            light[key] = value
        op = f"light {key}"
    elif doc.get("materials"):
        m = rng.choice(doc["materials"])
        key, value = rng.choice([("emission", [1e30] * 3), ("emission", [3e38] * 3),
                                 ("emission", [1e39] * 3), ("roughness", 0.0),
                                 ("roughness", 1e-9), ("ior", 0.01), ("ior", 100.0),
                                 ("thin_film_thickness", 1e5), ("alpha", 0.0),
                                 ("normal_strength", 1e3), ("sheen_weight", 1e3)])
        m[key] = value
        op = f"material {key}={value[0] if isinstance(value, list) else value}"
    members["scene.json"] = dump(doc)
    return zip_bytes(members), op


# ---- Whole-scene scale and offset ----
def mutate_scale(seed, rng):
    """Positions, camera, lights and sizes scaled by s (or moved by t): a valid scene that
    only the accelerators' range limits can break."""
    members = dict(seed.members)
    doc = copy.deepcopy(seed.doc)
    scale = rng.random() < 0.6
    s = rng.choice(SCALES) if scale else 1.0
    t = 0.0 if scale else rng.choice(OFFSETS)
    with np.errstate(over="ignore"):
        for mesh in doc["meshes"]:
            pos = seed.arrays[mesh["positions"]].astype(np.float64) * s + t
            members[mesh["positions"]] = npy_bytes(pos.astype(np.float32))

    def move(m):
        for r in range(3):
            m[r][3] = m[r][3] * s + t
    move(doc["camera"]["to_world"])
    doc["camera"]["clip"] = [c * abs(s) for c in doc["camera"]["clip"]]
    for light in doc.get("lights", []):
        if "to_world" in light:
            move(light["to_world"])
        if "position" in light:
            light["position"] = [p * s + t for p in light["position"]]
        if "size" in light:
            light["size"] = [x * abs(s) for x in light["size"]]
        if "radius" in light:
            light["radius"] *= abs(s)
    members["scene.json"] = dump(doc)
    return zip_bytes(members), f"scale {s:g}" if scale else f"offset {t:g}"


FAMILIES = {"zip": mutate_zip, "json": mutate_json, "npy": mutate_npy,
            "values": mutate_values, "scale": mutate_scale}
