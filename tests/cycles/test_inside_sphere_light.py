"""A floor inside a sphere light (difftest D20: a spot light of Radius 0.78 whose sphere cuts the
floor). Cycles lights a receiver inside a sphere light from the light's whole inner surface, a
spot's cone not applied there (kernel/light/point.h, spot.h: the inside branch samples the
hemisphere and skips the spot attenuation). Every upward direction from a floor point inside the
sphere meets that inner surface, of radiance L = P / (4 pi^2 r^2), so a Lambertian floor of
albedo rho reads exactly rho L there: the analytic image, which pt, bdpt and cis must match
(metrics.assert_agreement against the exact value, with its negative controls), for a point and
an upward spot light (whose cone misses the floor: before the fix Lantern sampled nothing from
inside and shaped the inner surface by the cone, so the spot's floor was black and the point's
only reached through BSDF sampling).

Cycles itself is not compared here: its spot light's intersection is one-sided (a ray from
inside heading away from the centre misses it) while its light sampling is not, so Cycles'
spot-inside image depends on its MIS weights (the D20 case reads 0.78 of rho L; docs/difftest.md);
its point light is consistent and agrees with Lantern (the D20 case as a point light: -0.4 %).
"""

import math
import os
import sys

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "tools"))
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402

SIZE, K, SPP = 16, 8, 16
RHO, RADIUS, POWER = 0.8, 0.8, 300.0


def _stage(kind):
    """A 12 m Diffuse floor, a sphere light of radius 0.8 centred 5 cm above it (spot: pointing
    up, 60 degrees), an orthographic camera 5 m up seeing 1 m x 1 m of the floor under the
    light (all of it inside the sphere's footprint of radius 0.798), a black world."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.resolution_x = sc.render.resolution_y = SIZE
    sc.render.resolution_percentage = 100
    bpy.ops.mesh.primitive_plane_add(size=12.0)
    mat = bpy.data.materials.new("Floor")
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    d = nt.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (RHO, RHO, RHO, 1.0)
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    nt.links.new(d.outputs[0], out.inputs["Surface"])
    bpy.context.object.data.materials.append(mat)
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 1.0
    cam.location = (0.0, 0.0, 5.0)
    sc.collection.objects.link(cam)
    sc.camera = cam
    light = bpy.data.lights.new("L", kind)
    light.energy = POWER
    light.shadow_soft_size = RADIUS
    light.use_soft_falloff = False
    if kind == "SPOT":
        light.spot_size = math.radians(60.0)
    lo = bpy.data.objects.new("L", light)
    lo.location = (0.0, 0.0, 0.05)
    lo.rotation_euler = (math.pi, 0.0, 0.0) if kind == "SPOT" else (0.0, 0.0, 0.0)
    lo.visible_camera = False
    sc.collection.objects.link(lo)
    world = bpy.data.worlds.new("W")
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    sc.world = world


@pytest.mark.parametrize("kind", ["POINT", "SPOT"])
def test_floor_inside_sphere_light_reads_rho_times_radiance(kind):
    _stage(kind)
    exact = RHO * POWER / (4.0 * math.pi ** 2 * RADIUS ** 2)
    for integrator in ("pt", "bdpt", "cis"):
        lan = []
        for k in range(K):
            img, messages = rc.render_lantern(seed=300 + k, spp=SPP, threads=1,
                                              integrator=integrator)
            assert messages == [], messages
            lan.append(img)
        label = f"{kind} inside ({integrator})"
        print(f"{label}: mean / exact {np.mean(lan) / exact:.4f}")
        rc.REPORT.append(f"inside sphere light {label}: mean / exact {np.mean(lan) / exact:.4f}")
        metrics.assert_agreement(label, lan, exact, block=8)
