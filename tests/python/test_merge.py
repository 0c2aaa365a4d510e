"""Render-farm chunks: EXR header metadata, `python -m lantern merge` (weights, multilayer
passes, refusals) and chunks of one render agreeing with one render of their summed samples."""
import numpy as np
import pytest

from lantern import cli, exr, imageio, merge, metrics, scenes, session

BACKENDS = ["oiio", "builtin"]


def _oiio(name):
    if name == "builtin":
        return None
    return pytest.importorskip("OpenImageIO")


@pytest.mark.parametrize("writer", BACKENDS)
@pytest.mark.parametrize("reader", BACKENDS)
def test_channels_and_metadata_round_trip(tmp_path, writer, reader):
    rng = np.random.default_rng(3)
    names = ["ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B",
             "ViewLayer.Combined.A", "ViewLayer.Depth.Z"]
    channels = {n: rng.random((7, 5)).astype(np.float32) for n in names}
    meta = merge.chunk_metadata("ab12", 64, 2**64 - 5, 3, "cis")
    path = tmp_path / "x.exr"
    exr.write_exr(path, channels, meta, oiio=_oiio(writer))
    back = exr.read_exr(path, oiio=_oiio(reader))
    assert set(back.channels) == set(names)
    for n in names:
        assert np.array_equal(back.channels[n], channels[n])
    for k, v in meta.items():
        assert back.metadata[k] == v, k
    assert int(back.metadata[merge.SEED]) == 2**64 - 5  # 64-bit seeds survive as text


def test_chunk_seeds():
    assert merge.chunk_seed(7, 0) == 7
    seeds = {merge.chunk_seed(7, k) for k in range(1000)}
    assert len(seeds) == 1000 and all(0 <= s < 2**64 for s in seeds)


def _chunk(path, channels, spp, chunk, scene="s1", seed=0):
    exr.write_exr(path, channels, merge.chunk_metadata(scene, spp, seed, chunk, "pt"))
    return path


def test_merge_weights_by_samples_every_pass(tmp_path):
    rng = np.random.default_rng(5)
    names = ["ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B",
             "ViewLayer.Depth.Z", "ViewLayer.IndexOB.X"]
    a = {n: rng.random((6, 8)).astype(np.float32) for n in names}
    b = {n: rng.random((6, 8)).astype(np.float32) for n in names}
    pa = _chunk(tmp_path / "a.exr", a, 16, 0)
    pb = _chunk(tmp_path / "b.exr", b, 48, 1)
    out = tmp_path / "m.exr"
    assert cli.main(["merge", str(pa), str(pb), "-o", str(out)]) == 0
    m = exr.read_exr(out)
    for n in names[:4]:
        want = (16 * a[n].astype(np.float64) + 48 * b[n]) / 64
        np.testing.assert_allclose(m.channels[n], want, rtol=1e-6, atol=1e-7)
    assert np.array_equal(m.channels["ViewLayer.IndexOB.X"], a["ViewLayer.IndexOB.X"])
    assert int(m.metadata[merge.SPP]) == 64
    assert m.metadata[merge.SCENE] == "s1"
    # a merged file merges again with a further chunk, by its summed samples
    pc = _chunk(tmp_path / "c.exr", a, 64, 2)
    out2 = tmp_path / "m2.exr"
    assert cli.main(["merge", str(out), str(pc), "-o", str(out2)]) == 0
    m2 = exr.read_exr(out2)
    want = (16 * a[names[0]].astype(np.float64) + 48 * b[names[0]] + 64 * a[names[0]]) / 128
    np.testing.assert_allclose(m2.channels[names[0]], want, rtol=1e-6, atol=1e-7)
    # ...but not with a chunk it already holds
    assert cli.main(["merge", str(out), str(pb), "-o", str(tmp_path / "m3.exr")]) == 1


def test_merge_refuses_with_a_reason(tmp_path, capsys):
    rgb = {c: np.ones((4, 6), np.float32) for c in "RGB"}
    small = {c: np.ones((3, 6), np.float32) for c in "RGB"}
    a = _chunk(tmp_path / "a.exr", rgb, 8, 0)
    cases = {
        "one resolution": _chunk(tmp_path / "r.exr", small, 8, 1),
        "different scenes": _chunk(tmp_path / "s.exr", rgb, 8, 1, scene="s2"),
        "same samples": _chunk(tmp_path / "d.exr", rgb, 8, 0),
        "same passes": _chunk(tmp_path / "p.exr", dict(rgb, A=rgb["R"]), 8, 1),
    }
    plain = tmp_path / "plain.exr"
    exr.write_exr(plain, rgb)
    cases["no sample count"] = plain
    for message, other in cases.items():
        out = tmp_path / "out.exr"
        assert cli.main(["merge", str(a), str(other), "-o", str(out)]) == 1
        err = capsys.readouterr().err
        assert message in err, (message, err)
        assert len(err.strip().splitlines()) == 1
        assert not out.exists()
    assert cli.main(["merge", str(a), str(a), "-o", str(a)]) == 1
    assert "overwrite" in capsys.readouterr().err


def test_chunk_needs_an_exr(tmp_path, capsys):
    path = tmp_path / "box.lantern"
    scenes.cornell_box(width=8, height=8).save(path)
    assert cli.main(["render", str(path), "-o", str(tmp_path / "x.png"), "--chunk", "2"]) == 1
    assert "write an .exr" in capsys.readouterr().err


def test_scene_identity():
    a, b = scenes.cornell_box(width=16, height=16), scenes.cornell_box(width=16, height=16)
    assert merge.scene_identity(a) == merge.scene_identity(b)
    b.world["color"] = [0.1, 0.0, 0.0]
    assert merge.scene_identity(a) != merge.scene_identity(b)
    assert merge.scene_identity(a, 8) != merge.scene_identity(a, 16)


def test_scene_identity_sees_strands_and_grids():
    """Two chunks of scenes whose hair or Volume object differs must not merge; a scene without
    either keeps the identity it had before strands and grids were hashed (the earlier code's
    digest, recomputed here), so chunks rendered then still merge."""
    import numpy as np
    import hashlib
    a, b = scenes.cornell_box(width=16, height=16), scenes.cornell_box(width=16, height=16)
    old = hashlib.blake2b(digest_size=16)  # the identity as it was computed before
    for part in ("film", "camera", "world", "materials", "textures", "meshes", "lights"):
        old.update(part.encode())
        merge._feed(old, getattr(a, part))
    merge._feed(old, {"max_depth": None})
    before = merge.scene_identity(a)
    assert before == old.hexdigest()
    pts = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.1], [0.0, 0.0, 0.2]], np.float32)
    for sc in (a, b):
        sc.add_curves(pts, np.full(3, 0.01, np.float32), np.array([0, 3], np.int32))
    assert merge.scene_identity(a) == merge.scene_identity(b) != before
    b.curves[0]["points"] = pts + np.float32(0.01)
    assert merge.scene_identity(a) != merge.scene_identity(b)
    c, d = scenes.cornell_box(width=16, height=16), scenes.cornell_box(width=16, height=16)
    c.add_grid(np.ones((2, 2, 2), np.float32))
    d.add_grid(np.full((2, 2, 2), 2.0, np.float32))
    assert merge.scene_identity(c) != merge.scene_identity(d)


needs_core = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")


@needs_core
def merged_and_full(tmp_path, seed_merged=10, seed_full=1000):
    """test_four_chunks_agree_with_one_render's 16 repetitions: 4 chunks of 32 spp rendered
    and merged through the CLI (the merge checked against the chunks' mean), and one render of
    128 spp (python/lantern/testing/fa_python.py measures the comparison with other seeds)."""
    path = tmp_path / "box.lantern"
    scenes.cornell_box(width=32, height=32).save(path)
    merged, full = [], []
    for rep in range(16):
        chunks = []
        for k in range(4):
            out = tmp_path / f"r{rep}_c{k}.exr"
            assert cli.main(["render", str(path), "-o", str(out), "--spp", "32", "-q",
                             "--backend", "cpu", "--seed", str(seed_merged + rep), "--chunk",
                             str(k)]) == 0
            chunks.append(out)
        out = tmp_path / f"r{rep}.exr"
        assert cli.main(["merge", *map(str, chunks), "-o", str(out)]) == 0
        images = [imageio.read_image(c) for c in chunks]
        assert not np.array_equal(images[0], images[1])  # chunks hold different samples
        m = imageio.read_image(out)
        np.testing.assert_allclose(m, np.mean(images, axis=0), rtol=1e-5, atol=1e-6)
        merged.append(m)
        ref = tmp_path / f"full{rep}.exr"
        assert cli.main(["render", str(path), "-o", str(ref), "--spp", "128", "-q",
                         "--backend", "cpu", "--seed", str(seed_full + rep)]) == 0
        full.append(imageio.read_image(ref))
    return merged, full


def test_four_chunks_agree_with_one_render(tmp_path):
    """Four 32-spp chunks merged agree with a 128-spp render over 16 independent repetitions:
    lantern.metrics.assert_agreement (tests/README.md), with its 1 % / 5 % negative controls."""
    merged, full = merged_and_full(tmp_path)
    assert exr.read_exr(tmp_path / "r0.exr").metadata[merge.SPP] == 128
    metrics.assert_agreement("4 merged chunks vs one render", [m[..., :3] for m in merged],
                             [f[..., :3] for f in full], block=8)
