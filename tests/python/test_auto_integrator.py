"""Integrator "auto" (issue 27; native/src/integrator/allocation.h): pt or cis per iteration,
chosen from the render's own estimates of each one's efficiency.

- Unbiased where it switches: on the Cornell box it renders its pilot's cis iteration and
  then pt; on the fixture it keeps cis; on a furnace it must give the analytic value. Each
  against pt (or the exact value) by lantern.metrics.assert_agreement with its negative
  controls (tests/README.md).
- Deterministic: same seed, same bits; the pilot's trials are not in the image (a render of
  one step holds one sample).
- It chooses cis where cis is several times more efficient (the fixture: 7x, bench/results/
  2026-12-04-auto) and pt where cis is half as efficient (the Cornell box), and pt alone where
  the scene has what only pt renders (a holdout), saying so."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

K = 16
SIZE = 32


@pytest.fixture(scope="module", autouse=True)
def core():
    if not lantern.native_available():
        pytest.skip(f"lantern._core is not built ({lantern.native_error()})")


def _renders(scene, integrator, spp, seed0, k=K, depth=8):
    out, stats = [], []
    for i in range(k):
        s = lantern.Session(scene, integrator=integrator, seed=seed0 + i, backend="cpu",
                            max_depth=depth, spp_per_iteration=1)
        for _ in range(spp):
            s.step()
        assert s.spp == spp
        out.append(s.image())
        stats.append(s.stats)
    return out, stats


def test_cornell_switches_from_cis_to_pt_unbiased():
    scene = scenes.cornell_box(SIZE, SIZE)
    auto, stats = _renders(scene, "auto", 24, 500)
    assert all(st["auto_choice"] == "pt" for st in stats), [st["auto_choice"] for st in stats]
    # the kept iterations: the pilot's cis, then pt (the four pt trials are not kept)
    assert all((st["auto_cis_iterations"], st["auto_pt_iterations"]) == (1, 27) for st in stats)
    ref, _ = _renders(scene, "pt", 96, 900)
    metrics.assert_agreement("auto (cis then pt) vs pt, Cornell", auto, ref)


def test_fixture_chooses_cis_and_renders_what_cis_does():
    """Where it chooses cis from the start, its kept iterations are cis's own, with the same
    seed and the same QMC indices (the pilot's pt trials draw from scrambles of their own and
    leave the bidirectional state alone): the same bits as integrator cis."""
    scene = scenes.fixture_box(SIZE, SIZE)
    auto, stats = _renders(scene, "auto", 6, 600)
    # the choice rests on a pilot's noisy estimates (allocation.h: 1 of 16 seeds below 1 here)
    chose = [st["auto_choice"] for st in stats]
    assert chose.count("cis") >= 12, chose
    for k, (img, c) in enumerate(zip(auto, chose)):
        if c == "cis":
            ref, _ = _renders(scene, "cis", 6, 600 + k, k=1)
            assert np.array_equal(img, ref[0]), f"seed {600 + k}"


def test_furnace_exact():
    albedo, emission, depth = 0.5, 1.0, 6
    scene = scenes.furnace_sphere(albedo=albedo, emission=emission, width=16, height=16)
    auto, stats = _renders(scene, "auto", 8, 100, depth=depth)
    exact = np.broadcast_to(scenes.furnace_expected(emission, albedo, depth),
                            (16, 16, 3)).astype(np.float32)
    metrics.assert_agreement("auto, furnace", auto, exact)


def test_same_seed_same_bits_and_trials_not_kept():
    scene = scenes.cornell_box(16, 16)
    a, sa = _renders(scene, "auto", 4, 7, k=1)
    b, _ = _renders(scene, "auto", 4, 7, k=1)
    assert np.array_equal(a[0], b[0])
    s = lantern.Session(scene, integrator="auto", seed=7, backend="cpu", max_depth=8)
    s.step()
    assert s.spp == 1 and s.stats["auto_pt_iterations"] == 4  # four trials, not kept
    assert s.stats["auto_cis_iterations"] == 1


def test_holdout_scene_is_rendered_by_pt_alone():
    scene = scenes.cornell_box(16, 16)
    scene.materials[0]["holdout"] = True
    s = lantern.Session(scene, integrator="auto", seed=1, backend="cpu", max_depth=8)
    s.step()
    s.step()
    assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
    assert any("holdout" in w and "auto" in w for w in s.warnings)
