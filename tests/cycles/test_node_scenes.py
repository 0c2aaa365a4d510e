"""Node-graph scenes (blend_scenes/nodes.py) against Cycles and across Lantern's integrators.

- Cycles: K seeds each (Cycles CPU, Lantern pt); every 8 x 8 block and channel must agree
  within the noise plus 2% of its mean: (|mean_L - mean_C| - 0.02 mean_C)+ / se under the
  Bonferroni threshold at 1e-3 (Student t, K - 1 dof; lantern.metrics).
- Cross-integrator: pt, bdpt, lvc and cis on the node-heavy scene, K seeds each, pairwise
  lantern.metrics.agreement against pt (the same test tests/python/test_bidirectional.py uses).
  The scene's graphs are not view-dependent there (nodes_procedural), so every integrator sees
  the same BSDF at a vertex."""

import os
import sys

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
lantern = pytest.importorskip("lantern")
if not lantern.native_available():
    pytest.skip(f"native core unavailable: {lantern.native_error()}", allow_module_level=True)

import node_stage as st  # noqa: E402
from lantern import metrics  # noqa: E402

sys.path.insert(0, os.path.join(st.ROOT, "blend_scenes"))
import nodes as node_scenes  # noqa: E402

K, SPP, ALPHA, SLACK = 6, 32, 1e-3, 0.02


@pytest.fixture(scope="module", autouse=True)
def _addon():
    st.addon()


@pytest.mark.parametrize("name", sorted(node_scenes.SCENES))
def test_node_scene_matches_cycles(name, tmp_path):
    from lantern_blender.export import export_scene
    sc = node_scenes.SCENES[name]()
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    assert report.messages == []
    lan = [np.asarray(lantern.render(scene, spp=SPP, integrator="pt", max_depth=8,
                                     seed=11 + k), np.float64) for k in range(K)]
    cyc = [st.render_cycles(sc, tmp_path / f"c{k}.exr", spp=SPP, bounces=8, seed=300 + k)
           for k in range(K)]
    mean_l, se_l = metrics.block_stats(lan)
    mean_c, se_c = metrics.block_stats(cyc)
    se = np.sqrt(se_l ** 2 + se_c ** 2) + 1e-6
    excess = np.maximum(np.abs(mean_l - mean_c) - SLACK * np.abs(mean_c), 0.0)
    z = excess / se
    thr = metrics.z_threshold(z.size, ALPHA, dof=K - 1)
    worst = np.unravel_index(int(np.argmax(z)), z.shape)
    ratio = mean_l.sum() / max(mean_c.sum(), 1e-9)
    assert z.max() < thr, (f"{name}: block {worst}: Lantern {mean_l[worst]:.4f}, Cycles "
                           f"{mean_c[worst]:.4f} (se {se[worst]:.4f}); |z| beyond 2% "
                           f"{z.max():.2f} >= {thr:.2f}; image ratio {ratio:.4f}")


def test_node_scene_integrators_agree():
    from lantern_blender.export import export_scene
    node_scenes.nodes_procedural()
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    assert report.messages == []
    sets = {}
    for integ in ("pt", "bdpt", "lvc", "cis"):
        sets[integ] = [np.asarray(lantern.render(scene, spp=16, integrator=integ, max_depth=6,
                                                 seed=101 + k), np.float64) for k in range(K)]
    for integ in ("bdpt", "lvc", "cis"):
        ok, cmp, over3, allowed = metrics.agreement(sets[integ], sets["pt"], block=8,
                                                    alpha=ALPHA)
        assert ok, f"{integ} vs pt: {cmp}; {over3} blocks over |z| 3 (allowed {allowed})"
