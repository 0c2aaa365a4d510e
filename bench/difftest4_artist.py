"""A second scene built by hand as an artist would (difftest4; the first is
bench/difftest3_artist.py), for light and shadow linking with Skin and fog, compared with
Cycles block by block through the differential tester's statistics (tools/difftest_run.py's
compare: 8x8 blocks, Welch t, Bonferroni at 1e-3, the image means; "inconclusive" where the
image mean's margin is over 25 %).

A product shot: Blender's factory startup (cube, 1000 W point light, camera) with the cube
removed; a floor and a backdrop card (a tall plane behind the subject); a Suzanne of Principled
BSDF with Subsurface Weight 1 (Random Walk (Skin)), smooth shaded, on a plinth (a cylinder,
Principled Roughness 0.3); then the lighting as one would set it with linking:
- a key: an area light (400 W, 1 m) on the left whose Receiver Collection includes Suzanne and
  the plinth only (it lights neither the floor nor the card);
- a rim: a spot behind (600 W) whose Blocker Collection excludes the backdrop card (the card
  would shadow it: the artist lets the light pass the card);
- a softbox: an emissive plane above (Emission Strength 6) whose Receiver Collection excludes
  the backdrop card;
- the factory point light with Cast Shadow off, as a fill;
- thin fog: the world's Volume, a Volume Scatter of Density 0.02 (Volume Bounces = Max Bounces,
  as the export advises).
Every input left at Blender's default unless said. Render settings as the tester's
(render_compare): no denoising / adaptive sampling / clamping, every bounce limit B.

    nice .venv/bin/python bench/difftest4_artist.py --integrator pt --seeds 16 --spp 32 \
        [--without fog|skin|keylink|rimblock|boxlink|noshadow ...] --json OUT.jsonl
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

PARTS = ("skin", "keylink", "rimblock", "boxlink", "fog", "noshadow")


def _material(name, ob, **inputs):
    import bpy
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    for k, v in inputs.items():
        p.inputs[k.replace("_", " ")].default_value = v
    ob.data.materials.append(m)
    return m, p


def _collection(name, objects, state):
    import bpy
    coll = bpy.data.collections.new(name)
    for ob in objects:
        coll.objects.link(ob)
    for entry in coll.collection_objects:
        entry.light_linking.link_state = state
    return coll


def build(parts):
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=False)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.render.resolution_x, sc.render.resolution_y = 64, 48
    sc.render.resolution_percentage = 100
    bpy.data.objects.remove(bpy.data.objects["Cube"])
    cam = bpy.data.objects["Camera"]
    point = bpy.data.objects["Light"]
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, -1))
    floor = bpy.context.object
    _material("Floor", floor, Base_Color=(0.5, 0.5, 0.5, 1))
    bpy.ops.mesh.primitive_plane_add(size=5, location=(-1.0, 2.2, 1.0),
                                     rotation=(math.radians(90), 0, math.radians(20)))
    card = bpy.context.object
    _material("Card", card, Base_Color=(0.15, 0.3, 0.6, 1), Roughness=0.8)
    bpy.ops.mesh.primitive_cylinder_add(radius=0.6, depth=0.6, location=(0, 0, -0.7))
    plinth = bpy.context.object
    _material("Plinth", plinth, Base_Color=(0.8, 0.8, 0.75, 1), Roughness=0.3)
    bpy.ops.mesh.primitive_monkey_add(size=1.0, location=(0, 0, 0.0), rotation=(0, 0, 0.5))
    monkey = bpy.context.object
    bpy.ops.object.shade_smooth()
    if "skin" in parts:
        _, p = _material("Skin", monkey, Base_Color=(0.8, 0.55, 0.45, 1),
                         Subsurface_Weight=1.0)
        p.subsurface_method = "RANDOM_WALK_SKIN"
    else:
        _material("Skin", monkey, Base_Color=(0.8, 0.55, 0.45, 1))
    key = bpy.data.lights.new("Key", "AREA")
    key.energy, key.size = 400, 1.0
    ko = bpy.data.objects.new("Key", key)
    ko.location, ko.rotation_euler = (-2.5, -1.5, 1.5), (math.radians(60), 0,
                                                         math.radians(-60))
    sc.collection.objects.link(ko)
    rim = bpy.data.lights.new("Rim", "SPOT")
    rim.energy, rim.shadow_soft_size = 600, 0.1
    ro = bpy.data.objects.new("Rim", rim)
    ro.location, ro.rotation_euler = (-0.5, 3.5, 2.0), (math.radians(-60), 0,
                                                        math.radians(175))
    sc.collection.objects.link(ro)
    bpy.ops.mesh.primitive_plane_add(size=1.2, location=(0.8, -0.8, 2.6),
                                     rotation=(math.radians(160), 0, 0))
    box = bpy.context.object
    m = bpy.data.materials.new("Softbox")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Strength"].default_value = 6.0
    nt.links.new(em.outputs["Emission"], nt.nodes["Material Output"].inputs["Surface"])
    box.data.materials.append(m)
    if "keylink" in parts:
        ko.light_linking.receiver_collection = _collection("KeyLit", [monkey, plinth],
                                                           "INCLUDE")
    if "rimblock" in parts:
        ro.light_linking.blocker_collection = _collection("RimPass", [card], "EXCLUDE")
    if "boxlink" in parts:
        box.light_linking.receiver_collection = _collection("BoxLit", [card], "EXCLUDE")
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
    return sc


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--integrator", default="pt")
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--spp", type=int, default=32)
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
