"""Anisotropic GGX through the add-on against Cycles: a metal UV sphere under an area light,
Principled Anisotropic 0.8 (Tangent unlinked and a Tangent node in UV Map mode) and the Glossy
BSDF's Anisotropy of both signs. 8x8-block means over K independent seeds per renderer must
agree within their standard errors (Bonferroni over the blocks); the isotropic image is far
outside that tolerance, so the test can tell anisotropy apart."""

import math
import os
import sys

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
lantern = pytest.importorskip("lantern")
if not lantern.native_available():
    pytest.skip(f"native core unavailable: {lantern.native_error()}", allow_module_level=True)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "tools"))
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402

SIZE, K, SPP, BLOCK = 48, 8, 32, 8


def _scene(kind, value, tangent_node):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.resolution_x = sc.render.resolution_y = SIZE
    sc.render.resolution_percentage = 100
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
    obj = bpy.context.object
    bpy.ops.object.shade_smooth()
    mat = bpy.data.materials.new("Brushed")
    nt = mat.node_tree
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    if kind == "principled":
        node = nt.nodes["Principled BSDF"]
        node.inputs["Base Color"].default_value = (0.9, 0.8, 0.6, 1)
        node.inputs["Metallic"].default_value = 1.0
        node.inputs["Roughness"].default_value = 0.4
        node.inputs["Anisotropic"].default_value = value
    else:
        nt.nodes.remove(nt.nodes["Principled BSDF"])
        node = nt.nodes.new("ShaderNodeBsdfGlossy")
        node.inputs["Color"].default_value = (0.9, 0.8, 0.6, 1)
        node.inputs["Roughness"].default_value = 0.4
        node.inputs["Anisotropy"].default_value = value
        nt.links.new(node.outputs[0], out.inputs["Surface"])
    if tangent_node:
        t = nt.nodes.new("ShaderNodeTangent")
        t.direction_type = "UV_MAP"
        nt.links.new(t.outputs[0], node.inputs["Tangent"])
    obj.data.materials.append(mat)
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.location, cam.rotation_euler = (0, -4.5, 1.5), (math.radians(72), 0, 0)
    sc.collection.objects.link(cam)
    sc.camera = cam
    light = bpy.data.lights.new("Area", "AREA")
    light.energy, light.size = 300.0, 1.0
    lo = bpy.data.objects.new("Area", light)
    lo.location, lo.rotation_euler = (2, -2, 3), (math.radians(40), math.radians(30), 0)
    sc.collection.objects.link(lo)
    world = bpy.data.worlds.new("W")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.05, 0.05, 0.05, 1)
    sc.world = world


def _blocks(imgs):
    b = np.stack([metrics.block_means(i, BLOCK) for i in imgs])
    return b.mean(axis=0), b.std(axis=0, ddof=1) / math.sqrt(len(imgs))


@pytest.mark.parametrize("kind, value, tangent_node", [
    ("principled", 0.8, False), ("principled", 0.8, True),
    ("glossy", 0.5, True), ("glossy", -0.5, False), ("glossy", 0.0, False)])
def test_anisotropy_matches_cycles(kind, value, tangent_node):
    _scene(kind, value, tangent_node)
    cyc = [rc.render_cycles(seed=10 + k, spp=SPP)[0] for k in range(K)]
    lan = [rc.render_lantern(seed=20 + k, spp=SPP, threads=2)[0] for k in range(K)]
    mc, sc = _blocks(cyc)
    ml, sl = _blocks(lan)
    se = np.sqrt(sc ** 2 + sl ** 2 + (1e-3 * mc) ** 2)   # (the constant world: se ~ 0)
    z = (ml - mc) / se
    thr = metrics.z_threshold(z.size, 1e-3, dof=K - 1)
    ratio = np.stack(lan).mean() / np.stack(cyc).mean()
    print(f"{kind} {value} tangent node {tangent_node}: worst |z| {np.abs(z).max():.2f} "
          f"(threshold {thr:.2f}), mean ratio {ratio:.4f}")
    assert np.abs(z).max() < thr
    assert abs(ratio - 1.0) < 0.02
    # the test can fail: the isotropic lobe is far outside the tolerance
    if kind == "principled" and tangent_node:
        bpy.context.object.active_material.node_tree.nodes["Principled BSDF"].inputs[
            "Anisotropic"].default_value = 0.0
        iso = [rc.render_lantern(seed=30 + k, spp=SPP, threads=2)[0] for k in range(K)]
        mi, si = _blocks(iso)
        z_iso = (mi - mc) / np.sqrt(sc ** 2 + si ** 2 + (1e-3 * mc) ** 2)
        assert np.abs(z_iso).max() > 3 * thr
