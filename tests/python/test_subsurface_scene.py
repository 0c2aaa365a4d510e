"""Random-walk subsurface scattering through the Python scene (docs/subsurface.md): a furnace (a
white principled sphere, subsurface albedo 1, under a uniform white world renders 1 everywhere:
the walk loses nothing and adds nothing) with a grey walk as its negative control; weight 0
against 1 on a slab lit from behind (must differ) and weight 0 equal to no subsurface, bit for
bit; bad input (radius 0, an enormous radius, an open mesh: a message and a finite image); the
bidirectional integrators and lt handing a subsurface mesh with a volume inside to pt with a
warning (volumes around it they render: test_subsurface_media.py). The bidirectional integrators' furnace and their agreement with pt:
test_subsurface_bidir.py; lt's adjoint walk: test_subsurface_lt.py."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes
from lantern.scenes import aabb_mesh

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable")


def sphere_scene(weight=1.0, base=1.0, radius=(0.5, 0.5, 0.5), method="random_walk",
                 level=0.0, size=12, subsurface=True, anisotropy=0.0):
    """A unit icosphere of a principled material seen by a camera 4 m away, world white."""
    s = lantern.Scene()
    s.film.update(width=size, height=size)
    s.look_at((0.0, -4.0, 0.0), (0.0, 0.0, 0.0), fov=32.0)
    s.world = {"color": [1.0, 1.0, 1.0]}
    sss = {"weight": weight, "radius": list(radius), "method": method,
           "anisotropy": anisotropy} if subsurface else None
    m = s.add_material("ball", type="principled", base_color=base, roughness=0.5,
                       specular_level=level, subsurface=sss)
    pos, idx = scenes.icosphere(3)
    s.add_mesh(pos, idx, material=m)
    return s


def _renders(scene, k=6, spp=16, integrator="pt", max_depth=16):
    return [np.asarray(lantern.render(scene, spp=spp, seed=11 + i, max_depth=max_depth,
                                      integrator=integrator, threads=1), np.float64)
            for i in range(k)]


# Radius x Scale giving a mean free path of about 0.5 m in the unit sphere (Random Walk walks
# radius / 4 pi; Skin radius x sqrt(3 (1 - a')), a' = 0.999999 for a white base): walks then
# leave long before the 256-scattering bound that ends a few of them, in Cycles too
FURNACE_RADIUS = {"random_walk": 6.0, "random_walk_skin": 300.0}


@pytest.mark.parametrize("method,g", [("random_walk", 0.0), ("random_walk_skin", 0.0),
                                      ("random_walk", 0.6)])
def test_furnace_white_walk_conserves_energy(method, g):
    # Specular IOR Level 0: the base alone, all of it under the surface; albedo 1 inside a
    # closed convex mesh under a world of 1: every path leaves with its throughput, so 1 (with
    # anisotropy too: Henyey-Greenstein, then the similarity step after 9 scatterings)
    r = FURNACE_RADIUS[method]
    renders = _renders(sphere_scene(method=method, radius=(r, r, r), anisotropy=g))
    metrics.assert_agreement(f"subsurface furnace {method} g {g}", renders, np.ones(3),
                             block=4, bias_cap=1e-3, rel_floor=1e-5)


def test_furnace_grey_walk_is_darker():
    # the furnace's negative control: a base colour of 0.5 absorbs inside, so the same
    # comparison against 1 must fail
    renders = _renders(sphere_scene(base=0.5, radius=(6.0, 6.0, 6.0)), k=4)
    res = metrics.compare_renders(renders, np.ones(3), block=4, bias_cap=1e-3, rel_floor=1e-5)
    assert not res.passed
    inner = np.stack(renders)[:, 4:8, 4:8].mean()
    assert 0.2 < inner < 0.95, inner


def slab_scene(weight, subsurface=True):
    """A 2 x 2 x 0.1 m slab, lit from behind by an emissive quad, seen from the front (an
    orthographic camera); world black: the front shows only light that came through."""
    s = lantern.Scene()
    s.film.update(width=8, height=8)
    s.camera = {"type": "orthographic", "screen": [-0.5, 0.5, -0.5, 0.5], "clip": [0.0, 100.0]}
    s.world = {"color": [0.0, 0.0, 0.0]}
    sss = {"weight": weight, "radius": [0.2, 0.1, 0.05]} if subsurface else None
    m = s.add_material("slab", type="principled", base_color=(0.9, 0.8, 0.7), roughness=0.5,
                       subsurface=sss)
    p, idx = aabb_mesh((-1.0, -1.0, -2.1), (1.0, 1.0, -2.0))
    s.add_mesh(p, idx, material=m)
    e = s.add_material("lamp", base_color=0.0, emission=2.0)
    q = np.array([[-2, -2, -3], [2, -2, -3], [2, 2, -3], [-2, 2, -3]], np.float32)
    s.add_mesh(q, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=e)
    return s


def test_weight_zero_and_one_differ():
    # negative control of the feature: the slab transmits only through its walk
    off = np.stack(_renders(slab_scene(0.0), k=4, spp=8))
    on = np.stack(_renders(slab_scene(1.0), k=4, spp=8))
    assert off.max() == 0.0  # diffuse: no light reaches the front
    m = on.mean(axis=(1, 2, 3))
    assert m.mean() > 10 * m.std(ddof=1) / np.sqrt(len(m)) and m.mean() > 1e-3, m


def test_weight_zero_is_the_material_without_subsurface():
    a = lantern.render(sphere_scene(weight=0.0, level=0.5), spp=4, seed=2, threads=1)
    b = lantern.render(sphere_scene(level=0.5, subsurface=False), spp=4, seed=2, threads=1)
    assert np.array_equal(np.asarray(a), np.asarray(b))


def _session(scene, **kw):
    s = lantern.Session(scene, integrator=kw.pop("integrator", "pt"), seed=3,
                        spp_per_iteration=2, max_depth=8, threads=1, **kw)
    s.step()
    return s


def test_radius_zero_renders_diffuse_with_a_message():
    s = _session(sphere_scene(radius=(0.0, 0.0, 0.0), level=0.5))
    assert any("Subsurface Radius x Scale is 0" in w for w in s.warnings), s.warnings
    ref = _session(sphere_scene(level=0.5, subsurface=False))
    assert np.array_equal(np.asarray(s.image()), np.asarray(ref.image()))


def test_enormous_radius_is_clamped_and_finite():
    s = _session(sphere_scene(radius=(1e30, 1e30, 1e30), level=0.5))
    assert any("clamped" in w for w in s.warnings), s.warnings
    img = np.asarray(s.image())
    assert np.isfinite(img).all() and img.max() > 0.0


def test_open_mesh_gives_a_finite_image():
    # a single quad with subsurface: walks leave through the back or are lost, never NaN
    s = lantern.Scene()
    s.film.update(width=8, height=8)
    s.look_at((0.0, -3.0, 0.0), (0.0, 0.0, 0.0), fov=40.0)
    s.world = {"color": [1.0, 1.0, 1.0]}
    m = s.add_material("sheet", type="principled", base_color=0.8,
                       subsurface={"weight": 1.0, "radius": [0.5, 0.3, 0.1]})
    q = np.array([[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]], np.float32)
    s.add_mesh(q, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=m)
    img = np.asarray(_session(s).image())
    assert np.isfinite(img).all() and img.max() > 0.0


def test_schema_checks_subsurface():
    with pytest.raises(ValueError):
        sphere_scene(method="burley")
    with pytest.raises(ValueError):
        sphere_scene(weight=2.0)
    with pytest.raises(TypeError):
        lantern.Scene().add_material("x", type="principled", subsurface={"wieght": 1.0})


@pytest.mark.parametrize("integ", ["bdpt", "cis", "lt"])
def test_bidirectional_with_a_volume_inside_hands_over_to_pt(integ):
    # the walks' exits leave into the medium around the object (test_subsurface_media.py); a
    # volume inside the walking mesh they do not follow: the scene goes to pt, warned by name
    scene = sphere_scene(level=0.5, size=8, method="random_walk_skin")
    scene.materials[0].update(volume={"sigma_s": [0.2] * 3, "sigma_a": [0.05] * 3})
    ref = _session(scene)
    s = _session(scene, integrator=integ)
    assert any("rendering with pt" in w and "subsurface" in w and "volume inside" in w
               and "'ball'" in w for w in s.warnings), s.warnings
    assert np.array_equal(np.asarray(s.image()), np.asarray(ref.image()))


@pytest.mark.parametrize("integ", ["bdpt", "cis", "lt"])
def test_bidirectional_with_a_volume_beside_walks(integ):
    # subsurface beside a volume: no hand-over (their agreement with pt: test_subsurface_media.py)
    scene = sphere_scene(level=0.5, size=8, method="random_walk_skin")
    pos, idx = scenes.icosphere(1)
    fog = scene.add_material("fog")
    scene.materials[fog].update(volume={"sigma_s": [0.2] * 3, "sigma_a": [0.05] * 3},
                                volume_only=True)
    scene.add_mesh(np.asarray(pos) * 0.3 + np.array([1.5, 0.0, 0.0]), idx, material=fog)
    s = _session(scene, integrator=integ)
    assert not any("rendering with pt" in w for w in s.warnings), s.warnings
    assert np.isfinite(np.asarray(s.image())).all()


def test_scene_file_round_trip(tmp_path):
    s = sphere_scene(level=0.5, method="random_walk_skin", size=8, anisotropy=0.3)
    s.save(str(tmp_path / "sss.lantern"))
    t = lantern.load_scene(str(tmp_path / "sss.lantern"))
    keys = [k for k in s.materials[0] if k.startswith("subsurface")]
    assert len(keys) == 5 and all(t.materials[0][k] == s.materials[0][k] for k in keys)
    a = lantern.render(s, spp=2, seed=1, threads=1)
    b = lantern.render(t, spp=2, seed=1, threads=1)
    assert np.array_equal(np.asarray(a), np.asarray(b))
