"""Heterogeneous volumes against Cycles through the add-on (docs/volumes.md): a smoke cube whose
Principled Volume Density is a Noise Texture (Generated coordinates, through Math nodes that
leave empty pockets), on a floor, lit by a sun from the side (its shadow rays cross the smoke:
ratio tracking) and a dim world. K seeds of each renderer (tools/render_compare.py's settings),
lantern.metrics.assert_agreement with its negative controls, and one more control of the
density's pattern: Lantern rendering the noise at Scale 3.5 instead of 3 (the same statistics,
another pattern) must be told apart from Cycles."""

import os
import sys


import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402
from bpy_stage import rough_material as _material  # noqa: E402

K = 8
SIZE = 32
SPP = (256, 256)   # Cycles', Lantern's per seed
SE_FLOOR = 1e-6


def _smoke_material():
    """Principled Volume (no Surface) of Density 8 x clamp(Noise Fac - 0.45, 0, 1)."""
    m = bpy.data.materials.new("smoke")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.85, 0.8, 0.7, 1.0)
    v.inputs["Absorption Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.name = "noise"
    noise.inputs["Scale"].default_value = 3.0
    noise.inputs["Detail"].default_value = 2.0
    sub = nt.nodes.new("ShaderNodeMath")
    sub.operation, sub.use_clamp = "SUBTRACT", True
    sub.inputs[1].default_value = 0.45
    mul = nt.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    mul.inputs[1].default_value = 8.0
    nt.links.new(noise.outputs["Fac"], sub.inputs[0])
    nt.links.new(sub.outputs[0], mul.inputs[0])
    nt.links.new(mul.outputs[0], v.inputs["Density"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def smoke():
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.06, 0.08))
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    _cube("smoke", (0, 0, 0.75), 1.3, _smoke_material())  # apart from the floor
    _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
    _camera(scene, (0, -3.5, 1.8), (70, 0, 0), lens=30.0)


def test_noise_smoke_matches_cycles():
    cyc = bpy_stage.compare_with_cycles("smoke", smoke, SPP, (0.01, 0.05), cycles_seed0=900,
                                        k_seeds=K, se_floor=SE_FLOOR)
    # the density's pattern matters: another noise scale is told apart
    bpy.data.materials["smoke"].node_tree.nodes["noise"].inputs["Scale"].default_value = 3.5
    bpy_stage.control_differs("smoke, noise scale 3.5", cyc, K, SPP[1], SE_FLOOR)
