"""Small analytic and classic test scenes built directly in numpy (no Blender).

- `furnace_sphere`: camera inside a closed emissive diffuse sphere; every pixel sees
  Le * sum_{k<max_depth} albedo^k (exact for any closed enclosure).
- `cornell_box`: a diffuse Cornell box lit by a rectangle area light.
- `integrating_sphere`: a closed diffuse sphere around a point (or small sphere) light."""

import math

import numpy as np

from .scene import Scene


def icosphere(subdivisions=3, radius=1.0, center=(0.0, 0.0, 0.0)):
    """Closed, watertight triangulated sphere: (positions float32 (V, 3), indices uint32 (T, 3)),
    triangles wound counter-clockwise seen from outside. 20 * 4**subdivisions triangles."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0),
             (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
             (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
             (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
             (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(v, dtype=np.float64) / np.linalg.norm(v) for v in verts]
    for _ in range(subdivisions):
        cache = {}

        def midpoint(a, b):
            key = (a, b) if a < b else (b, a)
            if key not in cache:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                cache[key] = len(verts) - 1
            return cache[key]

        new_faces = []
        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            new_faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new_faces
    pos = np.array(verts) * radius + np.asarray(center, dtype=np.float64)
    return pos.astype(np.float32), np.array(faces, dtype=np.uint32)


def aabb_mesh(lo, hi):
    """Axis-aligned box from corner `lo` to corner `hi`: positions float32 (8, 3), indices
    uint32 (12, 3), wound counter-clockwise seen from outside (outward normals). The one box
    builder the tests and benches share (reverse the index columns for a cavity's walls)."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    p = np.array([[x, y, z] for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)], np.float32)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    idx = [[a, b, c] for a, b, c, d in quads] + [[a, c, d] for a, b, c, d in quads]
    return p, np.array(idx, np.uint32)


def furnace_expected(emission, albedo, max_depth):
    """Radiance every pixel converges to in `furnace_sphere`: Le * sum_{k=0}^{D-1} a^k."""
    a = np.asarray(albedo, dtype=np.float64) * np.ones(3)
    le = np.asarray(emission, dtype=np.float64) * np.ones(3)
    return le * sum(a ** k for k in range(max_depth))


def furnace_sphere(albedo=0.5, emission=1.0, subdivisions=3, radius=1.0, width=32, height=32,
                   fov=90.0):
    """Camera at the centre of a closed, emissive diffuse icosphere; world black.

    `albedo`, `emission`: scalars or RGB. Expected pixel value: `furnace_expected`."""
    scene = Scene()
    scene.film.update(width=int(width), height=int(height))
    scene.look_at((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov=fov)
    scene.camera["clip"] = [1e-3, 100.0 * radius]
    mat = scene.add_material("furnace", base_color=albedo, emission=emission)
    pos, idx = icosphere(subdivisions, radius)
    scene.add_mesh(pos, idx, material=mat, name="furnace_sphere")
    return scene


def _quad(p0, p1, p2, p3):
    """Two triangles for the quad p0 p1 p2 p3 (counter-clockwise seen from the front)."""
    pos = np.array([p0, p1, p2, p3], dtype=np.float32)
    idx = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    return pos, idx


def _box(center, size, angle_deg):
    """Closed axis-aligned box rotated about +Z: six quads, outward facing."""
    cx, cy, z0 = center
    sx, sy, sz = size[0] / 2.0, size[1] / 2.0, size[2]
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    corners = []
    for z in (z0, z0 + sz):
        for x, y in ((-sx, -sy), (sx, -sy), (sx, sy), (-sx, sy)):
            corners.append((cx + c * x - s * y, cy + s * x + c * y, z))
    corners = np.array(corners, dtype=np.float32)
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    idx = []
    for a, b, c_, d in faces:
        idx += [(a, b, c_), (a, c_, d)]
    return corners, np.array(idx, dtype=np.uint32)


def cornell_box(width=64, height=64, light_power=40.0, boxes=True, light_visible=True):
    """Diffuse Cornell box, Blender axes (+Z up): a 2 m cube x, y in [-1, 1], z in [0, 2],
    open towards the camera at y = -1; red left wall, green right wall, a 0.5 x 0.4 m rectangle
    light just under the ceiling facing down. Optional short and tall boxes."""
    scene, white, red, green = _box_room(width, height)
    _walls(scene, white, red, green)
    if boxes:
        _boxes(scene, white, white)
    _ceiling_light(scene, light_power, visible=light_visible)
    return scene


def integrating_sphere_expected(albedo, power, radius, max_depth):
    """Wall radiance seen from inside an ideal integrating sphere (a smooth sphere of `radius`
    with an isotropic light of `power` W at its centre): direct irradiance E = P / (4 pi R^2),
    L = (a / pi) * E * sum_{k=0}^{D-2} a^k. A tessellated sphere deviates by O(facet size^2)."""
    a = np.asarray(albedo, dtype=np.float64) * np.ones(3)
    p = np.asarray(power, dtype=np.float64) * np.ones(3)
    irradiance = p / (4.0 * math.pi * radius ** 2)
    return (a / math.pi) * irradiance * sum(a ** k for k in range(max(max_depth - 1, 0)))


def integrating_sphere(albedo=0.5, power=100.0, radius=1.0, light="point", light_radius=0.05,
                       subdivisions=4, width=32, height=32, fov=90.0):
    """Closed diffuse (non-emissive) icosphere with a point light (`light="point"`) or a small
    sphere light (`light="sphere"`, radius `light_radius`, invisible to the camera) at its
    centre; the camera sits at the centre too. See `integrating_sphere_expected`."""
    if light not in ("point", "sphere"):
        raise ValueError(f"light must be 'point' or 'sphere', got {light!r}")
    scene = Scene()
    scene.film.update(width=int(width), height=int(height))
    scene.look_at((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov=fov)
    scene.camera["clip"] = [1e-3, 100.0 * radius]
    mat = scene.add_material("wall", base_color=albedo)
    pos, idx = icosphere(subdivisions, radius)
    scene.add_mesh(pos, idx, material=mat, name="integrating_sphere")
    scene.add_light("point", position=[0.0, 0.0, 0.0], power=power,
                    radius=light_radius if light == "sphere" else 0.0, visible_camera=False)
    return scene


# ---- Hard lighting for the bidirectional integrators (tests/python/test_bidirectional.py) ----

def _walls(scene, white, red, green, floor=None, back=None, uvs=None):
    """The Cornell box's five walls (2 m cube, open towards -Y); `floor` and `back` materials
    optional (white otherwise); `uvs`: the same four uvs on every wall (its quad's corners)."""
    walls = {
        "floor": (_quad((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)),
                  white if floor is None else floor),
        "ceiling": (_quad((-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2)), white),
        "back": (_quad((-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)),
                 white if back is None else back),
        "left": (_quad((-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)), red),
        "right": (_quad((1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)), green),
    }
    for name, ((pos, idx), mat) in walls.items():
        scene.add_mesh(pos, idx, material=mat, name=name, uvs=uvs)


def _boxes(scene, short, tall):
    """The Cornell box's short and tall boxes, with their materials."""
    pos, idx = _box((0.33, -0.3, 0.0), (0.6, 0.6, 0.6), -17.0)
    scene.add_mesh(pos, idx, material=short, name="short_box")
    pos, idx = _box((-0.35, 0.3, 0.0), (0.6, 0.6, 1.2), 17.0)
    scene.add_mesh(pos, idx, material=tall, name="tall_box")


def _ceiling_light(scene, power, visible=True):
    """The Cornell box's 0.5 x 0.4 m rectangle light just under the ceiling, facing down."""
    to_world = np.eye(4)
    to_world[:3, 3] = (0.0, 0.0, 1.98)
    scene.add_light("area", to_world=to_world.tolist(), shape="rectangle", size=[0.5, 0.4],
                    power=[power] * 3, visible_camera=bool(visible))


def _box_room(width, height):
    scene = Scene()
    scene.film.update(width=int(width), height=int(height))
    scene.look_at((0.0, -3.8, 1.0), (0.0, 0.0, 1.0), fov=39.3)
    white = scene.add_material("white", base_color=(0.73, 0.73, 0.73))
    red = scene.add_material("red", base_color=(0.63, 0.065, 0.05))
    green = scene.add_material("green", base_color=(0.14, 0.45, 0.091))
    return scene, white, red, green


def _shell(center, size, thickness):
    """A hollow box: outer faces outward, inner faces inward (towards the cavity), so a
    dielectric shell has air on both sides of its walls. Positions, indices."""
    cx, cy, cz = center
    outer_p, outer_i = _box((cx, cy, cz - size / 2), (size, size, size), 0.0)
    inner = size - 2 * thickness
    inner_p, inner_i = _box((cx, cy, cz - inner / 2), (inner, inner, inner), 0.0)
    inner_i = inner_i[:, ::-1] + len(outer_p)
    return (np.concatenate([outer_p, inner_p]).astype(np.float32),
            np.concatenate([outer_i, inner_i]).astype(np.uint32))


def fixture_box(width=64, height=64, opening=0.12, light_power=150.0, light_radius=0.04):
    """A light inside a fixture with a small opening: the Cornell box without its area light; a
    closed white shade (0.4 m cube, 1.3 to 1.7 m high) around a sphere light (soft falloff off)
    with one square hole of side `opening` in its bottom. Nearly every next-event ray from the
    room is blocked by the shade; light escapes only through the hole."""
    scene, white, red, green = _box_room(width, height)
    _walls(scene, white, red, green)
    s, h, z0, z1 = 0.2, opening / 2.0, 1.3, 1.7
    faces = [
        ((-s, -s, z1), (-s, s, z1), (s, s, z1), (s, -s, z1)),      # top
        ((-s, -s, z0), (s, -s, z0), (s, -s, z1), (-s, -s, z1)),    # sides
        ((s, -s, z0), (s, s, z0), (s, s, z1), (s, -s, z1)),
        ((s, s, z0), (-s, s, z0), (-s, s, z1), (s, s, z1)),
        ((-s, s, z0), (-s, -s, z0), (-s, -s, z1), (-s, s, z1)),
        # bottom around the hole
        ((-s, -s, z0), (-s, -h, z0), (s, -h, z0), (s, -s, z0)),
        ((-s, h, z0), (-s, s, z0), (s, s, z0), (s, h, z0)),
        ((-s, -h, z0), (-s, h, z0), (-h, h, z0), (-h, -h, z0)),
        ((h, -h, z0), (h, h, z0), (s, h, z0), (s, -h, z0)),
    ]
    pos = np.concatenate([_quad(*f)[0] for f in faces])
    idx = np.concatenate([_quad(*f)[1] + 4 * k for k, f in enumerate(faces)])
    scene.add_mesh(pos, idx, material=white, name="shade")
    scene.add_light("point", position=[0.0, 0.0, 1.5], radius=light_radius,
                    power=[light_power] * 3, soft_falloff=False, visible_camera=False)
    return scene


def glass_lantern(width=64, height=64, roughness=0.0, light_power=60.0, light_radius=0.05):
    """A light behind glass: a sphere light (soft falloff off) inside a hollow glass cube
    (0.5 m, 1 cm walls, IOR 1.5, `roughness` 0 = smooth) hanging in the Cornell box, over the
    tall box. Next-event rays from the room all end on the glass; caustics fall on the floor."""
    scene, white, red, green = _box_room(width, height)
    _walls(scene, white, red, green)
    pos, idx = _box((-0.35, 0.3, 0.0), (0.6, 0.6, 1.0), 17.0)
    scene.add_mesh(pos, idx, material=white, name="tall_box")
    glass = scene.add_material("glass", type="dielectric", base_color=(1.0, 1.0, 1.0),
                               roughness=roughness, ior=1.5)
    pos, idx = _shell((0.2, 0.0, 1.4), 0.5, 0.01)
    scene.add_mesh(pos, idx, material=glass, name="lantern_glass")
    scene.add_light("point", position=[0.2, 0.0, 1.4], radius=light_radius,
                    power=[light_power] * 3, soft_falloff=False, visible_camera=False)
    return scene


def emitter_in_glass(width=32, height=32, roughness=0.0, emission=2.0, fov=None, floor=False):
    """An emissive sphere (radius 0.3 m, `emission` W/m^2/sr, black BSDF) inside a solid glass
    sphere (radius 0.6 m, IOR 1.5, `roughness`), centred at the origin, seen from 4 m on -Y;
    world black. fov None: 6 degrees, so that every pixel looks through the glass at the
    emitter near normal incidence: as Cycles, radiance leaves the glass unscaled by 1/eta^2,
    each pixel tends to emission * (1 - F) (`emitter_in_glass_expected`). `floor`: a diffuse
    floor under the sphere (wider view), lit through the glass."""
    scene = Scene()
    scene.film.update(width=int(width), height=int(height))
    scene.look_at((0.0, -4.0, 0.0), (0.0, 0.0, 0.0), fov=6.0 if fov is None else fov)
    glass = scene.add_material("glass", type="dielectric", base_color=(1.0, 1.0, 1.0),
                               roughness=roughness, ior=1.5)
    lamp = scene.add_material("lamp", base_color=(0.0, 0.0, 0.0), emission=[emission] * 3)
    pos, idx = icosphere(4, 0.6)
    scene.add_mesh(pos, idx, material=glass, normals=pos / 0.6, name="glass_sphere")
    pos, idx = icosphere(3, 0.3)
    scene.add_mesh(pos, idx, material=lamp, name="emitter")
    if floor:
        white = scene.add_material("white", base_color=(0.7, 0.7, 0.7))
        scene.add_mesh(*_quad((-3, -3, -0.6), (3, -3, -0.6), (3, 3, -0.6), (-3, 3, -0.6)),
                       material=white, name="floor")
    return scene


def emitter_in_glass_expected(emission=2.0, ior=1.5):
    """What `emitter_in_glass` (smooth) converges to at normal incidence: emission * (1 - F0)."""
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    return emission * (1.0 - f0)


def glossy_box(width=64, height=64, roughness=0.15, light_power=20.0, light_radius=0.02,
               delta_light=False):
    """Glossy surfaces with a small light: a metal floor (GGX, `roughness`) and a rougher metal
    short box in the Cornell box, lit by a tiny sphere light (or a point light with
    `delta_light`) near the ceiling. Glossy inter-reflection and glossy caustics."""
    scene, white, red, green = _box_room(width, height)
    metal = scene.add_material("metal", type="conductor", base_color=(0.9, 0.85, 0.8),
                               roughness=roughness)
    rough_metal = scene.add_material("rough_metal", type="conductor",
                                     base_color=(0.95, 0.64, 0.54), roughness=0.4)
    _walls(scene, white, red, green, floor=metal)
    pos, idx = _box((0.33, -0.3, 0.0), (0.6, 0.6, 0.6), -17.0)
    scene.add_mesh(pos, idx, material=rough_metal, name="short_box")
    scene.add_light("point", position=[-0.2, 0.3, 1.7],
                    radius=0.0 if delta_light else light_radius, power=[light_power] * 3,
                    soft_falloff=False, visible_camera=False)
    return scene


def principled_box(width=64, height=64, light_power=40.0):
    """Layered materials in the Cornell box: plastic walls (Principled, roughness 0.3), a
    smooth-coated short box (roughness 0: a delta specular layer over a diffuse base), a
    half-metal tall box and a principled glass panel, under the rectangle light."""
    scene, white, red, green = _box_room(width, height)
    plastic = lambda name, c, **kw: scene.add_material(name, type="principled", base_color=c,
                                                       **kw)
    pw = plastic("plastic_white", (0.73, 0.73, 0.73), roughness=0.3)
    pr = plastic("plastic_red", (0.63, 0.065, 0.05), roughness=0.3)
    pg = plastic("plastic_green", (0.14, 0.45, 0.091), roughness=0.3)
    _walls(scene, pw, pr, pg)
    coated = plastic("coated", (0.2, 0.3, 0.8), roughness=0.0)
    half_metal = plastic("half_metal", (0.95, 0.7, 0.4), roughness=0.25, metallic=0.5)
    _boxes(scene, coated, half_metal)
    glass = plastic("glass_panel", (0.9, 1.0, 0.9), roughness=0.1, transmission=1.0)
    pos, idx = _shell((0.3, 0.2, 1.6), 0.3, 0.02)
    scene.add_mesh(pos, idx, material=glass, name="glass_cube")
    _ceiling_light(scene, light_power)
    return scene


def smooth_glossy_box(width=64, height=64, light_power=40.0):
    """Coarse smooth-shaded spheres (icosphere level 1, vertex normals on the sphere: up to 20
    degrees off the facets) in the Cornell box under the rectangle light: rough metal, plastic
    (Principled) and diffuse. Their rims show views below the interpolated normal, where the
    glossy lobes take the view-corrected normal and the diffuse reads the light's side
    (docs/materials.md, "Shading normals below the view")."""
    scene, white, red, green = _box_room(width, height)
    _walls(scene, white, red, green)
    metal = scene.add_material("rough_metal", type="conductor", base_color=(0.95, 0.64, 0.54),
                               roughness=0.3)
    plastic = scene.add_material("plastic", type="principled", base_color=(0.2, 0.3, 0.8),
                                 roughness=0.4)
    for name, mat, c in (("metal_ball", metal, (-0.5, 0.1, 0.4)),
                         ("plastic_ball", plastic, (0.5, -0.1, 0.4)),
                         ("diffuse_ball", white, (0.0, 0.5, 1.1))):
        pos, idx = icosphere(1, 0.38, c)
        scene.add_mesh(pos, idx, material=mat, normals=(pos - np.asarray(c, np.float32)) / 0.38,
                       name=name)
    _ceiling_light(scene, light_power)
    return scene


def _checker(n=8, a=(0.9, 0.85, 0.7), b=(0.15, 0.1, 0.05)):
    """An n x n 8-bit sRGB checker texture (RGBA)."""
    enc = lambda c: [int(round(255 * (x ** (1 / 2.2)))) for x in c] + [255]
    tile = np.indices((n, n)).sum(axis=0) % 2
    return np.where(tile[..., None] == 0, enc(a), enc(b)).astype(np.uint8)


def _tilt_map(scene, degrees):
    """A constant tangent-space normal map tilting the normal `degrees` towards -u."""
    t = math.radians(degrees)
    nrm = np.array([[[int(round((1 - math.sin(t)) * 127.5)), 128,
                      int(round((math.cos(t) + 1) * 127.5)), 255]]], np.uint8)
    return scene.add_texture(nrm, colorspace="linear")


def coat_normal_box(width=64, height=64, light_power=40.0):
    """Principled coats with their own normals (Coat Normal) in the Cornell box: the left wall
    a red base under a rough coat whose normal is tilted 30 degrees (its own map), the right
    wall a normal-mapped green base under a smooth (delta) coat on the interpolated normal, the
    back wall a part-metal base under a tilted rougher coat, a white floor and boxes."""
    scene, white, red, green = _box_room(width, height)
    tilt30 = _tilt_map(scene, 30.0)
    left = scene.add_material("coat_tilted", type="principled", base_color=(0.63, 0.065, 0.05),
                              roughness=0.5, coat_weight=1.0, coat_roughness=0.15,
                              coat_normal_texture=tilt30)
    right = scene.add_material("base_mapped", type="principled", base_color=(0.14, 0.45, 0.091),
                               roughness=0.4, coat_weight=1.0, coat_roughness=0.0,
                               normal_texture=_tilt_map(scene, 35.0))
    back = scene.add_material("coat_metal", type="principled", base_color=(0.8, 0.7, 0.5),
                              metallic=0.4, roughness=0.4, coat_weight=0.8, coat_roughness=0.3,
                              coat_normal_texture=tilt30, coat_normal_strength=0.7)
    _walls(scene, white, left, right, back=back,
           uvs=np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32))
    _boxes(scene, white, white)
    _ceiling_light(scene, light_power)
    return scene


def sheen_box(width=64, height=64, light_power=40.0):
    """Principled sheens (the LTC microfiber sheen, bsdf/sheen.h) in the Cornell box: every wall
    and box under a sheen of its own roughness (0.1 to 1), tint and weight, over diffuse,
    plastic and coated bases. The lobe is not reciprocal: light sub-paths evaluate its adjoint,
    so bidirectional integrators agree with pt only if both transports evaluate one function."""
    scene, white, red, green = _box_room(width, height)
    sheen = lambda name, c, w, r, tint=(1.0, 1.0, 1.0), **kw: scene.add_material(
        name, type="principled", base_color=c, sheen_weight=w, sheen_roughness=r,
        sheen_tint=tint, **kw)
    floor = sheen("sheen_floor", (0.5, 0.5, 0.5), 1.0, 0.5, roughness=0.5)
    left = sheen("sheen_red", (0.63, 0.065, 0.05), 1.0, 0.3, (1.0, 0.9, 0.8), roughness=0.6)
    right = sheen("sheen_green", (0.14, 0.45, 0.091), 0.8, 1.0, (0.6, 0.8, 1.0), roughness=0.5)
    back = sheen("sheen_back", (0.3, 0.3, 0.6), 1.0, 0.1, roughness=0.3)
    _walls(scene, white, left, right, floor=floor, back=back)
    short = sheen("sheen_coated", (0.6, 0.3, 0.2), 1.0, 0.7, (1.0, 0.6, 0.3), roughness=0.4,
                  coat_weight=0.6, coat_roughness=0.2)
    tall = sheen("sheen_velvet", (0.05, 0.05, 0.15), 1.0, 0.4, roughness=0.8)
    _boxes(scene, short, tall)
    _ceiling_light(scene, light_power)
    return scene


def features_box(width=64, height=64, light_power=40.0):
    """What the material system adds beyond the Principled layers, in the Cornell box: a
    checker-textured floor, a Mix Shader back wall (0.7 diffuse + 0.3 anisotropic rough metal
    along the uv tangent), a short box
    that mixes smooth glass with diffuse (a delta leaf), a tall box of diffuse + translucent
    (Add Shader weights 0.5 each), a normal-mapped left wall, and a card of alpha 0.5 hanging
    in front of the tall box."""
    scene, white, red, green = _box_room(width, height)
    checker = scene.add_texture(_checker(), interpolation="closest")
    floor = scene.add_material("checker_floor", base_color_texture=checker)
    d_white = scene.add_material("mix_diffuse", base_color=(0.73, 0.73, 0.73))
    metal = scene.add_material("mix_metal", type="conductor", base_color=(0.9, 0.8, 0.6),
                               roughness=0.35, anisotropy=0.8, anisotropic_rotation=0.1,
                               tangent="uv")
    back = scene.add_material("back_mix", type="mix", mix=[[d_white, 0.7], [metal, 0.3]])
    # a constant tangent-space normal map tilting the normal 25 degrees towards -u (-y, the
    # camera's side; uv-derived tangents)
    t = math.radians(25.0)
    nrm = np.array([[[int(round((1 - math.sin(t)) * 127.5)), 128,
                      int(round((math.cos(t) + 1) * 127.5)), 255]]], np.uint8)
    bumpy = scene.add_material("bumpy_red", base_color=(0.63, 0.065, 0.05),
                               normal_texture=scene.add_texture(nrm, colorspace="linear"))
    _walls(scene, white, bumpy, green, floor=floor, back=back,
           uvs=np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32))
    glass = scene.add_material("mix_glass", type="dielectric", roughness=0.0, ior=1.5,
                               base_color=(0.9, 0.95, 1.0))
    d_blue = scene.add_material("mix_blue", base_color=(0.2, 0.3, 0.8))
    glassy = scene.add_material("glass_diffuse", type="mix", mix=[[glass, 0.5], [d_blue, 0.5]])
    trans = scene.add_material("translucent", type="translucent", base_color=(0.8, 0.7, 0.5))
    d_tall = scene.add_material("tall_diffuse", base_color=(0.6, 0.6, 0.6))
    tall = scene.add_material("diffuse_translucent", type="mix",
                              mix=[[d_tall, 0.5], [trans, 0.5]])
    _boxes(scene, glassy, tall)
    card = scene.add_material("card", base_color=(0.9, 0.9, 0.2), alpha=0.5)
    pos, idx = _quad((-0.7, -0.3, 0.3), (0.0, -0.3, 0.3), (0.0, -0.3, 1.0), (-0.7, -0.3, 1.0))
    scene.add_mesh(pos, idx, material=card, name="alpha_card")
    _ceiling_light(scene, light_power)
    return scene


# ---- Many-light scenes (issue 14: the light tree), after blend_scenes/efficiency.py ----

def _aim(position, target):
    """A rigid to_world at `position` whose local -Z looks at `target` (Blender's track)."""
    p, t = np.asarray(position, dtype=np.float64), np.asarray(target, dtype=np.float64)
    f = t - p
    f /= np.linalg.norm(f)
    up = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.999 else np.array([0.0, 1.0, 0.0])
    x = np.cross(f, up)
    x /= np.linalg.norm(x)
    y = np.cross(x, f)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, y, -f, p
    return m.tolist()


def _efficiency_room(width, height, window=False):
    """blend_scenes/efficiency.py's 5 x 5 x 2.8 m room (camera inside), a window of
    y in [-0.6, 1.0], z in [0.9, 2.2] in the right wall when asked."""
    scene = Scene()
    scene.film.update(width=int(width), height=int(height))
    scene.look_at((0.0, -2.2, 1.5), (0.2, 1.0, 0.9), fov=84.0)
    x, y, h = 2.5, 2.5, 2.8
    white = scene.add_material("white", base_color=(0.8, 0.8, 0.8))
    quads = [((-x, -y, 0), (x, -y, 0), (x, y, 0), (-x, y, 0), (0.55, 0.45, 0.35)),
             ((-x, -y, h), (-x, y, h), (x, y, h), (x, -y, h), white),
             ((-x, y, 0), (x, y, 0), (x, y, h), (-x, y, h), white),
             ((-x, -y, 0), (-x, -y, h), (x, -y, h), (x, -y, 0), white),
             ((-x, -y, 0), (-x, y, 0), (-x, y, h), (-x, -y, h), (0.35, 0.45, 0.7))]
    sand = (0.75, 0.65, 0.45)
    if not window:
        quads.append(((x, -y, 0), (x, -y, h), (x, y, h), (x, y, 0), sand))
    else:
        y0, y1, z0, z1 = -0.6, 1.0, 0.9, 2.2
        for ya, yb, za, zb in ((-y, y0, 0, h), (y1, y, 0, h), (y0, y1, 0, z0), (y0, y1, z1, h)):
            quads.append(((x, ya, za), (x, ya, zb), (x, yb, zb), (x, yb, za), sand))
    for k, (a, b, c, d, m) in enumerate(quads):
        mat = m if isinstance(m, int) else scene.add_material(f"wall{k}", base_color=m)
        scene.add_mesh(*_quad(a, b, c, d), material=mat, name=f"wall{k}")
    for name, center, size, angle, colour in (
            ("table", (0.3, 0.8, 0.0), (1.4, 0.8, 0.75), 10, (0.5, 0.3, 0.15)),
            ("cabinet", (-1.9, 1.7, 0.0), (0.8, 0.6, 1.2), 0, (0.7, 0.2, 0.15)),
            ("block", (1.5, -0.6, 0.0), (0.5, 0.5, 0.5), 30, (0.2, 0.6, 0.3))):
        mat = scene.add_material(name, base_color=colour)
        scene.add_mesh(*_box(center, size, angle), material=mat, name=name)
    return scene


def room_area_point(width=64, height=64):
    """The room lit by a 1.0 x 0.5 m area light of 200 W under the ceiling, facing down, and
    a small point light (10 W, radius 5 cm) low in the far corner."""
    scene = _efficiency_room(width, height)
    scene.add_light("area", to_world=_aim((0.4, 0.6, 2.78), (0.4, 0.6, 0.0)),
                    shape="rectangle", size=[1.0, 0.5], power=[200.0] * 3)
    scene.add_light("point", position=[-2.2, 2.2, 0.4], radius=0.05, power=[10.0] * 3)
    return scene


def small_room_two_lights(width=64, height=64, lights="both"):
    """blend_scenes/efficiency.py's `small_room_two_lights` (issue 28, "Several lights"): a
    closed 2 x 2 x 2 m room (camera inside), a rough Principled ball on the floor, a 0.5 x 0.3 m
    rectangular area light (30 W) 2 cm under the ceiling facing down, and a small point light
    (15 W, radius 5 cm, soft falloff) at mid height near the left wall. `lights`: "both",
    "area" or "point" (one light alone, the issue's controls)."""
    scene = Scene()
    scene.film.update(width=int(width), height=int(height))
    scene.look_at((0.0, -0.9, 1.0), (0.0, 1.0, 0.9), fov=90.0)
    for k, (a, b, c, d, colour) in enumerate(SMALL_ROOM_WALLS):
        mat = scene.add_material(f"wall{k}", base_color=colour)
        scene.add_mesh(*_quad(a, b, c, d), material=mat, name=f"wall{k}")
    ball = scene.add_material("ball", type="principled", base_color=(0.8, 0.5, 0.3),
                              roughness=0.5)
    pos, idx = icosphere(4, 0.3, (0.3, 0.3, 0.3))
    scene.add_mesh(pos, idx, material=ball, name="ball")
    if lights in ("both", "area"):
        scene.add_light("area", to_world=_aim((0.0, 0.2, 1.98), (0.0, 0.2, 0.0)),
                        shape="rectangle", size=[0.5, 0.3], power=[30.0] * 3)
    if lights in ("both", "point"):
        scene.add_light("point", position=[-0.6, 0.5, 0.7], radius=0.05, soft_falloff=True,
                        power=[15.0] * 3)
    return scene


# floor, ceiling, back, front, left (red), right (green): corners counter-clockwise from inside
SMALL_ROOM_WALLS = (
    ((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0), (0.6, 0.6, 0.6)),
    ((-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2), (0.8, 0.8, 0.8)),
    ((-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2), (0.8, 0.8, 0.8)),
    ((-1, -1, 0), (-1, -1, 2), (1, -1, 2), (1, -1, 0), (0.8, 0.8, 0.8)),
    ((-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2), (0.7, 0.2, 0.15)),
    ((1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0), (0.2, 0.6, 0.25)))


def room_spot_sun_world(width=64, height=64):
    """The room with a window: a sun (4 W/m^2, 2 degrees) through it, a world colour (0.4,
    0.5, 0.7), and a spot (600 W, 40 degrees) from a ceiling corner aimed at the floor."""
    scene = _efficiency_room(width, height, window=True)
    scene.world["color"] = [0.4, 0.5, 0.7]
    d = np.array([0.0, 0.4, 0.0]) - np.array([6.0, 0.2, 5.0])
    scene.add_light("sun", direction=(d / np.linalg.norm(d)).tolist(), strength=[4.0] * 3,
                    angle=math.radians(2.0))
    scene.add_light("spot", to_world=_aim((-2.3, -2.3, 2.75), (-0.8, 0.3, 0.0)), radius=0.05,
                    power=[600.0] * 3, spot_size=math.radians(40.0), spot_blend=0.2)
    return scene


def many_lights_stage(width=64, height=64, n=24, spot=True, sun=True, panel=False, seed=14):
    """blend_scenes/scenes.py's stage (floor, back wall, two boxes) lit by n point lights of
    different colours and powers (5-120 W, radius 5 cm), with a spot facing the floor, a sun
    and an emissive panel (both sides, two triangles) when asked: the light tree's many-light
    scene."""
    scene = Scene()
    scene.film.update(width=int(width), height=int(height))
    scene.look_at((0.0, -5.5, 2.6), (0.0, 0.3, 0.7), fov=58.7)
    grey = scene.add_material("grey", base_color=(0.8, 0.8, 0.8))
    wall = scene.add_material("wall", base_color=(0.6, 0.7, 0.8))
    scene.add_mesh(*_quad((-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)), material=grey,
                   name="floor")
    scene.add_mesh(*_quad((-3, 2, 0), (3, 2, 0), (3, 2, 3), (-3, 2, 3)), material=wall,
                   name="back")
    scene.add_mesh(*_box((-0.6, 0.4, 0.0), (0.9, 0.9, 1.0), 25),
                   material=scene.add_material("orange", base_color=(0.8, 0.45, 0.15)),
                   name="box")
    scene.add_mesh(*_box((0.8, -0.3, 0.0), (0.6, 0.6, 0.6), -20),
                   material=scene.add_material("green", base_color=(0.2, 0.7, 0.3)),
                   name="block")
    rng = np.random.default_rng(seed)
    for _ in range(n):
        p = [rng.uniform(-2.5, 2.5), rng.uniform(-2.5, 1.8), rng.uniform(0.3, 2.6)]
        colour = 0.3 + 0.7 * rng.uniform(size=3)
        scene.add_light("point", position=p, radius=0.05,
                        power=(colour * rng.uniform(5.0, 120.0)).tolist())
    if spot:
        scene.add_light("spot", to_world=_aim((1.5, -1.5, 3.0), (0.0, 0.3, 0.0)), radius=0.1,
                        power=[300.0] * 3, spot_size=math.radians(50.0), spot_blend=0.3)
    if sun:
        d = np.array([-0.8, 1.2, 0.0]) - np.array([0.0, 0.0, 5.0])
        scene.add_light("sun", direction=(d / np.linalg.norm(d)).tolist(), strength=[0.5] * 3,
                        angle=math.radians(10.0))
    if panel:
        glow = scene.add_material("glow", base_color=(0.0, 0.0, 0.0), emission=(4.0, 3.6, 2.8))
        scene.add_mesh(*_quad((-0.4, -1.0, 2.2), (0.4, -1.0, 2.2), (0.4, -0.4, 2.6),
                              (-0.4, -0.4, 2.6)), material=glow, name="panel")
    return scene
