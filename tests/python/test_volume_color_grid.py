"""Colour grids of Volume objects (docs/volumes.md, issue 29): a vec3 grid (Principled Volume's
Color Attribute) written by the core's OpenVDB writer (lantern._core.vdb_write_list, Vec3S and
Vec3D) and read back (lantern.read_vdb: the block of 3 floats per voxel, its transform); an
absorbing smoke whose colour ramps red to blue across the image rendered by pt against
Beer-Lambert per pixel (absorption max(1 - Color c, 0) x Density, the trilinear colour exact on
a linear ramp; 6 seeds' standard error, the colour ignored as control), the scene file's round
trip; bad input: a colour grid with NaN and negative components (a finite image, a warning by
the grid's name), a vec3 grid as a density and a float grid as a colour (messages), the colour
grid over the limit (refused from the metadata)."""
import math

import numpy as np
import pytest

import lantern
import lantern._core
from lantern.scenes import aabb_mesh

pytestmark = [
    pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable"),
    pytest.mark.skipif(not lantern.vdb_available(), reason="Lantern built without OpenVDB")]

N = (11, 6, 15)      # nz, ny, nx
VOXEL = 0.1
ABSORB = [1.5, 1.0, 2.0]   # colour absorption per unit density (1/m)
BASE = [0.9, 0.8, 1.0]     # the Color socket


def index_to_world():
    """voxel (i, j, k) centred at (-0.7 + 0.1 i, -0.25 + 0.1 j, -3 + 0.1 k)."""
    return np.array([[VOXEL, 0, 0, -0.7], [0, VOXEL, 0, -0.25], [0, 0, VOXEL, -3.0],
                     [0, 0, 0, 1]], np.float64)


def ramp_colour():
    """(nz, ny, nx, 3): red rising 0 -> 1 along x from -0.5 to 0.5 (constant beyond), blue
    falling 1 -> 0, green 0.5."""
    nz, ny, nx = N
    u = ramp(centres())
    col = np.zeros((nz, ny, nx, 3), np.float32)
    col[..., 0] = u
    col[..., 1] = 0.5
    col[..., 2] = 1.0 - u
    return col


def centres():
    return -0.7 + VOXEL * np.arange(N[2])


def ramp(x):
    return np.clip(x + 0.5, 0.0, 1.0).astype(np.float32)


def write_smoke(path, colour=None, double=False):
    m = index_to_world()
    lantern._core.vdb_write_list(str(path), [
        {"name": "density", "voxels": np.ones(N, np.float32), "index_to_object": m},
        {"name": "color", "voxels": ramp_colour() if colour is None else colour,
         "index_to_object": m, "double": double}])


def smoke_scene(path, with_colour=True):
    den, m, _ = lantern.read_vdb(path, "density")
    col, mc, _ = lantern.read_vdb(path, "color")
    s = lantern.Scene()
    s.film.update(width=10, height=2)
    s.camera = {"type": "orthographic", "screen": [-0.5, 0.5, -0.1, 0.1], "clip": [0.0, 100.0]}
    s.world = {"color": [1.0, 1.0, 1.0]}
    g = s.add_grid(den, m, name="smoke:density")
    mat = s.add_material("smoke")
    vol = {"sigma_a": [0.0] * 3, "color_absorb": ABSORB, "color_base": BASE}
    s.materials[mat].update(volume=vol, volume_only=True, density_grid=g)
    if with_colour:
        s.materials[mat]["color_grid"] = s.add_grid(col, mc, name="smoke:color")
    p, idx = aabb_mesh((-0.65, -0.2, -2.75), (0.65, 0.2, -2.25))
    s.add_mesh(p, idx, material=mat)
    return s


def expected(colour_on=True):
    """Beer-Lambert per pixel (10 columns over x in [-0.5, 0.5]), the colour linear in x
    between the voxel centres (trilinear), the chord 0.5 m; averaged over each pixel with its
    filter (Blackman-Harris 1.5 pixels wide, the film's default)."""
    t = (np.arange(3000) + 0.5) / 3000
    w = 0.35875 - 0.48829 * np.cos(2 * np.pi * t) + 0.14128 * np.cos(4 * np.pi * t) - \
        0.01168 * np.cos(6 * np.pi * t)
    out = []
    for px in range(10):
        x = -0.5 + (px + 0.5 + (t - 0.5) * 1.5) * 0.1
        u = np.interp(x, centres(), ramp(centres()))
        c = np.stack([u, np.full_like(u, 0.5), 1.0 - u], axis=1) if colour_on else \
            np.ones((len(u), 3))
        k = np.maximum(1.0 - np.array(BASE) * c, 0.0) * np.array(ABSORB)
        out.append((np.exp(-k * 0.5) * w[:, None]).sum(axis=0) / w.sum())
    return np.array(out)


def test_vec3_grids_read_back(tmp_path):
    path = tmp_path / "smoke.vdb"
    write_smoke(path)
    types = {g["name"]: g["type"] for g in lantern._core.vdb_grids(str(path))}
    assert types == {"density": "float", "color": "vec3s"}
    col, m, background = lantern.read_vdb(path, "color")
    assert col.shape == N + (3,) and col.dtype == np.float32 and background == 0.0
    assert np.array_equal(col, ramp_colour())   # the values at the voxel centres
    assert np.allclose(m, index_to_world(), atol=1e-7)
    # Vec3D reads as floats
    write_smoke(tmp_path / "d.vdb", double=True)
    types = {g["name"]: g["type"] for g in lantern._core.vdb_grids(str(tmp_path / "d.vdb"))}
    assert types["color"] == "vec3d"
    assert np.array_equal(lantern.read_vdb(tmp_path / "d.vdb", "color")[0], ramp_colour())
    # the memory check counts 3 floats a voxel, from the metadata
    n = N[0] * N[1] * N[2]
    with pytest.raises(RuntimeError, match="3 floats each"):
        lantern.read_vdb(path, "color", max_voxels=3 * n - 1)
    assert lantern.read_vdb(path, "color", max_voxels=3 * n)[0].shape == N + (3,)


def _means(scene, seeds, spp=256):
    imgs = []
    for seed in seeds:
        sess = lantern.Session(scene, integrator="pt", max_depth=1, seed=seed,
                               spp_per_iteration=spp, threads=1)
        sess.step()
        assert not [w for w in sess.warnings if "grid" in w]
        imgs.append(np.asarray(sess.image(), np.float64)[..., :3].mean(axis=0))
    return np.array(imgs)   # (seeds, 10 columns, 3)


def test_colour_ramp_is_beer_lambert_per_column(tmp_path):
    path = tmp_path / "smoke.vdb"
    write_smoke(path)
    imgs = _means(smoke_scene(path), range(1, 7))
    mean = imgs.mean(axis=0)
    se = imgs.std(axis=0, ddof=1) / math.sqrt(len(imgs)) + 1e-4
    want = expected()
    z = np.abs(mean - want) / se
    assert z.max() < 5.0, (mean, want, se)
    # controls: the colour ignored (the Color socket alone), and the ramp mirrored
    assert (np.abs(mean - expected(False)) / se).max() > 20.0
    assert (np.abs(mean - want[::-1]) / se).max() > 20.0


def test_scene_file_keeps_the_colour_grid(tmp_path):
    path = tmp_path / "smoke.vdb"
    write_smoke(path)
    s = smoke_scene(path)
    s.save(tmp_path / "smoke.lantern")
    t = lantern.load_scene(tmp_path / "smoke.lantern")
    assert t.grids[1]["voxels"].shape == N + (3,) and t.materials[0]["color_grid"] == 1
    a = lantern.render(s, spp=4, integrator="pt", max_depth=1, seed=3, threads=1)
    b = lantern.render(t, spp=4, integrator="pt", max_depth=1, seed=3, threads=1)
    assert np.array_equal(np.asarray(a), np.asarray(b))
    t.materials[0].pop("color_grid")   # control: without it the image differs
    c = lantern.render(t, spp=4, integrator="pt", max_depth=1, seed=3, threads=1)
    assert not np.array_equal(np.asarray(a), np.asarray(c))


def test_bad_colour_grids_say_what(tmp_path):
    col = ramp_colour()
    col[0, 0, 0] = [np.nan, -1.0, 0.5]
    col[1, 1, 1, 2] = -0.5
    path = tmp_path / "bad.vdb"
    write_smoke(path, colour=col)
    s = smoke_scene(path)
    sess = lantern.Session(s, integrator="pt", max_depth=1, seed=1, spp_per_iteration=4,
                           threads=1)
    sess.step()
    warnings = list(sess.warnings)
    assert any("smoke:color" in w and "1 NaN colour" in w for w in warnings), warnings
    assert any("smoke:color" in w and "2 negative colour" in w for w in warnings), warnings
    assert np.all(np.isfinite(np.asarray(sess.image())))
    # a vec3 grid as the density, a float grid as the colour: messages naming the grid
    t = smoke_scene(path)
    t.materials[0]["density_grid"] = 1
    t.materials[0]["color_grid"] = 0
    with pytest.raises(ValueError, match="smoke:color' is a colour"):
        lantern.render(t, spp=1, threads=1)
    t.materials[0]["density_grid"] = 0
    with pytest.raises(ValueError, match="smoke:density' is a float grid"):
        lantern.render(t, spp=1, threads=1)
