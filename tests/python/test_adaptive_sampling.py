"""Per-pixel adaptive sampling (native/src/integrator/adaptive.h, issue 17): Cycles' noise
threshold stops each converged pixel, the rest keep sampling.

The scene: the diffuse Cornell box (noisy: indirect light) with a flat emitter covering the
left half of the view in front of it (no noise: every camera ray there sees the same
radiance). Small renders: 24 x 24 pixels, at most 32 samples."""

import threading
import time

import numpy as np
import pytest

import lantern
from lantern import metrics, scenes

W = H = 24
MAX_SPP = 32
GLOW = (0.8, 0.7, 0.6)  # the emitter's radiance


def half_emitter_box():
    scene = scenes.cornell_box(width=W, height=H)
    glow = scene.add_material("glow", base_color=(0.0, 0.0, 0.0), emission=GLOW)
    pos = np.array([(-1.0, -2.5, -0.5), (0.0, -2.5, -0.5), (0.0, -2.5, 2.5), (-1.0, -2.5, 2.5)],
                   np.float32)
    scene.add_mesh(pos, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=glow, name="glow")
    return scene


SCENE = None


def scene():
    global SCENE
    if SCENE is None:
        SCENE = half_emitter_box()
    return SCENE


def run(spp=MAX_SPP, **settings):
    s = lantern.Session(scene(), **dict({"backend": "cpu", "integrator": "pt"}, **settings))
    while s.spp < spp and not s.converged:
        s.step()
    return s


# the emitter's pixels, away from its edge (x < W/2 - 2: the filter reaches 1.5 px)
FLAT = (slice(None), slice(0, W // 2 - 3))
NOISY = (slice(2, H - 2), slice(W // 2 + 2, W - 2))


def test_flat_pixels_stop_at_min_samples_and_noisy_ones_keep_going(core):
    s = run(adaptive_threshold=0.02, adaptive_min_samples=8, seed=1)
    n = s.pixel_samples()
    assert n.shape == (H, W) and n.dtype == np.int32
    assert (n[FLAT] == 8).all(), n[FLAT]
    assert (n[NOISY] == MAX_SPP).mean() > 0.9, n[NOISY]
    assert s.spp == MAX_SPP and not s.converged
    assert 0 < s.active_pixels < W * H
    assert s.noise_error > 0.02  # the worst active pixel is still above the threshold
    # a stopped pixel keeps its value: its estimate is its own samples' mean
    img = s.image()
    np.testing.assert_allclose(img[FLAT], np.broadcast_to(GLOW, img[FLAT].shape), rtol=1e-5)


def test_the_dilation_keeps_the_emitters_edge_sampling(core):
    n = run(adaptive_threshold=0.02, adaptive_min_samples=8, seed=1).pixel_samples()
    edge = n[4:H - 4, W // 2 - 2:W // 2 + 1]  # the emitter's edge: filter-mixed, noisy
    assert (edge > 8).all(), edge


def test_threshold_zero_is_no_adaptive_stop(core):
    plain = run(spp=8, seed=4)
    zero = run(spp=8, seed=4, adaptive_threshold=0.0, adaptive_min_samples=2)
    assert np.array_equal(plain.image(), zero.image())  # the same bits
    assert (zero.pixel_samples() == 8).all()
    assert zero.active_pixels == W * H and not zero.converged


def test_min_samples_are_honoured(core):
    # a threshold nothing fails: every pixel stops at the first check, at min samples
    s = run(adaptive_threshold=1e3, adaptive_min_samples=12, seed=2)
    assert (s.pixel_samples() == 12).all() and s.converged and s.spp == 12
    auto = run(adaptive_threshold=1e3, seed=2)  # Cycles' automatic minimum: 4 here
    assert (auto.pixel_samples() == max(4, int(np.ceil(16.0 / 1e3 ** 0.3)))).all()
    five = run(adaptive_threshold=1e3, adaptive_min_samples=5, seed=2)
    assert (five.pixel_samples() == 5).all()
    assert lantern.render(scene(), spp=64, adaptive_threshold=1e3, adaptive_min_samples=6,
                          backend="cpu", integrator="pt").shape == (H, W, 3)


def test_a_converged_session_steps_without_adding_samples(core):
    s = run(adaptive_threshold=1e3, adaptive_min_samples=4, seed=2)
    before, img = s.spp, s.image()
    s.step()
    assert s.spp == before and np.array_equal(s.image(), img)


def test_bad_settings_say_what_is_wrong(core):
    with pytest.raises(ValueError, match="adaptive_threshold"):
        lantern.Session(scene(), adaptive_threshold=-0.1, integrator="pt")
    with pytest.raises(ValueError, match="adaptive_min_samples"):
        lantern.Session(scene(), adaptive_min_samples=-1, integrator="pt")
    with pytest.raises(ValueError, match="adaptive_step"):
        lantern.Session(scene(), adaptive_step=0, integrator="pt")


# the agreement test's settings: 16 seeds a side (Welch dof >= 15), 4 x 4 blocks (36), the
# full renders (the reference) at 64 (pt) and 32 (lvc) spp: they detect 0.67 % (pt) and
# 0.58 % (lvc), a typical block 4.0 % and 3.4 % (128 / 64 spp for the full side: 0.66 %,
# 0.49 %)
THRESHOLD = {"pt": 0.1, "lvc": 0.1}
FULL_SPP = {"pt": 64, "lvc": 32}
AGREE_SEEDS, BLOCK = 16, 4


@pytest.mark.parametrize("integrator", ["pt", "lvc"])
def test_adaptive_images_agree_with_full_ones(core, integrator):
    """No bias from stopping that this comparison can see (1 % on the image, 5 % on a block):
    adaptive renders against full ones (independent seeds), at a threshold where the pixels
    take 23 (pt) and 21 (lvc) samples on average of the 32 allowed (the emitter's stop at 8).
    lvc: a stopped pixel drops the light paths' splats with its camera paths, so each of its
    iterations is a whole estimate (keeping them read a block 1.7x too bright). Stopping on
    the samples' own error is not exactly unbiased (a pixel that has not yet met a rare bright
    path looks converged): at 0.3 (30x Cycles' default) pt's block-weighted mean read
    -0.12 +- 0.04 % (96 seeds a side against 128 spp), at 0.1 -0.02 +- 0.03 % (lvc -0.03 +-
    0.03 %), no block beyond |z| 3: below the 0.2 % cap and this test's noise."""
    threshold = THRESHOLD[integrator]
    adaptive = [run(adaptive_threshold=threshold, adaptive_min_samples=8, seed=100 + k,
                    integrator=integrator, spp_per_iteration=4).image().astype(np.float64)
                for k in range(AGREE_SEEDS)]
    spp = FULL_SPP[integrator]
    full = [run(spp=spp, seed=200 + k, integrator=integrator, spp_per_iteration=spp).image()
            .astype(np.float64) for k in range(AGREE_SEEDS)]
    metrics.assert_agreement(f"{integrator}: adaptive at {threshold} vs every pixel to {spp} spp",
                             adaptive, full, block=BLOCK)


def test_lvc_stopped_pixels_count_their_own_samples(core):
    s = run(adaptive_threshold=0.02, adaptive_min_samples=8, seed=3, integrator="lvc")
    n = s.pixel_samples()
    assert (n[FLAT] == 8).all() and (n[NOISY] == MAX_SPP).mean() > 0.9
    flat = s.image()[FLAT]
    np.testing.assert_allclose(flat, np.broadcast_to(GLOW, flat.shape), rtol=1e-5)


def test_cancel_keeps_the_samples_and_counts(core):
    s = lantern.Session(scene(), backend="cpu", adaptive_threshold=0.02,
                        adaptive_min_samples=4, seed=5, integrator="pt")
    while s.active_pixels == W * H:
        s.step()  # some pixels have stopped: the camera pass runs on a pixel list
    img, n, spp = s.image(), s.pixel_samples(), s.spp
    s.cancel()
    s.step()  # cancelled before it started
    assert s.spp == spp and np.array_equal(s.image(), img)
    assert np.array_equal(s.pixel_samples(), n)
    # a cancel during a long step returns promptly and leaves everything as it was
    big = lantern.Session(scene(), backend="cpu", adaptive_threshold=0.02,
                          adaptive_min_samples=4, seed=5, spp_per_iteration=4096, integrator="pt")
    done = {}

    def worker():
        t0 = time.monotonic()
        big.step()
        done["seconds"] = time.monotonic() - t0

    th = threading.Thread(target=worker)
    th.start()
    time.sleep(0.2)
    big.cancel()
    th.join(timeout=60)
    assert not th.is_alive(), "step() did not return after cancel()"
    assert big.spp == 0 and not big.image().any() and not big.pixel_samples().any()
