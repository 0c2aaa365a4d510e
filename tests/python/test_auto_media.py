"""Integrator "auto" in scenes with homogeneous media (native/src/integrator/allocation.h,
docs/auto_integrator.md "Media"; docs/volumes.md): its pt and cis trials choose between the two
there too (the setting `auto_media`, on by default since the medium stages make the cis trials'
moment channels, bdpt_medium_finish_c; no connection map in media), off: pt in any medium.

- Default: the fog room's pilot runs cis trials; with auto_media off auto renders it as pt
  does, bit for bit, with a warning naming the setting.
- The moment channels in fog against a direct measurement of the second moment they estimate
  (test_moment_channels_in_media_match_a_direct_measurement; control: pt's own).
- Unbiased (auto_media on): auto against pt on the fog room with a spot
  (test_volume_bidir.fog_spot, where it renders cis) by lantern.metrics.assert_agreement with
  its negative controls.
- Its choice with auto_media on (deterministic per seed) against the efficiencies measured in
  bench/ (bench/results/2026-12-04-automedia): cis on the lamp in a shade in fog
  (test_volume_bdpt.lamp_shade; cis many times pt's efficiency), pt on an open fog scene lit by a sun (open_fog below, where
  pt is the more efficient). Negative control: the same lamp scene with the sphere light's
  Soft Falloff on (cis starts no light paths on such a light) goes to pt.
- Emissive media stay pt's alone (a warning says so); a media scene's explicit
  connection_allocation is turned off with a warning."""
import math

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

from test_volume_bidir import _volume_box, fog_spot, renders  # noqa: F401
from test_volume_bdpt import lamp_shade

DEPTH = 8


pytestmark = pytest.mark.usefixtures("core")  # (conftest: skips without the core)


def open_fog(size=32):
    """An open stage in thin world fog lit by a low sun: a large floor with two boxes, nothing
    around them; every fog point sees the sun (pt's next-event estimate through the fog is
    nearly noise-free), light paths from the sun's disk mostly leave the frame."""
    scene = lantern.Scene()
    scene.film.update(width=int(size), height=int(size))
    scene.look_at((0.0, -6.0, 2.0), (0.0, 0.0, 0.5), fov=60.0)
    ground = scene.add_material("ground", base_color=(0.5, 0.5, 0.45))
    s = 20.0
    scene.add_mesh(*scenes._quad((-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)),
                   material=ground, name="ground")
    for name, center, size_, colour in (("a", (-0.8, 0.5, 0.0), (1.0, 1.0, 1.2), (0.7, 0.3, 0.2)),
                                        ("b", (1.0, -0.3, 0.0), (0.8, 0.8, 0.6), (0.2, 0.5, 0.7))):
        m = scene.add_material(name, base_color=colour)
        scene.add_mesh(*scenes._box(center, size_, 20), material=m, name=name)
    d = np.array([-0.5, 0.6, -0.6])
    scene.add_light("sun", direction=(d / np.linalg.norm(d)).tolist(), strength=[3.0] * 3,
                    angle=math.radians(1.0))
    # a fog box around the stage (world fog would take the sun's light at infinity)
    _volume_box(scene, "fog", {"sigma_s": [0.08, 0.08, 0.08], "sigma_a": [0.01, 0.01, 0.01],
                               "g": 0.3}, (-8.0, -8.0, 0.0), (8.0, 8.0, 4.0))
    return scene


def _choices(scene, seeds, steps=1, spp=1, **settings):
    out = []
    for seed in seeds:
        s = lantern.Session(scene, integrator="auto", seed=seed, backend="cpu", max_depth=DEPTH,
                            spp_per_iteration=spp, threads=1, auto_media=True, **settings)
        for _ in range(steps):
            s.step()
        assert not any("path tracing" in w for w in s.warnings), s.warnings
        out.append((s.stats["auto_choice"], round(s.stats["auto_cis_over_pt"], 2)))
    return out


def _auto_media_renders(scene, spp, seed0, k_seeds, steps=4):
    """renders() of test_volume_bidir for integrator auto with auto_media on."""
    out = []
    for k in range(k_seeds):
        s = lantern.Session(scene, integrator="auto", seed=seed0 + k, backend="cpu",
                            max_depth=DEPTH, spp_per_iteration=spp // steps, threads=1,
                            auto_media=True)
        for _ in range(steps):
            s.step()
        assert not any("path tracing" in w for w in s.warnings), s.warnings
        out.append(np.asarray(s.image())[..., :3])
    return out


def test_auto_chooses_in_media_by_default():
    """auto_media is on by default (the medium stages make moment channels): auto's pilot runs
    cis trials in the fog room; with auto_media off auto renders it as pt does, bit for bit,
    with a warning naming the setting."""
    scene = fog_spot()
    images = {}
    for name, settings in (("auto", {"integrator": "auto", "auto_media": False}),
                           ("pt", {"integrator": "pt"}),
                           ("auto_media", {"integrator": "auto"})):
        s = lantern.Session(scene, seed=7, backend="cpu", max_depth=DEPTH, spp_per_iteration=1,
                            threads=1, **settings)
        for _ in range(4):
            s.step()
        images[name] = np.asarray(s.image())
        if name == "auto":
            assert any("auto_media" in w for w in s.warnings), s.warnings
            assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
        if name == "auto_media":  # the default: its pilot's cis trials ran
            assert s.stats["auto_cis_iterations"] >= 2, s.stats
    assert np.array_equal(images["auto"], images["pt"])
    assert not np.array_equal(images["auto_media"], images["pt"])


@pytest.mark.long  # 21 s; CI: test_auto_chooses_in_media_by_default, the moment channels' test
def test_auto_agrees_with_pt_in_fog():
    scene = fog_spot()
    auto = _auto_media_renders(scene, 64, 5000, k_seeds=12)
    pt = renders(scene, "pt", 256, 1000, k_seeds=12, max_depth=DEPTH, steps=4)
    metrics.assert_agreement("fog_spot auto vs pt", auto, pt, block=8, image_bias=0.04,
                             block_bias=0.1)


def test_auto_chooses_cis_in_the_lamp_shade_and_pt_in_open_fog():
    """The choice after the checkpoints of the 8th and 16th iteration of one sample (the
    add-on's default). With the moment channels in media the lamp's pilot already chooses cis
    (estimates 20-31x pt; without them 1.3-3.9, where renders give 11x: bench/results/
    2026-12-05-automoments). Measured on these seeds: see the README there.
    """
    seeds = range(300, 308)
    lamp = _choices(lamp_shade(), seeds, steps=17)
    assert [c for c, _ in lamp].count("cis") >= 7, lamp
    fog = _choices(open_fog(), seeds, steps=17)
    assert [c for c, _ in fog].count("pt") == len(seeds), fog
    # Soft Falloff on (Blender's default bulb): its light paths start in the fog too since
    # branch softmedia (soft_light_medium.h), so cis again
    soft = lamp_shade()
    for light in soft.lights:
        light["soft_falloff"] = True
    soft_choice = _choices(soft, seeds, steps=17)
    assert [c for c, _ in soft_choice].count("cis") >= 7, soft_choice
    # negative control: no light paths at all (light_path_fraction 0: cis renders camera paths
    # alone, at its higher cost; before softmedia the soft bulb was this case): pt on most seeds
    control = _choices(soft, seeds, steps=17, light_path_fraction=0.0)
    assert [c for c, _ in control].count("pt") >= 5, control


def test_emissive_medium_stays_pt_and_connection_allocation_is_off():
    scene = fog_spot()
    scene.world["volume"]["emission"] = [0.1, 0.1, 0.1]
    s = lantern.Session(scene, integrator="auto", seed=1, backend="cpu", max_depth=DEPTH,
                        threads=1, auto_media=True)
    s.step()
    assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
    assert any("emissive" in w and "auto" in w for w in s.warnings), s.warnings
    s = lantern.Session(fog_spot(), integrator="cis", seed=1, backend="cpu", max_depth=DEPTH,
                        threads=1, connection_allocation=True)
    s.step()
    assert any("connection_allocation is off" in w for w in s.warnings), s.warnings
    assert "mean_connections" not in s.stats  # (the allocation reports it when on)


def _luma_moments(scene, integrator, seeds, channel=None, power=2, **settings):
    out = []
    for seed in seeds:
        s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", max_depth=2,
                            spp_per_iteration=1, threads=1, **settings)
        s.step()
        img = np.asarray(s.image()).astype(np.float64)[..., :3]
        if channel is None:  # the image's mean of the squared luminance: E[Y^2]
            out.append(float(np.mean((img @ np.array([0.2126, 0.7152, 0.0722])) ** power)))
        else:
            out.append(float(np.mean(img[..., channel])))
    return np.array(out)


def test_moment_channels_in_media_match_a_direct_measurement():
    """The moment channels of auto's cis trials in fog (bdpt_medium_finish_c: made at the
    shadow ray, where the medium stages finish a contribution's weight): the MIS identity's
    estimate of the second moment of path tracing by the bidirectional integrators' own two
    techniques (phase/BSDF sampling, s = 0, and next-event estimation, s = 1, distances by the
    uniform channel rule, power heuristic) against a direct measurement of that estimator: lvc
    with no light paths (light_path_fraction 0: every weight is those two techniques'), its
    E[Y^2] over independent seeds. At max_depth 2 (direct light through fog: a surface or a
    medium vertex, then the light) the two agree up to the techniques' covariance (the
    identity read 0.73-0.78 of the direct measurement on three seed sets, within 2 standard
    errors each: not resolved whether that is the covariance).
    Negative control: pt's own E[Y^2] (pt also samples equiangular distances to lights, so its
    second moment is ~3x lower here) is told apart by the same tolerance; without the channels
    (before) the identity read ~0 for every queued contribution."""
    scene = scenes.cornell_box(32, 32, light_visible=False)
    scene.world = {"color": [0.0, 0.0, 0.0],
                   "volume": {"sigma_s": [0.3, 0.3, 0.3], "sigma_a": [0.02, 0.03, 0.05],
                              "g": 0.3}}
    k = 160
    ident = _luma_moments(scene, "cis", range(500, 500 + k), channel=1, moment_channels=True)
    direct = _luma_moments(scene, "lvc", range(900, 900 + k), light_path_fraction=0.0)
    se = np.hypot(ident.std(ddof=1), direct.std(ddof=1)) / np.sqrt(k)
    # (the direct measurement is heavy-tailed, fog beside the light: its standard error is
    # ~12 % of its mean here, so this resolves a factor ~1.5, not 10 %)
    assert 4 * se < 0.6 * direct.mean(), (ident.mean(), direct.mean(), se)
    assert abs(ident.mean() - direct.mean()) < 4 * se, (ident.mean(), direct.mean(), se)
    pt = _luma_moments(scene, "pt", range(10, 10 + k))
    se_pt = np.hypot(ident.std(ddof=1), pt.std(ddof=1)) / np.sqrt(k)
    assert abs(ident.mean() - pt.mean()) > 4 * se_pt, (ident.mean(), pt.mean(), se_pt)
    # channel 0 is the luminance of the plain render (its contributions, summed)
    plain = _luma_moments(scene, "cis", range(500, 504), power=1)
    lum = _luma_moments(scene, "cis", range(500, 504), channel=0, moment_channels=True)
    np.testing.assert_allclose(lum, plain, rtol=1e-4)
