"""Texture coordinates inside a Volume object's density graph against Cycles through the add-on
(docs/volumes.md, issue 29). Cycles (bpy 5.0.1) gives a Volume object both Object and Generated
coordinates as the object-space position (measured here: Generated normalised to the Volume's
bounds, (p - min) / size over bpy's bound_box as intern/cycles/blender/volume.cpp's generated
transform reads, differed by |z| 180 in a block); Lantern exports them per vertex of the object's
box and the core fits the medium's affine maps. The blob of test_volumes_vdb_graph.py as a
turned, scaled Volume object; its Principled Volume's Density is `Gradient (Linear) of Generated x
(Object z + 0.6) x 12`, times its Density Attribute "density". Controls (Lantern only), each told
apart: Generated moved by 0.15 along x (a Mapping node), Object z + 0.3 instead of + 0.6."""

import math
import os
import sys

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import lantern
import lantern._core

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402
from bpy_stage import rough_material as _material  # noqa: E402

K = 8
SPP = (256, 128)   # Cycles', Lantern's per seed
SE_FLOOR = 1e-6

pytestmark = pytest.mark.skipif(not lantern.vdb_available(),
                                reason="Lantern built without OpenVDB")


SIZE = 32


def _cube_map(n, lo=-0.5, size=1.0):
    v = size / n
    return np.array([[v, 0, 0, lo + v / 2], [0, v, 0, lo + v / 2],
                     [0, 0, v, lo + v / 2], [0, 0, 0, 1]], np.float64)


def _blob(n=20):
    """test_volumes_vdb_graph.py's density blob (n^3 voxels over the unit cube)."""
    c = (np.arange(n) + 0.5) / n - 0.5
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    return np.clip(np.exp(-(x ** 2 + (y - 0.05) ** 2 + z ** 2) / (2 * 0.2 ** 2)) - 0.08, 0, None)


def write_vdb(path):
    n = 20
    d = _blob(n)
    lantern._core.vdb_write_list(str(path), [
        {"name": "density", "voxels": np.ascontiguousarray(d.astype(np.float32)),
         "index_to_object": _cube_map(n)}])


def _texcoord_material():
    m = bpy.data.materials.new("vdb_texcoord")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    v = nt.nodes.new("ShaderNodeVolumePrincipled")
    v.inputs["Color"].default_value = (0.85, 0.8, 0.7, 1.0)
    v.inputs["Absorption Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    tc = nt.nodes.new("ShaderNodeTexCoord")
    tc.name = "coords"
    grad = nt.nodes.new("ShaderNodeTexGradient")
    grad.name = "gradient"
    grad.gradient_type = "LINEAR"
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    add = nt.nodes.new("ShaderNodeMath")
    add.name = "add"
    add.operation = "ADD"
    add.inputs[1].default_value = 0.6
    mul = nt.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    scale = nt.nodes.new("ShaderNodeMath")
    scale.operation = "MULTIPLY"
    scale.inputs[1].default_value = 12.0
    nt.links.new(tc.outputs["Generated"], grad.inputs["Vector"])
    nt.links.new(tc.outputs["Object"], sep.inputs["Vector"])
    nt.links.new(sep.outputs["Z"], add.inputs[0])
    nt.links.new(grad.outputs["Fac"], mul.inputs[0])
    nt.links.new(add.outputs[0], mul.inputs[1])
    nt.links.new(mul.outputs[0], scale.inputs[0])
    nt.links.new(scale.outputs[0], v.inputs["Density"])
    nt.links.new(v.outputs[0], nt.nodes["Material Output"].inputs["Volume"])
    return m


def stage(vdb_path):
    """A floor, the Volume object reading vdb_path turned and scaled, a sun, the camera
    (test_volumes_vdb_graph.py's density scene)."""
    def build():
        scene = bpy_stage.reset(SIZE, world=(0.05, 0.06, 0.08))
        _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.7, 0.7, 0.7)),
              scale=(6, 6, 0.1))
        vol = bpy.data.volumes.new("texcoord")
        vol.filepath = str(vdb_path)
        obj = bpy.data.objects.new("texcoord", vol)
        scene.collection.objects.link(obj)
        obj.location = (0.1, 0.0, 0.8)
        obj.rotation_euler = tuple(math.radians(a) for a in (10, 0, 20))
        obj.scale = (1.4, 1.1, 1.2)
        vol.materials.append(_texcoord_material())
        _light(scene, "SUN", (0, 0, 3), 3.0, rotation=(50, 0, 40), angle=0.05)
        _camera(scene, (0, -3.5, 1.8), (70, 0, 0), lens=30.0)
    return build


def test_vdb_texture_coordinates_match_cycles(tmp_path):
    path = tmp_path / "texcoord.vdb"
    write_vdb(path)
    cyc = bpy_stage.compare_with_cycles("vdb texture coordinates", stage(path), SPP,
                                        (0.01, 0.05), cycles_seed0=980, k_seeds=K,
                                        se_floor=SE_FLOOR)
    nt = bpy.data.materials["vdb_texcoord"].node_tree
    # Generated moved by 0.15 along x (Lantern only) is told apart
    grad = nt.nodes["gradient"]
    mp = nt.nodes.new("ShaderNodeMapping")
    mp.inputs["Location"].default_value = (0.15, 0.0, 0.0)
    nt.links.new(nt.nodes["coords"].outputs["Generated"], mp.inputs["Vector"])
    nt.links.new(mp.outputs["Vector"], grad.inputs["Vector"])
    bpy_stage.control_differs("vdb texture coordinates, Generated moved", cyc, K, SPP[1],
                              SE_FLOOR)
    # Object z + 0.3 instead of + 0.6 too
    nt.links.new(nt.nodes["coords"].outputs["Generated"], grad.inputs["Vector"])
    nt.nodes["add"].inputs[1].default_value = 0.3
    bpy_stage.control_differs("vdb texture coordinates, z + 0.3", cyc, K, SPP[1], SE_FLOOR)
