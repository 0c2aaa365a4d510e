"""The Volume object fire driven by node graphs of its grids (test_volumes_vdb_graph's fire
scene: a density program and an Emission Strength program reading the grids) rendered by cis
and bdpt against pt through the add-on (docs/volumes.md "Node graphs on volume inputs"): K
seeds each, lantern.metrics.assert_agreement with its negative controls; cis with the flame's
Map Range to 3 instead of 4 must be told apart from pt. `long` (bench/long_tests.sh): the
bidirectional integrators cost several times pt's in heterogeneous media."""

import os
import sys

import numpy as np
import pytest

import bpy  # noqa: F401,E402 (conftest.py skips this folder without bpy or the core)
import lantern

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_compare as rc  # noqa: E402
import test_volumes_vdb_graph as graphs  # noqa: E402

K = 6
SPP = 64
SE_FLOOR = 1e-6

pytestmark = [pytest.mark.long,
              pytest.mark.skipif(not lantern.vdb_available(), reason="built without OpenVDB")]


def _renders(integrator):
    imgs = []
    for k in range(K):
        img, warnings = rc.render_lantern(seed=101 + k, spp=SPP, integrator=integrator)
        assert not [w for w in warnings if "fire" in w], warnings
        imgs.append(img)
    return np.stack(imgs).astype(np.float64)


def test_fire_graphs_bidirectional_agree_with_pt(tmp_path):
    from lantern import metrics
    path = tmp_path / "fire.vdb"
    graphs.write_fire_vdb(path)
    graphs.fire_stage(path)()
    pt = _renders("pt")
    for integ in ("cis", "bdpt"):
        other = _renders(integ)
        res = metrics.compare_renders(other, pt, block=rc.BLOCK, se_floor=SE_FLOOR,
                                      name=f"fire graphs {integ} vs pt")
        print(res)
        metrics.assert_agreement(f"fire graphs {integ} vs pt", other, pt, block=rc.BLOCK,
                                 se_floor=SE_FLOOR, image_bias=0.01, block_bias=0.05)
    nt = bpy.data.materials["vdb_graph_fire"].node_tree
    nt.nodes["map"].inputs["To Max"].default_value = 3.0
    ctl = metrics.compare_renders(_renders("cis"), pt, block=rc.BLOCK, se_floor=SE_FLOOR,
                                  name="fire graphs cis, To Max 3")
    print(f"control: {ctl}")
    assert not ctl.passed, ctl
