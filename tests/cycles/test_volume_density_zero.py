"""A volume switched off by its density: a cube whose material has a Principled Volume of
Density 0 and no Surface, around a spot light in a closed room. Cycles' rays and shadow rays
pass such a mesh (it has no surface) and find nothing inside, so the picture is the room without
the cube. Lantern dropped the medium but kept the mesh as a volume boundary, which it crosses
only where the scene has media: with none left the cube's faces stopped every ray, and the
room read 0.32 of Cycles' (a ptfog2 finding on the lamp in a shade, 2026-12-05).

Checked against Lantern's own render of the room with the cube deleted (what Cycles renders):
K seeds a side, lantern.metrics.assert_agreement with its negative controls; the control of the
scene: the cube at Density 0.25 is told apart."""

import math
import os
import sys

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402

K, SPP, SIZE = 8, 8, 24


def room(density, fog=True):
    """The closed room (normals in), an occluder under a spot light, and (with `fog`) a cube of
    Principled Volume of `density` and no Surface around them."""
    scene = bpy_stage.reset(SIZE)
    bpy.ops.mesh.primitive_cube_add(size=4.0, location=(0, 0, 1.5))
    walls = bpy.context.active_object
    walls.data.materials.append(bpy_stage.rough_material("wall", (0.7, 0.7, 0.7)))
    walls.data.flip_normals()
    if fog:
        m = bpy.data.materials.new("fog")
        m.use_nodes = True
        nt = m.node_tree
        nt.nodes.remove(nt.nodes["Principled BSDF"])
        v = nt.nodes.new("ShaderNodeVolumePrincipled")
        v.inputs["Density"].default_value = density
        nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
        bpy_stage.cube("fog", (0, 0, 1.5), 3.9, m)
    bpy_stage.cube("occluder", (0.0, 0.0, 2.2), 0.4,
                   bpy_stage.rough_material("occluder", (0.2, 0.2, 0.2)), scale=(1, 1, 0.1))
    bpy_stage.light(scene, "SPOT", (0, 0, 3.3), 400.0, spot_size=math.radians(40),
                    spot_blend=0.2, shadow_soft_size=0.0)
    bpy_stage.camera(scene, (0, -1.8, 1.0), (85, 0, 0), lens=20.0)
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
    room(0.25)
    fog, _ = bpy_stage.lantern_renders(K, SPP)
    res = metrics.compare_renders(fog, none, block=rc.BLOCK)
    print(f"density 0.25 vs no cube: {res}")
    assert not res.passed, f"fog of density 0.25 agrees with the room without it: {res}"
