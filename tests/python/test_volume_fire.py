"""Fire in Volume objects' grids through the Python scene (docs/volumes.md): an absorbing box
whose density, temperature and flame grids are constant across the view and ramp along it,
rendered by pt, against the emission integral int T(s) e(s) ds by quadrature, e from the
formulas of Principled Volume (sigma T^4 x the blackbody colour of T from Planck's law against
the CIE observer, addon/export/node_spectral.py, tinted, for each voxel's T and linear between
voxels; the flame grid times its emission; the constant emission); 8 seeds' standard error, the temperature 5 % off and the flame grid left out
as controls. The scene file keeps the fire grids (same image, bit for bit); bad input: NaN and
negative temperatures render finite with a warning naming the grid, a fire grid out of range or
without a density grid is refused."""
import importlib
import math
import os
import sys
import types

import numpy as np
import pytest

import lantern
from lantern.scenes import aabb_mesh

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable")

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
N = (11, 21, 21)   # nz, ny, nx: voxel size 0.1 over x, y -1..1, z -3..-2
SIGMA_A = np.array([0.5, 1.0, 2.0])
T_SOCKET = 1500.0          # the temperature grid runs 1 .. 2: 1500 .. 3000 K
TINT = np.array([1.0, 0.9, 0.8])
FLAME = 0.7                # the flame grid's value
FLAME_E = np.array([0.3, 0.2, 0.1])
E0 = np.array([0.01, 0.02, 0.04])
SIGMA_BB = 5.670373e-8 * 1e-6 / math.pi


def _spectral():
    """addon/export/node_spectral.py without Blender (its package is the add-on's export/)."""
    if "export.node_spectral" not in sys.modules:
        pkg = types.ModuleType("export")
        pkg.__path__ = [os.path.join(ROOT, "addon", "export")]
        sys.modules.setdefault("export", pkg)
    return importlib.import_module("export.node_spectral")


def fire_scene(temperature=T_SOCKET, flame=True, temps=None):
    nz, ny, nx = N
    m = np.array([[0.1, 0, 0, -1], [0, 0.1, 0, -1], [0, 0, 0.1, -3], [0, 0, 0, 1]], np.float64)
    k = np.arange(nz, dtype=np.float32)
    if temps is None:
        temps = np.broadcast_to((1.0 + 0.1 * k)[:, None, None], N).astype(np.float32)
    s = lantern.Scene()
    s.film.update(width=8, height=8)
    s.camera = {"type": "orthographic", "screen": [-0.1, 0.1, -0.1, 0.1], "clip": [0.0, 100.0]}
    s.world = {"color": [0.0, 0.0, 0.0]}
    g = s.add_grid(np.ones(N, np.float32), m, name="fire:density")
    t = s.add_grid(np.ascontiguousarray(temps), m, name="fire:temperature")
    f = s.add_grid(np.full(N, FLAME, np.float32), m, name="fire:flame")
    mat = s.add_material("fire")
    vol = {"sigma_a": SIGMA_A.tolist(), "emission": E0.tolist(), "blackbody_intensity": 1.0,
           "temperature": temperature, "blackbody_tint": TINT.tolist(),
           "flame_emission": FLAME_E.tolist()}
    s.materials[mat].update(volume=vol, volume_only=True, density_grid=g, temperature_grid=t)
    if flame:
        s.materials[mat]["flame_grid"] = f
    p, idx = aabb_mesh((-0.95, -0.95, -2.999), (0.95, 0.95, -2.001))
    s.add_mesh(p, idx, material=mat)
    return s


def emission_integral(temperature=T_SOCKET, flame=True, steps=4000):
    """int over the chord of exp(-sigma_a s) e(z(s)) ds, the midpoint rule; the blackbody is
    that of each voxel's temperature (voxel k at z = -3 + 0.1 k: 1 + 0.1 k times the socket),
    linear between voxel centres (Cycles' stochastic lookup's expectation)."""
    sp = _spectral()
    knots = [temperature * (1.0 + 0.1 * k) for k in range(N[0])]
    bb = [TINT * SIGMA_BB * t ** 4 * np.array(sp.blackbody_rgb(t)) for t in knots]  # unclamped
    a, b = -2.999, -2.001
    ds = (b - a) / steps
    total = np.zeros(3)
    for i in range(steps):
        s = (i + 0.5) * ds
        z = b - s
        u = (z + 3.0) / 0.1
        k = min(int(u), N[0] - 2)
        e = E0 + (FLAME * FLAME_E if flame else 0.0) + bb[k] + (bb[k + 1] - bb[k]) * (u - k)
        total += np.exp(-SIGMA_A * s) * e * ds
    return total


def _render(scene, seeds=8, spp=256):
    means, warnings = [], []
    for seed in range(1, seeds + 1):
        sess = lantern.Session(scene, integrator="pt", max_depth=1, seed=seed,
                               spp_per_iteration=spp, threads=1)
        sess.step()
        warnings += list(sess.warnings)
        means.append(np.asarray(sess.image(), np.float64)[..., :3].reshape(-1, 3).mean(axis=0))
    means = np.array(means)
    return means.mean(axis=0), means.std(axis=0, ddof=1) / math.sqrt(len(means)), warnings


def test_fire_grids_emit_the_emission_integral():
    mean, se, warnings = _render(fire_scene())
    assert not warnings, warnings
    want = emission_integral()
    tol = 4.5 * se + 2e-3 * want   # 2e-3: the table's linear steps in 1/T (256 knots)
    print("fire", mean, "want", want, "se", se)
    assert np.all(np.abs(mean - want) < tol), (mean, want, se)
    # controls: the temperature 5 % off, the flame grid left out
    for ctl in (emission_integral(temperature=T_SOCKET * 1.05), emission_integral(flame=False)):
        assert np.any(np.abs(mean - ctl) > 4.5 * se + 2e-3 * ctl), (mean, ctl, se)


def test_without_the_flame_grid_the_render_tells_it():
    mean, se, _ = _render(fire_scene(flame=False), seeds=4, spp=128)
    want = emission_integral(flame=False)
    assert np.all(np.abs(mean - want) < 4.5 * se + 2e-3 * want), (mean, want, se)


def test_scene_file_keeps_the_fire_grids(tmp_path):
    s = fire_scene()
    s.save(tmp_path / "fire.lantern")
    t = lantern.load_scene(tmp_path / "fire.lantern")
    assert t.materials[0]["temperature_grid"] == 1 and t.materials[0]["flame_grid"] == 2
    assert t.materials[0]["volume"]["temperature"] == T_SOCKET
    a = lantern.render(s, spp=4, integrator="pt", max_depth=1, seed=3, threads=1)
    b = lantern.render(t, spp=4, integrator="pt", max_depth=1, seed=3, threads=1)
    assert np.array_equal(np.asarray(a), np.asarray(b))
    t.materials[0].pop("temperature_grid")   # control: without it the image differs
    c = lantern.render(t, spp=4, integrator="pt", max_depth=1, seed=3, threads=1)
    assert not np.array_equal(np.asarray(a), np.asarray(c))


def test_bad_temperatures_render_finite_and_warn():
    temps = np.broadcast_to(np.float32(1.5), N).copy()
    temps[0, 0, 0], temps[3, 10, 10], temps[5, 4, 4] = np.nan, -400.0, np.inf
    sess = lantern.Session(fire_scene(temps=temps), integrator="pt", max_depth=2, seed=1,
                           spp_per_iteration=8, threads=1)
    sess.step()
    assert np.isfinite(np.asarray(sess.image())).all()
    said = [w for w in sess.warnings if "fire:temperature" in w]
    assert any("NaN" in w for w in said) and any("1e9" in w for w in said), said
    s = fire_scene()
    s.materials[0]["flame_grid"] = 7
    with pytest.raises(ValueError, match="flame_grid"):
        s.validate()
    s = fire_scene()
    s.materials[0].pop("density_grid")
    with pytest.raises(ValueError, match="need a density_grid"):
        s.validate()
    s = fire_scene()
    s.materials[0]["volume"]["temperature"] = -5.0
    with pytest.raises(ValueError, match="temperature"):
        s.validate()
