"""The stage the lobe tests of tests/cycles share (test_lobes.py, test_sharp_glossy.py): a
factory-empty scene with a 40 m plane at z = 0 (or a unit sphere at z = 1 over nothing), the
camera 3 m up looking 45 degrees down at the plane (the sphere: 65 degrees from 3.2 m away), one
material on the object emptied but for its output, and the comparison both files make: K
independent seeds a side, Lantern against Cycles by metrics.assert_agreement."""
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "tools"))
import render_compare as rc  # noqa: E402
from lantern import metrics  # noqa: E402


def stage(size, kind="plane", material="Lobe"):
    """Returns (scene, node tree of the object's material); the world is left to the caller."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.resolution_x = sc.render.resolution_y = size
    sc.render.resolution_percentage = 100
    if kind == "plane":
        bpy.ops.mesh.primitive_plane_add(size=40.0)
    else:
        bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=4, radius=1.0, location=(0, 0, 1))
        bpy.ops.object.shade_smooth()
    obj = bpy.context.object
    mat = bpy.data.materials.new(material)
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    obj.data.materials.append(mat)
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.location = (0.0, -3.0, 3.0) if kind == "plane" else (0.0, -3.2, 2.6)
    cam.rotation_euler = (math.radians(45.0 if kind == "plane" else 65.0), 0.0, 0.0)
    sc.collection.objects.link(cam)
    sc.camera = cam
    return sc, nt


def world(sc, color=(1.0, 1.0, 1.0, 1.0), strength=1.0):
    w = bpy.data.worlds.new("W")
    bg = w.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = color
    bg.inputs["Strength"].default_value = strength
    sc.world = w


def shader(nt, kind, **inputs):
    """A new node of `kind` with these input defaults, linked to the material's Surface."""
    node = nt.nodes.new(kind)
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    nt.links.new(node.outputs[0], out.inputs["Surface"])
    return node


def lantern_seeds(integrator, k_seeds, spp, base=200):
    imgs = []
    for k in range(k_seeds):
        img, messages = rc.render_lantern(seed=base + k, spp=spp, threads=1, integrator=integrator)
        assert messages == [], messages
        imgs.append(img)
    return imgs


def _stored_cycles(name, k_seeds, spp):
    """Cycles' seeds 100.. as stored per-seed block means (render_compare.stored_cycles), in
    tests/refs/cycles/<test module>/: the calling test module and this one are in the key."""
    import inspect
    caller = next(f.filename for f in inspect.stack()
                  if os.path.basename(f.filename).startswith("test_"))
    stem = os.path.splitext(os.path.basename(caller))[0]
    safe = "".join(c if c.isalnum() else "_" for c in name)
    return rc.stored_cycles(os.path.join(rc.CYCLES_REFS, stem, f"{safe}_100.npz"), spp, 100,
                            k_seeds, [caller, __file__])


def compare(report, name, integrators, k_seeds, spp, block_bias=0.05):
    """Cycles' seeds 100.., Lantern's 200.. of each integrator; `report` prefixes the line each
    comparison adds to render_compare.REPORT."""
    cyc = _stored_cycles(name, k_seeds, spp)
    assert cyc.blocks.mean() > 0.0, "Cycles rendered the scene black"
    for integrator in integrators:
        lan = lantern_seeds(integrator, k_seeds, spp)
        ratio = np.mean(lan) / cyc.blocks.mean()
        label = f"{name} ({integrator})"
        print(f"{label}: Lantern / Cycles image mean {ratio:.4f}")
        rc.REPORT.append(f"{report} {label}: Lantern / Cycles image mean {ratio:.4f}")
        metrics.assert_agreement(label, lan, cyc, block=8, rel_floor=1e-3, block_bias=block_bias)
