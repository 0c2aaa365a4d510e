"""The material and world graphs of the differential tester's random scenes
(tools/difftest_scene.py): what the add-on exports (the leaves, inner nodes, their properties
and ranges, the shaders), the socket probe (PROBE, read from a scratch bpy material) and
_Graph, which draws a node graph of a case (the format: difftest_scene's docstring)."""

import math


NODE_INPUT_DEPTH = 3        # links below a shader input
MAX_GRAPH_NODES = 8         # value nodes per material

# ---- what the add-on exports (addon/export/node_handlers.py, node_textures.py, ...) ----
# leaves: nodes without inputs; each listed output is one the add-on computes
LEAVES = {
    "ShaderNodeTexCoord": ["Generated", "Normal", "UV", "Object", "Camera", "Window",
                           "Reflection"],
    "ShaderNodeNewGeometry": ["Position", "Normal", "True Normal", "Incoming", "Backfacing"],
    "ShaderNodeUVMap": ["UV"],
    "ShaderNodeObjectInfo": ["Location", "Color", "Alpha", "Object Index"],
    "ShaderNodeCameraData": ["View Vector", "View Z Depth", "View Distance"],
    "ShaderNodeRGB": ["Color"],
    "ShaderNodeValue": ["Value"],
}
FLOAT_LEAVES = {("ShaderNodeValue", "Value"), ("ShaderNodeObjectInfo", "Alpha"),
                ("ShaderNodeObjectInfo", "Object Index"), ("ShaderNodeCameraData", "View Z Depth"),
                ("ShaderNodeCameraData", "View Distance"), ("ShaderNodeNewGeometry", "Backfacing")}
# view-dependent sources: not under an emission graph (docs/nodes.md: an emission graph is
# evaluated along the emitter's normal at next-event samples, by design)
VIEW_DEPENDENT = {("ShaderNodeTexCoord", "Reflection"), ("ShaderNodeTexCoord", "Camera"),
                  ("ShaderNodeNewGeometry", "Incoming"), ("ShaderNodeNewGeometry", "Normal"),
                  ("ShaderNodeNewGeometry", "Backfacing"), ("ShaderNodeTexCoord", "Normal"),
                  ("ShaderNodeCameraData", "View Vector"),
                  ("ShaderNodeCameraData", "View Z Depth"),
                  ("ShaderNodeCameraData", "View Distance")}
VIEW_DEPENDENT_NODES = {"ShaderNodeFresnel", "ShaderNodeLayerWeight"}
# inner nodes and their weights
INNER = {
    "ShaderNodeMath": 4, "ShaderNodeVectorMath": 2, "ShaderNodeMix": 3, "ShaderNodeMapRange": 2,
    "ShaderNodeClamp": 1, "ShaderNodeInvert": 1, "ShaderNodeGamma": 1,
    "ShaderNodeBrightContrast": 1, "ShaderNodeHueSaturation": 1, "ShaderNodeSeparateColor": 1,
    "ShaderNodeSeparateXYZ": 1, "ShaderNodeCombineColor": 1, "ShaderNodeCombineXYZ": 1,
    "ShaderNodeRGBToBW": 1, "ShaderNodeValToRGB": 2, "ShaderNodeRGBCurve": 1,
    "ShaderNodeFloatCurve": 1, "ShaderNodeMapping": 2, "ShaderNodeFresnel": 1,
    "ShaderNodeLayerWeight": 1, "ShaderNodeBlackbody": 1, "ShaderNodeWavelength": 1,
    "ShaderNodeNormal": 1,
    "ShaderNodeTexChecker": 2, "ShaderNodeTexGradient": 2, "ShaderNodeTexNoise": 2,
    "ShaderNodeTexVoronoi": 2, "ShaderNodeTexWave": 2, "ShaderNodeTexMagic": 1,
    "ShaderNodeTexBrick": 1,
}
TEXTURES_WITH_VECTOR = {"ShaderNodeTexChecker", "ShaderNodeTexGradient", "ShaderNodeTexNoise",
                        "ShaderNodeTexVoronoi", "ShaderNodeTexWave", "ShaderNodeTexMagic",
                        "ShaderNodeTexBrick"}
# enum values the add-on renders (others warn: docs/nodes.md), per node and property
PROPS = {
    "ShaderNodeTexVoronoi": {"voronoi_dimensions": ["2D", "3D"],
                             "feature": ["F1", "F2", "SMOOTH_F1"],
                             "distance": ["EUCLIDEAN", "MANHATTAN", "CHEBYCHEV", "MINKOWSKI"],
                             "normalize": [False]},
    "ShaderNodeMix": {"data_type": ["FLOAT", "VECTOR", "RGBA"]},
    "ShaderNodeMapping": {"vector_type": ["POINT", "TEXTURE", "VECTOR", "NORMAL"]},
}
# inputs held at a value (others warn: docs/nodes.md, Voronoi's Detail above 0)
FIXED_INPUTS = {"ShaderNodeTexVoronoi": {"Detail": 0.0}}
SKIP_PROPS = {"from_instancer", "object", "uv_map", "attribute_name", "attribute_type",
              "image", "interpolation", "projection", "extension", "image_user", "color_mapping",
              "texture_mapping", "mapping"}
# ranges of inputs where the generic rule (a factor in [0, 1], else around the default) would
# make degenerate or wildly varying graphs
RANGES = {
    "Scale": (0.3, 6.0), "Detail": (0.0, 3.0), "Distortion": (0.0, 2.0),
    "Detail Scale": (0.0, 3.0), "Lacunarity": (1.5, 3.0), "Exponent": (0.5, 3.0),
    "Temperature": (1000.0, 12000.0), "Wavelength": (380.0, 780.0), "IOR": (1.05, 2.5),
    "Gamma": (0.3, 3.0), "Steps": (2.0, 8.0), "Mortar Size": (0.0, 0.1),
    "Brick Width": (0.2, 1.0), "Row Height": (0.1, 0.5), "Phase Offset": (0.0, 6.3),
    "Mortar Smooth": (-0.2, 1.0),
}

SHADERS = {  # leaf shaders and their weights ("full"; the CI profile uses the same)
    "ShaderNodeBsdfPrincipled": 6, "ShaderNodeBsdfDiffuse": 2, "ShaderNodeBsdfGlossy": 1,
    "ShaderNodeBsdfMetallic": 1, "ShaderNodeBsdfGlass": 1, "ShaderNodeBsdfTranslucent": 1,
    "ShaderNodeEmission": 1,
}
# inputs a node graph may drive, per shader (material.py: base colour, roughness, metallic,
# alpha, emission, bump on Normal); the others take constants only
GRAPH_INPUTS = {
    "ShaderNodeBsdfPrincipled": ["Base Color", "Roughness", "Metallic", "Alpha",
                                 "Emission Color", "Emission Strength", "Normal"],
    "ShaderNodeBsdfDiffuse": ["Color", "Normal"],
    "ShaderNodeBsdfGlossy": ["Color", "Roughness", "Normal"],
    "ShaderNodeBsdfMetallic": ["Base Color", "Roughness", "Normal"],
    "ShaderNodeBsdfGlass": ["Color", "Normal"],
    "ShaderNodeBsdfTranslucent": ["Color", "Normal"],
    "ShaderNodeEmission": ["Color", "Strength"],
}


def _rgb(r, lo=0.0, hi=1.0):
    return [round(r.uniform(lo, hi), 4) for _ in range(3)] + [1.0]


def _u(r, lo, hi, nd=4):
    return round(r.uniform(lo, hi), nd)


class _Probe:
    """Sockets of a node type with given properties, read from a scratch material (cached)."""

    def __init__(self):
        self._cache = {}

    def __call__(self, typ, props):
        import bpy
        key = (typ, tuple(sorted(props.items())))
        if key not in self._cache:
            mat = bpy.data.materials.get("_difftest_probe") or \
                bpy.data.materials.new("_difftest_probe")
            nt = mat.node_tree
            node = nt.nodes.new(typ)
            for k, v in props.items():
                setattr(node, k, v)
            ins = [(s.identifier, s.name, s.type, s.bl_idname, bool(s.hide_value))
                   for s in node.inputs if s.enabled]
            outs = [(s.identifier, s.name, s.type) for s in node.outputs if s.enabled]
            enums = {}
            base = {p.identifier for p in bpy.types.ShaderNode.bl_rna.properties}
            for p in node.bl_rna.properties:
                if p.identifier in base or p.is_readonly or p.identifier in SKIP_PROPS:
                    continue
                if p.type == "ENUM":
                    enums[p.identifier] = [i.identifier for i in p.enum_items]
                elif p.type == "BOOLEAN":
                    enums[p.identifier] = [False, True]
            nt.nodes.remove(node)
            self._cache[key] = (ins, outs, enums)
        return self._cache[key]


PROBE = _Probe()


class _Graph:
    """Draws one node graph (a material's or the world's) into a description."""

    def __init__(self, r, avoid, opaque=False):
        self.r, self.avoid, self.opaque = r, avoid, opaque
        self.nodes, self.links = {}, []

    def add(self, typ, props=None, inputs=None, **extra):
        name = f"n{len(self.nodes)}"
        self.nodes[name] = dict({"type": typ, "props": props or {}, "inputs": inputs or {}},
                                **extra)
        return name

    def link(self, a, out, b, inp):
        self.links.append([a, out, b, inp])

    def value_nodes(self):
        return sum(1 for n in self.nodes.values() if n["type"] in INNER or n["type"] in LEAVES)

    # ---- values ----

    def random_value(self, name, stype, bl_idname):
        r = self.r
        if name == "Mortar Smooth" and "negative mortar smooth" in self.avoid:
            return _u(r, 0.0, 1.0)   # D18
        if stype == "RGBA":
            return _rgb(r)
        if stype == "VECTOR":
            return [_u(r, -1.5, 1.5) for _ in range(3)]
        if stype == "BOOLEAN":
            return r.random() < 0.5
        if stype == "INT":
            return r.randint(0, 4)
        if name in RANGES:
            return _u(r, *RANGES[name])
        if "Factor" in bl_idname:
            return _u(r, 0.0, 1.0)
        if "Angle" in bl_idname:
            return _u(r, -math.pi, math.pi)
        return _u(r, -2.0, 3.0)

    def fill_inputs(self, name, depth, emission):
        """Random values or sub-graphs on the node's enabled inputs."""
        node = self.nodes[name]
        ins, _, _ = PROBE(node["type"], node["props"])
        fixed = FIXED_INPUTS.get(node["type"], {})
        for ident, sname, stype, bl_idname, hidden in ins:
            if stype in ("SHADER", "ROTATION"):
                continue
            if ident in fixed:
                node["inputs"][ident] = fixed[ident]
                continue
            # issue 28: Voronoi / Wave with an unlinked Vector disagree (being fixed): avoided,
            # their Vector is always linked
            must = hidden and "voronoi/wave unlinked vector" in self.avoid and \
                node["type"] in ("ShaderNodeTexVoronoi", "ShaderNodeTexWave")
            p_link = 0.55 if depth < NODE_INPUT_DEPTH else 0.0
            if must or (self.value_nodes() < MAX_GRAPH_NODES and self.r.random() < p_link *
                        (0.6 if hidden else 0.35)):
                src = self.source(depth + 1, emission, vector=stype == "VECTOR")
                if src is not None:
                    self.link(src[0], src[1], name, ident)
                    continue
            if not hidden and self.r.random() < 0.6:
                node["inputs"][ident] = self.random_value(sname, stype, bl_idname)

    def random_props(self, typ):
        _, _, enums = PROBE(typ, {})
        props = {}
        allowed = PROPS.get(typ, {})
        for k, choices in enums.items():
            choices = allowed.get(k, choices)
            if k == "data_type" and typ == "ShaderNodeMix":
                choices = [c for c in choices if c != "ROTATION"]
            props[k] = self.r.choice(choices)
        if typ == "ShaderNodeTexBrick":
            props = {"offset": _u(self.r, 0, 1), "squash": _u(self.r, 0.5, 2)}
        return props

    def source(self, depth, emission, vector=False, scalar=False, value=False):
        """(node, output identifier) of a new value sub-graph, or None. `scalar`: for a
        shader's float input, which reads an RGB node only with a warning (the add-on's
        constant path takes Value nodes; material.py _constant_float). `value`: the output
        linked is a float one."""
        r = self.r
        leaf = depth >= NODE_INPUT_DEPTH or self.value_nodes() >= MAX_GRAPH_NODES or \
            r.random() < (0.5 if vector else 0.3)
        if leaf:
            choices = [(t, o) for t, outs in LEAVES.items() for o in outs
                       if not (emission and (t, o) in VIEW_DEPENDENT) and not (
                           t == "ShaderNodeCameraData" and "camera data" in self.avoid) and
                       not ((t, o) == ("ShaderNodeTexCoord", "Normal") and
                            "texture coordinate normal" in self.avoid)]
            if not vector:
                choices += [("ShaderNodeRGB", "Color")] * 2
            if scalar:
                choices = [x for x in choices if x[0] != "ShaderNodeRGB"]
            if value:
                choices = [x for x in choices if x in FLOAT_LEAVES]
            typ, out = r.choice(choices)
            if typ == "ShaderNodeRGB":
                return self.add(typ, color=_rgb(r)), "Color"
            if typ == "ShaderNodeValue":
                return self.add(typ, value=_u(r, 0.0, 1.0)), "Value"
            _, outs, _ = PROBE(typ, {})
            ident = next(i for i, n, _ in outs if n == out)
            return self.add(typ), ident
        types = [t for t in INNER if not (emission and t in VIEW_DEPENDENT_NODES)]
        typ = r.choices(types, weights=[INNER[t] for t in types])[0]
        props = self.random_props(typ)
        name = self.add(typ, props)
        node = self.nodes[name]
        if typ == "ShaderNodeValToRGB":
            n = r.randint(2, 4)
            node["ramp"] = {"interpolation": r.choice(["LINEAR", "CONSTANT", "EASE"]),
                            "stops": sorted([[_u(r, 0, 1), _rgb(r)] for _ in range(n)])}
        elif typ in ("ShaderNodeRGBCurve", "ShaderNodeFloatCurve"):
            node["curve"] = [[0.0, _u(r, 0, 0.3)], [_u(r, 0.3, 0.7), _u(r, 0.2, 0.9)],
                             [1.0, _u(r, 0.7, 1.0)]]
        self.fill_inputs(name, depth, emission)
        _, outs, _ = PROBE(typ, props)
        outs = [o for o in outs if o[2] not in ("SHADER", "ROTATION")]
        if vector:
            outs = [o for o in outs if o[2] == "VECTOR"] or outs
        if value:
            outs = [o for o in outs if o[2] == "VALUE"]
            if not outs:   # no float output: a Math node in between
                m = self.add("ShaderNodeMath", {"operation": "MULTIPLY"}, {"Value_001": 1.0})
                _, o2, _ = PROBE(typ, props)
                self.link(name, r.choice([o for o in o2 if o[2] not in ("SHADER", "ROTATION")])[0],
                          m, "Value")
                return m, "Value"
        return name, r.choice(outs)[0]

    # ---- shaders ----

    def shader(self, typ, allow_graph=True, emitter=False):
        """A leaf shader node with random inputs; graphs on the inputs the add-on compiles."""
        r = self.r
        ins = {}
        av = self.avoid
        distributions = ["GGX", "MULTI_GGX", "MULTI_GGX"]
        if typ == "ShaderNodeBsdfPrincipled":
            metal = r.random()
            ins = {"Base Color": _rgb(r, 0.05, 0.95),
                   "Metallic": 1.0 if metal < 0.2 else (_u(r, 0, 1) if metal < 0.35 else 0.0),
                   "Roughness": _u(r, 0.02, 1.0), "IOR": _u(r, 1.1, 2.4)}
            if r.random() < 0.3:
                ins["Specular IOR Level"] = _u(r, 0, 1)
            if r.random() < 0.2:
                ins["Specular Tint"] = _rgb(r, 0.3, 1.0)
            if r.random() < 0.2 and "diffuse roughness" not in av:
                ins["Diffuse Roughness"] = _u(r, 0, 1)
            if r.random() < 0.15 and not self.opaque:
                ins["Alpha"] = _u(r, 0.2, 1.0)
            if r.random() < 0.15:
                ins["Coat Weight"] = _u(r, 0.2, 1.0)
                ins["Coat Roughness"] = _u(r, 0.0, 0.6)
                ins["Coat IOR"] = _u(r, 1.3, 2.0)
                ins["Coat Tint"] = _rgb(r, 0.4, 1.0)
            if r.random() < 0.1 and "anisotropy" not in av:
                ins["Anisotropic"] = _u(r, 0.1, 1.0)
                ins["Anisotropic Rotation"] = _u(r, 0, 1)
            if r.random() < 0.15 and not self.opaque:
                # rough transmission has no multiple-scattering compensation yet
                # (docs/materials_vs_cycles.md, an approximation): smooth glass here
                ins["Transmission Weight"] = _u(r, 0.3, 1.0)
                ins["Roughness"] = 0.0
            if emitter or r.random() < 0.1:
                ins["Emission Color"] = _rgb(r, 0.3, 1.0)
                ins["Emission Strength"] = _u(r, 1.0, 15.0) if emitter else _u(r, 0.1, 2.0)
            props = {"distribution": r.choice(
                distributions[1:] if "principled GGX" in av else distributions)}
        elif typ == "ShaderNodeBsdfDiffuse":
            ins = {"Color": _rgb(r, 0.05, 0.95)}
            if r.random() < 0.3 and "diffuse roughness" not in av:
                ins["Roughness"] = _u(r, 0, 1)
            props = {}
        elif typ == "ShaderNodeBsdfGlossy":
            ins = {"Color": _rgb(r, 0.3, 1.0), "Roughness": _u(r, 0.02, 1.0)}
            if r.random() < 0.2 and "anisotropy" not in av:
                ins["Anisotropy"] = _u(r, -0.9, 0.9)
            props = {"distribution": r.choice(distributions[:2])}
        elif typ == "ShaderNodeBsdfMetallic":
            ins = {"Base Color": _rgb(r, 0.3, 1.0), "Edge Tint": _rgb(r, 0.3, 1.0),
                   "Roughness": _u(r, 0.02, 1.0)}
            props = {"distribution": r.choice(distributions[:2]), "fresnel_type": "F82"}
        elif typ == "ShaderNodeBsdfGlass":
            # smooth: rough glass is a documented approximation (materials_vs_cycles.md)
            ins = {"Color": [1.0, 1.0, 1.0, 1.0] if "tinted glass" in av else _rgb(r, 0.7, 1.0),
                   "IOR": _u(r, 1.1, 2.0), "Roughness": 0.0}
            props = {}
        elif typ == "ShaderNodeBsdfTranslucent":
            ins = {"Color": _rgb(r, 0.1, 0.9)}
            props = {}
        elif typ == "ShaderNodeEmission":
            ins = {"Color": _rgb(r, 0.3, 1.0),
                   "Strength": _u(r, 1.0, 15.0) if emitter else _u(r, 0.2, 3.0)}
            props = {}
        else:   # Transparent
            ins, props = {}, {}
        if "emission under coat" in self.avoid and "Emission Strength" in ins:
            ins.pop("Coat Weight", None)   # D12 (docs/difftest.md)
        if "coat over metal" in self.avoid and ins.get("Metallic", 0.0) > 0:
            ins.pop("Coat Weight", None)   # D16
        name = self.add(typ, props, ins)
        if not allow_graph:
            return name
        for sock in GRAPH_INPUTS.get(typ, []):
            if r.random() >= 0.3:
                continue
            if sock == "Roughness" and ("Transmission Weight" in ins or
                                        "graph on roughness" in self.avoid):
                continue
            if sock == "Metallic" and "graph on metallic" in self.avoid:
                continue
            if sock == "Alpha" and self.opaque:
                continue
            if sock.startswith("Emission") and "Coat Weight" in ins and \
                    "emission under coat" in self.avoid:
                continue
            if sock == "Normal":
                if "bump on a glossy lobe" not in self.avoid or typ in (
                        "ShaderNodeBsdfDiffuse", "ShaderNodeBsdfTranslucent"):
                    self.bump(name)
                continue
            if typ == "ShaderNodeBsdfGlass" and sock == "Color" and "tinted glass" in self.avoid:
                continue
            emission = sock.startswith("Emission") or typ == "ShaderNodeEmission"
            strength = sock in ("Emission Strength", "Strength")
            src = self.source(1, emission, vector=False,
                              scalar=sock in ("Roughness", "Metallic", "Alpha") or strength,
                              value=strength and "colour into a strength" in self.avoid)
            if src is not None and emission and "negative emission" in self.avoid:
                # D17: Cycles emits a graph's negative values, Lantern clamps them: keep >= 0
                if sock in ("Emission Strength", "Strength"):
                    m = self.add("ShaderNodeMath", {"operation": "MAXIMUM"}, {"Value_001": 0.0})
                    self.link(src[0], src[1], m, "Value")
                    src = (m, "Value")
                else:
                    m = self.add("ShaderNodeMix", {"data_type": "RGBA", "clamp_result": True},
                                 {"Factor_Float": 0.0})
                    self.link(src[0], src[1], m, "A_Color")
                    src = (m, "Result_Color")
            if src is not None and sock in ("Base Color", "Color") and \
                    typ != "ShaderNodeEmission" and "colour above 1" in self.avoid:
                # D13: a graph's colour above 1 is clamped in Lantern only: clamp it here
                m = self.add("ShaderNodeMix", {"data_type": "RGBA", "clamp_result": True},
                             {"Factor_Float": 0.0})
                self.link(src[0], src[1], m, "A_Color")
                src = (m, "Result_Color")
            if src is not None:
                self.link(src[0], src[1], name, sock)
        return name

    def bump(self, shader):
        """A Bump node on the shader's Normal, its height a smooth texture: Lantern differences
        the height over fixed offsets, Cycles over ray differentials (docs/nodes.md), which
        agree where the height is smooth over a pixel's footprint."""
        r = self.r
        tex = r.choice(["ShaderNodeTexNoise", "ShaderNodeTexGradient", "ShaderNodeTexWave"])
        props = self.random_props(tex)
        if tex == "ShaderNodeTexNoise":
            props["noise_dimensions"] = "3D"
        ins = {"Scale": _u(r, 0.3, 1.5)} if tex != "ShaderNodeTexGradient" else {}
        if tex != "ShaderNodeTexGradient":
            ins["Detail"] = 0.0
            ins["Distortion"] = 0.0
        t = self.add(tex, props, ins)
        coord = self.add("ShaderNodeTexCoord")
        self.link(coord, r.choice(["Generated", "Object"]), t, "Vector")
        b = self.add("ShaderNodeBump", {"invert": r.random() < 0.3},
                     {"Strength": _u(r, 0.1, 1.0), "Distance": _u(r, 0.02, 0.5)})
        self.link(t, "Fac", b, "Height")
        self.link(b, "Normal", shader, "Normal")

    def surface(self, emitter=False, glass=False):
        """The node on the Material Output's Surface: a leaf shader, or a Mix / Add Shader of
        two (one of them possibly Transparent)."""
        r = self.r
        if glass:
            typ = r.choice(["ShaderNodeBsdfGlass", "ShaderNodeBsdfPrincipled"])
            if typ == "ShaderNodeBsdfGlass":
                return self.shader(typ), "BSDF"
            name = self.shader(typ, allow_graph=False)
            self.nodes[name]["inputs"].update({"Transmission Weight": 1.0, "Roughness": 0.0,
                                               "Metallic": 0.0, "Alpha": 1.0})
            for k in ("Emission Strength", "Coat Weight", "Anisotropic"):
                self.nodes[name]["inputs"].pop(k, None)
            return name, "BSDF"
        if emitter:
            typ = r.choice(["ShaderNodeEmission", "ShaderNodeEmission",
                            "ShaderNodeBsdfPrincipled"])
            return self.shader(typ, emitter=True), "Emission" if typ == "ShaderNodeEmission" \
                else "BSDF"
        u = r.random()
        if u < 0.75:
            weights = [0 if (self.opaque and t == "ShaderNodeBsdfGlass") else w
                       for t, w in SHADERS.items()]
            typ = r.choices(list(SHADERS), weights=weights)[0]
            return self.shader(typ), "Emission" if typ == "ShaderNodeEmission" else "BSDF"
        kinds = list(SHADERS) + ([] if self.opaque else ["ShaderNodeBsdfTransparent"])
        weights = list(SHADERS.values()) + ([] if self.opaque else [1])
        if self.opaque:   # walls and floors: no glass (a glass room was all caustics)
            weights[kinds.index("ShaderNodeBsdfGlass")] = 0
        a, b = r.choices(kinds, weights=weights, k=2)
        if a == b == "ShaderNodeBsdfTransparent":
            b = "ShaderNodeBsdfDiffuse"
        mix = u < 0.9
        if not mix and "transparent in add" in self.avoid:
            a, b = [x if x != "ShaderNodeBsdfTransparent" else "ShaderNodeBsdfDiffuse"
                    for x in (a, b)]
        typ = "ShaderNodeMixShader" if mix else "ShaderNodeAddShader"
        graph_fac = mix and r.random() < 0.3
        m = self.add(typ, {}, {"Fac": _u(r, 0.1, 0.9)} if mix else {})
        na = self.shader(a, allow_graph=False)
        nb = self.shader(b, allow_graph=False)
        for n in (na, nb):   # Alpha inside a mix is not rendered (a warning): Transparent is
            self.nodes[n]["inputs"].pop("Alpha", None)
        off = 1 if mix else 0
        _, aout, _ = PROBE(a, self.nodes[na]["props"])
        _, bout, _ = PROBE(b, self.nodes[nb]["props"])
        self.link(na, aout[0][0], m, PROBE(typ, {})[0][off][0])
        self.link(nb, bout[0][0], m, PROBE(typ, {})[0][off + 1][0])
        if graph_fac and "emission under a graph mix" in self.avoid and any(
                self.nodes[n]["type"] == "ShaderNodeEmission" or
                "Emission Strength" in self.nodes[n]["inputs"] for n in (na, nb)):
            graph_fac = False
        if graph_fac:
            src = self.source(1, emission=False, scalar=True)
            if src is not None:
                self.link(src[0], src[1], m, "Fac")
        return m, "Shader"

    def done(self, out):
        return {"nodes": self.nodes, "links": self.links, "out": list(out)}
