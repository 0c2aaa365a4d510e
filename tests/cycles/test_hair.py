"""Hair against Cycles through the add-on (docs/curves.md), Cycles' curve shape set to Linear 3D
Curves (THICK_LINEAR: Embree's ROUND_LINEAR_CURVE, exactly Lantern's round linear segments):

- fur: particle hair on a sphere (children off, 3 render steps) with the Principled Hair BSDF
  (Chiang, Melanin parametrisation, Offset 2 degrees as the node's default), under an area light
  and a dim world;
- long hair: a Curves object of long, wavy strands with the Principled BSDF.

K seeds of each renderer, lantern.metrics.assert_agreement with its negative controls, and a
control of each scene's own kind: the fur's melanin changed (0.3 -> 0.45) and the long hair's
strands twice as thick must be told apart."""

import os
import sys

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, light as _light  # noqa: E402
from mesh_canon import canonical_faces  # noqa: E402

K = 8
SIZE = 32
SPP = (256, 256)  # each comparison resolves a whole-image bias of about 1.5 % (fur), 0.6 % (long)
SE_FLOOR = 1e-6


def _principled(name, color, roughness=0.5):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*color, 1.0)
    p.inputs["Roughness"].default_value = roughness
    return m


def _hair_material(name, melanin):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    h = nt.nodes.new("ShaderNodeBsdfHairPrincipled")
    h.name = "hair"
    h.parametrization = "MELANIN"
    h.inputs["Melanin"].default_value = melanin
    nt.links.new(h.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return m


def fur():
    scene = bpy_stage.reset(SIZE, world=(0.1, 0.1, 0.12))
    scene.cycles_curves.shape = "THICK_LINEAR"
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(0, 0, 0), segments=32,
                                         ring_count=16)
    ball = bpy.context.active_object
    canonical_faces(ball)
    ball.data.materials.append(_principled("skin", (0.6, 0.6, 0.6)))
    ball.data.materials.append(_hair_material("fur", 0.3))
    mod = ball.modifiers.new("Fur", "PARTICLE_SYSTEM")
    ps = mod.particle_system.settings
    ps.type = "HAIR"
    ps.count = 400
    ps.hair_length = 0.35
    ps.render_step = 3
    ps.display_step = 3
    ps.material = 2
    ps.root_radius, ps.tip_radius, ps.radius_scale = 1.0, 0.3, 0.02
    ps.child_type = "NONE"
    _light(scene, "AREA", (1.5, -1.5, 2.0), 300.0, rotation=(45, 0, 45), size=1.0)
    _camera(scene, (0, -3.0, 0.3), (84, 0, 0), lens=40.0)


def long_hair():
    scene = bpy_stage.reset(SIZE, world=(0.15, 0.15, 0.15))
    scene.cycles_curves.shape = "THICK_LINEAR"
    n, keys = 60, 12
    data = bpy.data.hair_curves.new("Hair")
    data.add_curves([keys] * n)
    rng = np.random.default_rng(7)
    x0 = rng.uniform(-0.6, 0.6, n)
    y0 = rng.uniform(-0.2, 0.2, n)
    t = np.linspace(0.0, 1.0, keys)
    pts = np.stack([x0[:, None] + 0.08 * np.sin(6.0 * t[None, :] + x0[:, None] * 5.0),
                    y0[:, None] + 0.0 * t[None, :],
                    1.0 - 2.0 * t[None, :] + 0.0 * x0[:, None]], axis=-1)
    data.attributes["position"].data.foreach_set("vector", pts.astype(np.float32).ravel())
    rad = data.attributes.get("radius") or data.attributes.new("radius", "FLOAT", "POINT")
    rad.data.foreach_set("value", np.full(n * keys, 0.012, np.float32))
    obj = bpy.data.objects.new("Hair", data)
    scene.collection.objects.link(obj)
    data.materials.append(_principled("strand", (0.8, 0.55, 0.3), roughness=0.4))
    _light(scene, "AREA", (1.0, -2.0, 1.5), 200.0, rotation=(60, 0, 25), size=1.0)
    _camera(scene, (0, -3.5, 0.0), (90, 0, 0), lens=40.0)


def test_fur_with_principled_hair_matches_cycles():
    cyc = bpy_stage.compare_with_cycles("fur, Principled Hair", fur, SPP, (0.02, 0.10),
                                        cycles_seed0=1200, k_seeds=K, se_floor=SE_FLOOR)
    bpy.data.materials["fur"].node_tree.nodes["hair"].inputs["Melanin"].default_value = 0.45
    bpy_stage.control_differs("fur, melanin 0.45", cyc, K, SPP[1], SE_FLOOR)


def test_long_hair_with_principled_bsdf_matches_cycles():
    cyc = bpy_stage.compare_with_cycles("long hair, Principled BSDF", long_hair, SPP,
                                        (0.01, 0.05), cycles_seed0=1300, k_seeds=K,
                                        se_floor=SE_FLOOR)
    rad = bpy.data.hair_curves["Hair"].attributes["radius"]
    rad.data.foreach_set("value", np.full(len(rad.data), 0.024, np.float32))
    bpy_stage.control_differs("long hair, twice as thick", cyc, K, SPP[1], SE_FLOOR)
