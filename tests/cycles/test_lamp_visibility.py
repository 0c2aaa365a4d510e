"""A lamp's own ray visibility against Cycles through the add-on (a light object's Visibility >
Ray Visibility: Diffuse, Glossy; export/light.py, pt: native/src/integrator/pt_ray_visibility.h),
CI-sized: a diffuse floor and a red diffuse box, a rough glossy panel behind, lit by an area
lamp (the one switched) and a point lamp, the camera not seeing the area lamp directly:

- diffuse: the area lamp lights no diffuse surface (next-event estimation from the floor and
  the box skips it, bounce rays off them do not see it); the panel still reflects it;
- glossy: the panel does not reflect it (neither strategy), the diffuse surfaces stay lit.

As Cycles excludes a light's shader from the rays of a kind. K seeds of each renderer,
lantern.metrics.assert_agreement with its negative controls; the switch's own control: Lantern
with it left on must not agree with Cycles' render with it off."""

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
SPP = {"diffuse": 256, "glossy": 64}  # per seed, both renderers
BOUNCES = 4      # Cycles max bounces (Lantern max_depth 6)
SE_FLOOR = 1e-6
# negative controls (image, block) the noise affords: with the lamp hidden from diffuse rays the
# floor is lit through the rough panel's reflection of it (a caustic path, noisy in both
# renderers): at 64 spp a +8 % block bias, at 128 spp +12 %, showed at z < 6.1
CONTROLS = {"diffuse": (0.03, 0.12), "glossy": (0.03, 0.08)}
FLAGS = {"diffuse": "visible_diffuse", "glossy": "visible_glossy"}


def stage(off=None):
    """The stage with the area lamp's switch `off` (a FLAGS key) turned off, or none."""
    scene = bpy_stage.reset(SIZE, world=(0.02, 0.02, 0.02))
    floor = bpy_stage.bsdf_material("floor", "ShaderNodeBsdfDiffuse", (0.8, 0.8, 0.8), 0.0)
    red = bpy_stage.bsdf_material("red", "ShaderNodeBsdfDiffuse", (0.8, 0.1, 0.05), 0.0)
    panel = bpy_stage.bsdf_material("panel", "ShaderNodeBsdfGlossy", (0.9, 0.9, 0.9), 0.15)
    bpy_stage.cube("floor", (0, 0, -0.05), 1.0, floor, scale=(6, 6, 0.1))
    bpy_stage.cube("panel", (0, 1.2, 1.0), 1.0, panel, scale=(3.0, 0.1, 2.0))
    box = bpy_stage.cube("box", (0.4, -0.1, 0.4), 0.8, red)
    box.rotation_euler = (0, 0, math.radians(30))
    area = bpy_stage.light(scene, "AREA", (0.0, -1.6, 2.2), 300.0, rotation=(40, 0, 0),
                           size=0.8)
    area.visible_camera = False
    if off is not None:
        setattr(area, FLAGS[off], False)
    bpy_stage.light(scene, "POINT", (-1.5, -0.5, 1.5), 150.0, shadow_soft_size=0.1)
    bpy_stage.camera(scene, (0, -4.0, 1.4), (78, 0, 0), lens=32.0)


_bounces = bpy_stage.bounces(BOUNCES)


@pytest.mark.parametrize("off", list(FLAGS))
def test_lamp_visibility_matches_cycles(off):
    cyc = bpy_stage.compare_with_cycles(f"lamp visibility {off}", lambda: stage(off),
                                        (SPP[off], SPP[off]), CONTROLS[off], 1400, K, SE_FLOOR)
    stage(None)  # the switch left on: the lamp lights (or shows in) what Cycles' render lacks
    bpy_stage.control_differs(f"lamp {FLAGS[off]} on", cyc, K, SPP[off], SE_FLOOR)
