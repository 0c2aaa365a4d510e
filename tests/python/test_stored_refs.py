"""Stored reference sets (lantern.testing.refs): a set is read only under the key it was stored
with, rendered otherwise (and said so), stored on request, and checked against a live render on
request. No native module needed: the renders here are numpy stand-ins."""
import warnings

import numpy as np
import pytest

from lantern import metrics, scenes
from lantern.testing import refs


def fake_renders(k=16, bias=1.0, seed=3):
    rng = np.random.default_rng(seed)
    return [bias * (1.0 + 0.05 * rng.standard_normal((16, 16, 3))) for _ in range(k)]


class Counter:
    def __init__(self, **kw):
        self.calls, self.kw = 0, kw

    def __call__(self):
        self.calls += 1
        return fake_renders(**self.kw)


def test_the_key_sees_the_scene_and_the_settings():
    a, b = scenes.cornell_box(8, 8), scenes.cornell_box(8, 8)
    key = dict(scene=a, integrator="pt", spp=64, seed0=1000, settings={})
    assert refs.key_digest(key) == refs.key_digest(dict(key, scene=b))
    b.materials[0]["base_color"] = [0.81, 0.8, 0.8]
    assert refs.key_digest(key) != refs.key_digest(dict(key, scene=b))
    assert refs.key_digest(key) != refs.key_digest(dict(key, spp=128))
    assert refs.key_digest(key) != refs.key_digest(dict(key, settings={"sort": True}))
    # an array's dtype and shape are part of it, not only its bytes
    assert refs.key_digest({"x": np.zeros(4, np.float32)}) != refs.key_digest(
        {"x": np.zeros(2, np.float64)})
    with pytest.raises(TypeError):
        refs.key_digest({"x": object()})


def test_stored_read_stale_rendered(tmp_path, monkeypatch):
    monkeypatch.delenv("LANTERN_STORE_REFS", raising=False)
    monkeypatch.delenv("LANTERN_VERIFY_REFS", raising=False)
    path, key = tmp_path / "r.npz", {"name": "flat", "spp": 4}
    render = Counter()
    with pytest.warns(refs.StaleReferenceWarning, match="missing"):
        live = refs.reference_blocks(path, render, key)
    assert render.calls == 1 and not path.exists()
    monkeypatch.setenv("LANTERN_STORE_REFS", "1")
    refs.reference_blocks(path, render, key)
    assert render.calls == 2 and path.exists()
    monkeypatch.delenv("LANTERN_STORE_REFS")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        stored = refs.reference_blocks(path, render, key)
    assert render.calls == 2                          # read, not rendered
    assert np.array_equal(stored.blocks, live.blocks)
    assert stored.blocks.shape == (16, 2, 2, 3)
    with pytest.warns(refs.StaleReferenceWarning, match="stale"):
        refs.reference_blocks(path, render, dict(key, spp=8))
    assert render.calls == 3
    # a stored set is a reference like any other: a 3 % bias against it is caught
    res = metrics.compare_renders(fake_renders(seed=9, bias=1.03), stored, block=8)
    assert not res.passed
    assert metrics.compare_renders(fake_renders(seed=9), stored, block=8).passed


def test_verify_mode_catches_a_reference_that_moved(tmp_path, monkeypatch):
    """LANTERN_VERIFY_REFS=1 renders a stored set again: a live image 5 % brighter than what
    was stored (the engine's expected image changed) fails; the same expectation passes."""
    path, key = tmp_path / "r.npz", {"name": "flat"}
    monkeypatch.setenv("LANTERN_STORE_REFS", "1")
    refs.reference_blocks(path, Counter(), key)
    monkeypatch.delenv("LANTERN_STORE_REFS")
    monkeypatch.setenv("LANTERN_VERIFY_REFS", "1")
    refs.reference_blocks(path, Counter(seed=5), key)
    with pytest.raises(AssertionError, match="no longer agrees"):
        refs.reference_blocks(path, Counter(seed=5, bias=1.05), key)


def test_non_finite_references_are_refused(tmp_path, monkeypatch):
    monkeypatch.setenv("LANTERN_STORE_REFS", "1")

    def nan_render():
        imgs = fake_renders()
        imgs[3][0, 0, 0] = np.nan
        return imgs
    with pytest.raises(ValueError, match="non-finite"):
        refs.reference_blocks(tmp_path / "r.npz", nan_render, {"name": "nan"})
    assert not (tmp_path / "r.npz").exists()


def test_an_unreadable_file_is_rendered_live(tmp_path, monkeypatch):
    monkeypatch.delenv("LANTERN_STORE_REFS", raising=False)
    path = tmp_path / "r.npz"
    path.write_bytes(b"not a zip file")
    render = Counter()
    with pytest.warns(refs.StaleReferenceWarning, match="unreadable"):
        refs.reference_blocks(path, render, {"name": "x"})
    assert render.calls == 1


def _digest_of(scene):
    return refs.key_digest({"scene": refs.order_free(scene)})


def test_order_free_keys_see_geometry_not_its_order():
    """Blender hands a mesh's corners over in an order that changes between runs of the same
    file (measured: a UV sphere, 2026-12-05), so Cycles' references key on refs.order_free:
    the same triangles listed in any vertex or triangle order, each from any corner, give the
    same key; a moved vertex, a flipped triangle or another material does not."""
    base = scenes.cornell_box(8, 8)
    ref = _digest_of(base)
    rng = np.random.default_rng(5)
    shuffled = scenes.cornell_box(8, 8)
    for m in shuffled.meshes:
        n, t = len(m["positions"]), len(m["indices"])
        perm = rng.permutation(n)                       # vertex order
        inv = np.empty(n, np.int64)
        inv[perm] = np.arange(n)
        for k in ("positions", "normals", "uvs"):
            if m.get(k) is not None:
                m[k] = np.asarray(m[k])[perm]
        tri = inv[np.asarray(m["indices"], np.int64)]
        order = rng.permutation(t)                      # triangle order
        tri = tri[order]
        tri = np.roll(tri, 1, axis=1)                   # each triangle from another corner
        m["indices"] = tri.astype(np.uint32)
        m["material_ids"] = np.asarray(m["material_ids"])[order]
    assert refs.key_digest({"scene": shuffled}) != refs.key_digest({"scene": base})
    assert _digest_of(shuffled) == ref
    moved = scenes.cornell_box(8, 8)
    moved.meshes[0]["positions"] = np.array(moved.meshes[0]["positions"], np.float32)
    moved.meshes[0]["positions"][0, 0] += 1e-3
    assert _digest_of(moved) != ref
    flipped = scenes.cornell_box(8, 8)
    flipped.meshes[0]["indices"] = np.array(flipped.meshes[0]["indices"])[:, ::-1].copy()
    assert _digest_of(flipped) != ref
    other = scenes.cornell_box(8, 8)
    other.meshes[0]["material_ids"] = (np.asarray(other.meshes[0]["material_ids"]) + 1) % len(
        other.materials)
    assert _digest_of(other) != ref


def test_order_free_keys_of_strands():
    def fur(order, shift=0.0):
        sc = scenes.cornell_box(8, 8)
        strands = [np.array([[0, 0, 0], [0, 0, 0.1], [0.01, 0, 0.2]], np.float32) + [i * 0.1, 0, 0]
                   for i in range(4)]
        strands[2] = strands[2] + np.float32(shift)
        pts = np.concatenate([strands[i] for i in order])
        sc.add_curves(pts, np.full(len(pts), 0.005, np.float32), np.arange(0, 13, 3))
        return sc
    assert _digest_of(fur([0, 1, 2, 3])) == _digest_of(fur([3, 1, 0, 2]))
    assert _digest_of(fur([0, 1, 2, 3])) != _digest_of(fur([0, 1, 2, 3], shift=1e-3))


def test_order_free_keys_of_moving_strands():
    """Motion blur's steps (curves deform, deform_radius) go with their strand in the key."""
    def fur(order, shift=0.0, radius_shift=0.0):
        sc = scenes.cornell_box(8, 8)
        strands = [np.array([[0, 0, 0], [0, 0, 0.1], [0.01, 0, 0.2]], np.float32) + [i * 0.1, 0, 0]
                   for i in range(4)]
        pts = np.concatenate([strands[i] for i in order])
        steps = np.stack([pts + [0.1 * k, 0.01 * k * (pts[:, 0] > 0.15).any(), 0]
                          for k in range(3)]).astype(np.float32)
        steps[2, 4] += np.float32(shift)
        rad = np.stack([np.full(len(pts), 0.005 + radius_shift * k, np.float32)
                        for k in range(3)])
        sc.add_curves(pts, np.full(len(pts), 0.005, np.float32), np.arange(0, 13, 3),
                      deform=steps, deform_radius=rad)
        return sc
    ref = _digest_of(fur([0, 1, 2, 3]))
    assert ref == _digest_of(fur([3, 1, 0, 2]))
    assert ref != _digest_of(fur([0, 1, 2, 3], shift=1e-3))
    assert ref != _digest_of(fur([0, 1, 2, 3], radius_shift=1e-3))
