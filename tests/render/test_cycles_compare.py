"""Lantern against Cycles on the blend scenes: each scene is built in bpy, exported by the
add-on and rendered with lantern.Session with K independent seeds, then compared with the
stored Cycles reference (tools/make_cycles_refs.py) block by block (8x8 pixels):

- z = (mean_lantern - mean_cycles) / sqrt(se_lantern^2 + se_cycles^2) per block and channel,
  with standard errors from the seeds of each. Both SEs come from few seeds, so z follows a
  Student t with Welch-Satterthwaite degrees of freedom, not a normal: the number of |z| > 3
  allowed is the expected count under that t plus 4 binomial standard deviations, plus 1.
- the image means agree within 1%.
"""

import glob
import json
import os

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
lantern = pytest.importorskip("lantern")
import render_compare as rc  # noqa: E402  (tools/, put on sys.path by conftest)

REFS = sorted(os.path.splitext(os.path.basename(p))[0]
              for p in glob.glob(os.path.join(rc.REF_DIR, "*.npz")))
LANTERN_SPP = int(os.environ.get("LANTERN_TEST_SPP", "256"))
LANTERN_SEEDS = rc.SEEDS
Z = 3.0
MEAN_TOL = 0.01


def _t_tail(df, z=Z, n=400_000):
    """P(|T| > z) for Student t with `df` degrees of freedom (Monte Carlo, fixed seed)."""
    rng = np.random.default_rng(12345)
    t = rng.standard_normal(n) / np.sqrt(rng.chisquare(df, n) / df)
    return float(np.mean(np.abs(t) > z))


def compare(lan, ref, k_lan, k_ref):
    se2_l, se2_c = lan["block_se"].astype(np.float64) ** 2, ref["block_se"].astype(np.float64) ** 2
    se2 = se2_l + se2_c
    diff = lan["block_mean"].astype(np.float64) - ref["block_mean"]
    scale = np.maximum(np.abs(ref["block_mean"]), 1e-6)
    ok_exact = se2 <= (1e-7 * scale) ** 2          # noise-free blocks (e.g. black background)
    z = np.where(ok_exact, np.where(np.abs(diff) <= 1e-4 * scale + 1e-6, 0.0, np.inf),
                 diff / np.sqrt(np.where(ok_exact, 1.0, se2)))
    # Welch-Satterthwaite degrees of freedom, per value; tail probability at the median df
    with np.errstate(divide="ignore", invalid="ignore"):
        df = se2 ** 2 / (se2_l ** 2 / (k_lan - 1) + se2_c ** 2 / (k_ref - 1))
    df = np.where(np.isfinite(df), df, k_lan + k_ref - 2)
    df_med = float(np.clip(np.median(df), 1.0, k_lan + k_ref - 2))
    p = _t_tail(df_med)
    n = z.size
    expected = n * p
    allowed = int(np.floor(expected + 4.0 * np.sqrt(n * p * (1 - p)) + 1))
    beyond = int(np.sum(np.abs(z) > Z))
    worst = np.unravel_index(np.argmax(np.abs(np.where(np.isfinite(z), z, 1e30))), z.shape)
    return {"z": z, "beyond": beyond, "allowed": allowed, "expected": expected, "n": n,
            "df": df_med, "worst_z": float(z[worst]), "worst_at": worst}


@pytest.fixture(scope="module")
def addon():
    import lantern_bpy
    if not lantern.native_available():
        pytest.skip(f"native core not available: {lantern.native_error()}")
    return lantern_bpy.load_addon()


@pytest.mark.skipif(not REFS, reason="no Cycles references in tests/render/refs")
@pytest.mark.parametrize("name", REFS)
def test_matches_cycles(name, addon):
    ref = dict(np.load(os.path.join(rc.REF_DIR, name + ".npz")))
    with open(os.path.join(rc.REF_DIR, name + ".json")) as f:
        meta = json.load(f)
    rc.build_scene(name)
    images = []
    for k in range(LANTERN_SEEDS):
        img, warnings = rc.render_lantern(seed=k + 1, spp=LANTERN_SPP)
        images.append(img)
    assert not warnings, f"export warnings: {warnings}"
    lan = rc.stats_over_seeds(images)
    assert lan["mean"].shape == ref["mean"].shape, (lan["mean"].shape, ref["mean"].shape)
    assert np.isfinite(lan["mean"]).all()

    res = compare(lan, ref, LANTERN_SEEDS, len(meta["seeds"]))
    m_l, m_c = float(lan["mean"].mean()), float(ref["mean"].mean())
    ratio = m_l / m_c if m_c > 0 else float("nan")
    ch_ratio = lan["mean"].reshape(-1, 3).mean(0) / np.maximum(ref["mean"].reshape(-1, 3).mean(0), 1e-12)
    by, bx, ch = res["worst_at"]
    line = (f"{name}: mean lantern {m_l:.5f} cycles {m_c:.5f} ratio {ratio:.4f} "
          f"(RGB {np.array2string(ch_ratio, precision=4)}); blocks |z|>{Z:g}: {res['beyond']}/"
          f"{res['n']} (expected {res['expected']:.1f}, allowed {res['allowed']}, df {res['df']:.1f});"
          f" worst z {res['worst_z']:+.2f} at block row {by} col {bx} channel {'RGB'[ch]} "
          f"(lantern {lan['block_mean'][by, bx, ch]:.5f} cycles {ref['block_mean'][by, bx, ch]:.5f})")
    print("\n" + line)
    rc.REPORT.append(line)
    _save_debug(name, lan, ref, res)
    assert abs(ratio - 1.0) <= MEAN_TOL, f"{name}: image mean ratio lantern/cycles {ratio:.4f}"
    assert res["beyond"] <= res["allowed"], (
        f"{name}: {res['beyond']} of {res['n']} block values beyond {Z:g} sigma "
        f"(allowed {res['allowed']}); worst z {res['worst_z']:+.2f} at {res['worst_at']}")


def _save_debug(name, lan, ref, res):
    """Images and z map for a human, in build/render_tests (not read by any test)."""
    out = os.path.join(rc.ROOT, "build", "render_tests")
    os.makedirs(out, exist_ok=True)
    np.savez_compressed(os.path.join(out, name + ".npz"), lantern=lan["mean"],
                        cycles=ref["mean"], z=res["z"].astype(np.float32))
