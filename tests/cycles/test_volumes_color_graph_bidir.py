"""Volumes' colour graphs (test_volumes_color_graph's three mesh volumes: "volume_color" and
"volume_absorption_color" programs) rendered by cis and bdpt against pt through the add-on
(docs/volumes.md "Node graphs on volume inputs"): K seeds each, lantern.metrics.
assert_agreement with its negative controls; cis with the Principled Volume's colour graph
taken out must be told apart from pt. `long` (bench/long_tests.sh): the bidirectional
integrators cost several times pt's in heterogeneous media."""

import os
import sys

import numpy as np
import pytest

import bpy  # noqa: F401,E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_compare as rc  # noqa: E402
import test_volumes_color_graph as colors  # noqa: E402

K = 6
SPP = 64
SE_FLOOR = 1e-6

pytestmark = pytest.mark.long


def _renders(integrator):
    imgs = []
    for k in range(K):
        img, warnings = rc.render_lantern(seed=201 + k, spp=SPP, integrator=integrator)
        assert not [w for w in warnings if "colour" in w or "Color" in w], warnings
        imgs.append(img)
    return np.stack(imgs).astype(np.float64)


def test_color_graphs_bidirectional_agree_with_pt():
    from lantern import metrics
    colors.colors()
    pt = _renders("pt")
    for integ in ("cis", "bdpt"):
        other = _renders(integ)
        res = metrics.compare_renders(other, pt, block=rc.BLOCK, se_floor=SE_FLOOR,
                                      name=f"colour graphs {integ} vs pt")
        print(res)
        metrics.assert_agreement(f"colour graphs {integ} vs pt", other, pt, block=rc.BLOCK,
                                 se_floor=SE_FLOOR, image_bias=0.01, block_bias=0.05)
    nt = bpy.data.materials["color_principled"].node_tree
    v = nt.nodes["Principled Volume"]
    nt.links.remove(v.inputs["Color"].links[0])
    ctl = metrics.compare_renders(_renders("cis"), pt, block=rc.BLOCK, se_floor=SE_FLOOR,
                                  name="colour graphs cis, graph ignored")
    print(f"control: {ctl}")
    assert not ctl.passed, ctl
