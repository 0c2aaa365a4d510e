"""A glass of murky water against Cycles through the add-on (docs/volumes.md): one closed mesh
(a cylinder) whose material has a Glass BSDF surface (IOR 1.33) and a Volume (Volume Scatter +
Volume Absorption) inside, standing on a floor under an area light, seen through its side.
Paths refract into the medium, scatter, and leave through the glass (the medium is entered and
left at the refracting surface). K seeds of each renderer (tools/render_compare.py's settings),
lantern.metrics.assert_agreement with its negative controls, and a control of the medium: Lantern
rendering the water clear (no volume) must be told apart from Cycles."""

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


def _murky_water():
    m = bpy.data.materials.new("water")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    out = nt.nodes["Material Output"]
    glass = nt.nodes.new("ShaderNodeBsdfGlass")
    glass.inputs["IOR"].default_value = 1.33
    glass.inputs["Roughness"].default_value = 0.0
    nt.links.new(glass.outputs[0], out.inputs["Surface"])
    sc = nt.nodes.new("ShaderNodeVolumeScatter")
    sc.inputs["Density"].default_value = 2.0
    sc.inputs["Color"].default_value = (0.7, 0.8, 0.6, 1)
    ab = nt.nodes.new("ShaderNodeVolumeAbsorption")
    ab.inputs["Density"].default_value = 1.0
    ab.inputs["Color"].default_value = (0.6, 0.7, 0.5, 1)
    add = nt.nodes.new("ShaderNodeAddShader")
    add.name = "add"
    nt.links.new(sc.outputs[0], add.inputs[0])
    nt.links.new(ab.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], out.inputs["Volume"])
    return m


def glass_of_water():
    scene = bpy_stage.reset(SIZE, world=(0.1, 0.1, 0.12))
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    bpy.ops.mesh.primitive_cylinder_add(radius=0.4, depth=1.0, location=(0, 0, 0.52),
                                        vertices=32)
    bpy.context.active_object.data.materials.append(_murky_water())
    _light(scene, "AREA", (0.6, -0.8, 2.2), 200.0, rotation=(30, 0, 30), size=1.0)
    _camera(scene, (0, -3.2, 1.2), (80, 0, 0), lens=35.0)


def test_glass_of_murky_water_matches_cycles():
    cyc = bpy_stage.compare_with_cycles("glass of murky water", glass_of_water, SPP, (0.02, 0.10), cycles_seed0=950,
                                        k_seeds=K, se_floor=SE_FLOOR)
    # the medium matters: clear water is told apart
    nt = bpy.data.materials["water"].node_tree
    nt.links.remove(nt.nodes["Material Output"].inputs["Volume"].links[0])
    bpy_stage.control_differs("glass, clear water", cyc, K, SPP[1], SE_FLOOR)
