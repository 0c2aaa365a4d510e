"""Cycles' max_bounces against Lantern's max_depth: Cycles with B bounces renders the same image
as Lantern with max_depth B + 2 (0 bounces = direct light only = 2 path segments). Cycles is
rendered here, at low samples: the image means differ by 45% between B = 0 and 1."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
lantern = pytest.importorskip("lantern")
import render_compare as rc  # noqa: E402


@pytest.mark.parametrize("bounces", [0, 1])
def test_cycles_bounces_match_lantern_depth(bounces, monkeypatch):
    import lantern_bpy
    if not lantern.native_available():
        pytest.skip(f"native core not available: {lantern.native_error()}")
    lantern_bpy.load_addon()
    rc.build_scene("cornell_box")
    monkeypatch.setattr(rc, "BOUNCES", bounces)
    cyc = np.mean([rc.render_cycles(seed=s, spp=64)[0].mean() for s in range(2)])
    lan = np.mean([rc.render_lantern(seed=s + 1, spp=64)[0].mean() for s in range(2)])
    line = (f"Cycles max_bounces={bounces}: {cyc:.5f}; Lantern max_depth="
            f"{rc.lantern_depth(bounces)}: {lan:.5f}; ratio {lan / cyc:.4f}")
    print("\n" + line)
    rc.REPORT.append(line)
    assert abs(lan / cyc - 1) < 0.015
