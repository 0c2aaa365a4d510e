"""Integrator "lt" (light tracing to the camera) against "pt": the same images, statistically.

K independent seeds per integrator; per 8x8 block and channel z = (mean_lt - mean_pt) /
sqrt(se_lt^2 + se_pt^2) with standard errors from the spread of the seeds; the worst |z| must
stay below the Bonferroni threshold for alpha = 1e-3 over all blocks (Student t, K - 1 dof)."""
import time

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

K = 8          # independent renders per integrator (t statistics with K - 1 = 7 dof)
SIZE = 32      # 32x32 pixels -> 4x4 blocks of 8x8, 3 channels: 48 z-scores; Bonferroni over
               # 48 tests at alpha 1e-3 with 7 dof puts the threshold near 10 (printed)


@pytest.fixture(scope="module")
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    from lantern import _core
    return _core


def cornell_area():
    return scenes.cornell_box(SIZE, SIZE)  # visible rectangle area light (front only)


def cornell_point():
    scene = scenes.cornell_box(SIZE, SIZE)
    scene.lights = []
    # radius 0: a true point (delta position) whatever soft_falloff says
    scene.add_light("point", position=[0.2, -0.1, 1.5], power=[30.0, 25.0, 20.0], radius=0.0)
    return scene


def cornell_mesh_light():
    scene = scenes.cornell_box(SIZE, SIZE)
    scene.lights = []
    glow = scene.add_material("glow", base_color=(0.5, 0.5, 0.5), emission=(6.0, 5.0, 4.0))
    # a horizontal quad: the camera sees its underside, its upper side lights the ceiling
    pos = np.array([[-0.3, -0.2, 1.5], [0.3, -0.2, 1.5], [0.3, 0.3, 1.5], [-0.3, 0.3, 1.5]],
                   dtype=np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    scene.add_mesh(pos, idx, material=glow, name="panel")
    return scene


def cornell_spot():
    scene = scenes.cornell_box(SIZE, SIZE)
    scene.lights = []
    m = np.eye(4)
    m[:3, 3] = (0.1, 0.2, 1.9)  # the cone points down (local -Z)
    scene.add_light("spot", to_world=m.tolist(), power=[40.0] * 3, radius=0.0, spot_size=1.2,
                    spot_blend=0.3)
    return scene


def cornell_sphere():
    scene = scenes.cornell_box(SIZE, SIZE)
    scene.lights = []
    scene.add_light("point", position=[0.2, 0.0, 1.5], power=[30.0] * 3, radius=0.15,
                    soft_falloff=False, visible_camera=True)
    return scene


def cornell_sun():
    scene = scenes.cornell_box(SIZE, SIZE)  # the sun shines in through the open front
    scene.lights = []
    scene.add_light("sun", direction=[0.2, 0.6, -0.3], strength=[2.0] * 3, angle=0.1)
    return scene


def renders(scene, integrator, spp, seed0, backend="cpu"):
    return [lantern.render(scene, spp=spp, seed=seed0 + k, integrator=integrator,
                           backend=backend, max_depth=8) for k in range(K)]


@pytest.mark.parametrize("make", [cornell_area, cornell_point, cornell_mesh_light, cornell_spot,
                                  cornell_sphere, cornell_sun])
def test_lt_matches_pt(core, make, backend):
    scene = make()
    t0 = time.perf_counter()
    pt = renders(scene, "pt", 512, 1000, backend=backend)
    # lt is noisier where the emitter itself is seen
    lt = renders(scene, "lt", 256, 2000, backend=backend)
    cmp = metrics.compare_sets(lt, pt, block=8)
    thr = cmp.threshold(1e-3)
    mean_pt = np.stack(pt).mean(axis=(0, 1, 2))
    mean_lt = np.stack(lt).mean(axis=(0, 1, 2))
    rel = np.abs(mean_lt / mean_pt - 1.0)
    means = [np.stack(x).mean(axis=(1, 2)) for x in (lt, pt)]
    se_mean = np.sqrt(sum(m.var(axis=0, ddof=1) / K for m in means))
    print(f"{make.__name__}: {cmp.n} block z-scores, worst |z| = {cmp.worst:.2f}, threshold "
          f"{thr:.2f} (Bonferroni alpha 1e-3, dof {cmp.dof}); image means lt {mean_lt} pt "
          f"{mean_pt} (rel. diff {rel.max():.4f}, z {np.max(np.abs(mean_lt - mean_pt) / se_mean):.2f}); {time.perf_counter() - t0:.1f} s")
    assert all(np.isfinite(x).all() for x in lt)
    assert cmp.passed(1e-3), str(cmp)
    assert (rel < 0.01).all(), (mean_lt, mean_pt)


def test_lt_same_bits_any_thread_count(core):
    scene = scenes.cornell_box(16, 16)
    a = lantern.render(scene, spp=4, seed=7, integrator="lt", backend="cpu", threads=1)
    b = lantern.render(scene, spp=4, seed=7, integrator="lt", backend="cpu", threads=2)
    c = lantern.render(scene, spp=4, seed=8, integrator="lt", backend="cpu", threads=2)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_lt_refuses_soft_falloff_lights(core, backend):
    scene = scenes.cornell_box(8, 8)
    scene.add_light("point", position=[0.0, 0.0, 1.0], power=[10.0] * 3, radius=0.1,
                    soft_falloff=True)
    with pytest.raises(ValueError, match=r"lights\[1\].*soft_falloff"):
        lantern.Session(scene, integrator="lt", backend="cpu")
    # the same light as a sphere (soft_falloff off) or a point (radius 0) renders
    scene.lights[1]["soft_falloff"] = False
    assert lantern.render(scene, spp=1, integrator="lt", backend="cpu").mean() > 0
