"""The features of issues 29 and 32 in the differential tester's "full" profile
(docs/difftest.md): volumes (a mesh's Volume: Principled Volume, Volume Scatter, Volume
Absorption, an Emission; homogeneous or a Noise on Density; with a Surface or without; the
world's Volume), subsurface (Principled Subsurface Weight, Random Walk / Skin), hair (particle
hair on a mesh, a Curves object; Principled Hair or an ordinary BSDF) and motion blur (an
object's location / rotation keys, a moving camera).

draw() adds them to a drawn case from its own random stream (the case's key + ":features"),
after everything else, so a full case without them and every "ci" case draw as before. Each
is tagged (FEATURES; features(case) reads them off the description): the summaries count the
tags and `--avoid TAG` leaves one out. They are kept small: strands few and thin, volumes of
modest optical depth, the case's own (low) bounces."""

import copy
import random

import difftest_features2 as f2
import difftest_features3 as f3
import difftest_features4 as f4
import difftest_features5 as f5
import difftest_features6 as f6
import difftest_features7 as f7
from difftest_graph import _rgb, _u

FEATURES = {
    "volume": "a mesh with a Volume material (Principled Volume, Volume Scatter, Volume "
              "Absorption or an Emission)",
    "volume noise density": "a Noise texture on a volume's Density (heterogeneous)",
    "volume with surface": "a material with a Surface and a Volume",
    "volume emission": "emission in a volume (Principled Volume Emission or an Emission)",
    "world volume": "the world's Volume output (scatter / absorption filling the scene)",
    "subsurface": "Principled Subsurface Weight > 0 (Random Walk or Random Walk (Skin))",
    "particle hair": "particle hair on a mesh",
    "curves hair": "a Curves object",
    "principled hair": "strands with the Principled Hair BSDF",
    "motion blur": "an object moving over the shutter (location or rotation keys)",
    "moving camera": "the camera moving over the shutter",
}
FEATURES.update(f2.FEATURES)   # the second batch (difftest2): Volume objects, Cast Shadow, ...
FEATURES.update(f3.FEATURES)   # the third (difftest3): moving emitters, motion in fog, hair mixes
FEATURES.update(f4.FEATURES)   # the fourth (difftest4): light and shadow linking
FEATURES.update(f5.FEATURES)   # the fifth (difftest5): parents, shutter position, steps, ...
FEATURES.update(f6.FEATURES)   # the sixth (difftest6): ray visibility by kind, object shadows
FEATURES.update(f7.FEATURES)   # the seventh (difftest8): a mesh volume that casts no shadow

P_VOLUME, P_WORLD_VOLUME, P_SUBSURFACE, P_HAIR, P_MOTION = 0.15, 0.06, 0.12, 0.10, 0.12


def _graph():
    return {"nodes": {}, "links": [], "out": None}


def _add(g, typ, props=None, inputs=None):
    name = f"v{len(g['nodes'])}"
    g["nodes"][name] = {"type": typ, "props": props or {}, "inputs": inputs or {}}
    return name


def _volume_shader(r, g, density, emission):
    """One volume shader node (its name, output), Density `density` unless a graph feeds it."""
    kind = r.choices(["P", "S", "A", "E"], weights=[4, 3, 2, 1 if emission else 0])[0]
    if kind == "P":
        inputs = {"Density": density, "Color": _rgb(r, 0.3, 1.0),
                  "Anisotropy": r.choice([0.0, _u(r, -0.6, 0.8)])}
        if r.random() < 0.3:
            inputs["Absorption Color"] = _rgb(r, 0.0, 1.0)
        if emission:
            inputs["Emission Strength"] = _u(r, 0.2, 3.0)
            inputs["Emission Color"] = _rgb(r, 0.3, 1.0)
        return _add(g, "ShaderNodeVolumePrincipled", {}, inputs), "Volume"
    if kind == "S":
        return _add(g, "ShaderNodeVolumeScatter", {}, {
            "Density": density, "Color": _rgb(r, 0.3, 1.0),
            "Anisotropy": r.choice([0.0, _u(r, -0.6, 0.8)])}), "Volume"
    if kind == "A":
        return _add(g, "ShaderNodeVolumeAbsorption", {}, {
            "Density": density, "Color": _rgb(r, 0.0, 1.0)}), "Volume"
    return _add(g, "ShaderNodeEmission", {}, {"Color": _rgb(r, 0.3, 1.0),
                                              "Strength": _u(r, 0.2, 3.0)}), "Emission"


def _volume_graph(r, world=False):
    g = _graph()
    emission = not world and r.random() < 0.25
    density = _u(r, 0.01, 0.08) if world else _u(r, 0.2, 3.0)
    shader = _volume_shader(r, g, density, emission)
    if not world and r.random() < 0.2 and g["nodes"][shader[0]]["type"] != \
            "ShaderNodeEmission":
        # heterogeneous: a Noise on the Density, scaled (Math Multiply)
        noise = _add(g, "ShaderNodeTexNoise", {"noise_dimensions": "3D"},
                     {"Scale": _u(r, 0.5, 6.0), "Detail": _u(r, 0.0, 4.0)})
        mul = _add(g, "ShaderNodeMath", {"operation": "MULTIPLY"}, {"Value_001": _u(r, 0.5, 4.0)})
        g["links"] += [[noise, "Fac", mul, "Value"], [mul, "Value", shader[0], "Density"]]
    elif r.random() < 0.25:   # two shaders added (scatter and absorption, or an emission)
        other = _volume_shader(r, g, _u(r, 0.01, 0.08) if world else _u(r, 0.1, 1.5),
                               emission)
        add = _add(g, "ShaderNodeAddShader")
        g["links"] += [[shader[0], shader[1], add, "Shader"],
                       [other[0], other[1], add, "Shader_001"]]
        shader = (add, "Shader")
    g["out"] = list(shader)
    return g


def _motion(r):
    if r.random() < 0.6:
        return {"location": [_u(r, -1.0, 1.0), _u(r, -1.0, 1.0), _u(r, -0.3, 0.3)]}
    return {"rotation": [_u(r, -1.0, 1.0), _u(r, -1.0, 1.0), _u(r, -2.0, 2.0)]}


def draw(key, case, avoid, material):
    """Add the features to `case` (the full profile), from the stream of `key`; `material(r)`
    draws an ordinary surface graph (difftest_scene._material)."""
    r = random.Random(key + ":features")
    objs = [o for o in case["objects"] if o["kind"] not in ("room",)
            and not (o["kind"] == "plane" and o["scale"][0] >= 6.0)]
    if r.random() < P_VOLUME and "volume" not in avoid:
        s = _u(r, 0.3, 0.8)
        obj = {"kind": r.choice(["cube", "ico"] + ([] if "smooth sphere" in avoid else ["sphere"])),
               "location": [_u(r, -1.5, 1.5), _u(r, -1.5, 1.5), round(s + _u(r, 0.0, 0.5), 4)],
               "rotation": [0.0, 0.0, _u(r, -3, 3)], "scale": [s, s, s], "material": None,
               "volume": "vol"}
        case.setdefault("volumes", {})["vol"] = _volume_graph(r)
        if r.random() < 0.25 and "volume with surface" not in avoid:
            obj["material"] = "volsurf"
            case["materials"]["volsurf"] = material(r)
        case["objects"].append(obj)
    if r.random() < P_WORLD_VOLUME and "world volume" not in avoid:
        case["world_volume"] = _volume_graph(r, world=True)
    if r.random() < P_SUBSURFACE and "subsurface" not in avoid and objs:
        o = r.choice(objs)
        name = f"sss{case['objects'].index(o)}"
        g = _graph()
        p = _add(g, "ShaderNodeBsdfPrincipled",
                 {"subsurface_method": r.choice(["RANDOM_WALK", "RANDOM_WALK_SKIN"])},
                 {"Base Color": _rgb(r, 0.3, 1.0), "Roughness": _u(r, 0.2, 1.0),
                  "Subsurface Weight": r.choice([1.0, _u(r, 0.2, 1.0)]),
                  "Subsurface Radius": [_u(r, 0.1, 1.0), _u(r, 0.05, 0.5), _u(r, 0.02, 0.3)],
                  "Subsurface Scale": _u(r, 0.02, 0.3),
                  "Subsurface Anisotropy": r.choice([0.0, _u(r, -0.5, 0.8)])})
        g["out"] = [p, "BSDF"]
        old, o["material"] = o.get("material"), name
        case["materials"][name] = g
        if old and not any(x.get("material") == old for x in case["objects"]):
            case["materials"].pop(old, None)
    if r.random() < P_HAIR:
        if r.random() < 0.5 and objs and "particle hair" not in avoid:
            o = r.choice(objs)
            o["hair"] = {"count": r.randint(30, 150), "length": _u(r, 0.1, 0.35),
                         "radius": _u(r, 0.004, 0.02), "seed": r.randrange(1000),
                         "material": "hair"}
            case["materials"]["hair"] = _hair_material(r, avoid, material)
        elif "curves hair" not in avoid:
            case["objects"].append(_curves(r))
            case["materials"]["hair"] = _hair_material(r, avoid, material)
    if r.random() < P_MOTION:
        case["shutter"] = r.choice([0.5, 1.0, _u(r, 0.2, 1.0)])
        if (r.random() < 0.7 or "moving camera" in avoid) and objs and \
                "motion blur" not in avoid:
            r.choice(objs)["motion"] = _motion(r)
        elif "moving camera" not in avoid:
            case["camera"]["motion"] = {"location": [_u(r, -0.5, 0.5), _u(r, -0.5, 0.5),
                                                     _u(r, -0.2, 0.2)]}
        else:
            case.pop("shutter")
    # each batch from a stream of its own: cases without them draw unchanged
    case = f4.draw(key, f3.draw(key, f2.draw(key, case, avoid), avoid, material, _volume_graph,
                                _curves), avoid)
    case = f5.draw(key, case, avoid, _volume_graph,
                   lambda rr: _hair_material(rr, avoid, material))
    return f7.draw(key, f6.draw(key, case, avoid, _volume_graph), avoid)


def _curves(r):
    """A Curves object's entry (its material "hair")."""
    return {"kind": "curves", "location": [_u(r, -1.2, 1.2), _u(r, -1.2, 1.2), 0.0],
            "rotation": [0.0, 0.0, _u(r, -3, 3)], "scale": [1.0, 1.0, 1.0],
            "material": "hair",
            "strands": {"count": r.randint(20, 80), "keys": r.randint(4, 10),
                        "length": _u(r, 0.4, 1.5), "spread": _u(r, 0.2, 0.8),
                        "wave": _u(r, 0.0, 0.15), "radius": _u(r, 0.005, 0.03),
                        "seed": r.randrange(1000)}}


def _hair_material(r, avoid, material):
    if r.random() < 0.5 and "principled hair" not in avoid:
        g = _graph()
        param = r.choice(["MELANIN", "COLOR", "ABSORPTION"])
        inputs = {"Roughness": _u(r, 0.1, 0.8), "Radial Roughness": _u(r, 0.1, 0.8),
                  "IOR": _u(r, 1.3, 1.8)}
        if param == "MELANIN":
            inputs.update({"Melanin": _u(r, 0.0, 1.0), "Melanin Redness": _u(r, 0.0, 1.0)})
        elif param == "COLOR":
            inputs["Color"] = _rgb(r, 0.1, 1.0)
        else:
            inputs["Absorption Coefficient"] = [_u(r, 0.05, 2.0) for _ in range(3)]
        h = _add(g, "ShaderNodeBsdfHairPrincipled", {"parametrization": param,
                                                     "model": "CHIANG"}, inputs)
        g["out"] = [h, "BSDF"]
        return g
    return material(r)


# ---- bpy ----

def _keys(ob, path, delta):
    """Linear keys at frames 0 and 2 around the drawn pose (the render is at frame 1)."""
    base = list(getattr(ob, path))
    for frame, sign in ((0, -0.5), (2, 0.5)):
        setattr(ob, path, [b + sign * d for b, d in zip(base, delta)])
        ob.keyframe_insert(path, frame=frame)
    for fc in ob.animation_data.action.fcurves if hasattr(ob.animation_data.action,
                                                           "fcurves") else []:
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"


def build_object(sc, o, mats, made):
    """The features of object entry `o` on its bpy object `made` (None for a Curves entry,
    which this makes); returns the object."""
    import bpy
    import numpy as np
    if made is not None:   # a Volume object, a low-poly mesh, a shape key
        made = f2.build_object(sc, o, made)
    if o["kind"] == "curves":
        st = o["strands"]
        n, keys = st["count"], st["keys"]
        rng = np.random.default_rng(st["seed"])
        data = bpy.data.hair_curves.new("Hair")
        data.add_curves([keys] * n)
        ang, rad = rng.uniform(0, 2 * np.pi, n), st["spread"] * np.sqrt(rng.uniform(0, 1, n))
        lean = rng.uniform(-0.3, 0.3, (n, 2))
        t = np.linspace(0.0, 1.0, keys)
        x = (rad * np.cos(ang))[:, None] + lean[:, :1] * t + st["wave"] * np.sin(
            8.0 * t[None, :] + ang[:, None])
        y = (rad * np.sin(ang))[:, None] + lean[:, 1:] * t
        z = st["length"] * t[None, :] + 0.0 * x
        pts = np.stack([x, y, z], axis=-1).astype(np.float32)
        data.attributes["position"].data.foreach_set("vector", pts.ravel())
        r = data.attributes.get("radius") or data.attributes.new("radius", "FLOAT", "POINT")
        r.data.foreach_set("value", np.full(n * keys, st["radius"], np.float32))
        made = bpy.data.objects.new("Hair", data)
        if o.get("material") in mats:
            data.materials.append(mats[o["material"]])
        made.location, made.rotation_euler = o["location"], o.get("rotation", [0, 0, 0])
        made.scale = o["scale"]
        sc.collection.objects.link(made)
        sc.cycles_curves.shape = "THICK_LINEAR"
    if "hair" in o and o["hair"]["material"] in mats:
        h = o["hair"]
        if not made.data.materials:   # slot 1 for the surface (Blender's default there)
            made.data.materials.append(None)
        made.data.materials.append(mats[h["material"]])
        mod = made.modifiers.new("Hair", "PARTICLE_SYSTEM")
        mod.particle_system.seed = h["seed"]
        ps = mod.particle_system.settings
        ps.type, ps.count, ps.hair_length = "HAIR", h["count"], h["length"]
        ps.render_step = ps.display_step = 3
        ps.material = len(made.data.materials)
        ps.root_radius, ps.tip_radius, ps.radius_scale = 1.0, 0.5, h["radius"]
        ps.child_type = "NONE"
        sc.cycles_curves.shape = "THICK_LINEAR"
        f2.hair_children(o, made)
    return f6.build_object(sc, o, f5.build_object(sc, o, made))


def build_scene(sc, case, camera, made):
    """The case's motion (after every object is made): keys and the render's motion blur."""
    import bpy
    f2.build_scene(sc, case)
    f4.build_scene(sc, case, made)
    f6.build_scene(sc, case)
    if case.get("volumes") or case.get("world_volume"):
        # Cycles' factory Volume Bounces (0) is below its Max Bounces, which the export warns
        # of; the tester sets both to the case's bounces at render time (difftest.py)
        sc.cycles.volume_bounces = sc.cycles.max_bounces
    if not case.get("shutter"):
        return
    bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
    movers = [(camera, case["camera"].get("motion"))]
    movers += [(ob, o.get("motion")) for o, ob in zip(case["objects"], made)]
    movers += list(f5.parents(case, made))
    for ob, m in movers:
        for key, path in (("location", "location"), ("rotation", "rotation_euler")):
            if m and key in m:
                _keys(ob, path, m[key])
    sc.render.use_motion_blur = True
    sc.render.motion_blur_shutter = case["shutter"]
    sc.render.motion_blur_position = "CENTER"
    f5.build_scene(sc, case, camera)
    sc.frame_set(1)


def features(case):
    """The FEATURES tags of a case, read off its description."""
    found = set()
    vols = [case["volumes"][o["volume"]] for o in case["objects"]
            if o.get("volume") in case.get("volumes", {}) and o["kind"] != "vdb"]
    for o in case["objects"]:
        if o.get("volume") in case.get("volumes", {}) and o["kind"] != "vdb":
            found.add("volume")
            if o.get("material"):
                found.add("volume with surface")
        if "hair" in o:
            found.add("particle hair")
        if o["kind"] == "curves":
            found.add("curves hair")
        if "motion" in o and case.get("shutter"):
            found.add("motion blur")
    if case.get("world_volume"):
        found.add("world volume")
        vols.append(case["world_volume"])
    for g in vols:
        types = [n["type"] for n in g["nodes"].values()]
        # (a Noise on the world's or on a Color: difftest_features2's tags)
        if "ShaderNodeTexNoise" in types and g is not case.get("world_volume") and any(
                lk[3] == "Density" and g["nodes"][lk[0]]["type"] == "ShaderNodeMath"
                for lk in g["links"]):
            found.add("volume noise density")
        if "ShaderNodeEmission" in types or any(
                n.get("inputs", {}).get("Emission Strength", 0.0) > 0
                for n in g["nodes"].values()):
            found.add("volume emission")
    used = {o.get("material") for o in case["objects"]} | \
        {o["hair"]["material"] for o in case["objects"] if "hair" in o}
    for name, g in case["materials"].items():
        if name not in used:
            continue
        for n in g["nodes"].values():
            if n.get("inputs", {}).get("Subsurface Weight", 0.0) > 0:
                found.add("subsurface")
            if n["type"] == "ShaderNodeBsdfHairPrincipled":
                found.add("principled hair")
    if "motion" in case["camera"] and case.get("shutter"):
        found.add("moving camera")
    return (found | f2.features(case) | f3.features(case) | f4.features(case) |
            f5.features(case) | f6.features(case) | f7.features(case))


def shrink_edits(case):
    """(label, edit(case)) removing the features one at a time (difftest_shrink.candidates)."""
    def edited(fn):
        c = copy.deepcopy(case)
        fn(c)
        return c
    if case.get("world_volume"):
        yield "no world volume", edited(lambda c: c.pop("world_volume"))
    for i, o in enumerate(case["objects"]):
        for key in ("volume", "hair", "motion"):
            if key in o and not (key == "volume" and not o.get("material")):
                yield f"object {i}: no {key}", edited(lambda c, i=i, key=key:
                                                      c["objects"][i].pop(key))
    if "motion" in case["camera"]:
        yield "camera: no motion", edited(lambda c: c["camera"].pop("motion"))
    if case.get("shutter") and case["shutter"] != 0.5:
        yield "shutter 0.5", edited(lambda c: c.update(shutter=0.5))
    yield from f2.shrink_edits(case)
    yield from f3.shrink_edits(case)
    yield from f4.shrink_edits(case)
    yield from f5.shrink_edits(case)
    yield from f6.shrink_edits(case)
