"""bpy data from a difftest case (tools/difftest_scene.py describes the format): a
factory-empty scene rebuilt from the description alone, so a saved case.json rebuilds the same
scene."""

import difftest_features as df

def _mesh(kind, name):
    import bmesh
    import bpy
    bm = bmesh.new()
    if kind in ("sphere",):
        bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=1.0,
                                  calc_uvs=True)
    elif kind == "ico":
        bmesh.ops.create_icosphere(bm, subdivisions=2, radius=1.0, calc_uvs=True)
    elif kind in ("cube", "room"):
        bmesh.ops.create_cube(bm, size=2.0 if kind == "cube" else 1.0, calc_uvs=True)
        if kind == "room":   # normals inwards, the floor at z = 0
            bmesh.ops.reverse_faces(bm, faces=bm.faces)
            bmesh.ops.translate(bm, verts=bm.verts, vec=(0.0, 0.0, 0.5))
    else:   # plane
        bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=1.0, calc_uvs=True)
    me = bpy.data.meshes.new(name)
    bm.to_mesh(me)
    bm.free()
    if kind == "sphere":
        me.shade_smooth()
    return me


def _socket(sockets, ident):
    s = next((s for s in sockets if s.identifier == ident), None)
    if s is None:
        s = next((s for s in sockets if s.name == ident and s.enabled), None)
    if s is None:
        raise KeyError(ident)
    return s


def _env_image(spec, name):
    """A small float equirectangular map, smooth colours (and a bright sun), packed."""
    import bpy
    import numpy as np
    rng = np.random.default_rng(spec["seed"])
    w, h = spec["w"], spec["h"]
    v = (np.arange(h) + 0.5) / h
    u = (np.arange(w) + 0.5) / w
    base = rng.uniform(0.05, 1.0, 3)
    top = rng.uniform(0.05, 1.0, 3)
    img = (base[None, None, :] * (1 - v)[:, None, None] + top[None, None, :] * v[:, None, None]
           ) * (0.6 + 0.4 * np.cos(2 * np.pi * (u[None, :, None] + rng.uniform())))
    if spec.get("sun"):
        i, j = rng.integers(h // 2, h), rng.integers(0, w)
        img[i, j] = rng.uniform(20, 80, 3)
    rgba = np.concatenate([img, np.ones((h, w, 1))], axis=2).astype(np.float32)
    im = bpy.data.images.new(name, w, h, float_buffer=True, alpha=False)
    im.pixels.foreach_set(rgba.ravel())
    im.pack()
    im.colorspace_settings.name = "Linear Rec.709"
    return im


def _build_graph(tree, graph, output_type, out_socket, volume=None):
    """`graph` into the node tree, on the output's `out_socket` (none when None); `volume`: a
    second graph (its node names apart from `graph`'s) on the output's Volume."""
    nodes = tree.nodes
    for n in list(nodes):
        nodes.remove(n)
    out = nodes.new(output_type)
    for g, sock in ((graph, out_socket), (volume, "Volume")):
        if g is not None:
            _add_graph(tree, g, out.inputs[sock])


def _add_graph(tree, graph, out_input):
    nodes = tree.nodes
    made = {}
    for name, spec in graph["nodes"].items():
        node = nodes.new(spec["type"])
        node.name = name
        for k, v in spec.get("props", {}).items():
            setattr(node, k, v)
        made[name] = node
        if "color" in spec:
            node.outputs[0].default_value = spec["color"]
        if "value" in spec:
            node.outputs[0].default_value = spec["value"]
        if "ramp" in spec:
            ramp = node.color_ramp
            ramp.interpolation = spec["ramp"]["interpolation"]
            stops = spec["ramp"]["stops"]
            while len(ramp.elements) < len(stops):
                ramp.elements.new(0.5)
            for el, (pos, col) in zip(ramp.elements, stops):
                el.position, el.color = pos, col
        if "curve" in spec:
            mapping = node.mapping
            curve = mapping.curves[3] if spec["type"] == "ShaderNodeRGBCurve" else \
                mapping.curves[0]
            pts = spec["curve"]
            while len(curve.points) < len(pts):
                curve.points.new(0.5, 0.5)
            for p, (x, y) in zip(curve.points, pts):
                p.location = (x, y)
            mapping.update()
        if "image" in spec:
            node.image = _env_image(spec["image"], f"{tree.name}_{name}_env")
        for ident, v in spec.get("inputs", {}).items():
            _socket(node.inputs, ident).default_value = v
    for a, ao, b, bi in graph["links"]:
        tree.links.new(_socket(made[a].outputs, ao), _socket(made[b].inputs, bi))
    src, so = graph["out"]
    tree.links.new(_socket(made[src].outputs, so), out_input)


def build(case):
    """A factory-empty bpy scene holding `case`; returns the scene."""
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.resolution_x = sc.render.resolution_y = case["size"]
    sc.render.resolution_percentage = 100
    mats = {}
    for name, graph in case["materials"].items():
        m = bpy.data.materials.new(name)
        _build_graph(m.node_tree, graph, "ShaderNodeOutputMaterial", "Surface")
        mats[name] = m
    made = []
    for i, o in enumerate(case["objects"]):
        if o["kind"] == "curves":   # a Curves object (difftest_features)
            made.append(df.build_object(sc, o, mats, None))
            continue
        me = _mesh(o["kind"], f"{o['kind']}{i}")
        if o.get("volume") in case.get("volumes", {}):   # a Volume (and Surface) material
            m = bpy.data.materials.new(f"{o.get('material')}+{o['volume']}")
            _build_graph(m.node_tree, case["materials"].get(o.get("material")),
                         "ShaderNodeOutputMaterial", "Surface", case["volumes"][o["volume"]])
            me.materials.append(m)
        elif o.get("material") in mats:
            me.materials.append(mats[o["material"]])
        ob = bpy.data.objects.new(f"{o['kind']}{i}", me)
        ob.location = o["location"]
        ob.rotation_euler = o.get("rotation", [0.0, 0.0, 0.0])
        ob.scale = o["scale"]
        sc.collection.objects.link(ob)
        made.append(df.build_object(sc, o, mats, ob))
    for i, spec in enumerate(case["lights"]):
        light = bpy.data.lights.new(f"{spec['type'].lower()}{i}", spec["type"])
        light.energy = spec["energy"]
        light.color = spec.get("color", [1.0, 1.0, 1.0])
        if "radius" in spec:
            light.shadow_soft_size = spec["radius"]
        if "soft_falloff" in spec:
            light.use_soft_falloff = spec["soft_falloff"]
        for k in ("spot_size", "spot_blend", "shape", "size", "size_y", "angle"):
            if k in spec:
                setattr(light, k, spec[k])
        ob = bpy.data.objects.new(light.name, light)
        ob.location, ob.rotation_euler = spec["location"], spec["rotation"]
        ob.visible_camera = bool(spec.get("visible_camera", False))
        sc.collection.objects.link(ob)
    if case.get("world") is not None or case.get("world_volume"):
        w = bpy.data.worlds.new("World")
        _build_graph(w.node_tree, case.get("world"), "ShaderNodeOutputWorld", "Surface",
                     case.get("world_volume"))
        # Cycles' importance map of the world (automatic: 1.8-2.5 s a render at one thread
        # for these worlds, 0.1-0.2 s so); its resolution changes the noise, not the image
        w.cycles.sampling_method = "MANUAL"
        w.cycles.sample_map_resolution = 256
        sc.world = w
    c = case["camera"]
    cam = bpy.data.cameras.new("Camera")
    cam.lens = c.get("lens", 50.0)
    if "ortho_scale" in c:
        cam.type, cam.ortho_scale = "ORTHO", c["ortho_scale"]
    co = bpy.data.objects.new("Camera", cam)
    co.location, co.rotation_euler = c["location"], c["rotation"]
    sc.collection.objects.link(co)
    sc.camera = co
    df.build_scene(sc, case, co, made)
    sc.view_settings.view_transform = "Standard"
    return sc


