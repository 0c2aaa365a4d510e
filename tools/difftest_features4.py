"""The fourth batch of features in the differential tester's "full" profile (docs/difftest.md,
2026-12-06 difftest4): light linking and shadow linking (Object > Shading > Light Linking:
a lamp's or an emissive mesh's Receiver or Blocker Collection of some of the case's meshes,
each Include or Exclude), which pt has had since issue 32 and bdpt / lvc / cis since linkbidir,
and a second lamp with Cast Shadow off beside linking (the bidirectional integrators used to
hand Cast Shadow off to pt).

draw() adds them to a drawn case from a stream of its own (the case's key + ":features4"),
after difftest_features3.draw, so every "ci" case and every full case without them draws as
before. Tags: FEATURES (features(case)). The case holds them as
case["linking"] = [{"emitter": ["light", i] | ["object", j], "kind": "receiver" | "blocker",
"objects": [j, ...], "states": ["INCLUDE" | "EXCLUDE", ...]}]."""

import copy
import random

FEATURES = {
    "light linking": "a lamp or an emissive mesh lighting only some meshes (a Receiver "
                     "Collection, Include or Exclude)",
    "shadow linking": "a lamp or an emissive mesh shadowed only by some meshes (a Blocker "
                      "Collection, Include or Exclude)",
    "linking without shadow": "light or shadow linking in a case with a lamp whose Cast Shadow "
                              "is off",
}

P_LIGHT_LINK, P_SHADOW_LINK, P_NO_SHADOW = 0.25, 0.2, 0.3
MESH_KINDS = ("cube", "ico", "sphere", "plane", "room")
EMISSIVE = ("emitter", "emit3")   # the generator's and difftest_features3's emissive materials


def _meshes(case):
    return [j for j, o in enumerate(case["objects"]) if o["kind"] in MESH_KINDS
            and not o.get("volume")]


def _emitters(case):
    out = [["light", i] for i in range(len(case["lights"]))]
    out += [["object", j] for j, o in enumerate(case["objects"])
            if o.get("material") in EMISSIVE and o["kind"] in MESH_KINDS]
    return out


def _link(r, case, kind):
    meshes = _meshes(case)
    emitters = _emitters(case)
    if not meshes or not emitters:
        return
    em = r.choice(emitters)
    pool = [j for j in meshes if em != ["object", j]]
    if not pool:
        return
    objs = sorted(r.sample(pool, r.randint(1, min(3, len(pool)))))
    mode = r.random()   # all Include, all Exclude, or mixed
    states = ["INCLUDE" if mode < 0.45 or (mode > 0.8 and r.random() < 0.5) else "EXCLUDE"
              for _ in objs]
    case.setdefault("linking", []).append({"emitter": em, "kind": kind, "objects": objs,
                                           "states": states})


def draw(key, case, avoid):
    """Add the features to `case` (full profile, after difftest_features3.draw)."""
    r = random.Random(key + ":features4")
    if r.random() < P_LIGHT_LINK and "light linking" not in avoid:
        _link(r, case, "receiver")
    if r.random() < P_SHADOW_LINK and "shadow linking" not in avoid:
        _link(r, case, "blocker")
    if case.get("linking") and len(case["lights"]) > 1 and r.random() < P_NO_SHADOW and \
            "no shadow" not in avoid and "linking without shadow" not in avoid:
        r.choice(case["lights"])["cast_shadow"] = False
    if case.get("linking") and "linking without shadow" in avoid:
        for lt in case["lights"]:   # (difftest_features2's Cast Shadow off too)
            lt.pop("cast_shadow", None)
    return case


def build_scene(sc, case, made):
    """The case's linking collections (after every object is made; `made`: the bpy objects
    in the order of case["objects"])."""
    import bpy
    for n, spec in enumerate(case.get("linking", [])):
        kind, i = spec["emitter"]
        if kind == "light":
            lt = case["lights"][i]
            ob = bpy.data.objects[f"{lt['type'].lower()}{i}"]
        else:
            ob = made[i]
        coll = bpy.data.collections.new(f"link{n}_{spec['kind']}")
        for j in spec["objects"]:
            coll.objects.link(made[j])
        for entry, state in zip(coll.collection_objects, spec["states"]):
            entry.light_linking.link_state = state
        setattr(ob.light_linking, f"{spec['kind']}_collection", coll)


def features(case):
    found = set()
    for spec in case.get("linking", []):
        found.add("light linking" if spec["kind"] == "receiver" else "shadow linking")
    if found and any(lt.get("cast_shadow") is False for lt in case["lights"]):
        found.add("linking without shadow")
    return found


def removed(case, what, i):
    """Keep case["linking"] pointing at the same lamps and meshes after the shrinker removed
    light or object `i` (a spec whose emitter went is dropped, a removed mesh leaves its
    collection)."""
    out = []
    for spec in case.get("linking", []):
        kind, e = spec["emitter"]
        if kind == what and e == i:
            continue
        if kind == what and e > i:
            spec["emitter"] = [kind, e - 1]
        if what == "object":
            keep = [(j - (j > i), s) for j, s in zip(spec["objects"], spec["states"]) if j != i]
            if not keep:
                continue
            spec["objects"], spec["states"] = [k[0] for k in keep], [k[1] for k in keep]
        out.append(spec)
    if out:
        case["linking"] = out
    else:
        case.pop("linking", None)


def shrink_edits(case):
    """(label, smaller case): a linking entry taken off, or one object of it."""
    for n, spec in enumerate(case.get("linking", [])):
        c = copy.deepcopy(case)
        c["linking"].pop(n)
        if not c["linking"]:
            c.pop("linking")
        yield f"linking {n}: none", c
        if len(spec["objects"]) > 1:
            for k in range(len(spec["objects"])):
                c = copy.deepcopy(case)
                s = c["linking"][n]
                s["objects"].pop(k)
                s["states"].pop(k)
                yield f"linking {n}: without object {spec['objects'][k]}", c
