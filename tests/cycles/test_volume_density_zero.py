"""A volume switched off by its density: a cube whose material has a Principled Volume of
Density 0 and no Surface, around a spot light in a closed room. Cycles' rays and shadow rays
pass such a mesh (it has no surface) and find nothing inside, so the picture is the room without
the cube. Lantern dropped the medium but kept the mesh as a volume boundary, which it crosses
only where the scene has media: with none left the cube's faces stopped every ray, and the
room read 0.32 of Cycles' (a ptfog2 finding on the lamp in a shade, 2026-12-05).

Checked against Lantern's own render of the room with the cube deleted (what Cycles renders):
K seeds a side, lantern.metrics.assert_agreement with its negative controls; the control of the
scene: the cube at Density 0.25 is told apart."""

import os
import sys

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
import render_compare as rc  # noqa: E402
import test_volumes  # noqa: E402 (its fog_spot scene)
from lantern import metrics  # noqa: E402

K, SPP, SIZE = 8, 8, 24


def room(density, fog=True):
    """test_volumes.fog_spot (a closed room, an occluder under a spot light, a cube of Principled
    Volume and no Surface around them) at SIZE pixels, its fog at `density`, or without the fog
    cube."""
    test_volumes.fog_spot()
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    fog_cube = bpy.data.objects["fog"]
    if fog:
        volume = fog_cube.active_material.node_tree.nodes["Principled Volume"]
        volume.inputs["Density"].default_value = density
    else:
        bpy.data.objects.remove(fog_cube)
    rc.cycles_settings(scene, 1, SPP)  # the comparisons' settings (bounces, film filter)
    return scene


def test_zero_density_volume_is_not_there():
    room(0.0)
    off, warnings = bpy_stage.lantern_renders(K, SPP)
    assert not warnings, warnings
    room(0.0, fog=False)
    none, _ = bpy_stage.lantern_renders(K, SPP)
    ratio = off.mean() / none.mean()
    print(f"density 0 / no cube: image mean {ratio:.4f}")
    # 8 x 8 spp at 24 x 24 resolve ~4 % of the image and 20-40 % of a dark block (the bug was
    # -100 %): controls 6 % / 60 %
    metrics.assert_agreement("density 0 vs no cube", off, none, block=rc.BLOCK,
                             image_bias=0.06, block_bias=0.6)
    room(0.25)  # fog_spot's own density
    fog, _ = bpy_stage.lantern_renders(K, SPP)
    res = metrics.compare_renders(fog, none, block=rc.BLOCK)
    print(f"density 0.25 vs no cube: {res}")
    assert not res.passed, f"fog of density 0.25 agrees with the room without it: {res}"
