"""What the motion-blur tests share (not a test module): the independent estimate of a shutter
integral they compare the core's motion renders with, and the exact matrices and box they place
their objects with (the core's slerp and lerp not involved).

shutter_average: per seed, still renders of the scene placed at J stratified times (j + u) / J,
u uniform per seed (from default_rng(rng_base + seed)), so the mean is unbiased over the shutter;
antithetic: each stratum at (j + u) / J and its mirror (j + 1 - u) / J. Render j takes the seed
100 * seed + j and spp / (the number of times) samples."""
import numpy as np


def box(half):
    """An axis-aligned box of half-extents `half` about the origin: (vertices, triangles)."""
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float64)
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], np.uint32)
    return v * np.asarray(half), f


def rz(a):
    """A rotation by `a` radians about z (4 x 4)."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def tr(x, y, z):
    """A translation (4 x 4)."""
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def shutter_average(still_at, render, seed, rng_base, spp, j_times, antithetic=False):
    """The mean of render(still_at(t), seed', spp') over the shutter's stratified times t (the
    module docstring); render returns an image."""
    u = np.random.default_rng(rng_base + seed).random()
    if antithetic:
        times = [(j + v) / j_times for j in range(j_times) for v in (u, 1.0 - u)]
    else:
        times = [(j + u) / j_times for j in range(j_times)]
    imgs = [render(still_at(t), 100 * seed + j, spp // len(times)) for j, t in enumerate(times)]
    return np.mean(imgs, axis=0)


def assert_embree_matches_bvh(name, scene, render, still, k, spp, monkeypatch):
    """Embree's motion (the default CPU accelerator) against the built-in BVH's on `scene`: the
    same shutter integral statistically (k seeds of spp each, other seeds on each side), and the
    same seed near-identical (test_cpu_accel.py's measure: the two round t and the barycentrics
    apart in the last bits at most), which the still scene `still` is not. render(scene, seed,
    spp) returns (image, warnings)."""
    from lantern import metrics
    out = {}
    for accel in ("embree", "bvh"):
        monkeypatch.setenv("LANTERN_ACCEL", accel)
        imgs = []
        for s in range(k):
            img, warnings = render(scene, 1 + s + (0 if accel == "embree" else 100), spp)
            assert all("built-in BVH (LANTERN_ACCEL=bvh)" in w for w in warnings), warnings
            imgs.append(img)
        out[accel] = np.stack(imgs)
    metrics.assert_agreement(name, out["embree"], out["bvh"], block=8, se_floor=1e-6)
    monkeypatch.setenv("LANTERN_ACCEL", "embree")
    a = render(scene, 7, 4)[0]
    monkeypatch.setenv("LANTERN_ACCEL", "bvh")
    b = render(scene, 7, 4)[0]
    far = np.abs(a - b) > 1e-4 * np.maximum(np.abs(b), 1e-3)
    assert far.mean() <= 0.002, f"{far.mean():.4%} of channels differ by over 1e-4"
    assert not np.array_equal(a, render(still, 7, 4)[0])
