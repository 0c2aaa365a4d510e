"""A third scene built by hand as an artist would (difftest5; the others are
bench/difftest3_artist.py and bench/difftest4_artist.py): issue 32's features together, skin,
hair, motion blur and linking, in thin fog, compared with Cycles block by block through the
differential tester's statistics (tools/difftest_run.py's compare: 8x8 blocks, Welch t,
Bonferroni at 1e-3, the image means; "inconclusive" where the image mean's margin is over 25 %).

A turntable shot: Blender's factory startup (cube, 1000 W point light, camera) with the cube
removed; a floor; a plinth (a cylinder, Principled Roughness 0.3);
- a furry Suzanne (smooth shaded) of Principled Subsurface Weight 1, Random Walk (Skin),
  Subsurface IOR 1.35, Subsurface Scale 0.1, with 300 particle strands (hair length 0.12,
  Principled Hair, Melanin 0.6) standing on the plinth, parented to an Empty, the turntable,
  that turns 0.6 rad over frames 0-2 (linear), Suzanne's Motion Steps 2;
- a ball (UV sphere, Principled, Roughness 0.25) rolling across the floor in front (location
  and rotation keys);
- the camera dollying in (0.3 m over frames 0-2); the shutter 0.5, its Position Start;
- a key area light (300 W, 1 m) whose Receiver Collection includes Suzanne and the plinth (it
  lights neither the floor nor the ball), a rim spot (500 W) behind whose Blocker Collection
  excludes the ball, the factory point light with Cast Shadow off as a fill;
- thin fog: the world's Volume, a Volume Scatter of Density 0.02 (Volume Bounces = Max Bounces,
  as the export advises); the curve shape 3D Curves (THICK), as the export advises.
Every input left at Blender's default unless said. Render settings as the tester's
(render_compare): no denoising / adaptive sampling / clamping, every bounce limit B.

    nice .venv/bin/python bench/difftest5_artist.py --integrator pt --seeds 16 --spp 16 \
        [--without skin|fur|turntable|ball|camera|start|steps|keylink|rimblock|noshadow|fog ...] \
        --json OUT.jsonl
"""

import argparse
import json
import math
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "python"))

PARTS = ("skin", "fur", "turntable", "ball", "camera", "start", "steps", "keylink", "rimblock",
         "noshadow", "fog")


def _material(name, ob, **inputs):
    import bpy
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    for k, v in inputs.items():
        _inp(p, k.replace("_", " ")).default_value = v
    ob.data.materials.append(m)
    return m, p


def _inp(node, name):
    """node.inputs[name]: (bpy 5.0.1's inputs["Subsurface IOR"], ["Melanin"] are not found by
    key here; by name they are)"""
    return next(s for s in node.inputs if s.name == name)


def _collection(name, objects, state):
    import bpy
    coll = bpy.data.collections.new(name)
    for ob in objects:
        coll.objects.link(ob)
    for entry in coll.collection_objects:
        entry.light_linking.link_state = state
    return coll


def _keys(ob, path, values):
    for frame, v in zip((0, 2), values):
        setattr(ob, path, v)
        ob.keyframe_insert(path, frame=frame)


def build(parts):
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=False)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.render.resolution_x, sc.render.resolution_y = 64, 48
    sc.render.resolution_percentage = 100
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
    bpy.data.objects.remove(bpy.data.objects["Cube"])
    cam = bpy.data.objects["Camera"]
    point = bpy.data.objects["Light"]
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, -1))
    floor = bpy.context.object
    _material("Floor", floor, Base_Color=(0.5, 0.5, 0.5, 1))
    bpy.ops.mesh.primitive_cylinder_add(radius=0.7, depth=0.3, location=(0, 0, -0.85))
    plinth = bpy.context.object
    _material("Plinth", plinth, Base_Color=(0.8, 0.8, 0.75, 1), Roughness=0.3)
    bpy.ops.mesh.primitive_monkey_add(size=1.0, location=(0, 0, -0.2), rotation=(0, 0, 0.5))
    monkey = bpy.context.object
    bpy.ops.object.shade_smooth()
    if "skin" in parts:
        _, p = _material("Skin", monkey, Base_Color=(0.8, 0.55, 0.45, 1),
                         Subsurface_Weight=1.0, Subsurface_IOR=1.35, Subsurface_Scale=0.1)
        p.subsurface_method = "RANDOM_WALK_SKIN"
    else:
        _material("Skin", monkey, Base_Color=(0.8, 0.55, 0.45, 1))
    if "fur" in parts:
        fur = bpy.data.materials.new("Fur")
        fur.use_nodes = True
        nt = fur.node_tree
        nt.nodes.remove(nt.nodes["Principled BSDF"])
        h = nt.nodes.new("ShaderNodeBsdfHairPrincipled")
        _inp(h, "Melanin").default_value = 0.6
        nt.links.new(h.outputs["BSDF"], nt.nodes["Material Output"].inputs["Surface"])
        monkey.data.materials.append(fur)
        mod = monkey.modifiers.new("Fur", "PARTICLE_SYSTEM")
        ps = mod.particle_system.settings
        ps.type, ps.count, ps.hair_length = "HAIR", 300, 0.12
        ps.material = 2
        # the export names the Ribbons shape and a viewport step count other than the
        # render's (D50's advice): the artist takes both
        ps.display_step = ps.render_step
        sc.cycles_curves.shape = "THICK"
    moving = False
    if "turntable" in parts:
        table = bpy.data.objects.new("Turntable", None)
        sc.collection.objects.link(table)
        bpy.context.view_layer.update()
        monkey.parent = table
        monkey.matrix_parent_inverse = table.matrix_world.inverted()
        _keys(table, "rotation_euler", [(0, 0, -0.3), (0, 0, 0.3)])
        if "steps" in parts:
            monkey.cycles.motion_steps = 2
        moving = True
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.3, location=(1.2, -1.4, -0.7))
    ball = bpy.context.object
    bpy.ops.object.shade_smooth()
    _material("Ball", ball, Base_Color=(0.1, 0.25, 0.8, 1), Roughness=0.25)
    if "ball" in parts:
        _keys(ball, "location", [(1.6, -1.6, -0.7), (0.8, -1.2, -0.7)])
        _keys(ball, "rotation_euler", [(0, 0.8, 0), (0, -0.8, 0)])
        moving = True
    if "camera" in parts:
        base = cam.location.copy()
        d = (-base).normalized() * 0.15
        _keys(cam, "location", [base - d, base + d])
        moving = True
    if moving:
        sc.render.use_motion_blur = True
        if "start" in parts:
            sc.render.motion_blur_position = "START"
    key = bpy.data.lights.new("Key", "AREA")
    key.energy, key.size = 300, 1.0
    ko = bpy.data.objects.new("Key", key)
    ko.location, ko.rotation_euler = (-2.5, -1.5, 1.5), (math.radians(60), 0,
                                                         math.radians(-60))
    sc.collection.objects.link(ko)
    rim = bpy.data.lights.new("Rim", "SPOT")
    rim.energy, rim.shadow_soft_size = 500, 0.1
    ro = bpy.data.objects.new("Rim", rim)
    ro.location, ro.rotation_euler = (-0.5, 3.5, 2.0), (math.radians(-60), 0,
                                                        math.radians(175))
    sc.collection.objects.link(ro)
    if "keylink" in parts:
        ko.light_linking.receiver_collection = _collection("KeyLit", [monkey, plinth],
                                                           "INCLUDE")
    if "rimblock" in parts:
        ro.light_linking.blocker_collection = _collection("RimPass", [ball], "EXCLUDE")
    if "noshadow" in parts:
        point.data.use_shadow = False
    if "fog" in parts:
        w = sc.world
        w.use_nodes = True
        vs = w.node_tree.nodes.new("ShaderNodeVolumeScatter")
        vs.inputs["Density"].default_value = 0.02
        w.node_tree.links.new(vs.outputs["Volume"],
                              w.node_tree.nodes["World Output"].inputs["Volume"])
    cam.data.lens = 40
    sc.cycles.volume_bounces = sc.cycles.max_bounces
    sc.frame_set(1)
    return sc


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--integrator", default="pt")
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--bounces", type=int, default=8)
    ap.add_argument("--without", action="append", default=[], choices=PARTS)
    ap.add_argument("--json", help="append the result here")
    ap.add_argument("--save-images", help="an .npz of both sides' renders")
    a = ap.parse_args()
    import difftest_run as dr
    dt = dr.difftest
    parts = [p for p in PARTS if p not in a.without]
    build(parts)
    t0 = time.process_time()
    scene, warned = dt.export_lantern()
    warned += dt.session_warnings(scene, a.bounces, a.integrator)
    print("warnings:", warned)
    seeds = list(range(1, a.seeds + 1))
    cyc = dt.render_cycles(a.bounces, seeds, a.spp, 1)
    t1 = time.process_time()
    lan = dt.render_lantern(scene, a.bounces, seeds, a.spp, a.integrator, 1)
    t2 = time.process_time()
    res = dr.compare(lan, cyc)
    res.warnings = warned
    print(f"{a.integrator} without {a.without}: {res.line()}")
    print(res.text)
    print(f"CPU s: export+Cycles {t1 - t0:.1f}, Lantern {t2 - t1:.1f}")
    if a.save_images:
        import numpy as np
        np.savez_compressed(a.save_images, cycles=np.stack(cyc), lantern=np.stack(lan))
    if a.json:
        from dataclasses import asdict
        with open(a.json, "a") as f:
            f.write(json.dumps({"integrator": a.integrator, "without": a.without,
                                "seeds": a.seeds, "spp": a.spp, "bounces": a.bounces,
                                "result": asdict(res), "cpu_cycles": t1 - t0,
                                "cpu_lantern": t2 - t1}) + "\n")


if __name__ == "__main__":
    main()
