"""Indirect Only collections against Cycles through the add-on (a view layer's collection flag
indirect_only; addon/export/visibility.py camera_visible: as Cycles' object sync, its objects
lose Camera ray visibility only), CI-sized: a diffuse floor, a sharp mirror behind, and in an
Indirect Only collection a glowing cube (Emission) and a red diffuse box, under an area light.
The camera sees neither of the two; the mirror shows both, the floor gets the cube's glow and
the box's red bounce, and both cast their shadows.

K seeds of each renderer, lantern.metrics.assert_agreement with its negative controls; the
feature's own control: Lantern with the collection's flag off (the camera sees both) must not
agree with Cycles' render with it on."""

import math
import os
import sys

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402

K = 16           # seeds: Welch dof >= 15 (tests/README.md)
SIZE = 32
SPP = 64         # per seed, both renderers
BOUNCES = 4      # Cycles max bounces (Lantern max_depth 6)
SE_FLOOR = 1e-6
CONTROLS = (0.03, 0.08)  # negative controls (image, block), as test_ray_visibility.py's stage


def stage(indirect=True):
    """The stage, its collection 'Bounce' Indirect Only when `indirect`."""
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.05, 0.05))
    floor = bpy_stage.bsdf_material("floor", "ShaderNodeBsdfDiffuse", (0.8, 0.8, 0.8), 0.0)
    mirror = bpy_stage.bsdf_material("mirror", "ShaderNodeBsdfGlossy", (0.9, 0.9, 0.9), 0.0)
    red = bpy_stage.bsdf_material("red", "ShaderNodeBsdfDiffuse", (0.8, 0.1, 0.05), 0.0)
    glow = bpy.data.materials.new("glow")
    glow.use_nodes = True
    nodes = glow.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    emit = nodes.new("ShaderNodeEmission")
    emit.inputs["Color"].default_value = (1.0, 0.4, 0.1, 1)
    emit.inputs["Strength"].default_value = 2.0
    glow.node_tree.links.new(emit.outputs[0], nodes["Material Output"].inputs["Surface"])
    bpy_stage.cube("floor", (0, 0, -0.05), 1.0, floor, scale=(6, 6, 0.1))
    bpy_stage.cube("mirror", (0, 1.2, 1.0), 1.0, mirror, scale=(3.0, 0.1, 2.0))
    bounce = bpy.data.collections.new("Bounce")
    scene.collection.children.link(bounce)
    for name, loc, size, mat in (("cube", (0.5, -0.2, 0.35), 0.7, glow),
                                 ("box", (-0.7, 0.1, 0.4), 0.8, red)):
        obj = bpy_stage.cube(name, loc, size, mat)
        obj.rotation_euler = (0, 0, math.radians(30))
        for col in list(obj.users_collection):
            col.objects.unlink(obj)
        bounce.objects.link(obj)
    scene.view_layers[0].layer_collection.children["Bounce"].indirect_only = indirect
    bpy_stage.light(scene, "AREA", (-0.6, -1.2, 2.6), 250.0, rotation=(20, -15, 0), size=1.0)
    bpy_stage.camera(scene, (0, -4.0, 1.4), (78, 0, 0), lens=32.0)


_bounces = bpy_stage.bounces(BOUNCES)


def test_indirect_only_matches_cycles():
    cyc = bpy_stage.compare_with_cycles("indirect only", stage, (SPP, SPP), CONTROLS, 1300, K,
                                        SE_FLOOR)
    # the flag off: the camera sees the cube and the box, which Cycles' render does not show
    stage(indirect=False)
    bpy_stage.control_differs("indirect only off", cyc, K, SPP, SE_FLOOR)
