"""The sixth batch of features in the differential tester's "full" profile (docs/difftest.md,
2026-12-07 difftest6): object and lamp ray visibility by kind (Object > Visibility > Ray
Visibility: Diffuse, Glossy, Transmission, Volume Scatter; a lamp's Light > Visibility), an
object's Cast Shadow off (Ray Visibility > Shadow), and what beside them the bidirectional
integrators and lt render with new rules (integrator/bidir_ray_visibility.h,
bidir_no_shadow.h, lt_linking.h): a lamp's Cast Shadow off in fog, shadow linking in fog, a
shadow-linked lamp beside a sharp glossy surface (pt's MIS for shadow-linked lamps).

draw() adds them to a drawn case from a stream of its own (the case's key + ":features6"),
after difftest_features5.draw, so every "ci" case and every full case without them draws as
before. Tags: FEATURES (features(case)). The case holds them as
- o["rays_off"] / light["rays_off"]: kinds of RAY_KINDS hidden (the object's visible_<kind>
  False; a lamp's too);
- o["cast_shadow"] = False: the object's visible_shadow off (a lamp's Cast Shadow is
  difftest_features2's light["cast_shadow"], the light's use_shadow);
- case["materials"]["gloss6"]: the sharp glossy surface beside a shadow-linked lamp."""

import copy
import random

from difftest_graph import _rgb, _u

FEATURES = {
    "object ray visibility": "a mesh hidden from diffuse, glossy, transmission or volume "
                             "scatter rays (Object > Visibility > Ray Visibility)",
    "lamp ray visibility": "a lamp hidden from diffuse, glossy, transmission or volume scatter "
                           "rays",
    "object no shadow": "a mesh whose Ray Visibility > Shadow is off (casts no shadow)",
    "object no shadow in fog": "a mesh that casts no shadow, in a world volume or beside a "
                               "mesh volume",
    "ray visibility in fog": "object or lamp ray visibility by kind with a world or mesh "
                             "volume",
    "no shadow in fog": "a lamp with Cast Shadow off, with a world or mesh volume",
    "shadow linking in fog": "shadow linking with a world volume",
    "shadow link beside glossy": "a shadow-linked lamp and a sharp glossy surface",
}
RAY_KINDS = ("diffuse", "glossy", "transmission", "volume_scatter")
# hidden kinds, weighted: diffuse and glossy together most (one of the two alone only where no
# Principled or mixed material is: the export names it there, unsupported; _mixture)
PATTERNS = ((("diffuse", "glossy"), 3), (("diffuse",), 1), (("glossy",), 1),
            (("transmission",), 1), (("diffuse", "glossy", "transmission"), 1))

P_OBJ_RAYS, P_LAMP_RAYS, P_OBJ_SHADOW, P_FOG = 0.15, 0.12, 0.15, 0.3
P_LAMP_SHADOW_FOG, P_SHLINK_FOG, P_GLOSSY = 0.15, 0.4, 0.4
MESHES = ("cube", "ico", "sphere", "plane", "room")


def _media(case):
    return bool(case.get("world_volume") or case.get("volumes"))


def _meshes(case, big=True):
    return [o for o in case["objects"] if o["kind"] in MESHES and not o.get("volume")
            and (big or not (o["kind"] == "room" or o["scale"][0] >= 6.0))]


def _mixture(case):
    """Whether a used material holds a Principled, Mix or Add Shader (or Blender's default
    Principled surface): Lantern samples it as one mixture of diffuse and glossy, and the
    export names diffuse or glossy hidden alone beside it (export/visibility.py)."""
    used = {o.get("material") for o in case["objects"]} | \
        {o["hair"]["material"] for o in case["objects"] if "hair" in o}
    return None in used or any(
        n["type"] in ("ShaderNodeBsdfPrincipled", "ShaderNodeMixShader", "ShaderNodeAddShader")
        for k, g in case["materials"].items() if k in used for n in g["nodes"].values())


def _kinds(r, case):
    pats = list(PATTERNS) + ([(("volume_scatter",), 2)] if _media(case) else [])
    if _mixture(case):   # one r.choices draw either way
        pats = [(p, w) for p, w in pats if ("diffuse" in p) == ("glossy" in p)]
    return list(r.choices([p for p, _ in pats], weights=[w for _, w in pats])[0])


def _blocked_lamps(case):
    return [spec["emitter"][1] for spec in case.get("linking", [])
            if spec["kind"] == "blocker" and spec["emitter"][0] == "light"]


def _gloss(r):
    g = {"nodes": {}, "links": [], "out": None}
    if r.random() < 0.5:
        g["nodes"]["z0"] = {"type": "ShaderNodeBsdfGlossy", "props": {},
                            "inputs": {"Color": _rgb(r, 0.5, 1.0),
                                       "Roughness": _u(r, 0.03, 0.3)}}
    else:
        g["nodes"]["z0"] = {"type": "ShaderNodeBsdfPrincipled", "props": {},
                            "inputs": {"Base Color": _rgb(r, 0.5, 1.0), "Metallic": 1.0,
                                       "Roughness": _u(r, 0.03, 0.3)}}
    g["out"] = ["z0", "BSDF"]
    return g


def _one_lobe(g):
    """A drawn world volume with its scatterers at one Anisotropy (the first's): scatterers of
    different Anisotropy under an Add Shader are named by the export (unsupported), which would
    waste the batch's fog; no random number drawn."""
    aniso = [n["inputs"]["Anisotropy"] for n in g["nodes"].values()
             if "Anisotropy" in n.get("inputs", {})]
    for n in g["nodes"].values():
        if "Anisotropy" in n.get("inputs", {}):
            n["inputs"]["Anisotropy"] = aniso[0]
    return g


def draw(key, case, avoid, volume_graph):
    """Add the features to `case` (full profile, after difftest_features5.draw);
    volume_graph(r, world=True) draws a world volume (difftest_features)."""
    r = random.Random(key + ":features6")
    meshes = _meshes(case)
    if meshes and r.random() < P_OBJ_RAYS and "object ray visibility" not in avoid:
        r.choice(meshes)["rays_off"] = _kinds(r, case)
    if case["lights"] and r.random() < P_LAMP_RAYS and "lamp ray visibility" not in avoid:
        r.choice(case["lights"])["rays_off"] = _kinds(r, case)
    small = _meshes(case, big=False)
    if small and r.random() < P_OBJ_SHADOW and "object no shadow" not in avoid:
        r.choice(small)["cast_shadow"] = False
    mine = any("rays_off" in x or x.get("cast_shadow") is False
               for x in case["objects"]) or any("rays_off" in x for x in case["lights"])
    if mine and not case.get("world_volume") and r.random() < P_FOG and \
            "world volume" not in avoid and "ray visibility in fog" not in avoid:
        case["world_volume"] = _one_lobe(volume_graph(r, world=True))
    if _media(case) and case["lights"] and not any(
            lt.get("cast_shadow") is False for lt in case["lights"]) and \
            r.random() < P_LAMP_SHADOW_FOG and "no shadow" not in avoid and \
            "no shadow in fog" not in avoid:
        r.choice(case["lights"])["cast_shadow"] = False
    blocked = _blocked_lamps(case)
    if blocked and not case.get("world_volume") and r.random() < P_SHLINK_FOG and \
            "world volume" not in avoid and "shadow linking in fog" not in avoid:
        case["world_volume"] = _one_lobe(volume_graph(r, world=True))
    if blocked and r.random() < P_GLOSSY and "shadow link beside glossy" not in avoid:
        pool = _meshes(case, big=False)
        if pool:
            o = r.choice(pool)
            old, o["material"] = o.get("material"), "gloss6"
            case["materials"]["gloss6"] = _gloss(r)
            if old and not any(x.get("material") == old for x in case["objects"]) and \
                    not any(x.get("hair", {}).get("material") == old
                            for x in case["objects"]):
                case["materials"].pop(old, None)
    _avoided(case, avoid)
    return case


def _avoided(case, avoid):
    """--avoid of a combined tag (X in fog) takes X off where the case has media from an
    earlier batch (so that the tag is gone, as --avoid promises)."""
    if _media(case):
        for o in case["objects"]:
            if "object no shadow in fog" in avoid and o.get("cast_shadow") is False:
                o.pop("cast_shadow")
            if "ray visibility in fog" in avoid:
                o.pop("rays_off", None)
        for lt in case["lights"]:
            if "ray visibility in fog" in avoid:
                lt.pop("rays_off", None)
            if "no shadow in fog" in avoid:
                lt.pop("cast_shadow", None)
    if case.get("world_volume") and "shadow linking in fog" in avoid and case.get("linking"):
        case["linking"] = [s for s in case["linking"] if s["kind"] != "blocker"]
        if not case["linking"]:
            case.pop("linking")


def build_object(sc, o, ob):
    """The object's ray visibility and Cast Shadow (`ob` its bpy object, or None)."""
    if ob is None:
        return ob
    for kind in o.get("rays_off", ()):
        setattr(ob, f"visible_{kind}", False)
    if o.get("cast_shadow") is False:
        ob.visible_shadow = False
    return ob


def build_scene(sc, case):
    """The lamps' ray visibility (their objects are named '<type><i>', difftest_build)."""
    import bpy
    for i, spec in enumerate(case["lights"]):
        for kind in spec.get("rays_off", ()):
            setattr(bpy.data.objects[f"{spec['type'].lower()}{i}"], f"visible_{kind}", False)


def features(case):
    found = set()
    media = _media(case)
    objs = [o for o in case["objects"] if o["kind"] in MESHES]
    if any(o.get("rays_off") for o in objs):
        found.add("object ray visibility")
    if any(lt.get("rays_off") for lt in case["lights"]):
        found.add("lamp ray visibility")
    if any(o.get("cast_shadow") is False for o in objs):
        found.add("object no shadow")
        if media:
            found.add("object no shadow in fog")
    if media and found & {"object ray visibility", "lamp ray visibility"}:
        found.add("ray visibility in fog")
    if media and any(lt.get("cast_shadow") is False for lt in case["lights"]):
        found.add("no shadow in fog")
    blocked = any(spec["kind"] == "blocker" for spec in case.get("linking", []))
    if blocked and case.get("world_volume"):
        found.add("shadow linking in fog")
    if _blocked_lamps(case) and "gloss6" in {o.get("material") for o in case["objects"]}:
        found.add("shadow link beside glossy")
    return found


def shrink_edits(case):
    """(label, smaller case): a kind made visible again, an object's shadow back."""
    def edited(fn):
        c = copy.deepcopy(case)
        fn(c)
        return c
    for what, items in (("object", case["objects"]), ("light", case["lights"])):
        key = "objects" if what == "object" else "lights"
        for i, x in enumerate(items):
            if x.get("rays_off"):
                yield f"{what} {i}: every ray kind", edited(
                    lambda c, i=i, key=key: c[key][i].pop("rays_off"))
                if len(x["rays_off"]) > 1:
                    for k in x["rays_off"]:
                        yield f"{what} {i}: {k} rays", edited(
                            lambda c, i=i, key=key, k=k: c[key][i]["rays_off"].remove(k))
    for i, o in enumerate(case["objects"]):
        if o.get("cast_shadow") is False:
            yield f"object {i}: casts shadows", edited(
                lambda c, i=i: c["objects"][i].pop("cast_shadow"))
