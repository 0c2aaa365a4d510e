"""Stored reference sets for the cross-integrator tests (tests/README.md, "Stored references").

A comparison such as "bdpt agrees with pt on the Cornell box" needs pt's per-seed block means,
not pt's pixels, and pt renders the same expected image on every run. So the reference side's
per-seed 8x8 block means (K x Bh x Bw x C numbers: a few KB) are stored beside the tests
(tests/refs/), as tests/render/refs holds Cycles' (lantern.blocks.SeedBlocks), and rendered
again only when what they were rendered from changed.

The key is a digest of everything the expected image depends on: the scene as the core receives
it (Scene.to_native(), every array's bytes), the integrator and its settings, the samples, seeds
and steps, the block size. A changed scene or setting gives another key, and the set is rendered
live (a StaleReferenceWarning names the file and the command that stores it again), so a stale
file costs time, never a wrong verdict. What the key cannot see is a change of the engine that
moves the expected image on purpose (a BSDF corrected): the test then fails against the old
reference, and its message names the file; store it again with LANTERN_STORE_REFS=1 after
checking the change against an independent reference (Cycles, an analytic value).

Environment:
  LANTERN_STORE_REFS=1   render every reference a test asks for and (re)write its file.
  LANTERN_VERIFY_REFS=1  render every stored reference live as well and require the stored and
                         the live sets to agree (lantern.agreement.compare_renders, no bias
                         cap beyond the default): bench/verify_refs.sh runs CI's suite so."""
import hashlib
import json
import os
import time
import warnings
import zipfile
from pathlib import Path

import numpy as np

from ..blocks import SeedBlocks, seed_blocks

FORMAT = 1  # bump when what a stored set means changes (not for a new scene or setting)


class StaleReferenceWarning(UserWarning):
    """A stored reference was missing or its key did not match: it was rendered live."""


def _feed(h, x):
    """Feed a canonical encoding of x (dicts by sorted key, arrays by dtype, shape and bytes)."""
    if isinstance(x, dict):
        h.update(b"{")
        for k in sorted(x, key=str):
            _feed(h, str(k))
            _feed(h, x[k])
        h.update(b"}")
    elif isinstance(x, (list, tuple)):
        h.update(b"[")
        for v in x:
            _feed(h, v)
        h.update(b"]")
    elif isinstance(x, np.ndarray):
        a = np.ascontiguousarray(x)
        h.update(f"a{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    elif isinstance(x, (bool, np.bool_)):
        h.update(b"T" if x else b"F")
    elif isinstance(x, (int, np.integer)):
        h.update(f"i{int(x)}".encode())
    elif isinstance(x, (float, np.floating)):
        h.update(f"f{float(x).hex()}".encode())
    elif x is None:
        h.update(b"N")
    elif isinstance(x, str):
        h.update(f"s{len(x)}:".encode() + x.encode())
    elif hasattr(x, "to_native"):  # a lantern.Scene
        _feed(h, x.to_native())
    else:
        raise TypeError(f"cannot key a reference on a {type(x).__name__}")


def _quantized(a):
    """Floats rounded to 1e-4 (0.1 mm, normals, uvs) as int64, so that the last bits a
    different summation order leaves do not change a key; integers as they are."""
    a = np.asarray(a)
    if a.dtype.kind == "f":
        return np.round(a.astype(np.float64) * 1e4).astype(np.int64)
    return a.astype(np.int64)


def _order_free_mesh(m):
    """A mesh's triangles as a sorted table of rows (each corner's attributes, each corner
    first in turn, the smallest rotation kept so the winding stays; then the triangle's own),
    in place of its arrays: the same surface listed in another vertex or triangle order (Blender
    evaluates a mesh on several threads, and hands its corners over in an order that changes
    from run to run) gives the same rows."""
    pos = np.asarray(m["positions"])
    tri = np.asarray(m["indices"], np.int64).reshape(-1, 3)
    n, t = len(pos), len(tri)
    corner, per_tri, rest = [], [], {}
    for k in sorted(m, key=str):
        v = m[k]
        if k == "indices" or not isinstance(v, np.ndarray) or v.ndim == 0:
            if k != "indices":
                rest[k] = v
            continue
        if k == "deform":  # (S * N, 3), step-major: each corner's steps side by side
            corner.append(_quantized(v).reshape(-1, n, 3).transpose(1, 0, 2).reshape(n, -1))
        elif len(v) == n and n != t:
            corner.append(_quantized(v).reshape(n, -1))
        elif len(v) == t:
            per_tri.append(_quantized(v).reshape(t, -1))
        else:
            rest[k] = v
    if not corner or t == 0:
        return m
    c = np.concatenate(corner, axis=1)
    rows = np.stack([np.concatenate([c[tri[:, (i + r) % 3]] for i in range(3)], axis=1)
                     for r in range(3)])                        # (3 rotations, T, 3 * width)
    best = np.zeros(t, np.int64)
    for r in (1, 2):  # the lexicographically smallest rotation of each triangle
        diff = rows[r] != rows[best, np.arange(t)]
        first = np.argmax(diff, axis=1)
        smaller = diff.any(axis=1) & (rows[r][np.arange(t), first] <
                                      rows[best, np.arange(t)][np.arange(t), first])
        best[smaller] = r
    table = np.concatenate([rows[best, np.arange(t)]] + per_tri, axis=1)
    table = table[np.lexsort(table.T[::-1])]
    return dict(rest, triangles=np.ascontiguousarray(table))


def _order_free_curves(c):
    """A strand set as its strands sorted by their points, radii and material."""
    off = np.asarray(c["offsets"], np.int64)
    pts, rad = _quantized(c["points"]).reshape(-1, 3), _quantized(c["radius"]).reshape(-1)
    mats = np.asarray(c.get("material_ids", np.zeros(max(len(off) - 1, 0))), np.int64)
    # motion blur's steps (docs/motion_blur.md "Strands"): each strand's points and radii at
    # every step go with it, (S * P, 3) and (S * P,) as to_native gives them
    np_ = len(rad)
    steps = [_quantized(c[k]).reshape(-1, np_, *((3,) if k == "deform" else ()))
             for k in ("deform", "deform_radius") if c.get(k) is not None and np_]
    strands = sorted(np.concatenate([[mats[s], off[s + 1] - off[s]],
                                     pts[off[s]:off[s + 1]].reshape(-1),
                                     rad[off[s]:off[s + 1]]] +
                                    [a[:, off[s]:off[s + 1]].reshape(-1) for a in steps]
                                    ).tobytes()
                     for s in range(len(off) - 1))
    rest = {k: v for k, v in c.items() if k not in ("offsets", "points", "radius",
                                                      "material_ids", "deform",
                                                      "deform_radius")}
    return dict(rest, strands=b"".join(strands).hex() if strands else "")


def order_free(scene):
    """`scene` (a lantern.Scene) as the dict its key is made from, with each mesh's and strand
    set's arrays replaced by an order-free table of its triangles / strands (floats rounded to
    1e-4): for keys of scenes that Blender exports (Cycles' references), whose vertex order
    varies between runs of the same file. Everything else as Scene.to_native() gives it."""
    native = dict(scene.to_native())
    native["meshes"] = [_order_free_mesh(_without_defaults(m)) for m in native.get("meshes") or []]
    if native.get("curves"):
        native["curves"] = [_order_free_curves(c) for c in native["curves"]]
    return native


# Mesh fields that the add-on exports at Blender's default, left out of the key where they have
# it: the references stored before the field was exported keep their keys (their Cycles renders
# had the same default); any other value enters the key.
_KEY_DEFAULTS = {"terminator_offset": 0.1}  # Shadow Terminator Geometry Offset (float32 0.1)
# Mesh fields the key's other content already holds: flat_shading (Blender's Face normals
# domain) is what the normals array, one normal per face, says.
_KEY_DERIVED = ("flat_shading",)


def _without_defaults(m):
    drop = [k for k, d in _KEY_DEFAULTS.items()
            if k in m and abs(float(m[k]) - d) < 1e-6] + [k for k in _KEY_DERIVED if k in m]
    return {k: v for k, v in m.items() if k not in drop} if drop else m


def file_digest(path):
    """The hex digest of a file's bytes (a source that stages a reference's scene)."""
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def key_digest(key):
    """The hex digest of `key` (a dict of the scene and the render's parameters)."""
    h = hashlib.sha256(f"lantern stored reference {FORMAT}".encode())
    _feed(h, key)
    return h.hexdigest()


def _mode(name):
    return os.environ.get(name, "0") == "1"


def reference_blocks(path, render, key, block=8):
    """The reference set's per-seed block means as a SeedBlocks: from `path` (.npz) when its
    stored key is `key`'s digest, else from render() (a list of per-seed images), then stored
    when LANTERN_STORE_REFS=1. `key`: a dict holding the scene (a lantern.Scene) and every
    parameter of render() that the expected image or the set's statistics depend on."""
    path = Path(path)
    digest = key_digest(dict(key, block=block))
    stored, unreadable = None, None
    if path.exists():
        try:
            with np.load(path, allow_pickle=False) as f:
                if str(f["key"]) == digest:
                    stored = np.asarray(f["blocks"], np.float64)
        except (OSError, ValueError, KeyError, zipfile.BadZipFile) as e:
            unreadable = f"unreadable ({type(e).__name__}: {e})"
    if stored is not None and not _mode("LANTERN_STORE_REFS"):
        if _mode("LANTERN_VERIFY_REFS"):
            _verify(path, stored, render(), block)
        return SeedBlocks(stored)
    t0 = time.perf_counter()
    blocks = seed_blocks(render(), block)
    seconds = time.perf_counter() - t0
    if not np.isfinite(blocks).all():
        raise ValueError(f"reference for {path.name}: non-finite block means")
    if _mode("LANTERN_STORE_REFS"):
        path.parent.mkdir(parents=True, exist_ok=True)
        meta = {k: v for k, v in key.items() if isinstance(v, (str, int, float, bool))}
        meta.update(seconds=round(seconds, 1), stored=time.strftime("%Y-%m-%d"))
        # per-pixel sets (block 1: a test that needs the pixels, e.g. region means) as float32,
        # a quarter of the file that float64 noise would take; block means keep float64
        np.savez_compressed(path, key=np.array(digest),
                            blocks=blocks.astype(np.float32) if block == 1 else blocks,
                            meta=np.array(json.dumps(meta, sort_keys=True)))
    else:
        why = unreadable or ("missing" if not path.exists() else "stale (its key differs)")
        warnings.warn(f"stored reference {path} is {why}: rendered live ({seconds:.1f} s); "
                      f"LANTERN_STORE_REFS=1 with this test stores it", StaleReferenceWarning,
                      stacklevel=2)
    return SeedBlocks(blocks)


def _verify(path, stored, live, block):
    from ..agreement import compare_renders
    res = compare_renders(SeedBlocks(seed_blocks(live, block)), SeedBlocks(stored), block,
                          name=f"stored reference {path.name} against a live render")
    print(res)
    assert res.passed, f"{path}: the stored reference no longer agrees with a live render: {res}"
