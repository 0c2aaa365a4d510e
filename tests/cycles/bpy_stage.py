"""Scene parts the feature tests of tests/cycles build in bpy (test_volumes.py,
test_subsurface.py, test_motion_blur.py): a factory-empty scene of a size with a constant world,
and cubes, cameras and lights placed by location and rotation in degrees."""
import math
import os

import bpy
import pytest


def reset(size, world=(0.0, 0.0, 0.0)):
    """A factory-empty scene rendered at size x size (Cycles on 2 threads), its world a constant
    colour; returns the scene."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.threads_mode, scene.render.threads = "FIXED", 2
    w = bpy.data.worlds.new("World")
    scene.world = w
    w.use_nodes = True
    w.node_tree.nodes["Background"].inputs["Color"].default_value = (*world, 1)
    return scene


def bsdf_material(name, node_type, color, roughness=None):
    """A material of one BSDF node of `node_type` (ShaderNodeBsdfDiffuse, ...Glossy) of `color`
    (and `roughness` when given) on the Surface, nothing else."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    for n in list(nodes):
        if n.type != "OUTPUT_MATERIAL":
            nodes.remove(n)
    bsdf = nodes.new(node_type)
    bsdf.inputs["Color"].default_value = (*color, 1)
    if roughness is not None:
        bsdf.inputs["Roughness"].default_value = roughness
    links.new(bsdf.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat


def rough_material(name, color):
    """The default Principled BSDF material with Base Color `color` and Roughness 1 (the walls
    and floors of the volume scenes)."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1.0)
    m.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 1.0
    return m


def bounces(n):
    """An autouse fixture for a test module: render_compare.BOUNCES is `n` (Cycles' max bounces;
    Lantern's max_depth n + 2) during each of its tests. `_bounces = bpy_stage.bounces(4)`."""
    @pytest.fixture(autouse=True)
    def _bounces():
        import render_compare as rc
        old = rc.BOUNCES
        rc.BOUNCES = n
        yield
        rc.BOUNCES = old
    return _bounces


def cube(name, location, size, material, scale=(1, 1, 1)):
    bpy.ops.mesh.primitive_cube_add(size=size, location=location, scale=scale)
    obj = bpy.context.active_object
    obj.name = name
    obj.data.materials.append(material)
    return obj


def camera(scene, location, rotation, lens=35.0):
    cam = bpy.data.cameras.new("Camera")
    cam.lens = lens
    obj = bpy.data.objects.new("Camera", cam)
    scene.collection.objects.link(obj)
    obj.location = location
    obj.rotation_euler = [math.radians(a) for a in rotation]
    scene.camera = obj
    return obj


def light(scene, kind, location, energy, rotation=(0, 0, 0), **kw):
    """A light of `kind` (POINT, SPOT, AREA, SUN) with its data's attributes set from kw."""
    data = bpy.data.lights.new(kind, kind)
    data.energy = energy
    for k, v in kw.items():
        setattr(data, k, v)
    obj = bpy.data.objects.new(kind, data)
    scene.collection.objects.link(obj)
    obj.location = location
    obj.rotation_euler = [math.radians(a) for a in rotation]
    return obj


def lantern_renders(k_seeds, spp):
    """The staged scene rendered by Lantern through the add-on, seeds 1..k_seeds at `spp` on
    every core (or LANTERN_THREADS; the same bits on any count): (the stack as float64, the
    last render's warnings)."""
    import numpy as np

    import render_compare as rc
    lan, warnings = [], []
    for k in range(k_seeds):
        img, warnings = rc.render_lantern(seed=1 + k, spp=spp)
        lan.append(img)
    return np.stack(lan).astype(np.float64), warnings


def cycles_reference(name, build, spp, cycles_seed0, k_seeds):
    """Cycles' k_seeds renders of the staged scene as stored per-seed block means
    (render_compare.stored_cycles), in tests/refs/cycles/<test module>/; the test module and
    this one are in their key."""
    import sys

    import render_compare as rc
    module = sys.modules[build.__module__]
    stem = os.path.splitext(os.path.basename(module.__file__))[0]
    safe = "".join(c if c.isalnum() else "_" for c in name)
    return rc.stored_cycles(os.path.join(rc.CYCLES_REFS, stem, f"{safe}_{cycles_seed0}.npz"),
                            spp, cycles_seed0, k_seeds, [module.__file__, __file__])


def compare_with_cycles(name, build, spp, controls, cycles_seed0, k_seeds, se_floor):
    """The feature tests' comparison: `build()` makes the scene; K seeds of each renderer at
    spp = (Cycles', Lantern's) (Cycles' as stored block means: cycles_reference; Lantern's
    seeds 1..), no Lantern warning, Cycles not black, metrics.assert_agreement with the (image,
    block) negative controls `controls`; the measured line goes to render_compare.REPORT.
    Returns Cycles' reference (for control_differs)."""
    import time

    import numpy as np

    import render_compare as rc
    from lantern import metrics
    t0 = time.perf_counter()
    build()
    cyc = cycles_reference(name, build, spp[0], cycles_seed0, k_seeds)
    lan, warnings = lantern_renders(k_seeds, spp[1])
    assert not warnings, warnings
    assert np.isfinite(lan).all()
    assert cyc.blocks.mean() > 1e-3, "the scene is black in Cycles"
    res = metrics.compare_renders(lan, cyc, block=rc.BLOCK, se_floor=se_floor, name=name)
    line = (f"{res}; mean ratio {lan.mean() / cyc.blocks.mean():.4f} "
            f"({time.perf_counter() - t0:.1f} s)")
    print(line)
    rc.REPORT.append(line)
    metrics.assert_agreement(name, lan, cyc, block=rc.BLOCK, se_floor=se_floor,
                             image_bias=controls[0], block_bias=controls[1])
    return cyc


def control_differs(name, cyc, k_seeds, spp, se_floor):
    """A negative control of the scene's own kind: the caller has changed the staged scene
    (the feature taken out or altered); Lantern's renders of it must not pass against Cycles'
    renders `cyc` of the scene as it was."""
    import render_compare as rc
    from lantern import metrics
    other, _ = lantern_renders(k_seeds, spp)
    ctl = metrics.compare_renders(other, cyc, block=rc.BLOCK, se_floor=se_floor, name=name)
    print(f"control: {ctl}; mean ratio {other.mean() / cyc.blocks.mean():.4f}")
    assert not ctl.passed, f"{name} passed against Cycles: {ctl}"
