"""Shadow linking in media against Cycles through the add-on (issue 32 item 4): a floor and two
cubes under a key area light whose Blocker Collection holds cube A only (A casts the key's
shadow, B does not), a dim fill without linking, in

- world: a world Volume Scatter;
- box: a mesh volume (a cube with Volume Scatter and no surface) around the cubes and the
  floor, the key 1 m above its top: the box is no blocker of the key either.

Cycles filters a shadow-linked light's shadow rays by the blocker set through volumes too
(intersection_skip_shadow_link on every hit of its shadow rays' queries, the volume stack
updated only at the hits they record). So the key's shadow rays also pass the box's top as if
it were not there, in the box's fog all the way up to the key (pt_shadow_loop's rule).
Before the fix pt's shadow rays in a scene with media ignored the blocker set (every surface
blocked: B cast the key's shadow) while next-event estimation stayed the key's only strategy:
B's shadow of the key came out black in fog.

Negative control: Lantern with the key's Blocker Collection removed (both cubes cast its
shadow) must not agree with Cycles' linked render."""

import os
import sys

import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402

K = 8
SIZE = 32
SPP = (64, 64)            # (Cycles, Lantern) per seed
CONTROLS = (0.03, 0.15)   # (image, block), as test_linking_fog.py's
SE_FLOOR = 1e-6
_bounces = bpy_stage.bounces(4)  # Cycles max bounces (Lantern max_depth 6)


def _scatter(nt, output, density):
    sc = nt.nodes.new("ShaderNodeVolumeScatter")
    sc.inputs["Density"].default_value = density
    nt.links.new(sc.outputs[0], output.inputs["Volume"])


def stage(case, linked=True):
    scene = bpy_stage.reset(SIZE, world=(0.02, 0.02, 0.02))
    if case == "world":
        nt = scene.world.node_tree
        _scatter(nt, nt.nodes["World Output"], 0.08)
    else:
        fog = bpy.data.materials.new("fog")
        fog.use_nodes = True
        nt = fog.node_tree
        nt.nodes.remove(nt.nodes["Principled BSDF"])
        _scatter(nt, nt.nodes["Material Output"], 0.15)
        bpy_stage.cube("fogbox", (0, 0, 0.7), 1.0, fog, scale=(4.5, 4.5, 1.8))
    rough = bpy_stage.rough_material
    bpy_stage.cube("floor", (0, 0, -0.05), 1.0, rough("floor", (0.7, 0.7, 0.7)),
                   scale=(6, 6, 0.1))
    a = bpy_stage.cube("A", (-0.7, 0, 0.35), 0.7, rough("a", (0.8, 0.3, 0.1)))
    bpy_stage.cube("B", (0.7, 0, 0.35), 0.7, rough("b", (0.1, 0.4, 0.8)))
    key = bpy_stage.light(scene, "AREA", (0.0, 0.0, 2.6), 300.0, size=0.6)
    bpy_stage.light(scene, "POINT", (-2.0, -1.5, 2.0), 40.0, shadow_soft_size=0.1)
    bpy_stage.camera(scene, (0, -4.0, 1.8), (68, 0, 0), lens=32.0)
    if linked:
        coll = bpy.data.collections.new("key_blockers")
        coll.objects.link(a)
        key.light_linking.blocker_collection = coll


@pytest.mark.parametrize("case", ["world", "box"])
def test_shadow_linking_in_fog_matches_cycles(case):
    name = f"shadow_link_{case}"
    cyc = bpy_stage.compare_with_cycles(name, lambda: stage(case), SPP, CONTROLS,
                                        cycles_seed0=950, k_seeds=K, se_floor=SE_FLOOR)
    stage(case, linked=False)
    bpy_stage.control_differs(f"{name} unlinked", cyc, K, SPP[1], SE_FLOOR)
