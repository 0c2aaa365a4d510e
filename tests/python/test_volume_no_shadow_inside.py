"""A volume whose mesh casts no shadow is skipped by shadow rays, from inside as well as
crossing it (D61, docs/difftest.md; Cycles 97dbe6f volume_shader_eval_entry: a volume whose
object is invisible to shadow rays stays in the shadow ray's volume stack but is not
evaluated). pt_volume.h shadow_medium / Medium::shadow_as; bdpt, lvc, cis take pt's T' in
bidir_no_shadow_medium.h (docs/lvc_notes.md "Cast Shadow off").

The scene makes the rule exact: a diffuse floor seen head on by an orthographic camera, lit by
a point lamp (not hittable), max_depth 2 (direct light alone: a BSDF ray finds nothing that
emits), and a purely absorbing fog box (sigma_s 0) that casts no shadow. Every camera ray
crosses the same depth of fog (0.5 m, or 1.5 m), so the floor's image is the image without the
box times exp(-sigma_a depth), pixel by pixel, where the fog box leaves the floor's shadow rays
alone: "floor" (the box holds the floor, the lamp outside), "both" (the box holds the floor
and the lamp), "lamp" (the box holds the lamp alone, out of the camera's view: every shadow
ray crosses it, the rule Lantern kept before D61), "world" (the box of "floor" in absorbing
world fog: the shadow ray keeps the world's fog and leaves the box's out; the reference is the
scene with the world fog and without the box), "nested" (a second non-casting box inside the
first, around the floor: its medium the two summed, which a shadow ray skips up to the
outer's outside), "inner_casting" (the same with the inner box casting its shadows: a shadow
ray inside it sees its fog alone, Medium::shadow_as the medium before nest_media summed it;
the reference: the scene with the inner box alone, the camera rays' outer fog 1 m). The
control: the box casting its shadows must
fail (its shadow ray attenuated by the box)."""
import numpy as np
import pytest

import lantern
from lantern import metrics
from lantern.scenes import aabb_mesh

SIGMA = np.array([0.8, 0.4, 0.2])  # the box's absorption (1/m)
WORLD = np.array([0.3, 0.2, 0.1])  # "world": the world fog's
INNER = np.array([0.5, 1.0, 1.5])  # "nested": the inner box's
BOXES = {"floor": ((-1.5, -1.5, -2.5), (1.5, 1.5, -1.5)),   # camera rays: 0.5 m of fog
         "both": ((-1.5, -1.5, -2.5), (1.5, 1.5, -0.5)),    # 1.5 m; the lamp at z -1 inside
         "lamp": ((0.6, 0.55, -1.3), (1.0, 0.9, -0.7)),     # out of view: 0 m
         "world": ((-1.5, -1.5, -2.5), (1.5, 1.5, -1.5)),
         "nested": ((-1.5, -1.5, -2.5), (1.5, 1.5, -1.0)),  # 1 m, the inner box's 0.5 m in it
         "inner_casting": ((-1.5, -1.5, -2.5), (1.5, 1.5, -1.0))}
NESTED = ((-1.2, -1.2, -2.3), (1.2, 1.2, -1.5))  # also casting no shadow (nest_media sums them)
DEPTH = {"floor": 0.5, "both": 1.5, "lamp": 0.0, "world": 0.5, "nested": 1.0,
         "inner_casting": 1.0}
K = 8  # seeds a side (the bidirectional integrators' comparison)


def scene(case=None, cast=False, box=True):
    """case's scene; box False: without the fog box (the reference); cast: the box casts its
    shadows (the control)."""
    s = lantern.Scene()
    s.film.update(width=8, height=8)
    s.camera = {"type": "orthographic", "screen": [-0.5, 0.5, -0.5, 0.5], "clip": [0.0, 100.0]}
    s.world = {"color": [0.0, 0.0, 0.0]}
    if case == "world":
        s.world["volume"] = {"sigma_s": [0.0] * 3, "sigma_a": WORLD.tolist(), "g": 0.0}
    m = s.add_material("floor", base_color=(0.8, 0.7, 0.6))
    p, idx = aabb_mesh((-1.0, -1.0, -2.1), (1.0, 1.0, -2.0))  # its top at z -2, seen from z 0
    s.add_mesh(p, idx, material=m)
    s.add_light("point", position=[0.8, 0.7, -1.0], power=[20.0] * 3, radius=0.0,
                soft_falloff=False)
    if case == "inner_casting" and not box:  # the reference: the inner box alone
        _inner(s, True)
    if case is not None and box:
        f = s.add_material("fog")
        s.materials[f]["volume"] = {"sigma_s": [0.0] * 3, "sigma_a": SIGMA.tolist(), "g": 0.0}
        s.materials[f]["volume_only"] = True
        p, idx = aabb_mesh(*BOXES[case])
        s.add_mesh(p, idx, material=f, name="fog")
        s.meshes[-1]["cast_shadow"] = bool(cast)
        if case in ("nested", "inner_casting"):
            _inner(s, case == "inner_casting")  # (cast: the outer box casts too)
    return s


def _inner(s, cast):
    g = s.add_material("inner")
    s.materials[g]["volume"] = {"sigma_s": [0.0] * 3, "sigma_a": INNER.tolist(), "g": 0.0}
    s.materials[g]["volume_only"] = True
    p, idx = aabb_mesh(*NESTED)
    s.add_mesh(p, idx, material=g, name="inner")
    s.meshes[-1]["cast_shadow"] = cast


def render(s, integrator, seed):
    ses = lantern.Session(s, integrator=integrator, seed=seed, backend="cpu", max_depth=2,
                          spp_per_iteration=4, threads=1)
    ses.step()
    return np.asarray(ses.image(), np.float64)[..., :3], ses.warnings


def expected(case, seed):
    """The image the rule gives: the scene without the box (with the world fog in "world"),
    times the camera rays' transmittance through the box."""
    ref, _ = render(scene(case, box=False), "pt", seed)
    return ref * np.exp(-SIGMA * DEPTH[case] - (INNER * 0.5 if case == "nested" else 0.0))


@pytest.mark.parametrize("case", list(BOXES))
def test_pt_skips_the_volume_exactly(core, case):
    """pt, pixel by pixel (the same seed: the same pixel positions; float rounding only)."""
    ref = expected(case, 7)
    assert ref.min() > 0.0
    img, warnings = render(scene(case), "pt", 7)
    assert not warnings, warnings
    np.testing.assert_allclose(img, ref, rtol=2e-4)
    cast, _ = render(scene(case, cast=True), "pt", 7)
    worst = float((cast / ref).min())
    print(f"{case}: control (the box casting) darkest ratio {worst:.3f}")
    assert worst < 0.9  # its shadow ray attenuated by the box


@pytest.mark.parametrize("case", list(BOXES))
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_bidirectional_skip_the_volume(core, integrator, case):
    """bdpt, lvc, cis (their own techniques: no hand-over) against the exact image,
    statistically (K seeds a side: the reference's pixel positions differ from theirs)."""
    ref = [expected(case, 100 + k) for k in range(K)]
    imgs = []
    for k in range(K):
        img, warnings = render(scene(case), integrator, 200 + k)
        assert not warnings, warnings  # rendered by the integrator itself
        imgs.append(img)
    metrics.assert_agreement(f"{case}, {integrator} vs the exact image", imgs, ref, block=4)
    cast = [render(scene(case, cast=True), integrator, 300 + k)[0] for k in range(K)]
    control = metrics.compare_renders(cast, ref, block=4)
    print("control (the box casting):", control)
    assert not control.passed
