"""Helpers for the benchmark scenes (bench_*.py): numpy-built meshes, subdivision and bevels
baked into the mesh data, Principled materials of several kinds (with what each is meant to
be), and light fixtures that enclose their lights. A builder calls `start(w, h)` first and
`finish(target_tris, fill)` last; `finish` tops the count up with real geometry in view."""

import math

import bpy
import numpy as np
from mathutils import Vector

from scenes import camera, emission  # noqa: F401  (re-exported for the builders)

NOTES = {}  # material name -> what it is meant to be (the add-on exports base colour only)


# ---- scene ----

def start(width, height):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("World")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world
    NOTES.clear()
    return scene


def link(obj):
    bpy.context.scene.collection.objects.link(obj)
    return obj


# ---- meshes from numpy ----

def mesh_object(name, verts, faces, material, smooth=False, uvs=None):
    """An object from vertices (N, 3) and faces (an (F, k) int array or a list of index
    sequences); `uvs` (N, 2) per vertex, when given, become the UV map."""
    verts = np.ascontiguousarray(verts, np.float32).reshape(-1, 3)
    if isinstance(faces, np.ndarray):
        sizes = np.full(len(faces), faces.shape[1], np.int32)
        flat = faces.astype(np.int32).ravel()
    else:
        sizes = np.array([len(f) for f in faces], np.int32)
        flat = np.concatenate([np.asarray(f, np.int32) for f in faces])
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(verts))
    me.vertices.foreach_set("co", verts.ravel())
    me.loops.add(len(flat))
    me.polygons.add(len(sizes))
    starts = np.zeros(len(sizes), np.int32)
    starts[1:] = np.cumsum(sizes)[:-1]
    me.polygons.foreach_set("loop_start", starts)
    me.polygons.foreach_set("vertices", flat)
    me.update(calc_edges=True)
    if uvs is not None:
        layer = me.uv_layers.new(name="UVMap")
        layer.uv.foreach_set("vector", np.asarray(uvs, np.float32)[flat].ravel())
    if smooth:
        me.shade_smooth()
    me.materials.append(material)
    return link(bpy.data.objects.new(name, me))


def _place(verts, center, rot_z_deg):
    c, s = math.cos(math.radians(rot_z_deg)), math.sin(math.radians(rot_z_deg))
    x, y = verts[:, 0] * c - verts[:, 1] * s, verts[:, 0] * s + verts[:, 1] * c
    return np.stack([x, y, verts[:, 2]], 1) + np.asarray(center, np.float32)


def block(name, center, size, material, rot_z=0.0, bevel=0.0, subdiv=0, smooth=None):
    """A box (centre, full size), optionally bevelled (2 segments) and subdivided."""
    c = np.array([[x, y, z] for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)])
    faces = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2],
                      [1, 3, 7, 5]])
    obj = mesh_object(name, _place(c * np.asarray(size), center, rot_z), faces, material,
                      smooth=bool(subdiv) if smooth is None else smooth)
    if bevel > 0:
        m = obj.modifiers.new("Bevel", "BEVEL")
        m.width, m.segments = bevel, 2
    if subdiv:
        subdivide(obj, subdiv)
    return obj


def grid(name, nx, ny, surface, material, smooth=True, uv_scale=None):
    """An nx x ny quad grid over surface(u, v) -> (x, y, z) arrays, u, v in [0, 1]:
    2 nx ny triangles."""
    u, v = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 1, ny + 1))
    x, y, z = surface(u, v)
    verts = np.stack([np.broadcast_to(a, u.shape).ravel() for a in (x, y, z)], 1)
    i = np.arange(ny)[:, None] * (nx + 1) + np.arange(nx)[None, :]
    faces = np.stack([i, i + 1, i + nx + 2, i + nx + 1], -1).reshape(-1, 4)
    uvs = None
    if uv_scale is not None:
        uvs = np.stack([u.ravel() * uv_scale[0], v.ravel() * uv_scale[1]], 1)
    return mesh_object(name, verts, faces, material, smooth=smooth, uvs=uvs)


def lathe(name, profile, segments, material, center=(0, 0, 0), smooth=True, subdiv=0):
    """A surface of revolution about +Z from (radius, z) pairs; a radius of 0 is a pole."""
    verts, rings = [], []
    ang = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    for r, z in profile:
        start = len(verts)
        if r == 0:
            verts.append((0.0, 0.0, z))
            rings.append([start] * segments)
        else:
            verts.extend(zip(r * np.cos(ang), r * np.sin(ang), np.full(segments, z)))
            rings.append(list(range(start, start + segments)))
    faces = []
    for a, b in zip(rings[:-1], rings[1:]):
        for k in range(segments):
            k1 = (k + 1) % segments
            quad = [a[k], a[k1], b[k1], b[k]]
            uniq = list(dict.fromkeys(quad))
            if len(uniq) >= 3:
                faces.append(uniq)
    obj = mesh_object(name, np.asarray(verts) + np.asarray(center), faces, material, smooth)
    if subdiv:
        subdivide(obj, subdiv)
    return obj


def holed_plane(name, x0, x1, y0, y1, z, holes, material, flip=False):
    """A horizontal rectangle minus rectangular holes (x0, x1, y0, y1): the cells of the grid
    through every hole edge that lie in no hole. Faces up (+Z), or down with flip."""
    xs = sorted({x0, x1, *[h[0] for h in holes], *[h[1] for h in holes]})
    ys = sorted({y0, y1, *[h[2] for h in holes], *[h[3] for h in holes]})
    verts, faces = [], []
    for i in range(len(xs) - 1):
        for j in range(len(ys) - 1):
            cx, cy = (xs[i] + xs[i + 1]) / 2, (ys[j] + ys[j + 1]) / 2
            if any(h[0] < cx < h[1] and h[2] < cy < h[3] for h in holes):
                continue
            n = len(verts)
            verts += [(xs[i], ys[j], z), (xs[i + 1], ys[j], z), (xs[i + 1], ys[j + 1], z),
                      (xs[i], ys[j + 1], z)]
            faces.append([n, n + 3, n + 2, n + 1] if flip else [n, n + 1, n + 2, n + 3])
    return mesh_object(name, verts, faces, material)


def suzanne(name, location, scale, material, levels, rot_z=0.0):
    """Blender's monkey (468 quads + 32 triangles = 968 triangles), Catmull-Clark subdivided:
    15,744 triangles at level 2, 62,976 at 3, 251,904 at 4; smooth shaded."""
    bpy.ops.mesh.primitive_monkey_add(size=2.0 * scale, location=location,
                                      rotation=(0, 0, math.radians(rot_z)))
    obj = bpy.context.active_object
    obj.name = name
    obj.data.materials.append(material)
    obj.data.shade_smooth()
    subdivide(obj, levels)
    return obj


def subdivide(obj, levels):
    m = obj.modifiers.new("Subdivision", "SUBSURF")
    m.levels = m.render_levels = levels


def bake_modifiers(keep_uvs=()):
    """Apply every object's modifiers into its mesh (one depsgraph evaluation) and drop UV maps
    of objects not named in keep_uvs (nothing reads them; they cost 8 bytes a corner)."""
    dg = bpy.context.evaluated_depsgraph_get()
    objects = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    baked = {o.name: bpy.data.meshes.new_from_object(o.evaluated_get(dg))
             for o in objects if o.modifiers}
    for obj in objects:
        if obj.name in baked:
            old = obj.data
            obj.modifiers.clear()
            obj.data = baked[obj.name]
            if old.users == 0:
                bpy.data.meshes.remove(old)
        if obj.name not in keep_uvs:
            while obj.data.uv_layers:
                obj.data.uv_layers.remove(obj.data.uv_layers[0])


def triangle_count():
    """Triangles of the scene's meshes as rendered (modifiers included)."""
    dg = bpy.context.evaluated_depsgraph_get()
    total = 0
    for inst in dg.object_instances:
        if inst.object.type == "MESH":
            polys = inst.object.data.polygons
            sizes = np.empty(len(polys), np.int32)
            polys.foreach_get("loop_total", sizes)
            total += int((sizes - 2).sum())
    return total


def finish(target=0, fill=None, keep_uvs=()):
    """Bake modifiers, then top the triangle count up to `target` with fill(name, tris) for
    each name of fill's list (curtains, a rug: real geometry in view). Returns the count."""
    bake_modifiers(keep_uvs)
    if fill is not None:
        fill_fn, names = fill
        missing = target - triangle_count()
        for name in names:
            fill_fn(name, max(8, missing // len(names)))
    return triangle_count()


# ---- materials (Principled BSDF, Blender 5.0 socket names) ----

def principled(name, base, note, **inputs):
    """A Principled BSDF; inputs by socket name with spaces as underscores."""
    m = bpy.data.materials.new(name)
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*base, 1.0)
    for key, value in inputs.items():
        sock = p.inputs[key.replace("_", " ")]
        sock.default_value = (*value, 1.0) if isinstance(value, tuple) else value
    NOTES[name] = note
    return m


def matte(name, color):
    return principled(name, color, "matte paint: diffuse (Specular IOR Level 0, roughness 1)",
                      Specular_IOR_Level=0.0, Roughness=1.0)


def metal(name, color, roughness):
    return principled(name, color, f"metal, GGX roughness {roughness}", Metallic=1.0,
                      Roughness=roughness)


def glass(name, roughness=0.0, ior=1.5):
    return principled(name, (1.0, 1.0, 1.0), f"clear glass, IOR {ior}, roughness {roughness}",
                      Transmission_Weight=1.0, Roughness=roughness, IOR=ior)


def coated(name, color):
    return principled(name, color, "lacquer: rough dielectric base under a clear coat "
                      "(Coat Weight 1, coat roughness 0.03)", Roughness=0.5, Coat_Weight=1.0,
                      Coat_Roughness=0.03)


def fabric(name, color):
    return principled(name, color, "fabric: diffuse with sheen (Sheen Weight 1, roughness "
                      "0.5), Specular IOR Level 0.2", Roughness=1.0, Sheen_Weight=1.0,
                      Sheen_Roughness=0.5, Specular_IOR_Level=0.2)


def wood(name, size=256, seed=7):
    """Varnished planks: an Image Texture made here from numpy (packed into the .blend) on
    Base Color, a clear coat on top. The add-on exports the image as a texture (8-bit sRGB,
    repeat; docs/materials.md "Textures"), one tile per metre of the floor's uv (room's
    floor_uv). Base Color's own value, unused while the texture is linked, is about the
    texture's mean (the colour seen if the link is removed)."""
    y, x = np.mgrid[0:size, 0:size] / size
    plank = np.floor(x * 6).astype(int)
    rng = np.random.default_rng(seed)
    tint = rng.uniform(0.8, 1.2, 6)[plank]
    grain = 0.5 + 0.5 * np.sin(2 * np.pi * (y * 9 + 0.6 * np.sin(x * 31 + plank * 1.7)))
    seam = np.where(np.abs(x * 6 - np.round(x * 6)) < 0.02, 0.5, 1.0)
    srgb = np.array([0.55, 0.36, 0.2]) * ((0.75 + 0.25 * grain) * tint * seam)[..., None]
    rgba = np.concatenate([np.clip(srgb, 0, 1), np.ones((size, size, 1))], -1)
    img = bpy.data.images.new(name + "Planks", size, size)
    img.pixels.foreach_set(rgba.astype(np.float32).ravel())
    try:
        img.pack()
    except RuntimeError:
        pass  # unpacked: the .blend keeps a blank generated image; Base Color still holds
    mean = tuple(float(c) for c in (srgb.mean((0, 1)) ** 2.2))
    m = principled(name, mean, "varnished wood planks: image texture on Base Color "
                   "(numpy-generated, 256 x 256), roughness 0.6, Coat Weight 0.5",
                   Roughness=0.6, Coat_Weight=0.5, Coat_Roughness=0.05)
    nt = m.node_tree
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    nt.links.new(tex.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    return m


# ---- rooms and light fixtures (each light sits inside geometry) ----

def room(x0, x1, y0, y1, h, floor, walls, ceiling, holes=(), floor_uv=None):
    """A closed box room (the camera sits inside); the ceiling has the given holes."""
    grid("Floor", 2, 2, lambda u, v: (x0 + (x1 - x0) * u, y0 + (y1 - y0) * v, 0 * u), floor,
         smooth=False, uv_scale=floor_uv)
    holed_plane("Ceiling", x0, x1, y0, y1, h, holes, ceiling, flip=True)
    q = [((x0, y1), (x1, y1)), ((x1, y1), (x1, y0)), ((x1, y0), (x0, y0)), ((x0, y0), (x0, y1))]
    for k, ((ax, ay), (bx, by)) in enumerate(q):
        mesh_object(f"Wall{k}", [(ax, ay, 0), (bx, by, 0), (bx, by, h), (ax, ay, h)],
                    [[0, 1, 2, 3]], walls)


def recessed_light(name, cx, cy, ceiling_z, size, depth, power, trim):
    """An area light at the top of a box recess above a ceiling hole. Returns the hole."""
    h = size / 2
    x0, x1, y0, y1 = cx - h, cx + h, cy - h, cy + h
    z0, z1 = ceiling_z, ceiling_z + depth
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    mesh_object(name + "Recess", v, [[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7],
                                     [4, 5, 6, 7]], trim)
    lamp(name, "AREA", (cx, cy, z1 - 0.01), power, shape="SQUARE", size=size * 0.8)
    return (x0, x1, y0, y1)


def lamp(name, kind, location, power, **props):
    data = bpy.data.lights.new(name, kind)
    data.energy = power
    data.color = (1.0, 0.9, 0.78)  # warm white
    for k, val in props.items():
        setattr(data, k, val)
    obj = link(bpy.data.objects.new(name, data))
    obj.location = location
    return obj


def bulb(name, location, power, radius=0.03):
    """A bulb: a point light with a radius and soft falloff off (a sphere light)."""
    return lamp(name, "POINT", location, power, shadow_soft_size=radius, use_soft_falloff=False)


def shade(name, x, y, z, material, r_bottom=0.25, r_top=0.1, height=0.3, segments=48):
    """A lamp shade closed at the top, open at the bottom (bottom rim at z)."""
    return lathe(name, [(r_bottom, 0.0), (r_top, height), (0.0, height)], segments, material,
                 center=(x, y, z))


def pendant(name, x, y, ceiling_z, drop, power, shade_mat, cord_mat, **shade_args):
    """A hanging lamp: a cord from the ceiling, a shade whose rim hangs `drop` below it, a bulb
    a third of the way down from the shade's top."""
    height = shade_args.get("height", 0.3)
    z = ceiling_z - drop
    shade(name + "Shade", x, y, z, shade_mat, **shade_args)
    lathe(name + "Cord", [(0.006, z + height), (0.006, ceiling_z)], 8, cord_mat, (x, y, 0))
    return bulb(name, (x, y, z + height * 0.6), power)


def table_lamp(name, x, y, z, power, shade_mat, base_mat, scale=1.0):
    """A ceramic base and stem, a shade (closed top) with a bulb inside, standing at z."""
    s = scale
    lathe(name + "Base", [(0, 0), (0.09 * s, 0), (0.11 * s, 0.08 * s), (0.07 * s, 0.2 * s),
                          (0.015 * s, 0.24 * s), (0.015 * s, 0.42 * s), (0, 0.42 * s)], 32,
          base_mat, (x, y, z), subdiv=1)
    shade(name + "Shade", x, y, z + 0.3 * s, shade_mat, r_bottom=0.2 * s, r_top=0.12 * s,
          height=0.25 * s)
    return bulb(name, (x, y, z + 0.45 * s), power, radius=0.025 * s)


def cup_light(name, x, y, top_z, power, radius, material, cup_r=0.05, cup_h=0.08, **props):
    """A small reflector cup open at the bottom, hanging from top_z, a small bulb inside."""
    lathe(name + "Cup", [(cup_r, top_z - cup_h), (cup_r, top_z), (0, top_z)], 32, material,
          (x, y, 0), smooth=False)
    return bulb(name, (x, y, top_z - cup_h * 0.4), power, radius=radius, **props)


def curtain_fill(panels, material):
    """fill(name, tris) for finish(): draped curtain panels (x0, y0, x1, y1, z0, z1)."""
    def fill(name, tris):
        x0, y0, x1, y1, z0, z1 = panels[name]
        width, height = math.hypot(x1 - x0, y1 - y0), z1 - z0
        nx = max(2, round(math.sqrt(tris / 2 * width / height)))
        ny = max(2, round(tris / 2 / nx))
        nrm = np.array([-(y1 - y0), x1 - x0]) / width
        folds = max(3, round(width / 0.12))

        def surface(u, v):
            off = 0.05 * np.sin(2 * np.pi * folds * u) * (0.6 + 0.4 * v)
            return (x0 + (x1 - x0) * u + nrm[0] * off, y0 + (y1 - y0) * u + nrm[1] * off,
                    z0 + height * v)
        grid(name, nx, ny, surface, material)
    return fill, list(panels)


def look(location, target, lens):
    return camera(location, target, lens=lens)


def light_enclosure(radius=0.6):
    """For each light: whether rays up and in 4 horizontal directions from it hit geometry
    within `radius` (name -> (up_hit, horizontal_hits))."""
    scene = bpy.context.scene
    dg = bpy.context.evaluated_depsgraph_get()
    out = {}
    for obj in scene.objects:
        if obj.type != "LIGHT":
            continue
        o = obj.matrix_world.translation
        dirs = [Vector((0, 0, 1)), Vector((1, 0, 0)), Vector((-1, 0, 0)), Vector((0, 1, 0)),
                Vector((0, -1, 0))]
        hits = [scene.ray_cast(dg, o, d, distance=radius)[0] for d in dirs]
        out[obj.name] = (hits[0], sum(hits[1:]))
    return out
