"""The fifth batch of features in the differential tester's "full" profile (docs/difftest.md,
2026-12-06 difftest5): the knobs of issue 32 that no earlier batch drew, and fairer shares of
those it drew rarely. Subsurface IOR (the Principled's IOR, which Random Walk reads, and its
Subsurface IOR, which Random Walk (Skin) reads) and more subsurface, Skin among it; particle
hair more often, with a Principled BSDF on the strands; motion blur through a parent (a mesh
parented to a moving Empty), the shutter's Position (Start / End), an object's or the
camera's Motion Steps (5 or 9 matrices), a turning camera, moving strands; and a world volume
beside those features.

draw() adds them to a drawn case from a stream of its own (the case's key + ":features5"),
after difftest_features4.draw, so every "ci" case and every full case without them draws as
before. Tags: FEATURES (features(case)). The case holds them as
- a Principled's "IOR" / "Subsurface IOR" inputs on a subsurface material;
- o["hair"] (difftest_features' particle hair) with material "hair5";
- o["parent"] = {"pivot": [x, y, z], "motion": {"location" | "rotation": [...]}}: an Empty at
  the pivot, keyed as an object's motion (frames 0 and 2 around its pose), the object its child
  with its world pose at frame 1 unchanged;
- o["motion_steps"] / case["camera"]["motion_steps"]: Object > Motion Blur > Steps;
- case["shutter_position"]: "START" or "END" (else Blender's "CENTER")."""

import copy
import random

from difftest_graph import _rgb, _u

FEATURES = {
    "subsurface ior": "a subsurface Principled with IOR (Random Walk) and Subsurface IOR "
                      "(Random Walk (Skin)) drawn",
    "parented motion": "a mesh moving with its parent (an Empty keyed over the shutter)",
    "shutter position": "the shutter's Position Start or End",
    "motion steps": "Motion Steps 2 or 3 (5 or 9 matrices) on a moving object or the camera",
    "camera rotation": "the camera turning over the shutter",
    "principled on strands": "strands (particle hair or Curves) with a Principled BSDF",
    "moving strands": "particle hair on a moving object, or a moving Curves object",
    "issue 32 in fog": "a world volume beside subsurface, strands, motion blur or linking",
}

P_SSS, P_SKIN, P_IOR, P_HAIR, P_PRINCIPLED_STRANDS = 0.12, 0.5, 0.7, 0.12, 0.6
P_PARENT, P_POSITION, P_STEPS, P_CAM_ROT, P_MOVING_STRANDS, P_FOG = \
    0.12, 0.35, 0.35, 0.06, 0.3, 0.08
MOVABLE = ("cube", "ico", "sphere", "plane")
HAIRY = ("cube", "ico", "sphere")


def _add(g, typ, props=None, inputs=None):
    name = f"y{len(g['nodes'])}"
    g["nodes"][name] = {"type": typ, "props": props or {}, "inputs": inputs or {}}
    return name


def _movable(case):
    return [o for o in case["objects"] if o["kind"] in MOVABLE and o["scale"][0] < 6.0
            and not o.get("volume")]


def _motion(r):
    if r.random() < 0.5:
        return {"location": [_u(r, -1.0, 1.0), _u(r, -1.0, 1.0), _u(r, -0.3, 0.3)]}
    return {"rotation": [_u(r, -1.0, 1.0), _u(r, -1.0, 1.0), _u(r, -2.0, 2.0)]}


def _sss_nodes(case):
    """(graph, node) of every Principled with Subsurface Weight > 0 in a used material."""
    used = {o.get("material") for o in case["objects"]}
    for name, g in case["materials"].items():
        if name in used:
            for n in g["nodes"].values():
                if n["type"] == "ShaderNodeBsdfPrincipled" and \
                        n.get("inputs", {}).get("Subsurface Weight", 0.0) > 0:
                    yield g, n


def _subsurface(r, case, objs):
    o = r.choice(objs)
    name = f"sss5_{case['objects'].index(o)}"
    g = {"nodes": {}, "links": [], "out": None}
    p = _add(g, "ShaderNodeBsdfPrincipled",
             {"subsurface_method": "RANDOM_WALK_SKIN" if r.random() < P_SKIN else "RANDOM_WALK"},
             {"Base Color": _rgb(r, 0.3, 1.0), "Roughness": _u(r, 0.2, 1.0),
              "Subsurface Weight": r.choice([1.0, _u(r, 0.3, 1.0)]),
              "Subsurface Radius": [_u(r, 0.1, 1.0), _u(r, 0.05, 0.5), _u(r, 0.02, 0.3)],
              "Subsurface Scale": _u(r, 0.02, 0.3),
              "Subsurface Anisotropy": r.choice([0.0, _u(r, 0.0, 0.9), _u(r, -0.5, 0.0)])})
    g["out"] = [p, "BSDF"]
    old, o["material"] = o.get("material"), name
    case["materials"][name] = g
    if old and not any(x.get("material") == old for x in case["objects"]) and \
            not any(x.get("hair", {}).get("material") == old for x in case["objects"]):
        case["materials"].pop(old, None)


def _strand_principled(r):
    """A Principled BSDF for strands (Cycles shades a curve's Principled as a surface facing
    the ray: its base, specular and, sometimes, metal and coat)."""
    g = {"nodes": {}, "links": [], "out": None}
    inputs = {"Base Color": _rgb(r, 0.1, 1.0), "Roughness": _u(r, 0.1, 0.9)}
    if r.random() < 0.3:
        inputs["Metallic"] = r.choice([1.0, _u(r, 0.0, 1.0)])
    if r.random() < 0.3:
        inputs["IOR"] = _u(r, 1.2, 2.0)
    if r.random() < 0.15:
        inputs["Coat Weight"] = _u(r, 0.2, 1.0)
    p = _add(g, "ShaderNodeBsdfPrincipled", {}, inputs)
    g["out"] = [p, "BSDF"]
    return g


def _shutter(r, case):
    case.setdefault("shutter", r.choice([0.5, 1.0, _u(r, 0.2, 1.0)]))


def draw(key, case, avoid, volume_graph, hair_material):
    """Add the features to `case` (full profile, after difftest_features4.draw);
    volume_graph(r, world=True) draws a world volume (difftest_features), hair_material(r)
    a hair material (difftest_features: Principled Hair or an ordinary one)."""
    r = random.Random(key + ":features5")
    objs = _movable(case)
    sss = list(_sss_nodes(case))
    if not sss and objs and r.random() < P_SSS and "subsurface" not in avoid:
        _subsurface(r, case, objs)
        sss = list(_sss_nodes(case))
    if sss and r.random() < P_IOR and "subsurface ior" not in avoid:
        for g, n in sss:
            n["inputs"]["IOR"] = _u(r, 1.1, 2.4)
            n["inputs"]["Subsurface IOR"] = _u(r, 1.05, 2.0)
    bare = [o for o in objs if o["kind"] in HAIRY and "hair" not in o]
    if bare and r.random() < P_HAIR and "particle hair" not in avoid:
        o = r.choice(bare)
        o["hair"] = {"count": r.randint(30, 150), "length": _u(r, 0.1, 0.35),
                     "radius": _u(r, 0.004, 0.02), "seed": r.randrange(1000),
                     "material": "hair5"}
        case["materials"]["hair5"] = _strand_principled(r) if (
            r.random() < P_PRINCIPLED_STRANDS and "principled on strands" not in avoid) \
            else hair_material(r)
    # motion blur: a parent, moving strands, the camera's turn; then position and steps
    still = [o for o in _movable(case) if "motion" not in o and "parent" not in o]
    if still and r.random() < P_PARENT and "parented motion" not in avoid and \
            "motion blur" not in avoid:
        o = r.choice(still)
        d = _u(r, 0.3, 1.5)
        pivot = [o["location"][0] + r.choice([-d, d]), o["location"][1] + _u(r, -0.5, 0.5),
                 o["location"][2] + _u(r, -0.3, 0.3)]
        o["parent"] = {"pivot": [round(x, 4) for x in pivot], "motion": _motion(r)}
        if r.random() < 0.3:   # its own motion besides
            o["motion"] = _motion(r)
        _shutter(r, case)
    hairy = [o for o in case["objects"] if ("hair" in o and o["kind"] in MOVABLE)
             or o["kind"] == "curves"]
    hairy = [o for o in hairy if "motion" not in o and "parent" not in o]
    if hairy and r.random() < P_MOVING_STRANDS and "moving strands" not in avoid and \
            "motion blur" not in avoid:
        r.choice(hairy)["motion"] = _motion(r)
        _shutter(r, case)
    if r.random() < P_CAM_ROT and "camera rotation" not in avoid and \
            "moving camera" not in avoid:
        m = case["camera"].setdefault("motion", {})
        m["rotation"] = [_u(r, -0.12, 0.12), _u(r, -0.12, 0.12), _u(r, -0.2, 0.2)]
        _shutter(r, case)
    if case.get("shutter"):
        if r.random() < P_POSITION and "shutter position" not in avoid:
            case["shutter_position"] = r.choice(["START", "END"])
        movers = [o for o in case["objects"] if "motion" in o or "parent" in o]
        if "motion" in case["camera"]:
            movers.append(case["camera"])
        if movers and r.random() < P_STEPS and "motion steps" not in avoid:
            r.choice(movers)["motion_steps"] = r.choice([2, 3])
    if not case.get("world_volume") and _issue32(case) and r.random() < P_FOG and \
            "world volume" not in avoid and "issue 32 in fog" not in avoid:
        case["world_volume"] = volume_graph(r, world=True)
    return case


def _issue32(case):
    """Whether the case has subsurface, strands, motion blur or linking (read off the
    description, not through difftest_features.features, which calls features() here)."""
    moves = case.get("shutter") and ("motion" in case["camera"] or any(
        "motion" in o or "parent" in o or o.get("deform") for o in case["objects"]))
    return bool(moves or case.get("linking") or any(True for _ in _sss_nodes(case)) or any(
        "hair" in o or o["kind"] == "curves" for o in case["objects"]))


def build_object(sc, o, ob):
    """The object's parent Empty (keyed) and its Motion Steps; called once the object is
    made, before the scene's keys (difftest_features.build_scene)."""
    import bpy
    if o.get("motion_steps"):
        ob.cycles.motion_steps = o["motion_steps"]
    if "parent" not in o:
        return ob
    p = o["parent"]
    e = bpy.data.objects.new(f"{ob.name}_parent", None)
    e.location = p["pivot"]
    sc.collection.objects.link(e)
    bpy.context.view_layer.update()
    ob.parent = e
    ob.matrix_parent_inverse = e.matrix_world.inverted()
    return ob


def parents(case, made):
    """(bpy Empty, its motion) of every parented object (the keys go on at build_scene)."""
    for o, ob in zip(case["objects"], made):
        if "parent" in o and ob is not None and ob.parent is not None:
            yield ob.parent, o["parent"]["motion"]


def build_scene(sc, case, camera):
    if case["camera"].get("motion_steps"):
        camera.cycles.motion_steps = case["camera"]["motion_steps"]
    if case.get("shutter") and case.get("shutter_position"):
        sc.render.motion_blur_position = case["shutter_position"]


def features(case):
    found = set()
    for o in case["objects"]:
        if "parent" in o and case.get("shutter"):
            found.add("parented motion")
        if ("motion" in o or "parent" in o) and case.get("shutter") and \
                ("hair" in o or o["kind"] == "curves"):
            found.add("moving strands")
        if o.get("motion_steps") and case.get("shutter"):
            found.add("motion steps")
    cam = case["camera"]
    if case.get("shutter") and "motion" in cam:
        if cam.get("motion_steps"):
            found.add("motion steps")
        if "rotation" in cam["motion"]:
            found.add("camera rotation")
    if case.get("shutter") and case.get("shutter_position", "CENTER") != "CENTER":
        found.add("shutter position")
    if any("Subsurface IOR" in n["inputs"] or "IOR" in n["inputs"]
           for _, n in _sss_nodes(case)):
        found.add("subsurface ior")
    strand_mats = {o["hair"]["material"] for o in case["objects"] if "hair" in o} | \
        {o.get("material") for o in case["objects"] if o["kind"] == "curves"}
    for name in strand_mats:
        g = case["materials"].get(name)
        if g and any(n["type"] == "ShaderNodeBsdfPrincipled" for n in g["nodes"].values()):
            found.add("principled on strands")
    if case.get("world_volume") and _issue32(case):
        found.add("issue 32 in fog")
    return found


def shrink_edits(case):
    """(label, smaller case): a parent, steps, the position, IOR, the camera's turn taken off."""
    def edited(fn):
        c = copy.deepcopy(case)
        fn(c)
        return c
    for i, o in enumerate(case["objects"]):
        if "parent" in o:
            yield f"object {i}: no parent", edited(lambda c, i=i: c["objects"][i].pop("parent"))
        if "motion_steps" in o:
            yield f"object {i}: motion steps 1", edited(
                lambda c, i=i: c["objects"][i].pop("motion_steps"))
    if "motion_steps" in case["camera"]:
        yield "camera: motion steps 1", edited(lambda c: c["camera"].pop("motion_steps"))
    if "rotation" in case["camera"].get("motion", {}) and \
            len(case["camera"]["motion"]) > 1:
        yield "camera: no rotation", edited(lambda c: c["camera"]["motion"].pop("rotation"))
    if case.get("shutter_position"):
        yield "shutter centred", edited(lambda c: c.pop("shutter_position"))
