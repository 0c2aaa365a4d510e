"""Light linking in the world's fog against Cycles through the add-on (difftest4's hand-made
scene, issue 32 item 4): a sphere on a floor in a world Volume Scatter, a key point light whose
Receiver Collection includes the sphere only, a fill point light without linking.

Cycles lights a world volume's point as OBJECT_NONE, receiver set 0: an object without linking,
which an Include-linked emitter does not light. So the key lights the sphere (and through it the
rest), never the fog directly. Before the fix the add-on's set 0 meant "lit by every linked
emitter" and pt lit a fog point by the set of the slot's last surface (or a previous path's),
so the key lit the fog: Lantern read about +20 % (bench/results/2026-12-06-difftest4).

Negative control: Lantern with the key's link removed (the fog lit by the key) must not agree
with Cycles' linked render."""

import os
import sys

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402

K = 8
SIZE = 32
SPP = (64, 64)            # (Cycles, Lantern) per seed
CONTROLS = (0.03, 0.15)   # (image, block), as test_volumes.py's fog_spot
SE_FLOOR = 1e-6


def _material(name, color):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1.0)
    m.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
    return m


def fog_include(linked=True):
    scene = bpy_stage.reset(SIZE)
    nt = scene.world.node_tree
    sc = nt.nodes.new("ShaderNodeVolumeScatter")
    sc.inputs["Density"].default_value = 0.08
    nt.links.new(sc.outputs[0], nt.nodes["World Output"].inputs["Volume"])
    bpy_stage.cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.6, 0.6, 0.6)),
                   scale=(8, 8, 0.1))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(0, 0, 0.6), segments=24,
                                         ring_count=12)
    ball = bpy.context.active_object
    ball.data.materials.append(_material("ball", (0.8, 0.3, 0.2)))
    key = bpy_stage.light(scene, "POINT", (1.0, -1.0, 2.5), 400.0, shadow_soft_size=0.1)
    bpy_stage.light(scene, "POINT", (-2.0, 0.5, 2.0), 60.0, shadow_soft_size=0.1)
    bpy_stage.camera(scene, (0, -5, 1.6), (78, 0, 0), lens=30.0)
    if linked:
        coll = bpy.data.collections.new("key_receivers")
        coll.objects.link(ball)
        key.light_linking.receiver_collection = coll


def test_world_fog_include_link_matches_cycles():
    cyc = bpy_stage.compare_with_cycles("fog_include", fog_include, SPP, CONTROLS,
                                        cycles_seed0=900, k_seeds=K, se_floor=SE_FLOOR)
    fog_include(linked=False)
    bpy_stage.control_differs("fog_include unlinked", cyc, K, SPP[1], SE_FLOOR)
