"""A mesh volume whose density is an Image Texture, against Cycles (docs/volumes.md, the Image
Texture's interval rule; volleft). The smoke cube's Principled Volume Density is 8 x an image
of thin columns (64 x 4 float texels, grey, Closest, over Generated (x, y)): columns 1, 3, 4, 6
of every 8 in the image's left 40 columns are 1, the others 0. Before the rule the density program had no bound: Lantern warned
and kept the largest density on a 25^3 lattice x 1.5, and that lattice reads only columns 0,
2, 5 (mod 8): majorant 0, the smoke not rendered at all. Now the majorant is the texels' range
per box (and per majorant brick). K seeds of each renderer (tools/render_compare.py's
settings), lantern.metrics.assert_agreement with its negative controls, and a control of the
image: Lantern with the same columns lit in the right 40 (the same amount of smoke, another
place) must be told apart from Cycles."""

import os
import sys

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402
from bpy_stage import rough_material as _material  # noqa: E402

K = 6
SIZE = 32
SPP = (256, 128)   # Cycles', Lantern's per seed
SE_FLOOR = 1e-6
LIT = (1, 3, 4, 6)


def _columns(left=True):
    """The 64 x 4 grey float image of columns LIT (mod 8) at 1 in the left (right) 40 columns,
    the others 0."""
    img = bpy.data.images.get("columns") or bpy.data.images.new("columns", 64, 4,
                                                                float_buffer=True)
    x = np.arange(64)
    v = (np.isin(x % 8, LIT) & ((x < 40) if left else (x >= 24))).astype(np.float32)
    px = np.zeros((4, 64, 4), np.float32)
    px[..., 0] = px[..., 1] = px[..., 2] = v[None, :]
    px[..., 3] = 1.0
    img.pixels.foreach_set(px.ravel())
    img.pack()
    return img


def _smoke_material():
    """Principled Volume (no Surface) of Density 8 x the image over Generated coordinates."""
    m = bpy.data.materials.new("columns")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.85, 0.8, 0.7, 1.0)
    v.inputs["Absorption Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    coord = nt.nodes.new("ShaderNodeTexCoord")
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.name = "columns"
    tex.image = _columns()
    tex.interpolation = "Closest"
    tex.extension = "REPEAT"
    mul = nt.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    mul.inputs[1].default_value = 8.0
    nt.links.new(coord.outputs["Generated"], tex.inputs["Vector"])
    nt.links.new(tex.outputs["Color"], mul.inputs[0])
    nt.links.new(mul.outputs[0], v.inputs["Density"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def smoke():
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.06, 0.08))
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)), scale=(6, 6, 0.1))
    _cube("smoke", (0, 0, 0.75), 1.3, _smoke_material())  # apart from the floor
    _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
    _camera(scene, (0, -3.5, 1.8), (70, 0, 0), lens=30.0)


def test_image_density_smoke_matches_cycles():
    cyc = bpy_stage.compare_with_cycles("columns", smoke, SPP, (0.01, 0.05), cycles_seed0=910,
                                        k_seeds=K, se_floor=SE_FLOOR)
    # the image matters: the columns lit on the right (as much smoke) are told apart
    _columns(left=False)
    bpy_stage.control_differs("columns, lit on the right", cyc, K, SPP[1], SE_FLOOR)
