"""Transparent film (lantern.film): the world is not drawn but still lights; alpha is the
coverage by geometry, with the camera's pixel filter; a surface of alpha a covers a; a shadow
catcher shows only the shadow it receives, as alpha."""
import numpy as np
import pytest

import lantern
from lantern import metrics
from lantern.film import coverage_scene, render_alpha


@pytest.fixture(scope="module")
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")
    from lantern import _core
    return _core


def half_plane_scene(alpha=1.0, size=32):
    """Orthographic camera looking down -Z at a plane covering x < 0 (the left half)."""
    scene = lantern.Scene()
    scene.film.update(width=size, height=size, transparent=True)
    scene.camera.update(type="orthographic", screen=[-1.0, 1.0, -1.0, 1.0], clip=[0.01, 10.0])
    scene.camera["to_world"] = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 2], [0, 0, 0, 1]]
    m = scene.add_material("grey", base_color=(0.5, 0.5, 0.5), alpha=alpha)
    scene.add_mesh(np.array([[-3, -3, 0], [0, -3, 0], [0, 3, 0], [-3, 3, 0]], np.float32),
                   np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=m, name="plane")
    scene.world = {"color": [0.8, 0.8, 0.8]}
    return scene


def test_world_hidden_but_lights(core):
    scene = half_plane_scene()
    img = lantern.render(scene, spp=64, seed=1)
    assert img[:, -8:].max() == 0.0                # the world is not drawn
    lit = img[:, :8].mean()
    # a grey Lambert plane under a uniform world of 0.8 (one bounce: it sees no geometry)
    assert abs(lit / (0.5 * 0.8) - 1.0) < 0.03, lit


@pytest.mark.parametrize("alpha", [1.0, 0.3])
def test_alpha_is_coverage(core, alpha):
    scene = half_plane_scene(alpha=alpha)
    a = [render_alpha(scene, spp=64, seed=k) for k in range(6)]
    assert a[0].shape == (32, 32)
    left = np.stack([x[:, :12] for x in a])        # fully covered (the filter spans 3 px)
    right = np.stack([x[:, -12:] for x in a])
    assert right.max() == 0.0
    cmp = metrics.compare_sets(list(left), [alpha], block=4, se_floor=1e-6)
    print(f"alpha {alpha}: {cmp}")
    assert cmp.passed(1e-3), str(cmp)
    # the edge column: half covered, through the filter (symmetric about the edge)
    edge = np.mean([x[:, 15:17].mean() for x in a])
    assert abs(edge - 0.5 * alpha) < 0.05 * alpha + 0.02, edge


def test_opaque_film_alpha_is_one(core):
    scene = half_plane_scene()
    scene.film["transparent"] = False
    assert (render_alpha(scene, spp=1) == 1.0).all()
    cov = coverage_scene(half_plane_scene(alpha=0.3))
    assert cov.lights == [] and cov.world["color"] == [0.0, 0.0, 0.0]
    assert cov.materials[0]["alpha"] == 0.3 and cov.materials[0]["emission"] == [1.0, 0.0, 0.0]


def holdout_scene():
    """half_plane_scene with a holdout quad (material "holdout") over its middle, 0.5 above the
    plane: it cuts the film and is black where the camera sees it, and it shadows the plane."""
    scene = half_plane_scene()
    h = scene.add_material("cut", base_color=(0.5, 0.5, 0.5))
    scene.materials[h]["holdout"] = True
    scene.add_mesh(np.array([[-1.5, -0.5, 0.5], [-0.5, -0.5, 0.5], [-0.5, 0.5, 0.5],
                             [-1.5, 0.5, 0.5]], np.float32),
                   np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=h, name="cut")
    return scene


def test_holdout_cuts_the_film_and_still_shadows(core):
    """Where the camera sees a holdout: colour 0, alpha 0; where it sees the plane, the holdout
    still occludes the world (the plane is darker under it than far from it)."""
    scene = holdout_scene()
    img = lantern.render(scene, spp=64, seed=1, integrator="pt")
    alpha = render_alpha(scene, spp=64, seed=1)
    # the screen spans [-1, 1] over 32 pixels: the quad covers columns 0..7, rows 8..23
    assert img[10:22, :6].max() == 0.0 and alpha[10:22, :6].max() == 0.0
    assert alpha[:4, :12].min() > 0.999 and alpha[-4:, :12].min() > 0.999
    beside = img[12:20, 8:10].mean()             # the plane right next to the holdout's edge
    far = img[:4, 2:12].mean()
    assert far > 0.3 and beside < 0.9 * far, (beside, far)
    # without "holdout" the quad renders as a grey surface and covers the film
    scene.materials[1]["holdout"] = False
    img2 = lantern.render(scene, spp=16, seed=1, integrator="pt")
    assert img2[10:22, :6].mean() > 0.05
    assert render_alpha(scene, spp=16, seed=1)[10:22, :6].min() > 0.999


def catcher_scene(wall):
    """half_plane_scene with the plane a shadow catcher; `wall`: a black vertical wall at
    x = -0.5 (edge-on to the camera, so unseen), 100 m high and long: from every point of the
    plane it hides the half of the uniform world towards it, a shadow of 1/2 of the cosine-
    weighted sky (less than 1e-3 of the sky shows above or beside it)."""
    scene = half_plane_scene()
    scene.meshes[0]["shadow_catcher"] = True
    if wall:
        b = scene.add_material("black", base_color=(0.0, 0.0, 0.0))
        scene.add_mesh(np.array([[-0.5, -100, 0], [-0.5, 100, 0], [-0.5, 100, 100],
                                 [-0.5, -100, 100]], np.float32),
                       np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=b, name="wall")
    return scene


def test_shadow_catcher_alpha_is_the_shadow(core):
    """The catcher is a matte (colour 0); alone under the world it casts no alpha at all (the
    two catcher renders agree bit for bit); beside the wall its alpha is the shadow, 1/2."""
    scene = catcher_scene(wall=False)
    img = lantern.render(scene, spp=16, seed=1, integrator="pt")
    assert img.max() == 0.0
    assert render_alpha(scene, spp=16, seed=1, max_depth=4).max() == 0.0
    scene = catcher_scene(wall=True)
    assert lantern.render(scene, spp=16, seed=1, integrator="pt").max() == 0.0
    a = [render_alpha(scene, spp=32, seed=k, max_depth=4) for k in range(6)]
    # columns 0..15 see the plane (x < 0) and the wall sits between columns 11 and 12
    inner = np.stack([x[:, [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 13, 14]] for x in a])
    assert np.stack(a)[:, :, -12:].max() == 0.0
    cmp = metrics.compare_sets(list(inner), [0.5], block=4, se_floor=1e-6)
    print(f"shadow catcher beside a wall: {cmp}")
    assert cmp.passed(1e-3), str(cmp)
