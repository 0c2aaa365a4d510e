"""The second batch of features in the differential tester's "full" profile (docs/difftest.md,
2026-12-06 difftest2): Volume objects (OpenVDB grids written by the core's writer, with
density and emission graphs: Attribute -> Math / Map Range -> Density / Emission Strength), a
lamp with Cast Shadow off, low-poly meshes smooth or flat with a Shadow Terminator Geometry
Offset, a Noise on a world volume's Density or on a volume's Color, phase functions other
than Henyey-Greenstein, hair children and deformation motion blur (a shape key keyed over the
shutter).

draw() adds them to a drawn case from a stream of their own (the case's key + ":features2"),
after difftest_features.draw, so every "ci" case and every full case without them draws as
before. Tags: FEATURES (features(case)); WARNED: tags of what the add-on names as not
rendered today (a case with one is "unsupported": tests/cycles/test_difftest.py checks that
the warning comes)."""

import copy
import hashlib
import json
import os
import random
import tempfile

from difftest_graph import _rgb, _u

FEATURES = {
    "vdb volume": "a Volume object (OpenVDB grids 'density' and 'heat')",
    "vdb density graph": "a node graph of a Volume object's grids on its Density (Attribute "
                         "-> Math / Map Range)",
    "vdb emission": "a Volume object's grid -> Map Range -> Emission Strength",
    "no shadow": "a lamp with Cast Shadow off",
    "low-poly smooth": "a low-poly mesh shaded smooth (the shadow terminator)",
    "low-poly flat": "a low-poly mesh shaded flat",
    "terminator offset": "an object's Shadow Terminator Geometry Offset not Blender's 0.1",
    "world volume noise": "a Noise texture on the world volume's Density",
    "volume colour noise": "a Noise texture on a volume shader's Color",
    "volume phase": "Volume Scatter with a phase function other than Henyey-Greenstein",
    "negative anisotropy": "a volume scatterer of Anisotropy < 0 (back-scattering)",
    "hair children": "particle hair with Simple or Interpolated children",
    "deformation blur": "a mesh deforming over the shutter (a shape key keyed 0 -> 1)",
}
# what the add-on names as not rendered (docs/volumes.md): graphs on the world's volume, phase
# functions other than Henyey-Greenstein (graphs on a volume's Color render since volcolor)
WARNED = {"world volume noise", "volume phase"}

P_VDB, P_NO_SHADOW, P_LOWPOLY, P_DEFORM = 0.15, 0.2, 0.2, 0.1
P_WORLD_NOISE, P_COLOUR_NOISE, P_PHASE, P_CHILDREN = 0.3, 0.15, 0.15, 0.8
PHASES = {"FOURNIER_FORAND": {"IOR": (1.01, 1.5), "Backscatter": (0.0, 0.3)},
          "DRAINE": {"Anisotropy": (-0.8, 0.8), "Alpha": (0.0, 2.0)},
          "RAYLEIGH": {}, "MIE": {"Diameter": (2.0, 50.0)}}
SCATTERERS = ("ShaderNodeVolumeScatter", "ShaderNodeVolumePrincipled")


def _add(g, typ, props=None, inputs=None):
    name = f"w{len(g['nodes'])}"
    g["nodes"][name] = {"type": typ, "props": props or {}, "inputs": inputs or {}}
    return name


def _grid_expr(r, g, attr):
    """Attribute `attr` (Fac) through 0-2 of Math / Map Range: (node, output) of a density."""
    src = (_add(g, "ShaderNodeAttribute", {"attribute_name": attr}), "Fac")
    for _ in range(r.choice([0, 1, 1, 2])):
        op = r.choice(["mul", "pow", "map", "add"])
        if op == "map":
            n = _add(g, "ShaderNodeMapRange",
                     {"interpolation_type": r.choice(["LINEAR", "LINEAR", "SMOOTHSTEP"]),
                      "clamp": r.random() < 0.7},
                     {"From Min": 0.0, "From Max": _u(r, 0.2, 1.0),
                      "To Min": _u(r, 0.0, 0.5), "To Max": _u(r, 1.0, 6.0)})
            g["links"].append([src[0], src[1], n, "Value"])
            src = (n, "Result")
        elif op == "add":   # the other grid, scaled, added
            other = _add(g, "ShaderNodeAttribute",
                         {"attribute_name": "heat" if attr == "density" else "density"})
            mul = _add(g, "ShaderNodeMath", {"operation": "MULTIPLY"},
                       {"Value_001": _u(r, 0.2, 2.0)})
            add = _add(g, "ShaderNodeMath", {"operation": "ADD"})
            g["links"] += [[other, "Fac", mul, "Value"], [src[0], src[1], add, "Value"],
                           [mul, "Value", add, "Value_001"]]
            src = (add, "Value")
        else:
            n = _add(g, "ShaderNodeMath", {"operation": "MULTIPLY" if op == "mul" else "POWER"},
                     {"Value_001": _u(r, 1.0, 8.0) if op == "mul" else _u(r, 0.5, 2.0)})
            g["links"].append([src[0], src[1], n, "Value"])
            src = (n, "Value")
    return src


def _vdb_graph(r):
    """A Volume object's material (its Volume output only)."""
    g = {"nodes": {}, "links": [], "out": None}
    kind = r.choices(["P", "S", "A"], weights=[4, 3, 2])[0]
    if kind == "P":
        v = _add(g, "ShaderNodeVolumePrincipled", {}, {
            "Density": _u(r, 1.0, 8.0), "Color": _rgb(r, 0.3, 1.0),
            "Anisotropy": r.choice([0.0, _u(r, -0.8, 0.8)])})
        if r.random() < 0.3:
            g["nodes"][v]["inputs"]["Absorption Color"] = _rgb(r, 0.0, 1.0)
        u = r.random()
        if u >= 0.4:   # a graph on Density (times the Density Attribute grid, or that cleared)
            src = _grid_expr(r, g, r.choice(["density", "density", "heat"]))
            g["links"].append([src[0], src[1], v, "Density"])
            if u < 0.7:
                g["nodes"][v]["inputs"]["Density Attribute"] = ""
        if r.random() < 0.4:   # grid-driven emission (a constant one: docs/volumes.md)
            a = _add(g, "ShaderNodeAttribute", {"attribute_name": r.choice(["heat", "density"])})
            m = _add(g, "ShaderNodeMapRange", {"clamp": True},
                     {"From Min": 0.0, "From Max": 1.0, "To Min": 0.0,
                      "To Max": _u(r, 0.5, 4.0)})
            g["links"] += [[a, "Fac", m, "Value"], [m, "Result", v, "Emission Strength"]]
            g["nodes"][v]["inputs"]["Emission Color"] = _rgb(r, 0.3, 1.0)
        g["out"] = [v, "Volume"]
        return g
    typ = "ShaderNodeVolumeScatter" if kind == "S" else "ShaderNodeVolumeAbsorption"
    inputs = {"Color": _rgb(r, 0.3, 1.0) if kind == "S" else _rgb(r, 0.0, 1.0)}
    if kind == "S":
        inputs["Anisotropy"] = r.choice([0.0, _u(r, -0.8, 0.8)])
    v = _add(g, typ, {}, inputs)
    src = _grid_expr(r, g, "density")
    if src[0] in g["nodes"] and g["nodes"][src[0]]["type"] == "ShaderNodeAttribute":
        # a lone Attribute: scaled, so the optical depth is that of the Principled's
        mul = _add(g, "ShaderNodeMath", {"operation": "MULTIPLY"}, {"Value_001": _u(r, 1.0, 8.0)})
        g["links"].append([src[0], src[1], mul, "Value"])
        src = (mul, "Value")
    g["links"].append([src[0], src[1], v, "Density"])
    g["out"] = [v, "Volume"]
    return g


def _shaders(graph, types):
    return [k for k, n in graph["nodes"].items() if n["type"] in types]


def _noise_on(r, g, node, socket, scale=False):
    """A 3D Noise (through a Multiply when `scale`) on `node`'s `socket`."""
    noise = _add(g, "ShaderNodeTexNoise", {"noise_dimensions": "3D"},
                 {"Scale": _u(r, 0.5, 6.0), "Detail": _u(r, 0.0, 4.0)})
    if scale:
        mul = _add(g, "ShaderNodeMath", {"operation": "MULTIPLY"}, {"Value_001": _u(r, 0.5, 4.0)})
        g["links"] += [[noise, "Fac", mul, "Value"], [mul, "Value", node, socket]]
    else:
        g["links"].append([noise, "Color", node, socket])


def draw(key, case, avoid):
    """Add the features to `case` (full profile, after difftest_features.draw)."""
    r = random.Random(key + ":features2")
    objs = [o for o in case["objects"] if o["kind"] in ("cube", "ico", "sphere")
            and not o.get("volume")]
    if r.random() < P_VDB and "vdb volume" not in avoid:
        s = [_u(r, 1.0, 2.2) * f for f in (1.0, _u(r, 0.8, 1.2), _u(r, 0.8, 1.2))]
        case["objects"].append({
            "kind": "vdb", "location": [_u(r, -1.2, 1.2), _u(r, -1.2, 1.2),
                                        round(s[2] / 2 + _u(r, 0.0, 0.4), 4)],
            "rotation": [_u(r, -0.3, 0.3), 0.0, _u(r, -3, 3)], "scale": s,
            "material": None, "volume": "vdb",
            "vdb": {"seed": r.randrange(1 << 30), "n": r.choice([12, 16, 20]),
                    "blobs": r.randint(1, 3), "m": r.choice([6, 8, 10]),
                    "axis": r.randrange(3)}})
        case.setdefault("volumes", {})["vdb"] = _vdb_graph(r)
    if case["lights"] and r.random() < P_NO_SHADOW and "no shadow" not in avoid:
        r.choice(case["lights"])["cast_shadow"] = False
    if objs and r.random() < P_LOWPOLY:
        o = r.choice(objs)
        smooth = r.random() < 0.7
        if ("low-poly smooth" if smooth else "low-poly flat") not in avoid:
            o["lowpoly"] = {"shape": r.choice(["ico", "uv", "cylinder"]), "smooth": smooth,
                            "offset": r.choice([None, 0.0, _u(r, 0.0, 1.0)])}
    # the volumes difftest_features drew: a Noise on the world's Density or a Color, phases
    wv = case.get("world_volume")
    if wv and r.random() < P_WORLD_NOISE and "world volume noise" not in avoid:
        sh = _shaders(wv, ("ShaderNodeVolumePrincipled", "ShaderNodeVolumeScatter",
                           "ShaderNodeVolumeAbsorption"))
        if sh:
            _noise_on(r, wv, sh[0], "Density", scale=True)
    vol = case.get("volumes", {}).get("vol")
    if vol and r.random() < P_COLOUR_NOISE and "volume colour noise" not in avoid:
        sh = _shaders(vol, ("ShaderNodeVolumePrincipled", "ShaderNodeVolumeScatter",
                            "ShaderNodeVolumeAbsorption"))
        if sh:
            _noise_on(r, vol, sh[0], "Color")
    for g in [x for x in (vol, wv, case.get("volumes", {}).get("vdb")) if x]:
        sc = _shaders(g, ("ShaderNodeVolumeScatter",))
        if sc and r.random() < P_PHASE and "volume phase" not in avoid:
            phase = r.choice(sorted(PHASES))
            n = g["nodes"][sc[0]]
            n["props"]["phase"] = phase
            n["inputs"].update({k: _u(r, *lim) for k, lim in PHASES[phase].items()})
    for o in case["objects"]:
        if "hair" in o and r.random() < P_CHILDREN and "hair children" not in avoid:
            o["hair"]["children"] = {"type": r.choice(["SIMPLE", "INTERPOLATED"]),
                                     "count": r.randint(2, 6), "radius": _u(r, 0.05, 0.3)}
    movable = [o for o in objs if "motion" not in o and "hair" not in o]
    if movable and r.random() < P_DEFORM and "deformation blur" not in avoid:
        o = r.choice(movable)
        o["deform"] = {"scale": [_u(r, 0.6, 1.4) for _ in range(3)],
                       "shift": [_u(r, -0.3, 0.3) for _ in range(3)]}
        case.setdefault("shutter", r.choice([0.5, 1.0]))
    return case


# ---- bpy ----

def vdb_path(spec):
    """The VDB of a grid spec (written once into the temp dir; its name is the spec's hash)."""
    h = hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:16]
    d = os.path.join(tempfile.gettempdir(), "lantern_difftest_vdb")
    path = os.path.join(d, f"{h}.vdb")
    if os.path.exists(path):
        return path
    import numpy as np
    import lantern._core
    os.makedirs(d, exist_ok=True)
    rng = np.random.default_rng(spec["seed"])
    n, m = spec["n"], spec["m"]
    c = (np.arange(n) + 0.5) / n - 0.5
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    d_ = np.zeros_like(x)
    for _ in range(spec["blobs"]):
        p, s = rng.uniform(-0.2, 0.2, 3), rng.uniform(0.1, 0.22)
        d_ += rng.uniform(0.5, 1.0) * np.exp(-((x - p[0]) ** 2 + (y - p[1]) ** 2 +
                                              (z - p[2]) ** 2) / (2 * s * s))
    d_ = np.clip(d_ - rng.uniform(0.02, 0.1), 0.0, None)
    cc = (np.arange(m) + 0.5) / m
    shape = [1, 1, 1]
    shape[2 - spec["axis"]] = m   # voxels [z, y, x]: the ramp along x, y or z
    heat = np.broadcast_to(cc.reshape(shape), (m, m, m)).astype(np.float32)

    def cube_map(k, lo=-0.5, size=1.0):
        v = size / k
        return np.array([[v, 0, 0, lo + v / 2], [0, v, 0, lo + v / 2],
                         [0, 0, v, lo + v / 2], [0, 0, 0, 1]], np.float64)
    tmp = f"{path}.{os.getpid()}.tmp"
    lantern._core.vdb_write_list(tmp, [
        {"name": "density", "voxels": np.ascontiguousarray(d_.astype(np.float32)),
         "index_to_object": cube_map(n)},
        {"name": "heat", "voxels": np.ascontiguousarray(heat),
         "index_to_object": cube_map(m, -0.55, 1.1)}])
    os.replace(tmp, path)
    return path


def _lowpoly_mesh(spec, name):
    import bmesh
    import bpy
    bm = bmesh.new()
    if spec["shape"] == "ico":
        bmesh.ops.create_icosphere(bm, subdivisions=1, radius=1.0)
    elif spec["shape"] == "uv":
        bmesh.ops.create_uvsphere(bm, u_segments=8, v_segments=5, radius=1.0)
    else:
        bmesh.ops.create_cone(bm, cap_ends=True, segments=8, radius1=1.0, radius2=1.0,
                              depth=2.0)
    me = bpy.data.meshes.new(name)
    bm.to_mesh(me)
    bm.free()
    if spec["smooth"]:
        me.shade_smooth()
    else:
        me.shade_flat()
    return me


def build_object(sc, o, made):
    """The features of object entry `o` on its bpy object `made` (before hair); returns the
    object (for a "vdb" entry a Volume object in place of the placeholder mesh)."""
    import bpy
    if o["kind"] == "vdb":
        vol = bpy.data.volumes.new(f"vdb_{made.name}")
        vol.filepath = vdb_path(o["vdb"])
        for m in made.data.materials:
            vol.materials.append(m)
        ob = bpy.data.objects.new(made.name + "_vdb", vol)
        ob.location, ob.rotation_euler, ob.scale = made.location, made.rotation_euler, \
            made.scale
        sc.collection.objects.link(ob)
        bpy.data.objects.remove(made)
        return ob
    lp = o.get("lowpoly")
    if lp:
        me = _lowpoly_mesh(lp, made.data.name + "_lp")
        for m in made.data.materials:
            me.materials.append(m)
        made.data = me
        if lp.get("offset") is not None:
            made.shadow_terminator_geometry_offset = lp["offset"]
    if o.get("deform"):
        bpy.context.preferences.edit.keyframe_new_interpolation_type = "LINEAR"
        made.shape_key_add(name="Basis")
        key = made.shape_key_add(name="Deform", from_mix=False)
        d = o["deform"]
        for p in key.data:
            p.co = [c * s + t for c, s, t in zip(p.co, d["scale"], d["shift"])]
        for frame, value in ((0, 0.0), (2, 1.0)):
            key.value = value
            key.keyframe_insert("value", frame=frame)
    return made


def hair_children(o, made):
    ch = o.get("hair", {}).get("children")
    if not ch or made is None:
        return
    for mod in made.modifiers:
        if mod.type == "PARTICLE_SYSTEM":
            ps = mod.particle_system.settings
            ps.child_type = ch["type"]
            ps.rendered_child_count = ps.child_percent = ch["count"]
            ps.child_radius = ch["radius"]


def build_scene(sc, case):
    import bpy
    for i, spec in enumerate(case["lights"]):
        if spec.get("cast_shadow") is False:
            bpy.data.objects[f"{spec['type'].lower()}{i}"].data.use_shadow = False


def features(case):
    found = set()
    vols = case.get("volumes", {})
    for o in case["objects"]:
        if o["kind"] == "vdb" and o.get("volume") in vols:
            found.add("vdb volume")
            g = vols[o["volume"]]
            for name, n in g["nodes"].items():
                if n["type"] in ("ShaderNodeVolumePrincipled", "ShaderNodeVolumeScatter",
                                 "ShaderNodeVolumeAbsorption"):
                    links = [lk for lk in g["links"] if lk[2] == name]
                    if any(lk[3] == "Density" for lk in links):
                        found.add("vdb density graph")
                    if any(lk[3] == "Emission Strength" for lk in links):
                        found.add("vdb emission")
        lp = o.get("lowpoly")
        if lp:
            found.add("low-poly smooth" if lp["smooth"] else "low-poly flat")
            if lp.get("offset") is not None and lp["offset"] != 0.1:
                found.add("terminator offset")
        if o.get("hair", {}).get("children"):
            found.add("hair children")
        if o.get("deform") and case.get("shutter"):
            found.add("deformation blur")
    if any(lt.get("cast_shadow") is False for lt in case["lights"]):
        found.add("no shadow")
    graphs = [(g, False) for g in vols.values()]
    if case.get("world_volume"):
        graphs.append((case["world_volume"], True))
    for g, world in graphs:
        for name, n in g["nodes"].items():
            if n["type"] in SCATTERERS and n.get("inputs", {}).get("Anisotropy", 0.0) < 0:
                found.add("negative anisotropy")
            if n.get("props", {}).get("phase", "HENYEY_GREENSTEIN") != "HENYEY_GREENSTEIN":
                found.add("volume phase")
            if n["type"] == "ShaderNodeTexNoise":
                for lk in g["links"]:
                    if lk[0] == name and lk[3] == "Color" and lk[1] == "Color":
                        found.add("volume colour noise")
                if world:
                    found.add("world volume noise")
    return found


def shrink_edits(case):
    """(label, smaller case): the features taken off one at a time."""
    def edited(fn):
        c = copy.deepcopy(case)
        fn(c)
        return c
    for i, lt in enumerate(case["lights"]):
        if "cast_shadow" in lt:
            yield f"light {i}: casts shadows", edited(lambda c, i=i: c["lights"][i].pop(
                "cast_shadow"))
    for i, o in enumerate(case["objects"]):
        if "deform" in o:
            yield f"object {i}: no deformation", edited(lambda c, i=i: c["objects"][i].pop(
                "deform"))
        if o.get("hair", {}).get("children"):
            yield f"object {i}: no hair children", edited(
                lambda c, i=i: c["objects"][i]["hair"].pop("children"))
        if "lowpoly" in o:
            yield f"object {i}: not low-poly", edited(lambda c, i=i: c["objects"][i].pop(
                "lowpoly"))
            if o["lowpoly"].get("offset") is not None:
                yield f"object {i}: default terminator offset", edited(
                    lambda c, i=i: c["objects"][i]["lowpoly"].update(offset=None))
    for where, g in [(k, v) for k, v in case.get("volumes", {}).items()] + (
            [("world volume", case["world_volume"])] if case.get("world_volume") else []):
        for name, n in g["nodes"].items():
            if "phase" in n.get("props", {}):
                def hg(c, where=where, name=name):
                    gg = c["world_volume"] if where == "world volume" else c["volumes"][where]
                    gg["nodes"][name]["props"].pop("phase")
                yield f"{where}: {name} Henyey-Greenstein", edited(hg)
