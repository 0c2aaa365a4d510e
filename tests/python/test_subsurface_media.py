"""Random-walk subsurface (Skin) in scenes with volumes in bdpt, lvc, cis and lt (issue 32 item 1
with issue 29's media; docs/subsurface.md "Subsurface with volumes"): a walk's exit leaves into
the medium its path arrived in at the entry (pt's rule, pt_sss.h), so that its next event,
connections, splats and continuation take that medium's transmittance and medium vertices
(bdpt_sss.h, lt_sss.h); light paths of bdpt, lvc and cis do not walk in scenes with media
(bdpt_sss_light.h). Two scenes against pt at 12 x 12, 16 seeds a side (pt 128 spp, bdpt, lvc,
cis 64, lt 256), blocks of 4 (lantern.metrics); about 32 s of CPU for the file:

- fog: a Skin sphere on a grey floor in homogeneous world fog under a point light;
- smoke: the same sphere beside a heterogeneous Volume object (two Gaussian blobs on a grid)
  between it and the lamp, in a thinner world fog.

Negative control (each scene, each integrator): LANTERN_SSS_ADJOINT=nomedium, the exits leave
into vacuum (no transmittance after the exit), must be told apart from pt. A volume inside the
walking mesh is still handed to pt with a warning by name (test_subsurface_scene.py)."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core unavailable")

SIZE = 12
K = 16        # seeds a side
DEPTH = 6
SPP_PT, SPP = 128, 64
SPP_LT = 256  # (lt's paths are cheap, its splats noisy)
INTEGRATORS = ["bdpt", "lvc", "cis", "lt"]


def _base(fog):
    s = lantern.Scene()
    s.film.update(width=SIZE, height=SIZE)
    s.look_at((0.0, -4.0, 0.6), (0.0, 0.0, -0.2), fov=40.0)
    s.world = {"color": [0.0] * 3, "volume": {"sigma_s": [fog] * 3, "sigma_a": [0.3 * fog] * 3}}
    m = s.add_material("skin", type="principled", base_color=(0.8, 0.55, 0.4), roughness=0.5,
                       subsurface={"weight": 1.0, "radius": [0.4, 0.2, 0.1],
                                   "method": "random_walk_skin"})
    pos, idx = scenes.icosphere(2)
    s.add_mesh(pos, idx, material=m)
    f = s.add_material("floor", base_color=0.5)
    q = np.array([[-3, -3, -1], [3, -3, -1], [3, 3, -1], [-3, 3, -1]], np.float32)
    s.add_mesh(q, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=f)
    s.add_light("point", position=[1.8, -1.0, 2.0], power=[400.0] * 3, radius=0.0)
    return s


def fog_scene():
    return _base(0.15)


SMOKE_BOX = ((0.6, -1.0, 0.2), (1.6, 0.0, 1.4))


def smoke_scene():
    """A grid smoke of two blobs (peaks 4 and 2 per unit of its coefficients) between the sphere
    and the lamp, world fog 0.1."""
    s = _base(0.1)
    n = 16
    lo, hi = np.array(SMOKE_BOX[0]), np.array(SMOKE_BOX[1])
    h = (hi - lo) / (n - 1)
    z, y, x = np.meshgrid(*[np.arange(n, dtype=np.float64)] * 3, indexing="ij")
    p = np.stack([x, y, z], -1) * h + lo
    vox = 4.0 * np.exp(-np.sum((p - [1.0, -0.5, 0.9]) ** 2, -1) / (2 * 0.25 ** 2))
    vox += 2.0 * np.exp(-np.sum((p - [1.2, -0.3, 0.5]) ** 2, -1) / (2 * 0.2 ** 2))
    m4 = np.eye(4)
    m4[:3, :3] = np.diag(h)
    m4[:3, 3] = lo
    g = s.add_grid(vox.astype(np.float32), m4, name="blobs:density")
    m = s.add_material("smoke")
    s.materials[m].update(volume={"sigma_s": [0.85, 0.8, 0.7], "sigma_a": [0.07, 0.09, 0.13],
                                  "g": 0.0},
                          volume_only=True, density_grid=g)
    pos, idx = scenes.aabb_mesh(*SMOKE_BOX)
    s.add_mesh(pos, idx, material=m, name="smoke")
    return s


SCENES = {"fog": fog_scene, "smoke": smoke_scene}


def _session(scene, integrator, spp, seed):
    s = lantern.Session(scene, integrator=integrator, max_depth=DEPTH, seed=seed, threads=1,
                        spp_per_iteration=spp)
    s.step()
    return s


def _renders(scene, integrator, spp, seed0):
    out = []
    for k in range(K):
        s = _session(scene, integrator, spp, seed0 + k)
        assert not any("rendering with pt" in w for w in s.warnings), s.warnings
        out.append(np.asarray(s.image(), np.float64))
    return out


_PT = {}


def pt_reference(name):
    if name not in _PT:
        _PT[name] = _renders(SCENES[name](), "pt", SPP_PT, 1001)
    return _PT[name]


@pytest.mark.parametrize("name", sorted(SCENES))
@pytest.mark.parametrize("integ", INTEGRATORS)
def test_agrees_with_pt(name, integ, monkeypatch):
    ref = pt_reference(name)
    scene = SCENES[name]()
    spp = SPP_LT if integ == "lt" else SPP
    renders = _renders(scene, integ, spp, 2001)
    metrics.assert_agreement(f"{integ} vs pt, Skin in {name}", renders, ref, block=4,
                             controls=False)
    # the control: the exits leave into vacuum (no transmittance after the walk)
    monkeypatch.setenv("LANTERN_SSS_ADJOINT", "nomedium")
    bad = _renders(scene, integ, spp, 2001)
    res = metrics.compare_renders(bad, ref, block=4)
    print(f"control (exits into vacuum): {res}")
    assert not res.passed, f"{integ} in {name}: the exits' medium dropped not told apart: {res}"
