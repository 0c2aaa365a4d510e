"""What a difftest case has that is known to differ from Cycles (tools/difftest.py): a tag per
known disagreement, read off the case's description. Three are issue 28's, being fixed by
others; the documented approximations (docs/materials_vs_cycles.md, docs/nodes.md); and those
this tester found (docs/difftest.md, D1...). The "ci" profile draws no case with any tag; the
shrinker keeps no edit that adds a tag the case did not have (so a case does not drift from
its own disagreement into a known one)."""

import math

import difftest_scene as ds

KNOWN = {
    # issue 28 (being fixed by others)
    "emitter inside glass": "issue 28: an emitter inside solid glass read 1/1.5^2 of Cycles",
    "voronoi/wave unlinked vector": "issue 28: Voronoi / Wave with an unlinked Vector",
    "two lights": "issue 28: two-light sampling noise",
    # documented approximations
    "rough transmission": "docs/materials_vs_cycles.md: rough transmission has no "
                          "multiple-scattering compensation",
    "fine bump": "docs/nodes.md: Bump differences the height over fixed offsets, Cycles over "
                 "ray differentials (heights finer than a pixel differ)",
    # found by this tester (docs/difftest.md)
    "colour into a strength": "D1: a colour or vector on an Emission Strength scales each "
                              "channel in Lantern, its grey value in Cycles",
    "no material": "D2: an object without a material is Lambert 0.8 in Lantern, Blender's "
                   "default Principled BSDF in Cycles",
    "diffuse roughness": "D3: Oren-Nayar (Diffuse BSDF Roughness, Principled Diffuse "
                         "Roughness) reads 0.3-1.7 % brighter than Cycles",
    "graph on metallic": "D4: a node graph on Metallic with the socket at 1 (or Metallic 0 "
                         "and Specular IOR Level 0) exports a conductor (diffuse), the graph "
                         "dropped",
    "smooth sphere": "D5: lit smooth-shaded silhouettes read darker in Lantern",
    "principled GGX": "D6: Principled with the GGX (not Multiscatter) distribution reads "
                      "about 1 % brighter at roughness 0.5",
    "tinted glass": "D7: Glass BSDF Color tints Cycles' reflection too, Lantern's "
                    "transmission only",
    "transparent in add": "D8: Add Shader with a Transparent BSDF: Lantern drops the other "
                          "shader (alpha 0)",
    "emission under a graph mix": "D9: Mix Shader with a node graph on Fac weights its "
                                  "emission by the socket's own value",
    "anisotropy": "D10: anisotropic tangent: Lantern the UV map's, Cycles' default radial "
                  "tangent (they agree on a UV sphere only)",
    "graph on roughness": "D11: a node graph on Roughness: the multiple-scattering and layer "
                          "tables are those of the socket's own value",
    "emission under coat": "D12: Principled emission is not dimmed by the coat in Lantern "
                           "(Cycles puts emission under the coat)",
    "colour above 1": "D13: a node graph on a BSDF colour is clamped to 1 in Lantern, not in "
                      "Cycles",
    "camera data": "D14: Camera Data (View Distance, View Z Depth) at secondary hits",
    "bump on a glossy lobe": "D15: Bump on a Principled / Glossy / Metallic / Glass normal "
                             "reads darker in Lantern under a small light",
    "coat over metal": "D16: a coat over a metal reads about 2 % darker in Lantern",
    "negative emission": "D17: a node graph gives emission below 0: Cycles emits negative "
                         "light, Lantern clamps it to 0",
    "negative mortar smooth": "D18: Brick texture with a negative Mortar Smooth",
    "texture coordinate normal": "D19: Texture Coordinate Normal seen on back faces (through "
                                 "alpha or on a plane) differs",
    "light intersects geometry": "D20: a spot light whose sphere (Radius) cuts a surface lights "
                                 "it in Cycles, not in Lantern",
    "specular tint on glass": "D21: Specular Tint on a Principled glass scales Cycles' "
                              "Fresnel F0 (reflection and transmission), not Lantern's",
    "emitter with alpha": "D22: an emitter with Alpha < 1 lights the scene with its full "
                          "emission in Lantern, alpha x emission in Cycles",
    "infinite graph value": "D23: Voronoi Minkowski with a linked Exponent (0 gives +inf): "
                            "Lantern clamps an infinite emission to 1e30, Cycles drops it",
    "environment pole in view": "D24: an Environment Texture seen near a pole: Cycles wraps "
                                "the image's rows there (EXTENSION_REPEAT), Lantern clamps",
    "visible sphere light": "D25: a point or spot light with a Radius seen by the camera: "
                            "the rim of its disk reads brighter in Lantern",
    "wavelength out of range": "D26: Wavelength outside 380-780 nm: Lantern clamps to the "
                               "ends' colours, Cycles gives black",
    "bump on translucent": "D27: Bump on a Translucent BSDF: Cycles' bumped-diffuse "
                           "convention, which Lantern applies to the Lambert only",
    "coat over glass": "D28: a coat over a Principled glass reads brighter in Lantern",
    "window coordinates": "D29: Texture Coordinate Window read at points the camera does "
                          "not see directly (through a bounce) differs",
    "power of zero": "D35: Math / Vector Math Power of a zero base and a negative exponent: "
                     "Cycles gives 0 at render time, Lantern +inf (fixed, parity4: the tag "
                     "stays until a long run has drawn such graphs again)",
    "translucent on low-poly smooth": "D43: a Translucent BSDF on a smooth-shaded low-poly "
                                      "mesh, lit through its interior, reads darker in "
                                      "Lantern (difftest_features2's low-poly meshes)",
    "moving low-poly smooth": "D49: a smooth-shaded low-poly mesh turning over the shutter "
                              "read darker in Lantern (pt and bdpt): its terminator offset was "
                              "dropped (fixed, fixd49: the tag stays until a long run has drawn "
                              "such meshes again)",
    "sharp specular on low-poly smooth": "D48: a sharp glass or specular layer (Glass BSDF, "
                                         "Principled Roughness 0) on a smooth-shaded low-poly "
                                         "mesh: Cycles corrects the bent normals at the rims",
}
# what keeps an emission graph's value at or above 0 (the generator puts one in front)
NON_NEGATIVE = {("ShaderNodeMath", "MAXIMUM"), ("ShaderNodeMix", True)}
COLOUR_INPUTS = {"ShaderNodeBsdfPrincipled": "Base Color", "ShaderNodeBsdfDiffuse": "Color",
                 "ShaderNodeBsdfGlossy": "Color", "ShaderNodeBsdfMetallic": "Base Color",
                 "ShaderNodeBsdfGlass": "Color", "ShaderNodeBsdfTranslucent": "Color"}

GLASSY = ("ShaderNodeBsdfGlass", "ShaderNodeBsdfPrincipled")
EMITTERS = ("ShaderNodeEmission", "ShaderNodeBsdfPrincipled")


def _out_type(node, ident):
    for i, _, t in ds.PROBE(node["type"], node.get("props", {}))[1]:
        if i == ident:
            return t
    return None


def _linked(graph, name, ident):
    return any(lk[2] == name and lk[3] == ident for lk in graph["links"])


def _source(graph, name, ident):
    for lk in graph["links"]:
        if lk[2] == name and lk[3] == ident:
            return lk[0], lk[1]
    return None, None


def _emits(node):
    ins = node.get("inputs", {})
    if node["type"] == "ShaderNodeEmission":
        return ins.get("Strength", 1.0) != 0.0
    return node["type"] == "ShaderNodeBsdfPrincipled" and ins.get("Emission Strength", 0.0) > 0


def _graph_tags(graph, found):
    nodes = graph["nodes"]
    for name, n in nodes.items():
        t, ins = n["type"], n.get("inputs", {})
        if t in ("ShaderNodeTexVoronoi", "ShaderNodeTexWave") and not _linked(graph, name,
                                                                               "Vector"):
            found.add("voronoi/wave unlinked vector")
        if t == "ShaderNodeBsdfGlass" and ins.get("Roughness", 0.0) > 0:
            found.add("rough transmission")
        if t == "ShaderNodeBsdfPrincipled" and ins.get("Transmission Weight", 0.0) > 0 and \
                (ins.get("Roughness", 0.5) > 0 or _linked(graph, name, "Roughness")):
            found.add("rough transmission")
        if t == "ShaderNodeBump":
            src, _ = _source(graph, name, "Height")
            if src is not None:
                h = nodes[src]
                hi = h.get("inputs", {})
                if h["type"] not in ("ShaderNodeTexNoise", "ShaderNodeTexGradient",
                                     "ShaderNodeTexWave") or hi.get("Scale", 5.0) > 2.0 or \
                        hi.get("Detail", 2.0) > 0 or hi.get("Distortion", 0.0) > 0:
                    found.add("fine bump")
        if t in ("ShaderNodeBsdfPrincipled", "ShaderNodeEmission"):
            sock = "Emission Strength" if t == "ShaderNodeBsdfPrincipled" else "Strength"
            src, out = _source(graph, name, sock)
            if src is not None and _out_type(nodes[src], out) != "VALUE":
                found.add("colour into a strength")
        if (t == "ShaderNodeBsdfDiffuse" and ins.get("Roughness", 0.0) > 0) or \
                (t == "ShaderNodeBsdfPrincipled" and ins.get("Diffuse Roughness", 0.0) > 0) or \
                (t in ("ShaderNodeBsdfDiffuse", "ShaderNodeBsdfPrincipled") and
                 _linked(graph, name, "Roughness" if t == "ShaderNodeBsdfDiffuse"
                         else "Diffuse Roughness")):
            found.add("diffuse roughness")
        if t == "ShaderNodeBsdfPrincipled" and _linked(graph, name, "Metallic"):
            found.add("graph on metallic")
        if t == "ShaderNodeBsdfPrincipled" and n.get("props", {}).get("distribution") == "GGX":
            found.add("principled GGX")
        if t == "ShaderNodeBsdfPrincipled" and (ins.get("Transmission Weight", 0.0) > 0 or
                                                _linked(graph, name, "Transmission Weight")) \
                and (ins.get("Coat Weight", 0.0) > 0 or _linked(graph, name, "Coat Weight")):
            found.add("coat over glass")
        if t == "ShaderNodeTexCoord" and any(lk[0] == name and lk[1] == "Window"
                                             for lk in graph["links"]):
            found.add("window coordinates")
        if t == "ShaderNodeBsdfTranslucent" and _linked(graph, name, "Normal"):
            found.add("bump on translucent")
        if t == "ShaderNodeWavelength" and (_linked(graph, name, "Wavelength") or not (
                380.0 <= ins.get("Wavelength", 500.0) < 780.0)):
            found.add("wavelength out of range")
        if t == "ShaderNodeTexVoronoi" and n.get("props", {}).get("distance") == "MINKOWSKI" \
                and (_linked(graph, name, "Exponent") or ins.get("Exponent", 0.5) < 0.05):
            found.add("infinite graph value")
        if t == "ShaderNodeBsdfPrincipled" and (ins.get("Emission Strength", 0.0) > 0 or
                                                _linked(graph, name, "Emission Strength")) \
                and (ins.get("Alpha", 1.0) < 1.0 or _linked(graph, name, "Alpha")):
            found.add("emitter with alpha")
        if t == "ShaderNodeBsdfPrincipled" and (ins.get("Transmission Weight", 0.0) > 0 or
                                                _linked(graph, name, "Transmission Weight")) \
                and (any(c != 1.0 for c in ins.get("Specular Tint", [1, 1, 1])[:3]) or
                     _linked(graph, name, "Specular Tint")):
            found.add("specular tint on glass")
        if t == "ShaderNodeBsdfGlass" and (any(c < 1.0 for c in ins.get("Color", [1, 1, 1])[:3])
                                           or _linked(graph, name, "Color")):
            found.add("tinted glass")
        if t == "ShaderNodeCameraData":
            found.add("camera data")
        if t == "ShaderNodeTexCoord" and any(lk[0] == name and lk[1] == "Normal"
                                             for lk in graph["links"]):
            found.add("texture coordinate normal")
        if t in COLOUR_INPUTS:
            src, _ = _source(graph, name, COLOUR_INPUTS[t])
            if src is not None and nodes[src]["type"] != "ShaderNodeRGB" and not (
                    nodes[src]["type"] == "ShaderNodeMix" and
                    nodes[src].get("props", {}).get("clamp_result")):
                found.add("colour above 1")
        if t == "ShaderNodeBsdfPrincipled" and (ins.get("Emission Strength", 0.0) > 0 or
                                                _linked(graph, name, "Emission Strength")) \
                and (ins.get("Coat Weight", 0.0) > 0 or _linked(graph, name, "Coat Weight")):
            found.add("emission under coat")
        if t not in ("ShaderNodeBsdfDiffuse", "ShaderNodeBsdfTranslucent") and \
                _linked(graph, name, "Normal"):
            found.add("bump on a glossy lobe")
        if t == "ShaderNodeBsdfPrincipled" and (ins.get("Metallic", 0.0) > 0 or
                                                _linked(graph, name, "Metallic")) and \
                (ins.get("Coat Weight", 0.0) > 0 or _linked(graph, name, "Coat Weight")):
            found.add("coat over metal")
        for sock in {"ShaderNodeBsdfPrincipled": ("Emission Color", "Emission Strength"),
                     "ShaderNodeEmission": ("Color", "Strength")}.get(t, ()):
            src, _ = _source(graph, name, sock)
            if src is None:
                continue
            sn = nodes[src]
            key = (sn["type"], sn.get("props", {}).get("operation") if sn["type"] ==
                   "ShaderNodeMath" else sn.get("props", {}).get("clamp_result"))
            if key not in NON_NEGATIVE and sn["type"] not in ("ShaderNodeRGB",
                                                              "ShaderNodeValue"):
                found.add("negative emission")
        if t in ("ShaderNodeMath", "ShaderNodeVectorMath") and \
                n.get("props", {}).get("operation") == "POWER":
            base, expo = ("Value", "Value_001") if t == "ShaderNodeMath" else \
                ("Vector", "Vector_001")
            b = ins.get(base, 0.5 if t == "ShaderNodeMath" else [0.0, 0.0, 0.0])
            e = ins.get(expo, 0.5 if t == "ShaderNodeMath" else [0.0, 0.0, 0.0])
            zero = not _linked(graph, name, base) and 0.0 in (b if isinstance(b, list) else [b])
            if zero and (_linked(graph, name, expo) or
                         min(e if isinstance(e, list) else [e]) < 0.0):
                found.add("power of zero")
        if t == "ShaderNodeTexBrick" and ins.get("Mortar Smooth", 0.1) < 0:
            found.add("negative mortar smooth")
        if t in ("ShaderNodeBsdfPrincipled", "ShaderNodeBsdfGlossy", "ShaderNodeBsdfMetallic",
                 "ShaderNodeBsdfGlass") and _linked(graph, name, "Roughness"):
            found.add("graph on roughness")
        if (t == "ShaderNodeBsdfPrincipled" and (ins.get("Anisotropic", 0.0) > 0 or
                                                 _linked(graph, name, "Anisotropic"))) or \
                (t in ("ShaderNodeBsdfGlossy", "ShaderNodeBsdfMetallic") and
                 ins.get("Anisotropy", 0.0) != 0):
            found.add("anisotropy")
        if t == "ShaderNodeAddShader" and any(
                nodes[lk[0]]["type"] == "ShaderNodeBsdfTransparent"
                for lk in graph["links"] if lk[2] == name):
            found.add("transparent in add")
        if t == "ShaderNodeMixShader" and _linked(graph, name, "Fac") and any(
                _emits(nodes[lk[0]]) for lk in graph["links"] if lk[2] == name):
            found.add("emission under a graph mix")


def _pole_in_view(case):
    """The camera sees the zenith or nadir of an environment image (within half a texel of
    the pole, plus a pixel): D24. Occlusion is not considered (a conservative tag)."""
    world = case.get("world") or {}
    envs = [n["image"] for n in world.get("nodes", {}).values()
            if n["type"] == "ShaderNodeTexEnvironment" and "image" in n]
    if not envs:
        return False
    c = case["camera"]
    rx, ry, rz = c["rotation"]
    # the camera looks along -Z rotated by Euler XYZ: R = Rz Ry Rx; only its z matters
    dz = -math.cos(rx) * math.cos(ry)
    off_pole = math.acos(min(1.0, abs(dz)))          # angle from the nearer pole
    band = max(0.5 * math.pi / e["h"] for e in envs)
    if "ortho_scale" in c:
        half = 0.0
    else:
        half = math.atan(18.0 * math.sqrt(2.0) / c.get("lens", 50.0))
    pixel = 2.0 * math.atan(18.0 / c.get("lens", 50.0)) / case["size"] if half else 0.0
    return off_pole < half + band + pixel


def tags(case):
    """The KNOWN tags of a case."""
    found = set()
    if _pole_in_view(case):
        found.add("environment pole in view")
    mats = case["materials"]
    for g in [o for o in case["objects"] if o.get("material") in mats and any(
            n["type"] in GLASSY for n in mats[o["material"]]["nodes"].values())]:
        graph = mats[g["material"]]
        if not any(n["type"] == "ShaderNodeBsdfGlass" or
                   n.get("inputs", {}).get("Transmission Weight", 0.0) > 0
                   for n in graph["nodes"].values()):
            continue
        half = [x if g["kind"] in ("sphere", "cube", "ico") else 0.0 for x in g["scale"]]

        def inside(p, g=g, half=half):
            return all(abs(a - c) < h for a, c, h in zip(p, g["location"], half))
        emitters = [o for o in case["objects"] if o is not g and o.get("material") in mats and
                    any(_emits(n) for n in mats[o["material"]]["nodes"].values())]
        if any(inside(o["location"]) for o in emitters) or \
                any(lt["type"] != "SUN" and inside(lt["location"]) for lt in case["lights"]):
            found.add("emitter inside glass")
    for graph in list(mats.values()) + ([case["world"]] if case.get("world") else []):
        _graph_tags(graph, found)
    if len(case["lights"]) >= 2:
        found.add("two lights")
    for lt in case["lights"]:
        if lt["type"] in ("POINT", "SPOT") and lt.get("radius", 0.0) > 0 and \
                lt["radius"] >= ds.clearance(lt, case["objects"]):
            found.add("light intersects geometry")
        # bpy.data.lights.new gives Radius 0 (a light without "radius" has no sphere)
        if lt["type"] in ("POINT", "SPOT") and lt.get("radius", 0.0) > 0 and \
                lt.get("visible_camera"):
            found.add("visible sphere light")
    for o in case["objects"]:
        if o.get("material") is None and not o.get("volume"):   # a volume: no Surface
            found.add("no material")
        if o["kind"] == "sphere":
            found.add("smooth sphere")
        if o.get("lowpoly", {}).get("smooth") and o.get("material") in mats and any(
                n["type"] == "ShaderNodeBsdfTranslucent"
                for n in mats[o["material"]]["nodes"].values()):
            found.add("translucent on low-poly smooth")
        if o.get("lowpoly", {}).get("smooth") and o.get("material") in mats and any(
                n["type"] in ("ShaderNodeBsdfGlass", "ShaderNodeBsdfGlossy",
                              "ShaderNodeBsdfPrincipled", "ShaderNodeBsdfMetallic") and
                n.get("inputs", {}).get("Roughness", 0.5 if n["type"] == "ShaderNodeBsdfPrincipled"
                                        else 0.0) < 0.03
                for n in mats[o["material"]]["nodes"].values()):
            found.add("sharp specular on low-poly smooth")
        if o.get("lowpoly", {}).get("smooth") and case.get("shutter") and (
                "motion" in o or o.get("deform")):
            found.add("moving low-poly smooth")
    return found
