"""Principled Coat Normal through the add-on against Cycles: a UV sphere whose coat (rough,
weight 1) has its own normal from a striped tangent-space normal map (stripes tilting +-25
degrees along the uv tangent) over a smooth blue base, under an area light. 4x4-block means over
K independent seeds per renderer must agree within their standard errors (Bonferroni over the
blocks) away from the sphere's limb; the coat on the smooth normal (Coat Normal unlinked) is far
outside that tolerance, so the test can tell them apart.

The limb is excluded and its gap measured: where a mapped normal faces away from the viewer
(view cosine below sin 25 degrees) Cycles bends it towards the viewer, Lantern keeps it (one BSDF
for camera and light sub-paths; docs/materials.md, "Normal maps"), so Lantern's coat is darker
there. Pixels whose view cosine is under 0.7 (and their neighbours, for the pixel filter) are
left out of the z-test: with 0.55 the blocks next to that band read 0.8-1.1 % dark (z 7-10 at
12 and 16 seeds, measured 2026-12-02), which the 8 seeds' Bonferroni threshold (13.3) hid."""

import math
import os
import sys

import numpy as np

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "tools"))
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402
from sphere_stage import camera_light_world, sphere_scene  # noqa: E402

SIZE, K, SPP, BLOCK = 48, 12, 128, 4   # K 8 before: the limb's 1 % controls need 12
LIMB_COS = 0.7
# Lantern / Cycles mean over the limb pixels (view cosine < LIMB_COS), measured (2026-12-02)
# with 64 + 64 seeds of 128 spp (seeds 1010+ and 1020+): 0.96557 +- 0.00070 (under 0.55:
# 0.97098 +- 0.00055; 0.9701 with 8 + 8 before)
LIMB_RATIO, LIMB_SE = 0.96557, 0.00070
TILT = math.radians(25.0)


def _stripes():
    """8 x 1 texels, alternately tilting the normal +-TILT along the tangent (Non-Color)."""
    img = bpy.data.images.new("CoatStripes", 8, 1, alpha=True)
    img.colorspace_settings.name = "Non-Color"
    px = np.zeros((1, 8, 4), np.float32)
    for i in range(8):
        s = math.sin(TILT) * (1 if i % 2 == 0 else -1)
        px[0, i] = (round((s + 1) * 127.5) / 255.0, 128 / 255.0,
                    round((math.cos(TILT) + 1) * 127.5) / 255.0, 1.0)
    img.pixels.foreach_set(px.ravel())
    img.pack()
    return img


def _scene():
    sc, obj, mat = sphere_scene(SIZE, "CoatNormal")
    nt = mat.node_tree
    node = nt.nodes["Principled BSDF"]
    node.inputs["Base Color"].default_value = (0.2, 0.35, 0.8, 1)
    node.inputs["Roughness"].default_value = 0.5
    node.inputs["Coat Weight"].default_value = 1.0
    node.inputs["Coat Roughness"].default_value = 0.15
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = _stripes()
    tex.interpolation = "Closest"
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nt.links.new(tex.outputs["Color"], nmap.inputs["Color"])
    nt.links.new(nmap.outputs["Normal"], node.inputs["Coat Normal"])
    obj.data.materials.append(mat)
    camera_light_world(sc)
    return nt, node


def _view_cosine():
    """(H, W): the cosine between the view ray and the unit sphere's normal at each pixel's
    centre, -1 off the sphere (top row first, as the renders)."""
    sc = bpy.context.scene
    bpy.context.view_layer.update()  # matrix_world of the objects just placed
    cam = sc.camera
    frame = cam.data.view_frame(scene=sc)  # top-right, bottom-right, bottom-left, top-left
    right, left = frame[0].x, frame[2].x
    top, bottom, z = frame[0].y, frame[1].y, frame[0].z
    rot = np.array(cam.matrix_world.to_3x3())
    o = np.array(cam.matrix_world.translation)
    out = np.full((SIZE, SIZE), -1.0)
    for i in range(SIZE):
        for j in range(SIZE):
            d = rot @ np.array([left + (j + 0.5) / SIZE * (right - left),
                                top - (i + 0.5) / SIZE * (top - bottom), z])
            d /= np.linalg.norm(d)
            b = o @ d
            disc = b * b - (o @ o - 1.0)
            if disc > 0.0:
                p = o + d * (-b - math.sqrt(disc))
                out[i, j] = -(p @ d)
    return out


def _interior_blocks():
    """Blocks with no pixel near the limb (view cosine < LIMB_COS, dilated by one pixel)."""
    c = _view_cosine()
    limb = (c > -1.0) & (c < LIMB_COS)
    grown = limb.copy()
    grown[1:] |= limb[:-1]
    grown[:-1] |= limb[1:]
    grown[:, 1:] |= limb[:, :-1]
    grown[:, :-1] |= limb[:, 1:]
    nb = SIZE // BLOCK
    return ~grown.reshape(nb, BLOCK, nb, BLOCK).any(axis=(1, 3)), limb


def test_coat_normal_matches_cycles():
    nt, node = _scene()
    interior, limb = _interior_blocks()
    cyc = [rc.render_cycles(seed=10 + k, spp=SPP)[0] for k in range(K)]
    lan, messages = [], []
    for k in range(K):
        img, messages = rc.render_lantern(seed=20 + k, spp=SPP, threads=2)
        lan.append(img)
    assert not any("Coat Normal" in str(m) for m in messages), messages
    res = metrics.compare_renders(lan, cyc, block=BLOCK, mask=interior, rel_floor=1e-3,
                                  name="coat normal")
    limb_ratio = np.stack(lan)[:, limb].mean() / np.stack(cyc)[:, limb].mean()
    # the ratio's standard error from both sides' seeds (delta method)
    l_seeds = np.stack(lan)[:, limb].reshape(K, -1).mean(axis=1)
    c_seeds = np.stack(cyc)[:, limb].reshape(K, -1).mean(axis=1)
    limb_se = limb_ratio * math.sqrt((l_seeds.var(ddof=1) / l_seeds.mean() ** 2
                                      + c_seeds.var(ddof=1) / c_seeds.mean() ** 2) / K)
    print(f"{res}\ncoat normal: {int(interior.sum())} interior blocks; limb "
          f"({int(limb.sum())} px, view cosine < {LIMB_COS}) mean ratio {limb_ratio:.4f} "
          f"(se {limb_se:.4f})")
    assert interior.sum() >= 40
    # interior: the comparison of tests/README.md (rel_floor: the constant world's se ~ 0),
    # with its negative controls
    metrics.assert_agreement("coat normal", lan, cyc, block=BLOCK, mask=interior,
                             rel_floor=1e-3)
    # the limb: Lantern keeps a mapped normal that faces away, Cycles bends it towards the
    # viewer, so Lantern is darker there (documented): the measured LIMB_RATIO, within the
    # noise of this run and of the measurement (Student t at 1e-3), and a ratio 1 % higher or
    # lower must fail (was t x se x sqrt 2 with 8 seeds: 1.15 %, a 1 % change passed)
    allowed = metrics.z_threshold(1, 1e-3, K - 1) * math.hypot(limb_se, LIMB_SE)
    print(f"coat normal limb: {limb_ratio:.5f} against {LIMB_RATIO} (allowed {allowed:.5f})")
    assert abs(limb_ratio - LIMB_RATIO) <= allowed, (limb_ratio, limb_se)
    for bias in (0.01, -0.01):
        assert abs(limb_ratio * (1.0 + bias) - LIMB_RATIO) > allowed, (bias, limb_ratio, limb_se)
    assert limb_ratio < 1.0
    # the test can fail: the coat on the smooth normal is far outside the tolerance
    nt.links.remove(node.inputs["Coat Normal"].links[0])
    smooth = [rc.render_lantern(seed=30 + k, spp=SPP, threads=2)[0] for k in range(K)]
    off = metrics.compare_renders(smooth, cyc, block=BLOCK, mask=interior, rel_floor=1e-3)
    print(f"coat on the smooth normal: {off}")
    assert not off.blocks_passed
