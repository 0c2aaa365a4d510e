"""Skin in fog against Cycles through the add-on (docs/subsurface.md, "Subsurface with volumes"):
a smooth sphere of Principled BSDF with Random Walk (Skin) on a floor in world fog (Volume
Scatter + Volume Absorption) under a point light, K seeds of Cycles (stored block means) against
K seeds of Lantern's bdpt (its camera walks' exits in the fog, integrator/bdpt_sss.h) and of pt,
compared by lantern.metrics.assert_agreement with its negative controls; the scene's own
control: bdpt with the exits leaving into vacuum (LANTERN_SSS_ADJOINT=nomedium) must not pass.
Before, bdpt handed any scene with subsurface and a volume to pt."""

import os
import sys

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402

K = 6
SIZE = 32
SE_FLOOR = 1e-6
SPP_CYCLES, SPP = 128, 64
CONTROLS = (0.02, 0.10)  # (image, block) negative controls the noise affords


def _material(name, color, sss=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*color, 1.0)
    p.inputs["Roughness"].default_value = 0.5
    p.inputs["Subsurface Weight"].default_value = sss
    p.inputs["Subsurface Radius"].default_value = (1.0, 0.35, 0.2)
    p.inputs["Subsurface Scale"].default_value = 0.15
    p.subsurface_method = "RANDOM_WALK_SKIN"
    p.inputs["Subsurface IOR"].default_value = 1.4
    return m


def skin_in_fog():
    scene = bpy_stage.reset(SIZE)
    nt = scene.world.node_tree
    out = nt.nodes["World Output"]
    sc = nt.nodes.new("ShaderNodeVolumeScatter")
    sc.inputs["Density"].default_value = 0.12
    sc.inputs["Color"].default_value = (0.9, 0.85, 0.8, 1)
    ab = nt.nodes.new("ShaderNodeVolumeAbsorption")
    ab.inputs["Density"].default_value = 0.04
    ab.inputs["Color"].default_value = (0.5, 0.6, 0.9, 1)
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(sc.outputs[0], add.inputs[0])
    nt.links.new(ab.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], out.inputs["Volume"])
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.6, 0.6, 0.6)), scale=(8, 8, 0.1))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(0, 0, 0.6), segments=32,
                                         ring_count=16)
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(
        _material("skin", (0.8, 0.55, 0.45), sss=1.0))
    _light(scene, "POINT", (1.2, -1.2, 2.2), 400.0, shadow_soft_size=0.1)
    _camera(scene, (0, -4.0, 1.2), (80, 0, 0), lens=40.0)


def _lantern(integrator, k_seeds, spp):
    """The staged scene exported by the add-on and rendered by `integrator`, seeds 1..k_seeds;
    no session may hand it over (its warnings are checked)."""
    import lantern
    import render_compare as rc
    rc.lantern_bpy.load_addon()
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    assert not report.messages, report.messages
    out = []
    for k in range(k_seeds):
        s = lantern.Session(scene, integrator=integrator, backend="cpu",
                            max_depth=rc.lantern_depth(rc.BOUNCES), seed=1 + k,
                            spp_per_iteration=spp, threads=0)
        s.step()
        assert not s.warnings, s.warnings
        out.append(np.asarray(s.image(), np.float64)[..., :3])
    return np.stack(out)


@pytest.mark.parametrize("integrator", ["pt", "bdpt"])
def test_skin_in_fog_matches_cycles(integrator, monkeypatch):
    import render_compare as rc
    from lantern import metrics
    skin_in_fog()  # (Cycles' settings, which the export reads, set by cycles_reference)
    cycles_ref = bpy_stage.cycles_reference("skin_in_fog", skin_in_fog, SPP_CYCLES, 900, K)
    assert cycles_ref.blocks.mean() > 1e-3, "the scene is black in Cycles"
    lan = _lantern(integrator, K, SPP)
    print(f"{integrator}: mean ratio {lan.mean() / cycles_ref.blocks.mean():.4f}")
    metrics.assert_agreement(f"skin in fog, {integrator}", lan, cycles_ref, block=rc.BLOCK,
                             se_floor=SE_FLOOR, image_bias=CONTROLS[0], block_bias=CONTROLS[1])
    if integrator == "bdpt":  # the exits into vacuum: no fog after the walk
        monkeypatch.setenv("LANTERN_SSS_ADJOINT", "nomedium")
        bad = _lantern(integrator, K, SPP)
        ctl = metrics.compare_renders(bad, cycles_ref, block=rc.BLOCK, se_floor=SE_FLOOR)
        print(f"control: {ctl}; mean ratio {bad.mean() / cycles_ref.blocks.mean():.4f}")
        assert not ctl.passed, f"bdpt with the exits into vacuum passed against Cycles: {ctl}"
