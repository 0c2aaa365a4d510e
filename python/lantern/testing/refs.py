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
        np.savez_compressed(path, key=np.array(digest), blocks=blocks,
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
