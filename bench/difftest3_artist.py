"""A scene built by hand as an artist would (difftest3, docs/difftest.md "By hand"), compared
with Cycles block by block through the differential tester's statistics (tools/difftest.py
compare: 8x8 blocks, Welch t, Bonferroni at 1e-3, the image mean within 0.2 % + noise).

Blender's factory startup (its cube, its 1000 W point light, its camera), then: a floor; the
cube turned into a glass shell (Glass BSDF, defaults) with a small red box inside it; a
Suzanne of Principled BSDF with Subsurface Weight 1 (Random Walk (Skin)); a UV sphere with
particle hair (Principled Hair BSDF at its defaults); a spot, an area light and a weak sun
besides the point; thin fog (the world's Volume: a Volume Scatter of Density 0.02); a sphere
sliding over the shutter with motion blur on (Blender's shutter 0.5). Two settings changed because the export named them: the curve shape
3D Curves (not the default Ribbons) and Volume Bounces = Max Bounces (not 0). Every material input
left at Blender's default unless said. Render settings as the tester's (render_compare):
no denoising / adaptive sampling / clamping, every bounce limit B.

    nice .venv/bin/python bench/difftest3_artist.py --integrator pt --seeds 8 --spp 16
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


HAIR = {"shape": "THICK", "tip": None, "bsdf": "hair", "flat": False, "strands": True,
        "display_step": None}   # the bisection's knobs (--hair-*)


def build(parts):
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=False)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.render.resolution_x, sc.render.resolution_y = 64, 48
    sc.render.resolution_percentage = 100
    cam = bpy.data.objects["Camera"]
    cube = bpy.data.objects["Cube"]
    # floor
    bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, -1))
    floor = bpy.context.object
    mfloor = bpy.data.materials.new("Floor")
    mfloor.use_nodes = True
    floor.data.materials.append(mfloor)
    if "glass" in parts:   # the cube: a glass shell with a red box inside
        cube.scale = (0.7, 0.7, 0.7)
        g = bpy.data.materials.new("Glass")
        g.use_nodes = True
        nt = g.node_tree
        nt.nodes.remove(nt.nodes["Principled BSDF"])
        glass = nt.nodes.new("ShaderNodeBsdfGlass")
        nt.links.new(glass.outputs["BSDF"], nt.nodes["Material Output"].inputs["Surface"])
        cube.data.materials.clear()
        cube.data.materials.append(g)
        bpy.ops.mesh.primitive_cube_add(size=0.6, location=(0, 0, 0), rotation=(0.3, 0.2, 0.5))
        inner = bpy.context.object
        red = bpy.data.materials.new("Red")
        red.use_nodes = True
        red.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = \
            (0.8, 0.05, 0.03, 1)
        inner.data.materials.append(red)
    else:
        bpy.data.objects.remove(cube)
    if "skin" in parts:
        bpy.ops.mesh.primitive_monkey_add(size=1.2, location=(2.2, 0.6, -0.35),
                                          rotation=(0, 0, 0.6))
        monkey = bpy.context.object
        bpy.ops.object.shade_smooth()
        skin = bpy.data.materials.new("Skin")
        skin.use_nodes = True
        p = skin.node_tree.nodes["Principled BSDF"]
        p.subsurface_method = "RANDOM_WALK_SKIN"
        p.inputs["Subsurface Weight"].default_value = 1.0
        p.inputs["Base Color"].default_value = (0.8, 0.55, 0.45, 1)
        monkey.data.materials.append(skin)
    if "hair" in parts:
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-1.8, 1.2, -0.5))
        ball = bpy.context.object
        if not HAIR["flat"]:
            bpy.ops.object.shade_smooth()
        fur = bpy.data.materials.new("Fur")
        fur.use_nodes = True
        nt = fur.node_tree
        nt.nodes.remove(nt.nodes["Principled BSDF"])
        hair = nt.nodes.new("ShaderNodeBsdfHairPrincipled" if HAIR["bsdf"] == "hair" else
                            "ShaderNodeBsdfDiffuse")
        nt.links.new(hair.outputs["BSDF"], nt.nodes["Material Output"].inputs["Surface"])
        ball.data.materials.append(fur)
        mod = ball.modifiers.new("Fur", "PARTICLE_SYSTEM")
        mod.show_render = HAIR["strands"]
        ps = mod.particle_system.settings
        ps.type = "HAIR"
        ps.count = 300
        ps.hair_length = 0.3
        ps.material = 1
        # the export names Blender's default curve shape (Ribbons) as not matched: the artist
        # takes its advice
        sc.cycles_curves.shape = HAIR["shape"]
        if HAIR["display_step"] is not None:
            ps.display_step = HAIR["display_step"]
        if HAIR["tip"] is not None:
            ps.tip_radius = HAIR["tip"]
    if "motion" in parts:   # a sphere sliding over the shutter
        bpy.ops.mesh.primitive_ico_sphere_add(radius=0.35, subdivisions=3,
                                              location=(0.2, -1.9, -0.65))
        mover = bpy.context.object
        bpy.ops.object.shade_smooth()
        blue = bpy.data.materials.new("Blue")
        blue.use_nodes = True
        pb = blue.node_tree.nodes["Principled BSDF"]
        pb.inputs["Base Color"].default_value = (0.1, 0.25, 0.8, 1)
        pb.inputs["Roughness"].default_value = 0.3
        mover.data.materials.append(blue)
        bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
        for frame, x in ((0, -0.4), (2, 0.8)):
            mover.location.x = x
            mover.keyframe_insert("location", frame=frame)
        sc.render.use_motion_blur = True
        sc.frame_set(1)
    if "lights" in parts:   # besides the factory point light (1000 W at (4.1, 1.0, 5.9))
        spot = bpy.data.lights.new("Spot", "SPOT")
        spot.energy = 800
        so = bpy.data.objects.new("Spot", spot)
        so.location = (-3.0, -2.5, 3.5)
        so.rotation_euler = (math.radians(45), 0, math.radians(-50))
        sc.collection.objects.link(so)
        area = bpy.data.lights.new("Area", "AREA")
        area.energy = 300
        area.size = 1.0
        ao = bpy.data.objects.new("Area", area)
        ao.location = (0.5, 3.0, 2.5)
        ao.rotation_euler = (math.radians(-40), 0, 0)
        sc.collection.objects.link(ao)
        sun = bpy.data.lights.new("Sun", "SUN")
        sun.energy = 1.0
        sno = bpy.data.objects.new("Sun", sun)
        sno.rotation_euler = (math.radians(50), 0, math.radians(30))
        sc.collection.objects.link(sno)
    if "fog" in parts:   # the world's volume
        w = sc.world
        w.use_nodes = True
        vs = w.node_tree.nodes.new("ShaderNodeVolumeScatter")
        vs.inputs["Density"].default_value = 0.02
        w.node_tree.links.new(vs.outputs["Volume"],
                              w.node_tree.nodes["World Output"].inputs["Volume"])
    cam.data.lens = 35
    # the export names the factory Volume Bounces (0) as not honoured: set to Max Bounces
    sc.cycles.volume_bounces = sc.cycles.max_bounces
    return sc


PARTS = ("glass", "skin", "hair", "motion", "lights", "fog")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--integrator", default="pt")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--bounces", type=int, default=8)
    ap.add_argument("--without", action="append", default=[], choices=PARTS)
    ap.add_argument("--json", help="append the result here")
    ap.add_argument("--hair-shape", default="THICK", choices=("THICK", "THICK_LINEAR"))
    ap.add_argument("--hair-tip", type=float, default=None, help="tip radius (default 0)")
    ap.add_argument("--hair-bsdf", default="hair", choices=("hair", "diffuse"))
    ap.add_argument("--ball-flat", action="store_true", help="the furry ball shaded flat")
    ap.add_argument("--no-strands", action="store_true", help="the ball without its hair")
    ap.add_argument("--display-step", type=int, default=None, help="the hair's viewport "
                    "steps (default Blender's 2; render steps stay 3)")
    a = ap.parse_args()
    HAIR["display_step"] = a.display_step
    HAIR.update(shape=a.hair_shape, tip=a.hair_tip, bsdf=a.hair_bsdf, flat=a.ball_flat,
                strands=not a.no_strands)
    import difftest as dt
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
    res = dt.compare(lan, cyc)
    res.warnings = warned
    print(f"{a.integrator} without {a.without}: {res.line()}")
    print(res.text)
    print(f"CPU s: export+Cycles {t1 - t0:.1f}, Lantern {t2 - t1:.1f}")
    if a.json:
        from dataclasses import asdict
        with open(a.json, "a") as f:
            f.write(json.dumps({"integrator": a.integrator, "without": a.without, "hair": HAIR,
                                "seeds": a.seeds, "spp": a.spp, "bounces": a.bounces,
                                "result": asdict(res), "cpu_cycles": t1 - t0,
                                "cpu_lantern": t2 - t1}) + "\n")


if __name__ == "__main__":
    main()
