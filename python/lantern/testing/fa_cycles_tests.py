"""False-alarm families of tests/cycles' comparisons against Cycles rendered in-process, for
false_alarm.py (its FAMILIES, loaded by load_family_modules). Each trial renders the
Lantern side with its own seeds at the test's settings. A Cycles trial costs minutes here, so
the Cycles side is one set per case, rendered once per process at the test's own Cycles seeds
and shared by the 20 trials, as the stored references of the `cycles` family are (each
trial's Lantern scene still gets the Cycles settings that the test's export sees after its
Cycles renders). SHARED_CYCLES[family] = False renders the Cycles side with each trial's own
seeds instead (test seeds + 1000 (trial + 1)). Needs bpy.

- anisotropy: test_anisotropy.py's five cases (16 seeds of 16 spp a side, 48 x 48);
- features: test_features.py's three rows, the blocks (compare_renders with its se_floor and
  rim mask) and, as a row of their own, the disc test (disc_z: Student t, Bonferroni);
- light_units: test_light_units.py's six lights (16 seeds of 32 spp a side);
- node_cycles: test_node_scenes.py::test_node_scene_matches_cycles on the five node scenes
  (16 seeds of 12 spp a side).
"""

import os
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
for sub in ("tools", "tests/cycles", "blend_scenes"):
    if str(ROOT / sub) not in sys.path:
        sys.path.insert(0, str(ROOT / sub))

# FA_CYCLES_PER_TRIAL=1 in the environment: every family renders its Cycles side per trial
_PER_TRIAL = os.environ.get("FA_CYCLES_PER_TRIAL") == "1"
SHARED_CYCLES = {f: not _PER_TRIAL for f in ("anisotropy", "features", "light_units",
                                             "node_cycles")}
_CYCLES = {}   # (family, case) -> the shared Cycles set
_TMP = Path(tempfile.mkdtemp(prefix="fa_cycles_tests_"))


def _addon():
    import lantern_bpy
    lantern_bpy.load_addon()


def _cycles(family, case, trial, render):
    """The Cycles set of `case`: render(seed_offset), once per process where shared (offset
    0: the test's own seeds), else with each trial's own offset."""
    if not SHARED_CYCLES[family]:
        return render(1000 * (trial + 1))
    if (family, case) not in _CYCLES:
        _CYCLES[family, case] = render(0)
    return _CYCLES[family, case]


def pairs_anisotropy(trial):
    import bpy
    import render_compare as rc
    import test_anisotropy as ta
    _addon()
    cases = [("principled", 0.8, False), ("principled", 0.8, True), ("glossy", 0.5, True),
             ("glossy", -0.5, False), ("glossy", 0.0, False)]

    def run(case):
        ta._scene(*case)
        cyc = _cycles("anisotropy", case, trial, lambda off: [
            rc.render_cycles(seed=10 + off + k, spp=ta.SPP)[0] for k in range(ta.K)])
        rc.cycles_settings(bpy.context.scene, 10, ta.SPP)  # the scene as the test exports it
        lan = [rc.render_lantern(seed=2300000 + 1000 * trial + k, spp=ta.SPP, threads=2)[0]
               for k in range(ta.K)]
        return lan, cyc, {"block": ta.BLOCK}
    for case in cases:
        yield f"anisotropy {case[0]} {case[1]} tangent node {case[2]} vs Cycles", (
            lambda case=case: run(case))


def _disc_rule(pair, _unused, alpha=1e-3):
    """test_features' disc test at `alpha`: the worst |z| (less the stated cap) against the
    Bonferroni threshold; p the worst disc's two-sided Student t tail (K - 1 dof)."""
    import test_features as tf
    from lantern import metrics, student_t
    lan, cyc, spheres, name = pair
    _, z, _ = tf.disc_z(lan, cyc, spheres, name)
    worst = float(np.abs(z).max())
    p = float(student_t.two_sided_tail(worst, tf.K - 1))
    return SimpleNamespace(passed=worst < metrics.z_threshold(z.size, alpha, dof=tf.K - 1),
                           blocks=SimpleNamespace(p=np.atleast_1d(p), n=z.size))


def pairs_features(trial):
    import bpy
    import features_vs_cycles as fv
    import render_compare as rc
    import test_features as tf
    _addon()
    cache = {}

    def renders(name):
        if name not in cache:
            spheres = tf.build(name)
            cyc = _cycles("features", name, trial, lambda off: np.stack([
                rc.render_cycles(seed=500 + off + k, spp=tf.CYCLES_SPP)[0]
                for k in range(tf.K)]).astype(np.float64))
            rc.cycles_settings(bpy.context.scene, 500, tf.CYCLES_SPP)  # as the test exports it
            lan = np.stack([rc.render_lantern(seed=2400000 + 1000 * trial + k,
                                              spp=tf.LANTERN_SPP, threads=2)[0]
                            for k in range(tf.K)]).astype(np.float64)
            cache[name] = lan, cyc, spheres
        return cache[name]

    def blocks(name):
        lan, cyc, spheres = renders(name)
        mask = (tf.BLOCK_MASKS[name](cyc.shape[1:], spheres, rc.BLOCK)
                if name in tf.BLOCK_MASKS else None)
        return lan, cyc, {"block": rc.BLOCK, "se_floor": fv.SE_FLOOR, "mask": mask}

    def discs(name):
        lan, cyc, spheres = renders(name)
        return (lan, cyc, spheres, name), None, {"compare": _disc_rule}
    for name in tf.SCENES:
        yield f"features {name} blocks vs Cycles", lambda name=name: blocks(name)
        yield f"features {name} discs vs Cycles", lambda name=name: discs(name)


def pairs_light_units(trial):
    import test_light_units as tl
    import lantern

    def run(kind):
        cyc = _cycles("light_units", kind, trial,
                      lambda off: tl._cycles_renders(kind, _TMP, seed0=off))
        scene = tl._lantern_scene(kind)
        lan = np.array([lantern.render(scene, spp=tl.LANTERN_SPP,
                                       seed=2500000 + 1000 * trial + k, max_depth=2,
                                       integrator="pt")
                        for k in range(tl.SEEDS)], dtype=np.float64)
        return list(lan), list(cyc), {"block": tl.BLOCK}
    for kind in ("POINT", "POINT_SPHERE", "SPOT", "AREA", "AREA_ELLIPSE", "SUN"):
        yield f"light units {kind} vs Cycles", lambda kind=kind: run(kind)


def pairs_node_cycles(trial):
    import bpy
    import lantern
    import node_stage as st
    st.addon()
    import test_node_scenes as tn
    from lantern_blender.export import export_scene

    def run(name):
        sc = tn.node_scenes.SCENES[name]()
        scene, _ = export_scene(bpy.context.evaluated_depsgraph_get())
        lan = [np.asarray(lantern.render(scene, spp=tn.SPP, integrator="pt", max_depth=8,
                                         seed=2600000 + 1000 * trial + k), np.float64)
               for k in range(tn.K)]
        cyc = _cycles("node_cycles", name, trial, lambda off: [
            st.render_cycles(sc, _TMP / f"{name}{k}.exr", spp=tn.SPP, bounces=8,
                             seed=300 + off + k) for k in range(tn.K)])
        return lan, cyc, {"block": 8}
    for name in sorted(tn.node_scenes.SCENES):
        yield f"{name} vs Cycles (test_node_scenes)", lambda name=name: run(name)


FAMILIES = {"anisotropy": pairs_anisotropy, "features": pairs_features,
            "light_units": pairs_light_units, "node_cycles": pairs_node_cycles}
