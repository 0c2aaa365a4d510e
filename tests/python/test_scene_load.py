"""Loading hostile `.lantern` files: resources are checked before they are taken, and every
failure is one `lantern.SceneError` that names the file, the member and what was expected."""
import io
import json
import os
import struct
import subprocess
import sys
import time
import tracemalloc
import zipfile

import numpy as np
import pytest

import lantern
from lantern import SceneError, load_scene, scenes

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools"))
from fuzz_zip import deflate_repeat, npy_raw, raw_zip  # noqa: E402


@pytest.fixture
def seed(tmp_path):
    path = tmp_path / "seed.lantern"
    scenes.cornell_box(width=8, height=8).save(path)
    with zipfile.ZipFile(path) as zf:
        members = {n: zf.read(n) for n in zf.namelist()}
    return path, members


def write(tmp_path, members, name="case.lantern", method=zipfile.ZIP_DEFLATED):
    path = tmp_path / name
    with zipfile.ZipFile(path, "w", method) as zf:
        for n, b in members.items():
            zf.writestr(n, b)
    return path


def refused(path, member, *phrases, **kw):
    """load_scene(path) raises a SceneError naming the file and `member`, with `phrases`."""
    with pytest.raises(SceneError) as info:
        load_scene(path, **kw)
    e = info.value
    assert isinstance(e, ValueError)
    assert e.file == str(path) and e.member == member, (e.file, e.member, str(e))
    text = str(e)
    assert text.startswith(f"{path}: {member}: " if member else f"{path}: ") and "\n" not in text
    for phrase in phrases:
        assert phrase in text, text
    return text


def measured(fn):
    """(seconds, peak bytes traced by tracemalloc: Python objects and numpy arrays)."""
    tracemalloc.start()
    t0 = time.monotonic()
    try:
        fn()
    finally:
        seconds = time.monotonic() - t0
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    return seconds, peak


# ---- Budgets: refused before reading ----
def test_json_bomb_refused_quickly_with_little_memory(tmp_path, seed):
    _, members = seed
    bomb = deflate_repeat(members["scene.json"][:-1], b" " * (1 << 20), 2047, b"}", crc=False)
    path = tmp_path / "bomb.lantern"
    path.write_bytes(raw_zip(members, "scene.json", bomb))
    assert path.stat().st_size < 3 << 20  # ~2 MB on disk, 2 GiB inflated
    seconds, peak = measured(lambda: refused(path, "scene.json", "declares 2.0 GiB of JSON",
                                             "at most 64.0 MiB"))
    assert seconds < 2.0 and peak < 20 << 20, (seconds, peak)


def test_array_bomb_refused_by_the_load_budget(tmp_path, seed):
    _, members = seed
    rows = 179 << 20  # 2.1 GiB of float32 zeros in a 2 MB file
    header = npy_raw(f"{{'descr': '<f4', 'fortran_order': False, 'shape': ({rows}, 3), }}")
    path = tmp_path / "bomb.lantern"
    path.write_bytes(raw_zip(members, "meshes/0/positions.npy",
                             deflate_repeat(header, bytes(12 << 20), rows >> 20, crc=False)))
    seconds, peak = measured(lambda: refused(
        path, "meshes/0/positions.npy", "declares 2.1 GiB uncompressed", "load budget of 512.0",
        "max_bytes=", "LANTERN_LOAD_MAX_BYTES"))
    assert seconds < 2.0 and peak < 20 << 20, (seconds, peak)


def test_budget_override(tmp_path, seed, monkeypatch):
    path, members = seed
    small = len(members["scene.json"]) + 100  # room for scene.json, not for the arrays
    refused(path, "meshes/0/positions.npy", f"load budget of {small / 1024:.1f} KiB",
            max_bytes=small)
    refused(path, "scene.json", "load budget of 1.0 KiB", max_bytes=1024)
    monkeypatch.setenv("LANTERN_LOAD_MAX_BYTES", str(small))
    with pytest.raises(SceneError, match="passes this file's load budget"):
        load_scene(path)
    assert len(load_scene(path, max_bytes=1 << 30).meshes) == len(load_scene(
        path, max_bytes=10 << 20).meshes)


def test_member_that_inflates_past_its_declared_size(tmp_path, seed):
    """zipfile stops at the declared size and the CRC then fails: named, not 'Bad CRC-32'."""
    _, members = seed
    members = dict(members, **{"scene.json": members["scene.json"][:-1] + b" " * (8 << 20)
                               + b"}"})
    data = bytearray(write(tmp_path, members).read_bytes())
    info = zipfile.ZipFile(io.BytesIO(bytes(data))).getinfo("scene.json")
    struct.pack_into("<I", data, info.header_offset + 22, 4096)  # local header
    at = data.find(b"PK\x01\x02")
    while at >= 0:  # central directory
        if data[at + 46:at + 56] == b"scene.json":
            struct.pack_into("<I", data, at + 24, 4096)
        at = data.find(b"PK\x01\x02", at + 1)
    path = tmp_path / "liar.lantern"
    path.write_bytes(bytes(data))
    seconds, peak = measured(lambda: refused(path, "scene.json", "is corrupt", "CRC"))
    assert seconds < 2.0 and peak < 20 << 20


# ---- .npy headers ----
def npy_member(tmp_path, members, member, data, name="case.lantern"):
    return write(tmp_path, dict(members, **{member: data}), name)


@pytest.mark.parametrize("header, phrases", [
    ("{'descr': '<f4', 'fortran_order': False, 'shape': (1099511627776, 3), }",
     ["declares shape (1099511627776, 3) of <f4 (12.0 TiB of data)", "holds 96 bytes"]),
    ("{'descr': '|O', 'fortran_order': False, 'shape': (8, 3), }",
     ["dtype |O is not allowed", "expected 2-D of dtype kind f with last dimension 3"]),
    ("{'descr': [('x', '<f4'), ('y', '<f4'), ('z', '<f4')], 'fortran_order': False, "
     "'shape': (8,), }", ["is not allowed"]),
    ("{'descr': '<c8', 'fortran_order': False, 'shape': (4, 3), }", ["dtype <c8 is not allowed"]),
    ("{'descr': '<f4', 'fortran_order': False, 'shape': (24,), }",
     ["shape (24,); expected 2-D"]),
    ("{'descr': '<f4', 'fortran_order': 1, 'shape': (8, 3), }", ["bad .npy header"]),
    ("[1, 2]", ["bad .npy header"]),
])
def test_npy_header_checked_before_reading(tmp_path, seed, header, phrases):
    _, members = seed
    member = "meshes/0/positions.npy"
    path = npy_member(tmp_path, members, member, npy_raw(header, bytes(96)))
    refused(path, member, "mesh 0 positions", *phrases)


def test_npy_magic_version_and_truncation(tmp_path, seed):
    _, members = seed
    member = "meshes/0/indices.npy"
    raw = members[member]
    refused(npy_member(tmp_path, members, member, b"\x93NUMPZ" + raw[6:], "a.lantern"), member,
            "is not a .npy array")
    refused(npy_member(tmp_path, members, member, raw[:6] + b"\x03\x00" + raw[8:], "b.lantern"),
            member, "version 3.0; expected 1.0 or 2.0")
    refused(npy_member(tmp_path, members, member, raw[:-5], "c.lantern"), member,
            "declares shape", "but the member holds")
    refused(npy_member(tmp_path, members, member, raw[:9], "d.lantern"), member,
            "ends inside its .npy header")
    refused(npy_member(tmp_path, members, member, raw[:8] + b"\xff\xff" + raw[10:],
                       "e.lantern"), member, "declares a .npy header of 65535 bytes")


def test_other_layouts_of_the_same_arrays_load(tmp_path, seed):
    path, members = seed
    ref = load_scene(path)
    pos = ref.meshes[0]["positions"]
    for i, arr in enumerate([np.asfortranarray(pos), pos.astype(">f4"), pos.astype(np.float64)]):
        buf = io.BytesIO()
        np.save(buf, arr)
        got = load_scene(npy_member(tmp_path, members, "meshes/0/positions.npy",
                                    buf.getvalue(), f"{i}.lantern"))
        assert got.meshes[0]["positions"].dtype == np.float32
        np.testing.assert_array_equal(got.meshes[0]["positions"], pos)
    stored = load_scene(write(tmp_path, members, "stored.lantern", zipfile.ZIP_STORED))
    np.testing.assert_array_equal(stored.meshes[0]["indices"], ref.meshes[0]["indices"])


def test_cross_array_errors_name_the_member(tmp_path, seed):
    _, members = seed
    buf = io.BytesIO()
    np.save(buf, np.array([[0, 1, 99]], dtype=np.uint32))
    refused(npy_member(tmp_path, members, "meshes/0/indices.npy", buf.getvalue()),
            "meshes/0/indices.npy", "vertex index 99 out of range")


# ---- Zip structure ----
def test_zip_methods_encryption_and_crc(tmp_path, seed):
    _, members = seed
    raw = write(tmp_path, members).read_bytes()
    infos = zipfile.ZipFile(io.BytesIO(raw)).infolist()
    first = infos[0]
    cd = raw.find(b"PK\x01\x02")  # the first entry: infos[0]
    for name, off_cd, off_local, fmt, value, phrase in (
            ("bz2", 10, 8, "<H", 12, "compression method 12; expected deflate or stored"),
            ("enc", 8, 6, "<H", 1, "is encrypted"),
            ("crc", 16, 14, "<I", first.CRC ^ 1, "is corrupt: Bad CRC-32")):
        data = bytearray(raw)
        struct.pack_into(fmt, data, cd + off_cd, value)
        struct.pack_into(fmt, data, first.header_offset + off_local, value)
        path = tmp_path / f"{name}.lantern"
        path.write_bytes(bytes(data))
        refused(path, first.filename, phrase)
    broken = tmp_path / "broken.lantern"
    broken.write_bytes(raw[:cd + 10] + raw[cd + 30:])
    refused(broken, None, "expected a Lantern scene file")


# ---- JSON ----
@pytest.mark.parametrize("text, phrases", [
    (b'{"format": "lantern-scene", "version": 1, "x": ' + b"[" * 100_000 + b"]" * 100_000
     + b"}", ["nested deeper", "at most 32 levels"]),
    (b'{"format": "lantern-scene", "version": 1, "x": ' + b"[" * 40 + b"]" * 40 + b"}",
     ["nested more than 32 levels"]),
    (b'{"format": "lantern-scene", "version": 1, "world": {"color": [NaN, 0, 0]}}',
     ["NaN is not a JSON number"]),
    (b'{"format": "lantern-scene", "version": 1, "film": {"width": 1' + b"0" * 5000 + b"}}",
     ["is not valid JSON"]),
    (b'{"format": "lantern-scene", "version": 1, "materials": 7}',
     ["materials: expected a list, got int"]),
    (b'{"format": "lantern-scene", "version": 1, "meshes": [3]}',
     ["mesh 0: expected an object, got int"]),
    (b'{"format": "lantern-scene", "version": 1, "meshes": [{"positions": 5, "indices": 1}]}',
     ["mesh 0 positions: expected the name of a .npy member, got 5"]),
    (b'{"format": "lantern-scene", "version": 1, "camera": {"clip": [1, 0]}}',
     ["camera clip: need 0 <= start < end"]),
    (b'{"format": "lantern-scene", "version": 1, "name": "' + b"n" * 70_000 + b'"}',
     ["a string of 70000 characters"]),
    (b'{"format": "lantern-scene", "version": 1,\xff}', ["is not UTF-8 text"]),
    (b'{"format": "lantern-scene", "version": 1, "film": ', ["is not valid JSON"]),
])
def test_json_problems(tmp_path, seed, text, phrases):
    _, members = seed
    refused(write(tmp_path, dict(members, **{"scene.json": text})), "scene.json", *phrases)


def test_bom_is_accepted(tmp_path, seed):
    path, members = seed
    bom = write(tmp_path, dict(members, **{"scene.json": b"\xef\xbb\xbf" + members["scene.json"]}))
    assert len(load_scene(bom).meshes) == len(load_scene(path).meshes)


# ---- The command line ----
def test_cli_prints_one_line_for_a_bomb(tmp_path, seed):
    _, members = seed
    path = tmp_path / "bomb.lantern"
    path.write_bytes(raw_zip(members, "scene.json", deflate_repeat(
        members["scene.json"][:-1], b" " * (1 << 20), 100, b"}")))
    out = subprocess.run([sys.executable, "-m", "lantern", "info", str(path)],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 1 and out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in out.stderr, out.stderr
    assert lines[0].startswith(f"lantern: error: {path}: scene.json: declares 100.0 MiB"), lines
    assert lantern.SceneError is SceneError


def test_light_fields_the_core_reads_are_checked(tmp_path):
    """The core reads soft_falloff, to_world, size ... from every light: a value it cannot
    take is named at load (not std::bad_cast later), one that does not apply is dropped."""
    scene = scenes.integrating_sphere(width=4, height=4)
    scene.lights[0].update(soft_falloff="yes")
    path = tmp_path / "a.lantern"
    with zipfile.ZipFile(path, "w") as zf:
        doc = {"format": "lantern-scene", "version": 1, "lights": scene.lights}
        zf.writestr("scene.json", json.dumps(doc))
    refused(path, "scene.json", "light 0 (point) soft_falloff: expected a bool, got 'yes'")
    scene.lights[0].update(soft_falloff=False, to_world="x", size="y", angle=[])
    light = scene.validate().lights[0]
    assert light["soft_falloff"] is False and not {"to_world", "size", "angle"} & set(light)
