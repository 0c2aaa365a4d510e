"""Mutations of valid `.lantern` files for tools/fuzz_scene.py: each takes a seed scene (its
members, decoded) and a `random.Random`, and returns the bytes of one hostile file and a short
label. Families: zip structure (fuzz_zip.py), JSON, .npy headers and data, values,
whole-scene scale."""

import copy
import io
import json
import math
import struct
import zipfile

import numpy as np

from fuzz_zip import mutate_zip, npy_bytes, npy_raw, zip_bytes

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


def dump(doc):
    return json.dumps(doc, allow_nan=True).encode()


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
