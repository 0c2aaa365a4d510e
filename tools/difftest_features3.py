"""The third batch of features in the differential tester's "full" profile (docs/difftest.md,
2026-12-06 difftest3): what landed since difftest2 and no earlier batch drew together. Moving
emitters (an emissive mesh with object motion or a shape-key deformation over the shutter),
motion in fog (a moving or deforming mesh in a scene with a world volume, inside or beside a
mesh volume; the volume's own mesh moving, homogeneous or with a Noise on its Density),
Principled Hair in a Mix Shader (on particle hair or a Curves object, in fog or not), node
graphs on a mesh volume's Emission Strength / Emission Color, and a Translucent BSDF on a
smooth low-poly mesh (D43's known tag: drawn only where the run allows it).

draw() adds them to a drawn case from a stream of its own (the case's key + ":features3"),
after difftest_features2.draw, so every "ci" case and every full case without them draws as
before. The bidirectional integrators, lt and auto are the run's choice (tools/difftest_run.py
--integrator), not the case's. Tags: FEATURES (features(case))."""

import copy
import random

from difftest_graph import _rgb, _u

FEATURES = {
    "moving emitter": "an emissive mesh moving (location / rotation keys) or deforming over "
                      "the shutter",
    "motion in fog": "a mesh moving or deforming over the shutter in a scene with a world "
                     "volume or a mesh volume",
    "moving volume": "a mesh volume's own mesh moving over the shutter",
    "hair mix": "Principled Hair in a Mix Shader with another BSDF",
    "strands in fog": "strands (particle hair or Curves) in a scene with a world volume",
    "skin subsurface": "Random Walk (Skin) subsurface",
    "volume emission graph": "a node graph on a mesh volume's Emission Strength or Emission "
                             "Color (Principled Volume) or an Emission's Strength",
}

P_EMIT, P_FOG_MOTION, P_HAIR_MIX, P_VOL_EMIT, P_TRANSLUCENT = 0.12, 0.15, 0.12, 0.2, 0.3
D43 = "translucent on low-poly smooth"


def _add(g, typ, props=None, inputs=None):
    name = f"x{len(g['nodes'])}"
    g["nodes"][name] = {"type": typ, "props": props or {}, "inputs": inputs or {}}
    return name


def _motion(r):
    if r.random() < 0.6:
        return {"location": [_u(r, -1.0, 1.0), _u(r, -1.0, 1.0), _u(r, -0.3, 0.3)]}
    return {"rotation": [_u(r, -1.0, 1.0), _u(r, -1.0, 1.0), _u(r, -2.0, 2.0)]}


def _deform(r):
    return {"scale": [_u(r, 0.6, 1.4) for _ in range(3)],
            "shift": [_u(r, -0.3, 0.3) for _ in range(3)]}


def _movable(case):
    return [o for o in case["objects"] if o["kind"] in ("cube", "ico", "sphere", "plane")
            and o["scale"][0] < 6.0 and not o.get("volume") and "hair" not in o]


def _set_material(case, o, name, graph):
    old, o["material"] = o.get("material"), name
    case["materials"][name] = graph
    if old and old != name and not any(x.get("material") == old for x in case["objects"]) \
            and not any(x.get("hair", {}).get("material") == old for x in case["objects"]):
        case["materials"].pop(old, None)


def _emitter(r):
    """An emissive surface: an Emission, or a Principled emitting; its strength a Noise
    (positive: Fac x c) for 30 %."""
    g = {"nodes": {}, "links": [], "out": None}
    if r.random() < 0.5:
        e = _add(g, "ShaderNodeEmission", {}, {"Color": _rgb(r, 0.3, 1.0),
                                                "Strength": _u(r, 2.0, 10.0)})
        g["out"], sock = [e, "Emission"], "Strength"
    else:
        e = _add(g, "ShaderNodeBsdfPrincipled", {}, {
            "Base Color": _rgb(r, 0.2, 1.0), "Roughness": _u(r, 0.2, 1.0),
            "Emission Color": _rgb(r, 0.3, 1.0), "Emission Strength": _u(r, 1.0, 8.0)})
        g["out"], sock = [e, "BSDF"], "Emission Strength"
    if r.random() < 0.3:
        noise = _add(g, "ShaderNodeTexNoise", {"noise_dimensions": "3D"},
                     {"Scale": _u(r, 0.5, 6.0), "Detail": _u(r, 0.0, 4.0)})
        mul = _add(g, "ShaderNodeMath", {"operation": "MULTIPLY"},
                   {"Value_001": _u(r, 2.0, 10.0)})
        g["links"] += [[noise, "Fac", mul, "Value"], [mul, "Value", e, sock]]
    return g


def _principled_hair(r, g):
    param = r.choice(["MELANIN", "COLOR", "ABSORPTION"])
    inputs = {"Roughness": _u(r, 0.1, 0.8), "Radial Roughness": _u(r, 0.1, 0.8),
              "IOR": _u(r, 1.3, 1.8)}
    if param == "MELANIN":
        inputs.update({"Melanin": _u(r, 0.0, 1.0), "Melanin Redness": _u(r, 0.0, 1.0)})
    elif param == "COLOR":
        inputs["Color"] = _rgb(r, 0.1, 1.0)
    else:
        inputs["Absorption Coefficient"] = [_u(r, 0.05, 2.0) for _ in range(3)]
    return _add(g, "ShaderNodeBsdfHairPrincipled", {"parametrization": param,
                                                    "model": "CHIANG"}, inputs)


def _hair_mix(r):
    """Mix Shader (Fac 0.1-0.9) of a Principled Hair and a Diffuse, a Glossy, a Translucent
    or another Principled Hair."""
    g = {"nodes": {}, "links": [], "out": None}
    h = _principled_hair(r, g)
    other = r.choice(["hair", "diffuse", "diffuse", "glossy", "translucent"])
    if other == "hair":
        o = _principled_hair(r, g)
    elif other == "diffuse":
        o = _add(g, "ShaderNodeBsdfDiffuse", {}, {"Color": _rgb(r, 0.2, 1.0)})
    elif other == "glossy":
        o = _add(g, "ShaderNodeBsdfGlossy", {}, {"Color": _rgb(r, 0.2, 1.0),
                                                  "Roughness": _u(r, 0.2, 0.8)})
    else:
        o = _add(g, "ShaderNodeBsdfTranslucent", {}, {"Color": _rgb(r, 0.2, 1.0)})
    mix = _add(g, "ShaderNodeMixShader", {}, {"Fac": _u(r, 0.1, 0.9)})
    ab = [h, o] if r.random() < 0.5 else [o, h]
    g["links"] += [[ab[0], "BSDF", mix, "Shader"], [ab[1], "BSDF", mix, "Shader_001"]]
    g["out"] = [mix, "Shader"]
    return g


def _shutter(r, case):
    case.setdefault("shutter", r.choice([0.5, 1.0]))


def _volume_emission_graph(r, g):
    """A Noise on a mesh volume's emission: Fac x c on Emission Strength (Principled Volume,
    which emits then) or an Emission's Strength, or its Color on Emission Color."""
    shaders = [k for k, n in g["nodes"].items() if n["type"] in (
        "ShaderNodeVolumePrincipled", "ShaderNodeEmission")]
    if not shaders:
        return
    s = r.choice(shaders)
    node = g["nodes"][s]
    noise = _add(g, "ShaderNodeTexNoise", {"noise_dimensions": "3D"},
                 {"Scale": _u(r, 0.5, 6.0), "Detail": _u(r, 0.0, 4.0)})
    if node["type"] == "ShaderNodeVolumePrincipled" and r.random() < 0.4:
        node["inputs"].setdefault("Emission Strength", _u(r, 0.2, 3.0))
        g["links"].append([noise, "Color", s, "Emission Color"])
        return
    mul = _add(g, "ShaderNodeMath", {"operation": "MULTIPLY"}, {"Value_001": _u(r, 0.5, 4.0)})
    sock = "Strength" if node["type"] == "ShaderNodeEmission" else "Emission Strength"
    if sock == "Emission Strength":
        node["inputs"].setdefault("Emission Color", _rgb(r, 0.3, 1.0))
    g["links"] += [[noise, "Fac", mul, "Value"], [mul, "Value", s, sock]]


def draw(key, case, avoid, material, volume_graph, curves):
    """Add the features to `case` (full profile, after difftest_features2.draw).
    `material(r)`: an ordinary surface graph; `volume_graph(r, world)`: a volume graph
    (difftest_features._volume_graph); `curves(r)`: a Curves object entry."""
    r = random.Random(key + ":features3")
    movable = _movable(case)
    if movable and r.random() < P_EMIT and "moving emitter" not in avoid:
        o = r.choice(movable)
        _set_material(case, o, "emit3", _emitter(r))
        if "motion" not in o and "deform" not in o:
            if r.random() < 0.7:
                o["motion"] = _motion(r)
            else:
                o["deform"] = _deform(r)
        _shutter(r, case)
    vol = next((o for o in case["objects"] if o.get("volume") == "vol"), None)
    if r.random() < P_FOG_MOTION and "motion in fog" not in avoid:
        u = r.random()
        if vol is not None and u < 0.4 and "moving volume" not in avoid:
            vol["motion"] = _motion(r)
        elif movable:
            o = r.choice(movable)
            if vol is not None and u < 0.7:   # inside (or through) the mesh volume
                o["location"] = [round(a + _u(r, -0.3, 0.3), 4) for a in vol["location"]]
                o["scale"] = [round(min(s, 0.6 * vol["scale"][0]), 4) for s in o["scale"]]
            elif not case.get("world_volume"):
                case["world_volume"] = volume_graph(r, True)
            if "motion" not in o and "deform" not in o:
                if r.random() < 0.8:
                    o["motion"] = _motion(r)
                else:
                    o["deform"] = _deform(r)
        if vol is not None or movable:
            _shutter(r, case)
    if r.random() < P_HAIR_MIX and "hair mix" not in avoid:
        if not any("hair" in o or o["kind"] == "curves" for o in case["objects"]):
            case["objects"].append(curves(r))
        case["materials"]["hair"] = _hair_mix(r)
        if r.random() < 0.4 and not case.get("world_volume") and "strands in fog" not in avoid:
            case["world_volume"] = volume_graph(r, True)
    g = case.get("volumes", {}).get("vol")
    if g and r.random() < P_VOL_EMIT and "volume emission graph" not in avoid:
        _volume_emission_graph(r, g)
    if D43 not in avoid and r.random() < P_TRANSLUCENT:
        smooth = [o for o in case["objects"] if o.get("lowpoly", {}).get("smooth")]
        if smooth:
            o = r.choice(smooth)
            t = {"nodes": {"t": {"type": "ShaderNodeBsdfTranslucent", "props": {},
                                 "inputs": {"Color": _rgb(r, 0.3, 1.0)}}},
                 "links": [], "out": ["t", "BSDF"]}
            _set_material(case, o, "translucent3", t)
    return case


def features(case):
    found = set()
    used = {o.get("material") for o in case["objects"]}
    moving = [o for o in case["objects"] if case.get("shutter") and (
        "motion" in o or o.get("deform"))]
    mats = case["materials"]
    for o in moving:
        g = mats.get(o.get("material"))
        if g and any(_emits(n, g, k) for k, n in g["nodes"].items()):
            found.add("moving emitter")
    vols = case.get("volumes", {})
    mesh_vols = [o for o in case["objects"] if o.get("volume") in vols and o["kind"] != "vdb"]
    if moving and (case.get("world_volume") or vols):
        found.add("motion in fog")
    if any("motion" in o and case.get("shutter") for o in mesh_vols):
        found.add("moving volume")
    strands = [o for o in case["objects"] if "hair" in o or o["kind"] == "curves"]
    hair_mats = {o["hair"]["material"] if "hair" in o else o.get("material") for o in strands}
    for name in hair_mats:
        g = mats.get(name)
        if g and any(n["type"] == "ShaderNodeMixShader" for n in g["nodes"].values()) and any(
                n["type"] == "ShaderNodeBsdfHairPrincipled" for n in g["nodes"].values()):
            found.add("hair mix")
    if strands and case.get("world_volume"):
        found.add("strands in fog")
    for name, g in mats.items():
        if name in used or name in hair_mats:
            for n in g["nodes"].values():
                if n.get("inputs", {}).get("Subsurface Weight", 0.0) > 0 and n.get(
                        "props", {}).get("subsurface_method") == "RANDOM_WALK_SKIN":
                    found.add("skin subsurface")
    for o in mesh_vols:
        g = vols[o["volume"]]
        if any(lk[3] in ("Emission Strength", "Emission Color") or (
                lk[3] == "Strength" and g["nodes"][lk[2]]["type"] == "ShaderNodeEmission")
                for lk in g["links"]):
            found.add("volume emission graph")
    return found


def _emits(node, g, name):
    ins = node.get("inputs", {})
    linked = any(lk[2] == name and lk[3] in ("Strength", "Emission Strength")
                 for lk in g["links"])
    if node["type"] == "ShaderNodeEmission":
        return linked or ins.get("Strength", 1.0) != 0.0
    return node["type"] == "ShaderNodeBsdfPrincipled" and (
        linked or ins.get("Emission Strength", 0.0) > 0)


def shrink_edits(case):
    """(label, smaller case): the mix's other shader taken off a hair material."""
    for name, g in case["materials"].items():
        mixes = [k for k, n in g["nodes"].items() if n["type"] == "ShaderNodeMixShader"]
        if len(mixes) != 1 or not any(n["type"] == "ShaderNodeBsdfHairPrincipled"
                                      for n in g["nodes"].values()):
            continue
        for lk in g["links"]:
            if lk[2] == mixes[0] and g["nodes"][lk[0]]["type"] == \
                    "ShaderNodeBsdfHairPrincipled":
                c = copy.deepcopy(case)
                c["materials"][name]["out"] = [lk[0], "BSDF"]
                yield f"{name}: the Principled Hair alone", c
                break
