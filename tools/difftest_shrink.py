"""Shrinking a failing difftest case (tools/difftest.py): greedy, one edit at a time, coarse
to fine (a light, an object, the world, a material, a shader mix, a link, an input value, a
property), keeping each edit while the case still fails, until no edit keeps it failing or
the budget of evaluations is spent. Edits work on the description (difftest_scene), so the
result rebuilds exactly; an input or property dropped from the description takes Blender's
default."""

import copy
import time

import difftest_features
import difftest_features4

# optional light keys: dropped, the light takes Blender's default (bpy.data.lights.new)
LIGHT_OPTIONAL = ("color", "radius", "soft_falloff", "spot_size", "spot_blend", "size_y",
                  "shape", "size", "angle", "visible_camera")


PLAIN = {"nodes": {"n0": {"type": "ShaderNodeBsdfDiffuse", "props": {}, "inputs": {}}},
         "links": [], "out": ["n0", "BSDF"]}


def _plain(case, name):
    return name is not None and case["materials"].get(name) == PLAIN


def prune(graph):
    """Drop the nodes (and their links) that no longer feed the graph's output."""
    keep, todo = set(), [graph["out"][0]]
    while todo:
        n = todo.pop()
        if n in keep:
            continue
        keep.add(n)
        todo += [lk[0] for lk in graph["links"] if lk[2] == n]
    graph["nodes"] = {k: v for k, v in graph["nodes"].items() if k in keep}
    graph["links"] = [lk for lk in graph["links"] if lk[0] in keep and lk[2] in keep]


def _graph_edits(graph, where):
    """(label, edit(graph)) for one node graph, coarse first."""
    out_node = graph["nodes"][graph["out"][0]]
    # a Mix / Add Shader on the output: keep one of its shaders
    if out_node["type"] in ("ShaderNodeMixShader", "ShaderNodeAddShader"):
        for lk in [lk for lk in graph["links"] if lk[2] == graph["out"][0] and lk[3] != "Fac"]:
            def bypass(g, lk=lk):
                g["out"] = [lk[0], lk[1]]
                prune(g)
            yield f"{where}: keep only {graph['nodes'][lk[0]]['type']} of the mix", bypass
    for i, lk in enumerate(graph["links"]):
        def unlink(g, lk=lk):
            g["links"] = [x for x in g["links"] if x != lk]
            prune(g)
        yield f"{where}: unlink {lk[0]}.{lk[1]} -> {lk[2]}.{lk[3]}", unlink
    for name, node in graph["nodes"].items():
        for key in ("ramp", "curve"):
            if key in node:
                def drop(g, name=name, key=key):
                    g["nodes"][name].pop(key, None)
                yield f"{where}: default {key} on {name}", drop
        for ident in list(node.get("inputs", {})):
            def reset(g, name=name, ident=ident):
                g["nodes"][name]["inputs"].pop(ident, None)
            yield f"{where}: default {name}.{ident}", reset
        for prop in list(node.get("props", {})):
            def reset_prop(g, name=name, prop=prop):
                g["nodes"][name]["props"].pop(prop, None)
            yield f"{where}: default {name}.{prop}", reset_prop


def candidates(case):
    """(label, smaller case) edits of a case, coarse to fine."""
    def edited(fn):
        c = copy.deepcopy(case)
        fn(c)
        return c

    for i, lt in enumerate(case["lights"]):
        yield f"remove light {i} ({lt['type']})", edited(
            lambda c, i=i: (c["lights"].pop(i), difftest_features4.removed(c, "light", i)))
    for i, o in enumerate(case["objects"]):
        def rm(c, i=i):
            c["objects"].pop(i)
            difftest_features4.removed(c, "object", i)   # linking's indices
            used = {x.get("material") for x in c["objects"]} | {
                x["hair"]["material"] for x in c["objects"] if "hair" in x}
            c["materials"] = {k: v for k, v in c["materials"].items() if k in used}
            if "volumes" in c:
                c["volumes"] = {k: v for k, v in c["volumes"].items()
                                if any(x.get("volume") == k for x in c["objects"])}
        yield f"remove object {i} ({o['kind']})", edited(rm)
    if case.get("world") is not None:
        yield "no world (black)", edited(lambda c: c.update(world=None))
    for i, o in enumerate(case["objects"]):
        if not _plain(case, o.get("material")):
            # an explicit Diffuse BSDF, not "no material": Blender's default surface is a
            # Principled BSDF, which is its own case (difftest_scene.tags "no material")
            def plain(c, i=i):
                name = f"plain{i}"
                c["objects"][i]["material"] = name
                c["materials"][name] = copy.deepcopy(PLAIN)
                used = {x.get("material") for x in c["objects"]} | {
                x["hair"]["material"] for x in c["objects"] if "hair" in x}
                c["materials"] = {k: v for k, v in c["materials"].items() if k in used}
            yield f"object {i}: plain diffuse material", edited(plain)
    yield from difftest_features.shrink_edits(case)
    if case["bounces"] > 0:
        yield f"bounces {case['bounces']} -> {case['bounces'] // 2}", \
            edited(lambda c: c.update(bounces=c["bounces"] // 2))
    graphs = [(f"material {k}", ("materials", k)) for k in case["materials"]]
    if case.get("world") is not None:
        graphs.append(("world", ("world",)))
    graphs += [(f"volume {k}", ("volumes", k)) for k in case.get("volumes", {})]
    if case.get("world_volume"):
        graphs.append(("world volume", ("world_volume",)))
    for where, path in graphs:
        graph = case[path[0]] if len(path) == 1 else case[path[0]][path[1]]
        for label, fn in _graph_edits(graph, where):
            def apply(c, path=path, fn=fn):
                fn(c[path[0]] if len(path) == 1 else c[path[0]][path[1]])
            yield label, edited(apply)
    for i, lt in enumerate(case["lights"]):
        for key in LIGHT_OPTIONAL:
            if key in lt:
                def drop(c, i=i, key=key):
                    c["lights"][i].pop(key, None)
                    if key == "shape":
                        c["lights"][i].pop("size_y", None)
                yield f"light {i}: default {key}", edited(drop)
    for i, o in enumerate(case["objects"]):
        if any(o.get("rotation", [0, 0, 0])):
            yield f"object {i}: no rotation", edited(
                lambda c, i=i: c["objects"][i].update(rotation=[0.0, 0.0, 0.0]))
    if "ortho_scale" in case["camera"]:
        yield "perspective camera", edited(lambda c: c["camera"].pop("ortho_scale"))


def size(case):
    """How big a case is (what shrinking lowers)."""
    n = len(case["lights"]) + len(case["objects"]) + (case.get("world") is not None)
    for g in list(case["materials"].values()) + list(case.get("volumes", {}).values()) + \
            [case[k] for k in ("world", "world_volume") if case.get(k)]:
        n += len(g["nodes"]) + len(g["links"])
        n += sum(len(x.get("inputs", {})) + len(x.get("props", {})) for x in g["nodes"].values())
    n += sum(len(lt) for lt in case["lights"])
    return n


def shrink(case, fails, max_evals=150, say=print, deadline=None):
    """The smallest case reached by edits that keep fails(case) True; and the edits kept.
    deadline: a time.time() after which no further edit is tried."""
    evals, kept, i, progress = 0, [], 0, False
    while evals < max_evals and (deadline is None or time.time() < deadline):
        cands = list(candidates(case))
        if i >= len(cands):        # the end of a pass: another while the last one shrank
            if not progress:
                break
            i, progress = 0, False
            continue
        label, smaller = cands[i]
        evals += 1
        if fails(smaller):         # keep it; the same index is the next edit of the new case
            case = smaller
            kept.append(label)
            progress = True
            say(f"    shrink [{evals}]: {label} (size {size(case)})")
        else:
            i += 1
    say(f"    shrink: {len(kept)} edits kept in {evals} evaluations")
    return case, kept
