"""Nested media against Cycles through the add-on (docs/volumes.md): a coloured volume cube
inside a fog cube (both pure volume boundaries, the inner one off-centre), on a floor under a
large area light just above the fog, the camera outside. Cycles sums the volumes a point is inside
(its volume stack); Lantern's nesting: the medium inside a mesh that lies inside another
medium's mesh holds both (coefficients add), and a path leaving it is back in the outer one.
K seeds of each renderer, lantern.metrics.assert_agreement with its negative controls, and a
control of the rule: Lantern with the inner cube's density taken as the outer fog's added to
it once more (the sum counted twice) must be told apart."""

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
SPP = (256, 256)
SE_FLOOR = 1e-6
FOG = 0.8      # the outer fog's density
INNER = 1.0    # the inner cube's


def _volume(name, density, color, surface=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    out = nt.nodes["Material Output"]
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.name = "volume"
    v.inputs["Density"].default_value = density
    v.inputs["Color"].default_value = (*color, 1.0)
    nt.links.new(v.outputs[0], out.inputs["Volume"])
    if surface is not None:
        g = nt.nodes.new("ShaderNodeBsdfGlass")
        g.inputs["IOR"].default_value = surface
        g.inputs["Roughness"].default_value = 0.0
        nt.links.new(g.outputs[0], out.inputs["Surface"])
    return m


def nested():
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.05, 0.06))
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    _cube("fog", (0, 0, 1.05), 2.0, _volume("fog", FOG, (0.9, 0.9, 0.9)))  # apart from the floor
    _cube("inner", (-0.35, 0, 1.2), 0.8, _volume("inner", INNER, (0.9, 0.5, 0.3)))
    # a large light near the fog: the phase and BSDF samples that reach it through a volume
    # boundary need their MIS pdf from the vertex, not the boundary (Lantern was 3.5 % bright)
    _light(scene, "AREA", (0.3, -0.6, 3.0), 300.0, rotation=(15, 0, 0), size=1.5)
    _camera(scene, (0, -4.5, 1.4), (85, 0, 0), lens=30.0)


def test_nested_media_match_cycles():
    cyc = bpy_stage.compare_with_cycles("nested media", nested, SPP, (0.02, 0.10), cycles_seed0=980,
                                        k_seeds=K, se_floor=SE_FLOOR)
    # the rule matters: the outer fog counted twice inside the inner cube is told apart
    v = bpy.data.materials["inner"].node_tree.nodes["volume"]
    v.inputs["Density"].default_value = INNER + FOG
    bpy_stage.control_differs("nested, fog counted twice", cyc, K, SPP[1], SE_FLOOR)
