"""Light linking against Cycles through the add-on (Object > Shading > Light Linking > Receiver
Collection; pt: native/src/integrator/pt_light_linking.h; add-on: export/linking.py), CI-sized:
a diffuse floor and two cubes under a key area light and a dim world,

- include: the key's collection includes cube A only (the floor and cube B get only the world
  and the light bounced off A);
- exclude: the key's collection excludes the floor (the cubes are lit, the floor is not);
- emitter: the key replaced by a glowing panel (Emission) whose collection includes cube B;
- blocker: shadow linking, the key's Blocker collection excludes cube A (A casts the key no
  shadow; Lantern: next-event estimation alone for the key, Cycles: its dedicated light rays).

Each is compared with Cycles (K seeds, lantern.metrics.assert_agreement and its negative
controls), with a negative control of its own: Lantern with the link removed must not agree
with Cycles' linked render."""

import math
import os
import sys

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402

K = 16           # seeds: Welch dof >= 15 (tests/README.md)
SIZE = 32
SPP = 64         # per seed, both renderers
BOUNCES = 4      # Cycles max bounces (Lantern max_depth 6)
SE_FLOOR = 1e-6
CONTROLS = (0.03, 0.08)  # negative controls (image, block), as test_ray_visibility.py's


def _diffuse(name, color):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1)
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = 1.0
    return mat


def stage(case, linked=True):
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.05, 0.05))
    floor = bpy_stage.cube("floor", (0, 0, -0.05), 1.0, _diffuse("floor", (0.8, 0.8, 0.8)),
                           scale=(6, 6, 0.1))
    a = bpy_stage.cube("A", (-0.7, 0, 0.35), 0.7, _diffuse("a", (0.8, 0.3, 0.1)))
    b = bpy_stage.cube("B", (0.7, 0, 0.35), 0.7, _diffuse("b", (0.1, 0.4, 0.8)))
    if case == "emitter":
        glow = _diffuse("glow", (0.0, 0.0, 0.0))
        bsdf = glow.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Emission Color"].default_value = (1.0, 1.0, 1.0, 1)
        bsdf.inputs["Emission Strength"].default_value = 6.0
        key = bpy_stage.cube("panel", (0.0, 0.0, 2.2), 1.0, glow, scale=(1.2, 1.2, 0.05))
        key.visible_camera = False
    else:
        key = bpy_stage.light(scene, "AREA", (0.3, -1.0, 2.5), 300.0, rotation=(25, 0, 0),
                              size=1.2)
    bpy_stage.camera(scene, (0, -4.0, 1.6), (72, 0, 0), lens=35.0)
    if linked:
        coll = bpy.data.collections.new("receivers")
        if case == "include":
            coll.objects.link(a)
        elif case == "exclude":
            coll.objects.link(floor)
            coll.collection_objects[0].light_linking.link_state = "EXCLUDE"
        elif case == "emitter":
            coll.objects.link(b)
        else:
            coll.objects.link(a)
            coll.collection_objects[0].light_linking.link_state = "EXCLUDE"
        if case == "blocker":
            key.light_linking.blocker_collection = coll
        else:
            key.light_linking.receiver_collection = coll


CASES = ("include", "exclude", "emitter", "blocker")


_bounces = bpy_stage.bounces(BOUNCES)


def _lantern(case, linked=True):
    stage(case, linked)
    lan, warnings = [], []
    for k in range(K):
        img, warnings = rc.render_lantern(seed=1 + k, spp=SPP, threads=2)
        lan.append(img)
    return np.stack(lan).astype(np.float64), warnings


@pytest.mark.parametrize("case", CASES)
def test_light_linking_matches_cycles(case):
    stage(case)
    # stored per-seed block means (bpy_stage.cycles_reference: rendered again when the scene's
    # export, this file or the settings change)
    cyc = bpy_stage.cycles_reference(case, stage, SPP, 1300, K)
    lan, warnings = _lantern(case)
    assert not warnings, warnings
    assert np.isfinite(lan).all() and cyc.blocks.mean() > 1e-3
    res = metrics.compare_renders(lan, cyc, block=rc.BLOCK, se_floor=SE_FLOOR, name=case)
    line = f"{res}; mean ratio {lan.mean() / cyc.blocks.mean():.4f}"
    print(line)
    rc.REPORT.append(f"light linking {case}: {line}")
    metrics.assert_agreement(f"light linking {case}", lan, cyc, block=rc.BLOCK,
                             se_floor=SE_FLOOR, image_bias=CONTROLS[0], block_bias=CONTROLS[1])
    free, _ = _lantern(case, linked=False)
    res = metrics.compare_renders(free, cyc, block=rc.BLOCK, se_floor=SE_FLOOR,
                                  name=f"{case} unlinked")
    print(res)
    assert not res.passed, f"{case}: Lantern without the link agrees with Cycles': {res}"
