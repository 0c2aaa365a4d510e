"""The HDRI world (blend_scenes/scenes.py:world_hdri: bpy's sunset.exr through a Mapping
rotation) against Cycles for the bidirectional integrators too; pt runs in
test_cycles_compare.py. Same rule: block z-scores within the t bound, image mean within 1%."""

import json
import os

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
lantern = pytest.importorskip("lantern")
import render_compare as rc  # noqa: E402
from test_cycles_compare import MEAN_TOL, compare  # noqa: E402

NAME = "world_hdri"
REF = os.path.join(rc.REF_DIR, NAME + ".npz")
SPP = int(os.environ.get("LANTERN_TEST_SPP", "128"))


@pytest.fixture(scope="module")
def addon():
    import lantern_bpy
    if not lantern.native_available():
        pytest.skip(f"native core not available: {lantern.native_error()}")
    return lantern_bpy.load_addon()


@pytest.mark.skipif(not os.path.exists(REF), reason="no Cycles reference for world_hdri")
@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_hdri_world_matches_cycles(integrator, addon):
    ref = dict(np.load(REF))
    with open(os.path.join(rc.REF_DIR, NAME + ".json")) as f:
        meta = json.load(f)
    rc.build_scene(NAME)
    images = []
    for k in range(rc.SEEDS):
        img, warnings = rc.render_lantern(seed=k + 1, spp=SPP, integrator=integrator)
        images.append(img)
    assert not warnings, f"export warnings: {warnings}"
    lan = rc.stats_over_seeds(images)
    assert np.isfinite(lan["mean"]).all()
    res = compare(lan, ref, rc.SEEDS, len(meta["seeds"]))
    ratio = float(lan["mean"].mean()) / float(ref["mean"].mean())
    line = (f"{NAME} {integrator}: mean ratio lantern/cycles {ratio:.4f}; blocks |z|>3: "
            f"{res['beyond']}/{res['n']} (allowed {res['allowed']}); worst z "
            f"{res['worst_z']:+.2f} at {res['worst_at']}")
    print("\n" + line)
    rc.REPORT.append(line)
    assert abs(ratio - 1.0) <= MEAN_TOL, line
    assert res["beyond"] <= res["allowed"], line
