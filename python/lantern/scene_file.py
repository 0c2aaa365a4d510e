"""Reading a `.lantern` file without trusting it: every zip member, JSON document and `.npy`
header is checked against its declared size and a memory budget *before* it is read, and every
failure is one `SceneError` naming the file, the member and what was expected.

`SceneArchive` opens the zip; `read_json()` and `read_array()` take one member each and count
it against the file's budget (`load_budget`). `load_scene` (scene.py) builds the Scene."""

import io
import json
import os
import zipfile

import numpy as np

from .scene_schema import MESH_ARRAYS, validate_mesh

# ---- Limits (a real scene is far inside every one of them) ----
# Arrays and JSON together may inflate to max(LOAD_FLOOR_BYTES, LOAD_RATIO x the file's size),
# and never past half the machine's memory: a 2 MB file cannot take gigabytes. Deflate reaches
# ~1000:1 on zeros; real meshes compress 1.2-3:1, so only padding or bombs hit the ratio.
LOAD_FLOOR_BYTES = 512 << 20
LOAD_RATIO = 32
MAX_LOAD_ENV = "LANTERN_LOAD_MAX_BYTES"  # overrides the budget (bytes), like max_bytes=
MAX_JSON_BYTES = 64 << 20      # scene.json holds no arrays: 64 MiB is ~100k lights
MAX_JSON_CONTAINERS = 2_000_000  # objects + arrays (each costs ~200 bytes in Python)
MAX_JSON_ITEMS = 8_000_000     # commas, an upper bound on the values
MAX_JSON_DEPTH = 32            # the deepest real field (a light's to_world) is 4 levels down
MAX_JSON_STRING = 64 << 10     # names and member paths
MAX_NPY_HEADER = 64 << 10
ALLOWED_COMPRESSION = {zipfile.ZIP_STORED: "stored", zipfile.ZIP_DEFLATED: "deflate"}
READ_CHUNK = 4 << 20


class SceneError(ValueError):
    """A scene file that cannot be loaded. `file`, `member` (the zip member, or None for the
    archive itself) and `detail` (what was found and what was expected); str() is one line
    that says all three. A ValueError, so callers catching ValueError keep working."""

    def __init__(self, file, member, detail):
        self.file = str(file)
        self.member = member
        self.detail = " ".join(str(detail).split())  # one line, whatever the cause said
        where = f"{self.file}: {member}" if member else self.file
        super().__init__(f"{where}: {self.detail}")


def _size(n):
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB"):
        if n < 1024 or unit == "TiB":
            return f"{n} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024.0
    return f"{n:.1f} TiB"


def _cause(e):
    text = " ".join(str(e).split()) or "no message"
    return f"{text} ({type(e).__name__})"


def load_budget(file_size, max_bytes=None):
    """Bytes the members of a file of `file_size` bytes may inflate to, in all."""
    if max_bytes is None and os.environ.get(MAX_LOAD_ENV):
        try:
            max_bytes = int(os.environ[MAX_LOAD_ENV])
        except ValueError:
            raise ValueError(f"{MAX_LOAD_ENV}={os.environ[MAX_LOAD_ENV]!r}: expected a number "
                             "of bytes") from None
    if max_bytes is not None:
        return int(max_bytes)
    budget = max(LOAD_FLOOR_BYTES, LOAD_RATIO * int(file_size))
    try:
        budget = min(budget, os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 2)
    except (ValueError, OSError, AttributeError):
        pass
    return budget


# ---- JSON ----
def _reject_constant(name):
    raise ValueError(f"{name} is not a JSON number (write finite numbers; Lantern's files never "
                     "hold NaN or Infinity)")


def _check_tree(doc):
    """Depth and string lengths of a parsed document, without recursion."""
    stack = [(doc, 1)]
    while stack:
        value, depth = stack.pop()
        if isinstance(value, str):
            if len(value) > MAX_JSON_STRING:
                return f"a string of {len(value)} characters (at most {MAX_JSON_STRING})"
            continue
        if not isinstance(value, (dict, list)):
            continue
        if depth > MAX_JSON_DEPTH:
            return f"values nested more than {MAX_JSON_DEPTH} levels deep"
        if isinstance(value, dict):
            for key in value:
                if len(key) > MAX_JSON_STRING:
                    return f"a key of {len(key)} characters (at most {MAX_JSON_STRING})"
            items = value.values()
        else:
            items = value
        stack.extend((v, depth + 1) for v in items if isinstance(v, (dict, list, str)))
    return None


def parse_json(data):
    """Parse scene.json's bytes; ValueError with what was expected (the caller names the
    file and member)."""
    try:
        text = data.decode("utf-8-sig")  # a byte-order mark from an editor is harmless
    except UnicodeDecodeError as e:
        raise ValueError(f"is not UTF-8 text (byte {e.start}: {e.reason}); expected a JSON "
                         "document") from None
    containers = text.count("{") + text.count("[")
    if containers > MAX_JSON_CONTAINERS or text.count(",") > MAX_JSON_ITEMS:
        raise ValueError(f"holds {containers} objects and arrays and {text.count(',')} commas, "
                         f"more than a scene has (at most {MAX_JSON_CONTAINERS} and "
                         f"{MAX_JSON_ITEMS})")
    try:
        doc = json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as e:
        raise ValueError(f"is not valid JSON: {e.msg} at line {e.lineno} column {e.colno}") \
            from None
    except RecursionError:
        raise ValueError(f"is not a scene: values nested deeper than the JSON parser allows "
                         f"(expected at most {MAX_JSON_DEPTH} levels)") from None
    except ValueError as e:  # parse_constant, or an integer of thousands of digits
        raise ValueError(f"is not valid JSON: {' '.join(str(e).split())}") from None
    problem = _check_tree(doc)
    if problem:
        raise ValueError(f"is not a scene: it holds {problem}")
    return doc


# ---- .npy ----
def parse_npy_header(head, member_size):
    """(dtype, shape, fortran_order, header_bytes) from the first bytes of a `.npy` member."""
    magic = np.lib.format.MAGIC_PREFIX
    if len(head) < len(magic) + 2 or head[:len(magic)] != magic:
        raise ValueError("is not a .npy array (no \\x93NUMPY magic at its start)")
    version = (head[len(magic)], head[len(magic) + 1])
    if version not in ((1, 0), (2, 0)):
        raise ValueError(f"is .npy format version {version[0]}.{version[1]}; expected 1.0 or "
                         "2.0 (numpy.save)")
    len_bytes = 2 if version == (1, 0) else 4
    start = len(magic) + 2 + len_bytes
    if len(head) < start:
        raise ValueError("ends inside its .npy header")
    hlen = int.from_bytes(head[start - len_bytes:start], "little")
    if hlen > MAX_NPY_HEADER or start + hlen > member_size:
        raise ValueError(f"declares a .npy header of {hlen} bytes in a member of {member_size} "
                         f"bytes (expected at most {MAX_NPY_HEADER})")
    if len(head) < start + hlen:
        raise ValueError("ends inside its .npy header")
    reader = (np.lib.format.read_array_header_1_0 if version == (1, 0)
              else np.lib.format.read_array_header_2_0)
    try:
        shape, fortran, dtype = reader(io.BytesIO(head[len(magic) + 2:start + hlen]),
                                       max_header_size=MAX_NPY_HEADER)
    except (ValueError, TypeError, SyntaxError, RecursionError) as e:
        raise ValueError(f"has a bad .npy header: {_cause(e)}") from None
    return dtype, shape, fortran, start + hlen


def check_npy_size(dtype, shape, hbytes, member_size):
    """The data the header declares must be exactly what is left in the member."""
    if any(d < 0 for d in shape):
        raise ValueError(f"declares a negative shape {shape}")
    count = 1
    for d in shape:
        count *= d
    declared = hbytes + count * dtype.itemsize
    if declared != member_size:
        raise ValueError(f"declares shape {shape} of {dtype.str} ({_size(count * dtype.itemsize)}"
                         f" of data) but the member holds {_size(max(member_size - hbytes, 0))}"
                         " after its header")


class SceneArchive:
    """A `.lantern` zip opened for checked reading; use as a context manager."""

    def __init__(self, path, max_bytes=None):
        self.path = path
        try:
            file_size = os.path.getsize(path)
            self.zf = zipfile.ZipFile(path)
            infos = self.zf.infolist()
        except (MemoryError, RecursionError):
            raise
        except Exception as e:  # zipfile reports a broken archive in many ways
            raise SceneError(path, None, f"is not a readable zip archive: {_cause(e)}; "
                             "expected a Lantern scene file (a zip of scene.json and .npy "
                             "arrays)") from None
        self.infos = {}
        for info in infos:
            self.infos[info.filename] = info
        self.budget = load_budget(file_size, max_bytes)
        self.file_size = file_size
        self.taken = 0

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.zf.close()
        return False

    def names(self):
        return set(self.infos)

    def error(self, member, detail):
        return SceneError(self.path, member, detail)

    def _info(self, member, what, limit=None, limit_what=""):
        info = self.infos.get(member)
        if info is None:
            raise self.error(member, f"{what}: member {member!r} is missing from the archive")
        if limit is not None and info.file_size > limit:
            raise self.error(member, f"declares {_size(info.file_size)} of {limit_what}")
        if info.flag_bits & 0x1:
            raise self.error(member, "is encrypted; expected a plain (unencrypted) member")
        if info.compress_type not in ALLOWED_COMPRESSION:
            raise self.error(member, f"uses zip compression method {info.compress_type}; "
                             "expected deflate or stored (as Lantern writes)")
        if self.taken + info.file_size > self.budget:
            raise self.error(member, f"declares {_size(info.file_size)} uncompressed "
                             f"({_size(info.compress_size)} compressed), which with the "
                             f"{_size(self.taken)} read so far passes this file's load budget "
                             f"of {_size(self.budget)} (for a {_size(self.file_size)} file); "
                             f"if the scene is real, raise it with "
                             f"load_scene(path, max_bytes=...) or {MAX_LOAD_ENV}")
        self.taken += info.file_size
        return info

    def _read_into(self, stream, buf, member, offset):
        view = memoryview(buf).cast("B")
        pos = 0
        while pos < len(view):
            n = stream.readinto(view[pos:pos + READ_CHUNK])
            if not n:
                raise self.error(member, f"ends after {offset + pos} of {offset + len(view)} "
                                 "declared bytes (truncated)")
            pos += n

    def _corrupt(self, member, e):
        if isinstance(e, SceneError):
            return e
        return self.error(member, f"is corrupt: {_cause(e)}; expected an intact zip member")

    def read_json(self, member, what="scene"):
        info = self._info(member, what, MAX_JSON_BYTES, f"JSON; a scene's JSON is at most "
                          f"{_size(MAX_JSON_BYTES)} (arrays go in .npy members)")
        data = bytearray(info.file_size)
        try:
            with self.zf.open(info) as f:
                self._read_into(f, data, member, 0)
                f.read(1)  # reach the end of the stream: zipfile checks the CRC there
        except (MemoryError, RecursionError):
            raise
        except Exception as e:
            raise self._corrupt(member, e) from None
        try:
            return parse_json(bytes(data))
        except ValueError as e:
            raise self.error(member, str(e)) from None

    def read_array(self, member, what, kinds, ndim, last=None):
        """The array in `member`, checked before reading: `kinds` (numpy dtype kinds, e.g.
        "f" or "iu"), `ndim` dimensions and, if given, the sizes allowed for the last one.
        `what` names the field ("mesh 0 ('wall') positions")."""
        info = self._info(member, what)
        try:
            with self.zf.open(info) as f:
                head = f.read(min(info.file_size, MAX_NPY_HEADER + 16))
                try:
                    dtype, shape, fortran, hbytes = parse_npy_header(head, info.file_size)
                except ValueError as e:
                    raise self.error(member, f"{what}: {e}") from None
                expect = f"expected {ndim}-D of dtype kind {'/'.join(kinds)}" + \
                    (f" with last dimension {' or '.join(map(str, last))}" if last else "")
                if (dtype.kind not in kinds or dtype.fields is not None
                        or dtype.subdtype is not None or dtype.itemsize > 8):
                    raise self.error(member, f"{what}: dtype {dtype.str} is not allowed; "
                                     f"{expect} (at most 8 bytes per value)")
                if len(shape) != ndim or (last and shape[-1] not in last):
                    raise self.error(member, f"{what}: shape {shape}; {expect}")
                try:
                    check_npy_size(dtype, shape, hbytes, info.file_size)
                except ValueError as e:
                    raise self.error(member, f"{what}: {e}") from None
                arr = np.empty(shape[::-1] if fortran else shape, dtype=dtype)
                rest = np.frombuffer(head, np.uint8)[hbytes:]
                flat = arr.reshape(-1).view(np.uint8)
                flat[:len(rest)] = rest
                self._read_into(f, flat[len(rest):], member, len(rest))
                f.read(1)  # reach the end of the stream: zipfile checks the CRC there
        except (MemoryError, RecursionError):
            raise
        except Exception as e:
            raise self._corrupt(member, e) from None
        return arr.T if fortran else arr


# ---- Scene elements (load_scene in scene.py puts them together) ----
# field -> (numpy dtype kinds, dimensions, allowed last dimension) of its .npy member
ARRAY_SPECS = {"positions": ("f", 2, (3,)), "normals": ("f", 2, (3,)), "uvs": ("f", 2, (2,)),
               "tangents": ("f", 2, (4,)), "indices": ("iu", 2, (3,)),
               "material_ids": ("iu", 1, None), "attributes": ("f", 2, None),
               "deform": ("f", 3, (3,)),
               "pixels": ("fiu", 3, (3, 4)), "map": ("f", 3, (3, 4))}


def entries(archive, doc, key):
    value = doc.get(key)
    if value is None:
        return []
    if not isinstance(value, list):
        raise archive.error("scene.json", f"{key}: expected a list, got "
                            f"{type(value).__name__}")
    return value


def member_name(archive, entry, key, what):
    member = entry.get(key)
    if not isinstance(member, str):
        raise archive.error("scene.json", f"{what}: expected the name of a .npy member, "
                            f"got {member!r}")
    if member not in archive.names():
        raise archive.error("scene.json", f"{what}: member {member!r} is missing from the "
                            "archive")
    return member


def read_mesh(archive, entry, i, num_materials):
    what = f"mesh {i} ({str(entry.get('name', f'mesh_{i}'))!r})"
    mesh, members = dict(entry), {}
    for key in MESH_ARRAYS:
        if entry.get(key) is None:
            if key in ("positions", "indices"):
                raise archive.error("scene.json", f"{what}: missing {key} (expected a .npy "
                                    "member name)")
            if key in entry or key != "deform":  # deform (optional, newer) stays absent
                mesh[key] = None
            continue
        members[key] = member_name(archive, entry, key, f"mesh {i} {key}")
        kinds, ndim, last = ARRAY_SPECS[key]
        mesh[key] = archive.read_array(members[key], f"mesh {i} {key}", kinds, ndim, last)
    try:
        validate_mesh(mesh, i, num_materials=num_materials)
    except ValueError as e:
        # the array the message is about: "... normals: 5 rows", "vertex index", "material id"
        text = str(e)
        key = next((k for k in members if f" {k}" in text[len(what):]), None)
        if key is None:
            key = "indices" if "vertex index" in text else (
                "material_ids" if "material id" in text else None)
        raise archive.error(members.get(key, "scene.json"), text) from None
    return mesh
