"""Integrator "auto" on scenes it used to give to pt alone (branch autowide;
native/src/integrator/allocation.cpp pt_only_reason, docs/auto_integrator.md "pt only").

Motion blur. cis renders a pass at one shutter time (docs/motion_blur.md); auto's image is one
integrator's after the choice (its CPU trials are never in the image), so it is exact when the
chosen one is. The choice reads pt's second moment through the MIS identity from cis's trials
(bdpt.h, bdpt_moment), each at its pass's time: the mean over the times is pt's own second
moment (pt draws a time per sample, and its density of a (time, path) pair is its still density
at that time), checked on a moving, growing emitter at max_depth 2. With more than one sample a
pass (one time for several samples, a noise one-sample trials do not see) auto keeps pt.

Light and shadow linking, a lamp's or an object's Cast Shadow off, and subsurface scattering
(the CPU): cis renders them itself; the identity is checked at max_depth 2 (linking: exact;
Cast Shadow off: two unequal integrals, not exact in principle, within 1 % on a small light),
through walks to their noise; auto's image against pt's on a scene where it picks cis, and its
pick of pt on the Cornell box with each. Shadow linking's channels follow pt's rule (branch
automis: MIS on free segments, next-event estimation alone past non-blockers). Object and lamp
ray visibility on surfaces (branch automis): restricted paths are pt's techniques at pt's
weights, the identity checked against the same stage unrestricted; beside linking, Cast Shadow
off, media and walks too since branch autotidy (test_auto_kinds.py).
Scenes: tests/python/auto_wide_scenes.py; efficiency: bench/auto_wide.py,
bench/results/2026-12-06-autowide/ (auto picked the better integrator on every seed of 18
scenes)."""
from pathlib import Path

import numpy as np
import pytest

import lantern
from lantern import metrics, session
from lantern.testing import refs

import auto_wide_scenes as aws
import test_motion_emitter as emitter

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

REFS = Path(__file__).resolve().parent.parent / "refs" / "auto_wide"
LUMA = np.array([0.2126, 0.7152, 0.0722])


def _renders(scene, integrator, spp, seed0, k=16, depth=6, **settings):
    out, stats = [], []
    for i in range(k):
        s = lantern.Session(scene, integrator=integrator, seed=seed0 + i, backend="cpu",
                            threads=1, max_depth=depth, spp_per_iteration=1, **settings)
        for _ in range(spp):
            s.step()
        out.append(np.asarray(s.image(), np.float64))
        stats.append((s.stats, list(s.warnings)))
    return np.stack(out), stats


def _second_moments(scene, integrator, seeds, channel=None, depth=2, **settings):
    """Per seed, one sample a pixel (max_depth 2 unless told): the image's mean of Y^2 (pt's
    second moment) or of a channel (the moment channels' pt second moment: channel 1)."""
    out = []
    for seed in seeds:
        s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", threads=1,
                            max_depth=depth, spp_per_iteration=1, **settings)
        s.step()
        img = np.asarray(s.image(), np.float64)
        out.append(float(np.mean((img @ LUMA) ** 2)) if channel is None
                   else float(np.mean(img[..., channel])))
    return np.array(out)


def test_moment_identity_in_motion():
    """The moment channels of cis's passes, each at its own shutter time, against pt's own
    E[Y^2] with a time per sample, on test_motion_emitter.py's emitter that grows (area 0.25 to
    2.25 of the frame's) and turns: pt's densities (the light's area) are those at the time.
    Negative control: the still frame's E[Y^2] (the emitter where it is at mid-shutter) differs
    (~35 % lower), and the comparison resolves it."""
    moving, still = emitter._moving("grow"), emitter._static_at("grow", 0.5)
    for sc in (moving, still):
        sc.film["width"] = sc.film["height"] = 16
    pt = _second_moments(moving, "pt", range(10, 74))
    ident = _second_moments(moving, "cis", range(500, 1012), channel=1, moment_channels=True)
    ref_still = _second_moments(still, "pt", range(10, 74))
    se = np.hypot(pt.std(ddof=1) / np.sqrt(len(pt)), ident.std(ddof=1) / np.sqrt(len(ident)))
    print(pt.mean(), ident.mean(), ref_still.mean(), se)
    assert abs(ident.mean() - pt.mean()) < 4 * se, (pt.mean(), ident.mean(), se)
    se_still = np.hypot(ref_still.std(ddof=1) / np.sqrt(len(ref_still)),
                        ident.std(ddof=1) / np.sqrt(len(ident)))
    assert abs(ident.mean() - ref_still.mean()) > 4 * se_still, (ref_still.mean(), ident.mean())


def _pt_ref(name, scene, spp=256, seed0=100, depth=6):
    """pt's per-seed block means (16 seeds of `spp`), stored in tests/refs/auto_wide
    (lantern.testing.refs: rendered again only when the scene changed)."""
    return refs.reference_blocks(
        REFS / f"{name}.npz", lambda: _renders(scene, "pt", spp, seed0, depth=depth)[0],
        dict(scene=scene, integrator="pt", spp=spp, seed0=seed0, k_seeds=16, max_depth=depth,
             steps=spp, threads=1))


def _auto_picks_cis_and_matches_pt(label, scene, ref, **bias):
    """auto renders `scene` itself (no hand-over to pt), with cis on most of 16 seeds of 32 spp,
    and agrees with pt's stored reference `ref` (metrics.assert_agreement with `bias`)."""
    auto, stats = _renders(scene, "auto", 32, 300)
    chose = [st["auto_choice"] for st, _ in stats]
    assert chose.count("cis") >= 12, chose
    assert not any("path tracing" in w for _, ws in stats for w in ws), stats[0][1]
    metrics.assert_agreement(label, auto, ref, **bias)


def test_motion_auto_chooses_cis_and_matches_pt():
    """The glossy box with its short box sliding: auto renders it with cis and agrees with pt
    (a stored reference of 256 spp a seed). Its 32 spp resolve ~2 %: the whole-image control
    is 3 %."""
    scene = aws.glossy_motion(24, 24)
    _auto_picks_cis_and_matches_pt("auto (motion) vs pt, glossy box", scene,
                                   _pt_ref("glossy_motion_pt", scene), image_bias=0.03)


def test_motion_cornell_chooses_pt():
    """The Cornell box with its tall box sliding: cis is about half pt's efficiency
    (bench/results/2026-12-06-autowide), auto's pilot picks pt."""
    chose = []
    for seed in range(40, 48):
        s = lantern.Session(aws.cornell_motion(48, 48), integrator="auto", seed=seed,
                            backend="cpu", threads=1, max_depth=12, spp_per_iteration=1)
        s.step()
        chose.append(s.stats["auto_choice"])
    assert chose.count("pt") >= 7, chose


def test_motion_with_samples_per_pass_stays_pt():
    """More than one sample an iteration: a cis pass holds one time for all of them, which the
    one-sample trials do not measure, so auto keeps pt and says why."""
    s = lantern.Session(aws.lantern_motion(16, 16), integrator="auto", seed=1, backend="cpu",
                        threads=1, max_depth=6, spp_per_iteration=4)
    s.step()
    assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
    assert any("motion blur" in w and "more than one sample" in w for w in s.warnings), \
        s.warnings
    still = lantern.Session(aws.lantern_motion(16, 16), integrator="auto", seed=1,
                            backend="cpu", threads=1, max_depth=6, spp_per_iteration=1)
    still.step()
    assert still.stats["auto_cis_iterations"] > 0


# ---- Light and shadow linking, a lamp's or an object's Cast Shadow off ----

def _identity_and_pt(scene, k=48):
    pt = _second_moments(scene, "pt", range(10, 10 + k))
    ident = _second_moments(scene, "cis", range(500, 500 + k), channel=1, moment_channels=True)
    return pt, ident


def _se(a, b):
    return np.hypot(a.std(ddof=1) / np.sqrt(len(a)), b.std(ddof=1) / np.sqrt(len(b)))


@pytest.mark.parametrize("feature", ["light", "lamp", "object"])
def test_moment_identity_with_linking(feature):
    """The moment channels on the slab stage (auto_wide_scenes.slab_stage) at max_depth 2
    against pt's own E[Y^2], with the feature on (shadow linking: the next test).
    - light linking (the small light lights the floor alone): both techniques apply the same
      zero and no density changes (bidir_linking.h), so the identity is pt's; control: the
      stage without linking (the slab lit too).
    - a lamp's or the slab's Cast Shadow off (the small light): pt's two unequal integrals
      (bidir_linking.h, bidir_no_shadow.h), which the identity's single integrand does not
      describe exactly where BSDF sampling carries a share (docs/auto_integrator.md); with a 3 cm
      light it is ~1 % of the light, and the channels must read pt's; control: the stage with
      shadows (the floor under the slab dark), ~25 % lower."""
    pt, ident = _identity_and_pt(aws.slab_stage(feature))
    se = _se(pt, ident)
    assert 4 * se < 0.06 * pt.mean(), (pt.mean(), se)
    assert abs(ident.mean() - pt.mean()) < 4 * se, (feature, pt.mean(), ident.mean(), se)
    control = _second_moments(aws.slab_stage(None), "pt", range(10, 58))
    print(feature, "pt", pt.mean(), "identity", ident.mean(), "se", se, "control",
          control.mean())
    assert abs(control.mean() - pt.mean()) > 4 * _se(control, pt), \
        (feature, pt.mean(), control.mean())


def test_moment_identity_with_shadow_linking():
    """Shadow linking (the large light's shadows cast by the slab alone: the image is the
    stage's own) at max_depth 2. pt weighs a shadow-linked light by the power heuristic of its
    two techniques where the segment to it meets no surface, by next-event estimation alone
    where it passes surfaces that cast the light no shadow (pt_light_linking.h); cis makes
    these paths by next-event estimation alone, and its channels follow pt's rule by the shadow
    ray's answer (bidir_linking.h, bidir_linked_moment).
    - passed: a sheet over the stage that casts no shadow ("shadow_passed"; every segment to
      the light passes it): pt's estimator is next-event estimation alone, with no covariance
      between two techniques for the identity to miss, so the channels read pt's E[Y^2].
    - free ("shadow": no surface on a lit segment): pt's estimator is the stage's without
      linking, so the channels read what they read without linking (both below pt's E[Y^2] by
      the covariance they never see, ~0.9 of it). Control: the channels of the old model
      (next-event estimation's density alone on free segments too, the value pt's passed stage
      has), ~12 % higher: resolved. The old code failed here."""
    pt_passed, ident_passed = _identity_and_pt(aws.slab_stage("shadow_passed", True))
    se = _se(pt_passed, ident_passed)
    assert 4 * se < 0.06 * pt_passed.mean(), (pt_passed.mean(), se)
    assert abs(ident_passed.mean() - pt_passed.mean()) < 4 * se, \
        ("passed", pt_passed.mean(), ident_passed.mean(), se)
    ident_free = _second_moments(aws.slab_stage("shadow", True), "cis", range(500, 548),
                                 channel=1, moment_channels=True)
    ident_plain = _second_moments(aws.slab_stage(None, True), "cis", range(600, 648), channel=1,
                                  moment_channels=True)
    se_free = _se(ident_free, ident_plain)
    print("passed: pt", pt_passed.mean(), "identity", ident_passed.mean(), "se", se,
          "free: identity", ident_free.mean(), "unlinked", ident_plain.mean(), "se", se_free)
    assert abs(ident_free.mean() - ident_plain.mean()) < 4 * se_free, \
        ("free", ident_free.mean(), ident_plain.mean(), se_free)
    assert abs(ident_free.mean() - pt_passed.mean()) > 4 * _se(ident_free, pt_passed), \
        ("control", ident_free.mean(), pt_passed.mean())


# scene (auto_wide_scenes), pt's samples a pixel in the stored reference, the whole-image
# control the comparison resolves (tests/README.md)
LINKED = {"light": ("glossy_light_link", 256, 0.03), "object": ("glossy_object_noshadow", 256, 0.03),
          "shadow": ("lantern_shadow_link", 1024, 0.1), "lamp": ("lantern_lamp_noshadow", 1024, 0.1)}
BLOCK_BIAS = {"shadow": 0.3, "lamp": 0.3}  # (the glass lantern, as the fixture's 0.5: test_auto_integrator.py)


@pytest.mark.parametrize("feature", list(LINKED))
def test_linking_auto_chooses_cis_and_matches_pt(feature):
    """A scene with the feature where cis wins: auto renders it itself, with cis on most seeds,
    and agrees with pt (a stored reference of 16 seeds). Light linking and an object's Cast
    Shadow off: the glossy box (auto_wide_scenes._glossy; 32 spp resolve ~2 %: the whole-image
    control is 3 %). Shadow linking and a lamp's Cast Shadow off: the glass lantern (on the
    glossy box these cut cis's light paths at the floor, where only next-event estimation may
    make the light's paths, bidir_linking.h: pt is the better there and auto picks it,
    bench/results/2026-12-06-autowide); the bulb behind glass is noisy for pt."""
    name, ref_spp, bias = LINKED[feature]
    scene = aws.SCENES[name](24, 24)
    _auto_picks_cis_and_matches_pt(f"auto ({feature}) vs pt, {name}", scene,
                                   _pt_ref(f"{name}_pt", scene, spp=ref_spp), image_bias=bias,
                                   block_bias=BLOCK_BIAS.get(feature, 0.05))


def test_linking_cornell_chooses_pt():
    """The Cornell box with each feature: cis ~0.4-0.6x pt (bench/results/2026-12-06-autowide),
    auto's pilot picks pt."""
    for name in ("cornell_light_link", "cornell_shadow_link", "cornell_lamp_noshadow",
                 "cornell_object_noshadow"):
        chose = []
        for seed in range(40, 48):
            s = lantern.Session(aws.SCENES[name](48, 48), integrator="auto", seed=seed,
                                backend="cpu", threads=1, max_depth=12, spp_per_iteration=1)
            s.step()
            chose.append(s.stats["auto_choice"])
        assert chose.count("pt") >= 7, (name, chose)


def test_ray_visibility_beside_linking_auto_weighs():
    """Object ray visibility beside light linking: cis renders it (no hand-over in
    bidir_visibility_reason since rayvismix) and auto's moment channels read pt's beside it
    (test_auto_kinds.py, branch autotidy; before, pt_only_reason kept pt): no warning, auto's
    pilot weighs cis."""
    scene = aws.cornell_light_link(16, 16)
    aws._mesh(scene, "short_box")["visible_glossy"] = False
    s = lantern.Session(scene, integrator="auto", seed=1, backend="cpu", threads=1)
    s.step()
    assert s.stats["auto_cis_iterations"] > 0
    assert not any("path tracing" in w for w in s.warnings), s.warnings


def _hidden_boxes(kind):
    """The Cornell box (16 x 16, its light hidden from the camera: its seen pixels would rule
    E[Y^2]) with both boxes hidden from `kind` rays ("glossy", "diffuse"), or None."""
    from lantern import scenes
    scene = scenes.cornell_box(16, 16)
    scene.lights[0]["visible_camera"] = False
    if kind:
        for name in ("short_box", "tall_box"):
            aws._mesh(scene, name)["visible_" + kind] = False
    return scene


def test_moment_identity_with_ray_visibility():
    """The moment channels with object ray visibility at max_depth 3. The boxes hidden from
    glossy rays in the all-diffuse Cornell box: pt's image and estimator are the stage's own
    (its E[Y^2] the same to 1e-6, same seeds), but every path whose bounce lands on a box is
    restricted in cis (bidir_ray_visibility.h: pt's two techniques with pt's weights, no light
    paths): cis's own samples change, and the channels, pt's second moment through pt's
    weights (1 / w = 1 + a: bdpt_pt_factor), must not (the same seeds a side: 192, ~1.3 %).
    Control: the boxes hidden from diffuse rays (pt's image changes: BSDF sampling passes
    them, next-event estimation's shadow rays do not), where the same comparison resolves the
    change (~28 %)."""
    seeds = range(500, 692)
    plain = _second_moments(_hidden_boxes(None), "cis", seeds, channel=1, depth=3,
                            moment_channels=True)
    glossy = _second_moments(_hidden_boxes("glossy"), "cis", seeds, channel=1, depth=3,
                             moment_channels=True)
    own = _second_moments(_hidden_boxes("glossy"), "cis", seeds[:8], channel=0, depth=3,
                          moment_channels=True)
    own_plain = _second_moments(_hidden_boxes(None), "cis", seeds[:8], channel=0, depth=3,
                                moment_channels=True)
    assert np.abs(own - own_plain).max() > 1e-3 * own_plain.mean(), (own, own_plain)
    pt_seeds = range(10, 26)
    pt_plain = _second_moments(_hidden_boxes(None), "pt", pt_seeds, depth=3)
    pt_glossy = _second_moments(_hidden_boxes("glossy"), "pt", pt_seeds, depth=3)
    np.testing.assert_allclose(pt_glossy, pt_plain, rtol=1e-5)
    se = _se(glossy, plain)
    print("glossy-hidden identity", glossy.mean(), "plain", plain.mean(), "se", se)
    assert 4 * se < 0.07 * plain.mean(), (plain.mean(), se)
    assert abs(glossy.mean() - plain.mean()) < 4 * se, (glossy.mean(), plain.mean(), se)
    diffuse = _second_moments(_hidden_boxes("diffuse"), "cis", seeds[:48], channel=1, depth=3,
                              moment_channels=True)
    assert abs(diffuse.mean() - plain.mean()) > 4 * _se(diffuse, plain), \
        (diffuse.mean(), plain.mean())


def test_ray_visibility_auto_chooses():
    """Object and lamp ray visibility on surfaces: auto weighs cis (no hand-over to pt, no
    warning) and picks pt on the Cornell box with its tall box hidden from glossy rays (cis
    below pt there: bench/results/2026-12-07-automis)."""
    chose = []
    for seed in range(40, 46):
        scene = aws.SCENES["cornell_glossy_hidden"](48, 48)
        s = lantern.Session(scene, integrator="auto", seed=seed, backend="cpu", threads=1,
                            max_depth=12, spp_per_iteration=1)
        s.step()
        chose.append(s.stats["auto_choice"])
        assert not any("path tracing" in w for w in s.warnings), s.warnings
    assert chose.count("pt") >= 5, chose


# ---- Subsurface scattering ----

def test_moment_identity_through_walks():
    """The moment channels of cis's camera-side walks (light paths do not walk with them on:
    bdpt_sss_light.h) against pt's own E[Y^2], on test_subsurface_bidir.py's Random Walk sphere
    under a point light (next-event estimation pt's only technique of it) at max_depth 3: a
    walk's estimate is sampled, never evaluated, and pt samples it as cis's camera does, so the
    channels (the contribution times its own estimate over its weight) hold the walk's second
    moment as pt's. Control: the sphere without subsurface (~25 % lower). The test resolves
    only ~12 % (4 standard errors: the walks' heavy noise; 192 seeds a side, ~2 CPU seconds):
    it shows the channels are of the right size through a walk, not that they are exact."""
    import test_subsurface_bidir as sss
    sphere = sss.lit_sphere(size=16)
    pt = _second_moments(sphere, "pt", range(10, 202), depth=3)
    ident = _second_moments(sphere, "cis", range(500, 692), channel=1, depth=3,
                            moment_channels=True)
    se = _se(pt, ident)
    print("walk pt", pt.mean(), "identity", ident.mean(), "se", se)
    assert 4 * se < 0.15 * pt.mean(), (pt.mean(), se)
    assert abs(ident.mean() - pt.mean()) < 4 * se, (pt.mean(), ident.mean(), se)
    sphere.materials[0]["subsurface_weight"] = 0.0
    plain = _second_moments(sphere, "pt", range(10, 202), depth=3)
    assert abs(plain.mean() - pt.mean()) > 4 * _se(plain, pt), (plain.mean(), pt.mean())


def test_subsurface_auto_chooses_cis_and_matches_pt():
    """The glossy box with its short box of Random Walk subsurface: auto renders it itself,
    with cis on most seeds, and agrees with pt (a stored reference, 16 seeds of 256 spp)."""
    scene = aws.glossy_sss(24, 24)
    _auto_picks_cis_and_matches_pt("auto (subsurface) vs pt, glossy box", scene,
                                   _pt_ref("glossy_sss_pt", scene), image_bias=0.03)


def test_subsurface_cornell_chooses_pt():
    """The Cornell box with its tall box of subsurface: cis below pt (bench/results/
    2026-12-06-autowide/subsurface), auto's pilot picks pt."""
    chose = []
    for seed in range(40, 48):
        s = lantern.Session(aws.cornell_sss(48, 48), integrator="auto", seed=seed,
                            backend="cpu", threads=1, max_depth=12, spp_per_iteration=1)
        s.step()
        chose.append(s.stats["auto_choice"])
    assert chose.count("pt") >= 7, chose


def test_moment_identity_with_light_linking_through_walks():
    """Light linking beside subsurface scattering (auto weighs it since branch automis): a
    second point light that lights the floor alone (the sphere in receiver set 1) on
    test_subsurface_bidir.py's sphere at max_depth 3. Light linking is a zero every technique
    applies, a walk's exit receiving as its own surface (bdpt_sss.h), so the identity reads pt's
    E[Y^2] as through walks without it (0.963, se 0.022 of it; without the linking 0.966: the
    covariance it never sees), to the walks' noise (192 seeds a side: it resolves ~9 %).
    Control: the stage with the second light lighting the sphere too (~1.7x)."""
    import test_subsurface_bidir as sss

    def stage(linked):
        s = sss.lit_sphere(size=16)
        s.add_light("point", position=[-1.5, -1.0, 1.5], power=[200.0] * 3, radius=0.0)
        if linked:
            s.meshes[0]["light_set"] = 1
            s.lights[1]["receivers"] = [0]
        return s
    pt = _second_moments(stage(True), "pt", range(10, 202), depth=3)
    ident = _second_moments(stage(True), "cis", range(500, 692), channel=1, depth=3,
                            moment_channels=True)
    se = _se(pt, ident)
    print("light linking through walks: pt", pt.mean(), "identity", ident.mean(), "se", se)
    assert 4 * se < 0.15 * pt.mean(), (pt.mean(), se)
    assert abs(ident.mean() - pt.mean()) < 4 * se, (pt.mean(), ident.mean(), se)
    plain = _second_moments(stage(False), "pt", range(10, 74), depth=3)
    assert abs(plain.mean() - pt.mean()) > 4 * _se(plain, pt), (plain.mean(), pt.mean())


def test_light_linking_beside_subsurface_auto_chooses():
    """Light linking beside subsurface scattering: no hand-over to pt, auto's pilot weighs it
    (the choice: bench/results/2026-12-07-automis)."""
    s = lantern.Session(aws.SCENES["glossy_sss_light_link"](16, 16), integrator="auto",
                        seed=1, backend="cpu", threads=1)
    s.step()
    assert not any("linking" in w and "auto" in w for w in s.warnings), s.warnings
    assert s.stats["auto_cis_iterations"] > 0


@pytest.mark.parametrize("beside", ["fog", "subsurface"])
def test_linking_beside_unchecked_features_stays_pt(beside):
    """Linking beside media, shadow linking beside subsurface scattering (cis renders both,
    bidir_linking_medium.h, bdpt_sss.h): combinations auto was not checked on, so it keeps pt
    and names them (light linking alone beside subsurface it weighs: above). Control: the same
    scene without the linking goes to auto's pilot."""
    for linked in (True, False):
        feature = "light" if beside == "fog" else "shadow"
        scene = aws._glossy(16, 16, feature if linked else None)
        if beside == "fog":
            scene.world["volume"] = {"sigma_s": [0.25] * 3, "sigma_a": [0.02] * 3, "g": 0.3}
        else:
            aws._skin(scene, "short_box")
        s = lantern.Session(scene, integrator="auto", seed=1, backend="cpu", threads=1)
        s.step()
        if linked:
            assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
            assert any("linking" in w and "auto" in w for w in s.warnings), s.warnings
        else:
            assert s.stats["auto_cis_iterations"] > 0, s.warnings
