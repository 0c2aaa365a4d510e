"""Shader nodes against Cycles where they shade rather than emit (the node comparison of
test_nodes.py, its helpers in nodes_common.py): Bump on a lit plane, a Normal Map fed by a
node graph, and a node graph on Roughness."""

import math

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

import node_stage as st  # noqa: E402
from nodes_common import (BENT_TOL, _coord, _ident, _node, assert_exact, render_cycles,
    render_lantern)  # noqa: E402


@pytest.fixture(scope="module", autouse=True)
def _addon():
    st.addon()


# ---- Bump: a diffuse plane under a sun straight above, one bounce: each pixel is
# albedo / pi x E x cos(bumped normal), so the image is the bumped normal's z. Under an oblique
# sun Cycles also applies its bump shadowing term (the GGX masking of the normal's tilt at the
# sun's angle to the unbent normal, docs/nodes.md "Bump and displacement"), as Lantern does:
# bump_linear_oblique_sun (slope 0.5, sun 60 deg off the plane's normal) is 2.2 % darker than
# the cosine, which a Lantern without the term puts off in every pixel. Its sun is on the side
# the normal tilts towards (the term is the same either way): tilted away, the pixels read
# 0.045 of the unbent 0.38, where the normal's float rounding (BENT_TOL) is 1 % of them.
def _bump_stage(height_idname, inputs, distance, strength=1.0, invert=False, chain=False,
                displacement=False, sun_deg=0.0):
    sc, nt, emit = st.stage("plane")
    nt.nodes.remove(emit)
    d = _node(nt, "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
    nt.links.new(d.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    h = _node(nt, height_idname, **inputs)
    if displacement:
        disp = _node(nt, "ShaderNodeDisplacement", Midlevel=0.5, Scale=distance)
        nt.links.new(h.outputs[0], disp.inputs["Height"])
        nt.links.new(disp.outputs[0], nt.nodes["Material Output"].inputs["Displacement"])
    else:
        b = _node(nt, "ShaderNodeBump", {"invert": invert}, Distance=distance,
                  Strength=strength)
        nt.links.new(h.outputs[0], b.inputs["Height"])
        nt.links.new(b.outputs[0], d.inputs["Normal"])
        if chain:   # a second bump under the first
            w = _node(nt, "ShaderNodeTexWave", {"bands_direction": "Y"}, Scale=1.5)
            b2 = _node(nt, "ShaderNodeBump", Distance=0.05)
            nt.links.new(w.outputs["Fac"], b2.inputs["Height"])
            nt.links.new(b2.outputs[0], b.inputs["Normal"])
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, 0.0
    sun.rotation_euler = (0.0, math.radians(sun_deg), 0.0)
    sc.collection.objects.link(sun)
    return sc


# Noise and Wave heights: Cycles differences them over the ray differentials (0.1 px, the
# Bump's Filter Width), Lantern over its 2e-4 offsets, and a height that bends within a pixel
# has another slope over each (docs/nodes.md "Bump and displacement"): per pixel the measured
# worst (3.5e-3, 7.1e-3, 1.8e-3 on the unbent value), which a 1 % bias of either sign still
# exceeds where the differences have that sign, and the image mean within 2e-4, where they
# cancel (measured 5.8e-6, 4.2e-5, 5.0e-6)
BUMP_TOL = {"bump_noise": (5e-3, 2e-4), "bump_wave_chained": (1e-2, 2e-4),
            "displacement_as_bump": (2.5e-3, 2e-4)}

BUMPS = {
    "bump_linear": ("ShaderNodeTexGradient", {}, {"distance": 0.5}),
    "bump_linear_oblique_sun": ("ShaderNodeTexGradient", {}, {"distance": 1.0, "sun_deg": -60.0}),
    "bump_linear_inverted_half": ("ShaderNodeTexGradient", {}, {"distance": 1.0,
                                                                 "invert": True,
                                                                 "strength": 0.5}),
    "bump_noise": ("ShaderNodeTexNoise", {"Scale": 3.0}, {"distance": 0.3, "strength": 0.7}),
    "bump_wave_chained": ("ShaderNodeTexWave", {"Scale": 2.0}, {"distance": 0.05,
                                                                "chain": True}),
    "displacement_as_bump": ("ShaderNodeTexNoise", {"Scale": 2.0}, {"distance": 0.3,
                                                                    "displacement": True}),
}


@pytest.mark.parametrize("case", sorted(BUMPS))
def test_bump_matches_cycles(case, tmp_path):
    idname, inputs, kw = BUMPS[case]
    sc = _bump_stage(idname, inputs, **kw)
    img_l, warnings = render_lantern(max_depth=2)
    img_c = render_cycles(sc, tmp_path / "cycles.exr", bounces=0)
    assert warnings == []
    flat = 0.8 / math.pi * 3.0 * math.cos(math.radians(kw.get("sun_deg", 0.0)))
    # the normal moved (a plain plane renders `flat` everywhere)
    assert np.abs(img_c - flat).max() > 0.01 * flat, "no bump: the case would test nothing"
    tol, mean_tol = BUMP_TOL.get(case, (BENT_TOL, None))
    assert_exact(case, img_l, img_c, tol=tol, floor=flat, mean_tol=mean_tol)


# ---- Normal Map fed by a node graph (its Color a mix of two colours along x, Strength 0.8),
# on a diffuse plane under an oblique sun turned about both axes, so that both tilt
# directions show; the tilts stay under 0.25, where Cycles' bump shadowing term (docs/nodes.md
# "Bump and displacement", which Lantern applies too) is under 0.3%. World and object spaces on a turned
# plane (its uv tangent frame turns with it), object space also unevenly scaled (the normal
# matrix is the inverse transpose); Blender's own spaces flip y and z. Measured controls:
# Lantern rendering the world case as tangent space puts 73% of the pixel channels off, the
# object case as world space 52%, Blender World as World 95%.
# Tangent space: Cycles applies Strength to the mapped vector before normalising it (the
# colour's 2c - 1 in the tangent frame, of length 0.95-1.05 here), Lantern to the normalised
# one (pt.h normal_from_tangent_color); with Strength 0.8 the images differ by up to 1.7e-3
# on the unbent value, a model of Cycles' order reproduces Cycles to 1e-5 (docs/nodes.md);
# the Object and World spaces normalise first in both
NORMAL_MAP_TOL = {"TANGENT": 2.5e-3}
NORMAL_MAP_COLORS = {"TANGENT": ((0.38, 0.6, 1.0), (0.62, 0.42, 0.95)),
                     "WORLD": ((0.38, 0.6, 1.0), (0.62, 0.42, 0.95)),
                     "OBJECT": ((0.4, 0.58, 1.0), (0.6, 0.45, 0.95)),
                     "BLENDER_WORLD": ((0.38, 0.4, 0.0), (0.62, 0.58, 0.05))}


def _normal_map_stage(space):
    sc, nt, emit = st.stage("plane")
    nt.nodes.remove(emit)
    obj = bpy.data.objects["Plane"]
    if space != "TANGENT":   # turned: world, object and tangent frames all differ
        obj.rotation_euler = (0.0, 0.0, 0.8)
    if space == "OBJECT":
        obj.scale = (1.4, 0.7, 1.0)
    d = _node(nt, "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.8, 1.0))
    nt.links.new(d.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    x = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(_coord(nt), x.inputs[0])
    m = nt.nodes.new("ShaderNodeMix")
    m.data_type = "RGBA"
    nt.links.new(x.outputs["X"], _ident(m, "Factor_Float"))
    a, b = NORMAL_MAP_COLORS[space]
    _ident(m, "A_Color").default_value = a + (1.0,)
    _ident(m, "B_Color").default_value = b + (1.0,)
    nm = _node(nt, "ShaderNodeNormalMap", {"space": space}, Strength=0.8)
    nt.links.new(next(s for s in m.outputs if s.identifier == "Result_Color"), nm.inputs["Color"])
    nt.links.new(nm.outputs[0], d.inputs["Normal"])
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, 0.0
    sun.rotation_euler = (0.5, 0.6, 0.0)
    sc.collection.objects.link(sun)
    return sc


@pytest.mark.parametrize("space", sorted(NORMAL_MAP_COLORS))
def test_normal_map_from_a_graph_matches_cycles(space, tmp_path):
    sc = _normal_map_stage(space)
    img_l, warnings = render_lantern(max_depth=2)
    img_c = render_cycles(sc, tmp_path / "cycles.exr", bounces=0)
    assert warnings == []
    assert np.std(img_c) > 0.01 * img_c.mean(), "the map bends nothing: it would test nothing"
    assert_exact(space, img_l, img_c, tol=NORMAL_MAP_TOL.get(space, BENT_TOL),
                 floor=0.8 / math.pi * 3.0)


# ---- A node graph on Roughness: the image must not depend on the socket's hidden value.
# Cycles computes the multiple-scattering compensation (and the Principled layer's albedo) at
# each hit's roughness. Lantern did so at the material's constant roughness, which for a
# graph-driven input is the socket's own (hidden) value; measured before the fix (bench/
# textured_roughness_cycles.py): a metal sphere in a white world whose Roughness is a Voronoi
# Distance rendered 5.5 % darker than Cycles, a Wave Fac 8 % darker, hidden values 0 and 1 from
# -15 % to +66 %. Now a material with a per-hit roughness reads its tables from rows at
# roughness j / 32 interpolated at the hit's (scene/scene_materials.cpp fill_lobe_tables, bsdf/
# multiscatter.h ms_rough). Noise-free checks, same seed: a graph whose value is 0.3 everywhere
# (not constant-folded) renders the same image whatever the hidden value (TOL: only float
# rounding may differ), and matches the constant 0.3 within ROWS_TOL, the rows' interpolation
# (the tables' quadrature varies by up to 1e-3 from one roughness to the next, about what
# Cycles' own 32 x 32 tables carry; measured worst pixel 8.1e-4 metal, 4.1e-4 dielectric).
ROWS_TOL = 2e-3


def _graph_roughness_sphere(hidden, graph_value, metallic):
    sc, nt, emit = st.stage("sphere", size=24)
    sc.world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    nt.nodes.remove(emit)
    p = _node(nt, "ShaderNodeBsdfPrincipled", **{"Base Color": (0.9, 0.6, 0.3, 1.0),
                                                 "Metallic": metallic, "Roughness": hidden})
    nt.links.new(p.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    if graph_value is not None:   # graph_value + 0 x Generated X
        x = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(_coord(nt), x.inputs[0])
        m = _node(nt, "ShaderNodeMath", {"operation": "MULTIPLY_ADD"})
        nt.links.new(x.outputs["X"], m.inputs[0])
        m.inputs[1].default_value, m.inputs[2].default_value = 0.0, graph_value
        nt.links.new(m.outputs[0], p.inputs["Roughness"])
    img, warnings = render_lantern(max_depth=4, seed=3)
    assert warnings == []
    return img


@pytest.mark.parametrize("metallic", [1.0, 0.0])
def test_graph_roughness_matches_the_constant(metallic):
    ref = _graph_roughness_sphere(0.3, None, metallic)
    assert_exact(f"graph_roughness_control_{metallic}", _graph_roughness_sphere(0.3, 0.3, metallic),
                 ref, ref.max(axis=2) < 1.0, tol=ROWS_TOL)


@pytest.mark.parametrize("hidden", [0.9, 0.0])
@pytest.mark.parametrize("metallic", [1.0, 0.0])
def test_graph_roughness_ignores_the_hidden_value(metallic, hidden):
    ref = _graph_roughness_sphere(0.3, 0.3, metallic)
    assert_exact(f"graph_roughness_hidden_{hidden}_{metallic}",
                 _graph_roughness_sphere(hidden, 0.3, metallic), ref, ref.max(axis=2) < 1.0)
