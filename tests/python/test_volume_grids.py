"""Volume objects' grids through the Python scene (docs/volumes.md): an OpenVDB file written by
the core (lantern._core.vdb_write) and read back (lantern.read_vdb: the block, its transform);
an absorbing smoke box of that grid rendered by pt against Beer-Lambert along its ramp (8 seeds'
standard error, a 2 % control); the scene file's round trip (same image, bit for bit); bad
input: a missing file, a missing grid, a grid over the voxel limit, NaN / negative / enormous
voxels (a finite image and warnings), a density_grid out of range."""
import math

import numpy as np
import pytest

import lantern
from lantern.scenes import aabb_mesh

pytestmark = [
    pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable"),
    pytest.mark.skipif(not lantern.vdb_available(), reason="Lantern built without OpenVDB")]

SIGMA_A = [0.2, 0.5, 1.0]
N = (11, 21, 21)   # nz, ny, nx
VOXEL = 0.1


def ramp_vdb(path):
    """A grid whose density is -z in the world (voxel k at z = -3 + 0.1 k), its index map
    (voxel size 0.1, origin (-1, -1, -3)) in the file; written with zero borders so that the
    active block starts at index (1, 1, 1)."""
    nz, ny, nx = N
    k = np.arange(nz, dtype=np.float32)
    vox = np.zeros((nz + 2, ny + 2, nx + 2), np.float32)
    vox[1:-1, 1:-1, 1:-1] = (3.0 - VOXEL * k)[:, None, None]
    m = np.array([[VOXEL, 0, 0, -1 - VOXEL], [0, VOXEL, 0, -1 - VOXEL],
                  [0, 0, VOXEL, -3 - VOXEL], [0, 0, 0, 1]], np.float64)
    lantern._core.vdb_write(str(path), "density", vox, m)


def smoke_scene(voxels, index_to_world):
    s = lantern.Scene()
    s.film.update(width=8, height=8)
    s.camera = {"type": "orthographic", "screen": [-0.1, 0.1, -0.1, 0.1], "clip": [0.0, 100.0]}
    s.world = {"color": [1.0, 1.0, 1.0]}
    g = s.add_grid(voxels, index_to_world, name="smoke:density")
    m = s.add_material("smoke")
    s.materials[m].update(volume={"sigma_a": SIGMA_A}, volume_only=True, density_grid=g)
    p, idx = aabb_mesh((-0.95, -0.95, -2.999), (0.95, 0.95, -2.001))
    s.add_mesh(p, idx, material=m)
    return s


def test_vdb_file_reads_back_its_block_and_transform(tmp_path):
    path = tmp_path / "ramp.vdb"
    ramp_vdb(path)
    grids = lantern._core.vdb_grids(str(path))
    assert [(g["name"], g["type"]) for g in grids] == [("density", "float")]
    assert grids[0]["bbox_min"] == (1, 1, 1) and grids[0]["dense_voxels"] == N[0] * N[1] * N[2]
    vox, m, background = lantern.read_vdb(path, "density")
    assert vox.shape == N and background == 0.0
    assert np.allclose(vox[:, 0, 0], 3.0 - VOXEL * np.arange(N[0]))
    # the block's voxel (0, 0, 0) is at the world's (-1, -1, -3)
    assert np.allclose(m @ [0, 0, 0, 1], [-1, -1, -3, 1], atol=1e-6)
    assert np.allclose(m @ [1, 2, 3, 1], [-0.9, -0.8, -2.7, 1], atol=1e-6)


def test_absorbing_vdb_smoke_is_beer_lambert(tmp_path):
    path = tmp_path / "ramp.vdb"
    ramp_vdb(path)
    vox, m, _ = lantern.read_vdb(path, "density")
    s = smoke_scene(vox, m)
    means = []
    for seed in range(1, 9):
        sess = lantern.Session(s, integrator="pt", max_depth=1, seed=seed, spp_per_iteration=512,
                               threads=1)
        sess.step()
        assert not [w for w in sess.stats.get("warnings", []) if "grid" in w]
        means.append(np.asarray(sess.image(), np.float64)[..., :3].reshape(-1, 3).mean(axis=0))
    means = np.array(means)
    mean, se = means.mean(axis=0), means.std(axis=0, ddof=1) / math.sqrt(len(means)) + 1e-7
    a, b = -2.999, -2.001
    integral = (b - a) * -(a + b) / 2   # of the density -z over the chord
    want = np.exp(-np.array(SIGMA_A) * integral)
    assert np.all(np.abs(mean - want) < 5 * se), (mean, want, se)
    control = np.exp(-np.array(SIGMA_A) * integral * 1.02)   # 2 % more extinction
    assert np.all(np.abs(mean - control) > 5 * se), (mean, control, se)


def test_scene_file_keeps_grids(tmp_path):
    path = tmp_path / "ramp.vdb"
    ramp_vdb(path)
    vox, m, _ = lantern.read_vdb(path, "density")
    s = smoke_scene(vox, m)
    s.save(tmp_path / "smoke.lantern")
    t = lantern.load_scene(tmp_path / "smoke.lantern")
    assert len(t.grids) == 1 and t.materials[0]["density_grid"] == 0
    assert np.array_equal(t.grids[0]["voxels"], s.grids[0]["voxels"])
    a = lantern.render(s, spp=4, integrator="pt", max_depth=1, seed=3, threads=1)
    b = lantern.render(t, spp=4, integrator="pt", max_depth=1, seed=3, threads=1)
    assert np.array_equal(np.asarray(a), np.asarray(b))
    # negative control: the scene without its grid renders differently
    t.materials[0].pop("density_grid")
    c = lantern.render(t, spp=4, integrator="pt", max_depth=1, seed=3, threads=1)
    assert not np.array_equal(np.asarray(a), np.asarray(c))


def test_bad_vdb_input_says_what(tmp_path):
    with pytest.raises(RuntimeError, match="cannot be read"):
        lantern.read_vdb(tmp_path / "missing.vdb", "density")
    path = tmp_path / "ramp.vdb"
    ramp_vdb(path)
    with pytest.raises(RuntimeError, match="no grid named 'flame'.*'density'"):
        lantern.read_vdb(path, "flame")
    with pytest.raises(RuntimeError, match="above the limit of 1000 voxels"):
        lantern.read_vdb(path, "density", max_voxels=1000)
    # billions of voxels: two voxels 2^20 apart, refused from the metadata (no allocation)
    huge = tmp_path / "huge.vdb"
    lantern._core.vdb_write_sparse(str(huge), "density",
                                   np.array([[0, 0, 0], [1 << 20] * 3], np.int32),
                                   np.array([1.0, 2.0], np.float32), np.eye(4))
    with pytest.raises(RuntimeError, match="above the limit"):
        lantern.read_vdb(huge, "density")
    s = smoke_scene(np.ones((2, 2, 2), np.float32), np.eye(4))
    s.materials[0]["density_grid"] = 3
    with pytest.raises(ValueError, match="density_grid: grid 3 out of range"):
        s.validate()


def test_nan_negative_and_enormous_voxels_render_finite(tmp_path):
    vox = np.full((4, 4, 4), 2.0, np.float32)
    vox[0, 0, 0], vox[1, 1, 1], vox[2, 2, 2] = np.nan, -5.0, np.inf
    s = smoke_scene(vox, np.array([[0.5, 0, 0, -1], [0, 0.5, 0, -1], [0, 0, 0.5, -3.0],
                                   [0, 0, 0, 1]]))
    sess = lantern.Session(s, integrator="pt", max_depth=2, seed=1, spp_per_iteration=4,
                           threads=1)
    sess.step()
    assert np.isfinite(np.asarray(sess.image())).all()
    text = " ".join(sess.warnings) if hasattr(sess, "warnings") else str(sess.stats)
    assert "NaN voxels" in text and "above 1e9" in text, text
