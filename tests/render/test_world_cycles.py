"""The HDRI world (blend_scenes/scenes.py:world_hdri: bpy's sunset.exr through a Mapping
rotation) against Cycles for the bidirectional integrators too; pt runs in
test_cycles_compare.py. Same rule as there (lantern.metrics.assert_agreement: Welch blocks,
image-mean z-tests with the bias cap, negative controls that must fail)."""

import json
import os

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
lantern = pytest.importorskip("lantern")
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402
from test_cycles_compare import LANTERN_SEEDS, LANTERN_SPP  # noqa: E402

NAME = "world_hdri"
REF = os.path.join(rc.REF_DIR, NAME + ".npz")


@pytest.fixture(scope="module")
def addon():
    import lantern_bpy
    if not lantern.native_available():
        pytest.skip(f"native core not available: {lantern.native_error()}")
    return lantern_bpy.load_addon()


@pytest.mark.skipif(not os.path.exists(REF), reason="no Cycles reference for world_hdri")
# bdpt in CI (the cheapest, 33 s of CPU); lvc and cis (38 and 44 s) are `long`
# (bench/long_tests.sh): CI covers them by transitivity, pt against Cycles on this scene
# (test_cycles_compare.py::test_matches_cycles[world_hdri]) and lvc and cis against pt under an
# HDRI map through a rotation, each with its 1 % / 5 % controls
# (tests/python/test_world.py::test_integrators_agree_under_hdri, paired with bdpt too)
@pytest.mark.parametrize("integrator", ["bdpt", pytest.param("lvc", marks=pytest.mark.long),
                                        pytest.param("cis", marks=pytest.mark.long)])
def test_hdri_world_matches_cycles(integrator, addon):
    ref = dict(np.load(REF))
    with open(os.path.join(rc.REF_DIR, NAME + ".json")) as f:
        meta = json.load(f)
    rc.build_scene(NAME)
    images = []
    for k in range(LANTERN_SEEDS):
        img, warnings = rc.render_lantern(seed=k + 1, spp=LANTERN_SPP, integrator=integrator)
        images.append(img)
    assert not warnings, f"export warnings: {warnings}"
    cycles = metrics.SeedBlocks(ref["seed_block_means"])
    assert len(cycles) == len(meta["seeds"])
    name = f"{NAME} {integrator}"
    res = metrics.compare_renders(images, cycles, block=rc.BLOCK, name=name)
    rc.REPORT.append(f"{name}: {res.blocks}; whole-image bias resolved >= "
                     f"{res.detectable_bias():.2%}")
    metrics.assert_agreement(name, images, cycles, block=rc.BLOCK)
