"""Integrator "auto" on scenes it used to give to pt alone (branch autowide;
native/src/integrator/allocation.cpp pt_only_reason, docs/auto_integrator.md "pt only").

Motion blur. cis renders a pass at one shutter time (docs/motion_blur.md); auto's image is one
integrator's after the choice (its CPU trials are never in the image), so it is exact when the
chosen one is. The choice reads pt's second moment through the MIS identity from cis's trials
(bdpt.h, bdpt_moment), each at its pass's time: the mean over the times is pt's own second
moment (pt draws a time per sample, and its density of a (time, path) pair is its still density
at that time), checked on a moving, growing emitter at max_depth 2. With more than one sample a
pass (one time for several samples, a noise one-sample trials do not see) auto keeps pt.
Scenes: tests/python/auto_wide_scenes.py; efficiency: bench/auto_wide.py,
bench/results/2026-12-06-autowide/."""
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


def _second_moments(scene, integrator, seeds, channel=None, **settings):
    """Per seed, one sample a pixel at max_depth 2: the image's mean of Y^2 (pt's second
    moment) or of a channel (the moment channels' pt second moment: channel 1)."""
    out = []
    for seed in seeds:
        s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu", threads=1,
                            max_depth=2, spp_per_iteration=1, **settings)
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


def test_motion_auto_chooses_cis_and_matches_pt():
    """The glossy box with its short box sliding: auto renders it with cis and agrees with pt
    (a stored reference of 256 spp a seed). Its 32 spp resolve ~2 %: the whole-image control
    is 3 %."""
    scene = aws.glossy_motion(24, 24)
    auto, stats = _renders(scene, "auto", 32, 300)
    chose = [st["auto_choice"] for st, _ in stats]
    assert chose.count("cis") >= 12, chose
    assert not any("path tracing" in w for _, ws in stats for w in ws), stats[0][1]
    metrics.assert_agreement("auto (motion) vs pt, glossy box", auto,
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
