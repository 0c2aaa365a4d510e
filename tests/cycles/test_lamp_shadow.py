"""A lamp's Cast Shadow off (the light's use_shadow, Object Data > Settings) against Cycles
through the add-on (export/light.py; pt: integrator/pt_ray_visibility.h pt_lamp_unshadowed),
CI-sized: a red diffuse cube floating over a diffuse floor, under the switched lamp (an area
lamp, or a point lamp of Blender's default radius), and an ordinary point lamp beside, whose
shadow of the cube stays. Cycles traces no shadow ray for the switched lamp's next-event
estimates and keeps their MIS weight, while a bounce ray still finds it only where the cube
does not block it: under the cube the floor gets next-event estimation's share of the lamp's
light (about 90 % for the area lamp, all of it for the point lamp), not the unshadowed image.

K seeds of each renderer, lantern.metrics.assert_agreement with its negative controls; the
switch's own control: Lantern with it left on (the cube's shadow cast) must not agree with
Cycles' render with it off."""

import math
import os
import sys

import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402

K = 16           # seeds: Welch dof >= 15 (tests/README.md)
SIZE = 32
SPP = 64         # per seed, both renderers
BOUNCES = 4      # Cycles max bounces (Lantern max_depth 6)
SE_FLOOR = 1e-6
CONTROLS = (0.01, 0.05)  # (image, block) negative controls: the defaults (it resolves 0.3-0.4 %)


def stage(lamp, cast_shadow):
    """The stage with the switched lamp of kind `lamp` (AREA, POINT) and its Cast Shadow."""
    scene = bpy_stage.reset(SIZE, world=(0.02, 0.02, 0.02))
    floor = bpy_stage.bsdf_material("floor", "ShaderNodeBsdfDiffuse", (0.8, 0.8, 0.8), 0.0)
    red = bpy_stage.bsdf_material("red", "ShaderNodeBsdfDiffuse", (0.8, 0.1, 0.05), 0.0)
    bpy_stage.cube("floor", (0, 0, -0.05), 1.0, floor, scale=(6, 6, 0.1))
    cube = bpy_stage.cube("cube", (0.0, 0.2, 0.7), 0.7, red)
    cube.rotation_euler = (0, 0, math.radians(30))
    if lamp == "AREA":
        switched = bpy_stage.light(scene, "AREA", (0.0, 0.2, 1.8), 150.0, size=1.0)
    else:
        switched = bpy_stage.light(scene, "POINT", (0.0, 0.2, 2.0), 150.0,
                                   shadow_soft_size=0.25)
    switched.visible_camera = False
    switched.data.use_shadow = cast_shadow
    bpy_stage.light(scene, "POINT", (-1.8, -0.6, 1.6), 120.0, shadow_soft_size=0.1)
    bpy_stage.camera(scene, (0, -3.6, 2.4), (62, 0, 0), lens=30.0)


_bounces = bpy_stage.bounces(BOUNCES)


@pytest.mark.parametrize("lamp", ["AREA", "POINT"])
def test_lamp_without_shadow_matches_cycles(lamp):
    cyc = bpy_stage.compare_with_cycles(f"lamp cast shadow off {lamp.lower()}",
                                        lambda: stage(lamp, False), (SPP, SPP), CONTROLS, 1500,
                                        K, SE_FLOOR)
    stage(lamp, True)  # the flag ignored: the cube's shadow from the switched lamp is back
    bpy_stage.control_differs(f"lamp {lamp.lower()} cast shadow on", cyc, K, SPP, SE_FLOOR)
