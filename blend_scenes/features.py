"""Sphere-per-feature scenes: one scene per shader input or node, a row of 3-4 smooth UV spheres
(radius 0.4, 48 x 24 segments, with UVs), each with a different value of the swept input, on a
grey Diffuse BSDF ground plane, lit by one square area light and a dim uniform world. Used by
tools/features_vs_cycles.py (Lantern against Cycles, docs/materials_vs_cycles.md) and by
tests/cycles/test_features.py.

    FEATURES[name] = Feature(builder, values, note)   # values: one label per sphere, left to right
    build(name, path=None)                             # build into bpy; save when path is given
    register(scenes.SCENES)                            # as "feature_<name>" (blend_scenes/build.py)

Every builder starts from an empty file (scenes._reset), so it leaves exactly its scene as the
current bpy data. Images (checker, roughness stripes, ridge normal map) are generated in numpy
and packed into the file. Principled BSDFs keep Blender's defaults except the swept input and
what `BASE` / each builder sets; "Multiscatter GGX" (the default distribution) throughout."""

import math
import os
import sys
from dataclasses import dataclass

import bpy
import numpy as np
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402

WIDTH, HEIGHT = 96, 48           # small: a full Cycles + Lantern sweep fits 40 min on 2 cores
RADIUS, SEGMENTS, RINGS = 0.4, 48, 24
SPACING = 1.1                    # sphere centres along x
GROUND = 0.5                     # ground albedo (Diffuse BSDF)
WORLD = 0.05                     # uniform world radiance
LIGHT_W = 250.0                  # square area light, 1.5 m, Blender watts


@dataclass(frozen=True)
class Feature:
    build: object      # builder: no arguments, leaves the scene as the current bpy data
    values: tuple      # one label per sphere, left to right
    note: str          # what is swept and on what


# ---- stage ----

def _reset():
    scene = scenes._reset(world_color=(WORLD, WORLD, WORLD))
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    return scene


def _stage(n):
    """Ground, light, camera for a row of n spheres (after _reset); returns the centres."""
    scenes.quad("Ground", [(-8, -8, 0), (8, -8, 0), (8, 8, 0), (-8, 8, 0)],
                scenes.diffuse("Ground", (GROUND, GROUND, GROUND)))
    scenes.light("AREA", "Area", (-1.5, -2.5, 3.5), target=(0, 0, 0.4), shape="SQUARE",
                 size=1.5, energy=LIGHT_W)
    # 40 mm lens (half-width 0.45 of the distance): the row fills the width with 0.25 m to
    # spare either side, seen from 15 degrees above
    d = ((n - 1) / 2 * SPACING + RADIUS + 0.25) / 0.45
    e = math.radians(15.0)
    scenes.camera((0.0, -d * math.cos(e), RADIUS + d * math.sin(e)), (0.0, 0.0, RADIUS),
                  lens=40.0)
    return [((i - (n - 1) / 2) * SPACING, 0.0, RADIUS) for i in range(n)]


def sphere(name, center, material):
    """A smooth UV sphere with its UV map (primitive_uv_sphere_add makes one)."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=SEGMENTS, ring_count=RINGS, radius=RADIUS,
                                         location=center)
    obj = bpy.context.active_object
    obj.name = name
    obj.data.shade_smooth()
    obj.data.materials.append(material)
    return obj


def row(materials):
    """A row of spheres, one per material, left to right."""
    for i, (c, m) in enumerate(zip(_stage(len(materials)), materials)):
        sphere(f"Sphere{i}", c, m)


# ---- materials ----

def _rgba(c):
    return (*c, 1.0) if len(c) == 3 else tuple(c)


def principled(name, **inputs):
    """A Principled BSDF material; keyword names are socket names with '_' for ' '."""
    m = bpy.data.materials.new(name)
    p = m.node_tree.nodes["Principled BSDF"]
    for key, v in inputs.items():
        sock = p.inputs[key.replace("_", " ")]
        sock.default_value = _rgba(v) if isinstance(v, tuple) else v
    return m


def _bare(name):
    m = bpy.data.materials.new(name)
    nt = m.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    return m, nt, nt.nodes["Material Output"]


def _node(nt, idname, **inputs):
    n = nt.nodes.new(idname)
    for key, v in inputs.items():
        n.inputs[key.replace("_", " ")].default_value = _rgba(v) if isinstance(v, tuple) else v
    return n


def shader(name, idname, **inputs):
    """A material whose Surface is one shader node."""
    m, nt, out = _bare(name)
    n = _node(nt, idname, **inputs)
    nt.links.new(n.outputs[0], out.inputs["Surface"])
    return m


def mix(name, fac, a, b, add=False):
    """Mix Shader (1 - fac) a + fac b, or Add Shader a + b; a, b: (idname, inputs)."""
    m, nt, out = _bare(name)
    na, nb = _node(nt, a[0], **a[1]), _node(nt, b[0], **b[1])
    if add:
        top = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(na.outputs[0], top.inputs[0])
        nt.links.new(nb.outputs[0], top.inputs[1])
    else:
        top = nt.nodes.new("ShaderNodeMixShader")
        top.inputs["Fac"].default_value = fac
        nt.links.new(na.outputs[0], top.inputs[1])
        nt.links.new(nb.outputs[0], top.inputs[2])
    nt.links.new(top.outputs[0], out.inputs["Surface"])
    return m


def image(name, texels, colorspace):
    """A packed 8-bit image from float texels (H, W, 4) in [0, 1], rows bottom to top."""
    h, w = texels.shape[:2]
    img = bpy.data.images.new(name, w, h, alpha=True)
    img.colorspace_settings.name = colorspace
    img.pixels.foreach_set(np.ascontiguousarray(texels, np.float32).ravel())
    img.pack()
    return img


def checker_texels(n=64, cells=8, a=(0.8, 0.15, 0.05), b=(0.9, 0.85, 0.7)):
    """sRGB-encoded checker: n x n texels, cells x cells squares of colours a and b (linear)."""
    i = (np.arange(n) * cells // n)
    sel = ((i[:, None] + i[None, :]) % 2).astype(bool)
    enc = lambda c: np.where(np.asarray(c) <= 0.0031308, 12.92 * np.asarray(c),  # noqa: E731
                             1.055 * np.asarray(c) ** (1 / 2.4) - 0.055)
    t = np.empty((n, n, 4), np.float32)
    t[..., :3] = np.where(sel[..., None], enc(b), enc(a))
    t[..., 3] = 1.0
    return np.round(t * 255) / 255


def stripe_texels(n=64, stripes=6, lo=0.1, hi=0.7):
    """Non-Color roughness stripes along u: lo and hi alternating."""
    v = np.where((np.arange(n) * stripes // n) % 2 == 0, lo, hi).astype(np.float32)
    t = np.ones((n, n, 4), np.float32)
    t[..., :3] = v[None, :, None]
    return np.round(t * 255) / 255


def ridge_normal_texels(n=128, ridges=8, amp=0.35):
    """Tangent-space normal map (Non-Color, encoded n * 0.5 + 0.5) of a height field of ridges
    along u with a bump pattern along v: h = amp * (sin(2 pi k u) + 0.5 sin(2 pi k v)) / (2 pi k)."""
    u = v = (np.arange(n) + 0.5) / n
    k = 2 * np.pi * ridges
    dhdu = amp * np.cos(k * u)[None, :] * np.ones((n, 1))          # columns: u
    dhdv = 0.5 * amp * np.cos(k * v)[:, None] * np.ones((1, n))    # rows: v
    nrm = np.stack([-dhdu, -dhdv, np.ones((n, n))], -1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    t = np.ones((n, n, 4), np.float32)
    t[..., :3] = nrm * 0.5 + 0.5
    return np.round(t * 255) / 255


def textured(name, img, socket, interpolation="Linear", normal_strength=None, **inputs):
    """A Principled BSDF with an Image Texture on `socket` (or through a Normal Map node on
    Normal, at `normal_strength`); its other inputs as in principled()."""
    m = principled(name, **inputs)
    nt = m.node_tree
    p = nt.nodes["Principled BSDF"]
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = interpolation
    if normal_strength is None:
        nt.links.new(tex.outputs["Color"], p.inputs[socket])
    else:
        nm = nt.nodes.new("ShaderNodeNormalMap")
        nm.space = "TANGENT"
        nm.inputs["Strength"].default_value = normal_strength
        nt.links.new(tex.outputs["Color"], nm.inputs["Color"])
        nt.links.new(nm.outputs["Normal"], p.inputs["Normal"])
    return m


def scene(fn):
    """A feature builder: an empty file first (materials made before it would be freed)."""
    def builder():
        _reset()
        fn()
    builder.__name__, builder.__doc__ = fn.__name__, fn.__doc__
    return builder


# ---- features ----

RED = (0.8, 0.15, 0.1)
BLUE = (0.1, 0.2, 0.6)
GOLD = (0.95, 0.7, 0.35)
DARK = (0.05, 0.05, 0.05)


@scene
def base_color():
    row([principled(f"Base{i}", Base_Color=c) for i, c in enumerate(
        [(0.8, 0.8, 0.8), RED, (0.15, 0.6, 0.15), BLUE])])


@scene
def metallic():
    row([principled(f"Metallic{v}", Base_Color=GOLD, Metallic=v, Roughness=0.3)
         for v in (0.0, 0.5, 1.0)])


ROUGH = (0.05, 0.3, 0.7, 1.0)


@scene
def roughness_dielectric():
    row([principled(f"Rough{v}", Base_Color=BLUE, Roughness=v) for v in ROUGH])


@scene
def roughness_metal():
    row([principled(f"RoughMetal{v}", Base_Color=GOLD, Metallic=1.0, Roughness=v)
         for v in ROUGH])


@scene
def ior():
    row([principled(f"IOR{v}", Base_Color=(0.2, 0.2, 0.2), Roughness=0.2, IOR=v)
         for v in (1.2, 1.5, 2.5)])


@scene
def specular_ior_level():
    row([principled(f"Level{v}", Base_Color=(0.3, 0.5, 0.2), Roughness=0.2,
                    Specular_IOR_Level=v) for v in (0.0, 0.5, 1.0)])


TINTS = ((1.0, 1.0, 1.0), (1.0, 0.5, 0.2), (0.2, 0.5, 1.0))


@scene
def specular_tint():
    row([principled(f"SpecTint{i}", Base_Color=DARK, Roughness=0.2, Specular_Tint=t)
         for i, t in enumerate(TINTS)])


TRANSMISSION = ((0.5, 0.0), (1.0, 0.0), (0.5, 0.3), (1.0, 0.3))   # (weight, roughness)


@scene
def transmission():
    row([principled(f"Glass{w}_{r}", Base_Color=(1.0, 1.0, 1.0), Transmission_Weight=w,
                    Roughness=r) for w, r in TRANSMISSION])


COAT_BASE = dict(Base_Color=RED, Roughness=0.5)


@scene
def coat_weight():
    row([principled(f"Coat{v}", Coat_Weight=v, Coat_Roughness=0.05, **COAT_BASE)
         for v in (0.0, 0.5, 1.0)])


@scene
def coat_roughness():
    row([principled(f"CoatRough{v}", Coat_Weight=1.0, Coat_Roughness=v, **COAT_BASE)
         for v in (0.03, 0.3, 0.7)])


@scene
def coat_ior():
    row([principled(f"CoatIOR{v}", Coat_Weight=1.0, Coat_Roughness=0.1, Coat_IOR=v,
                    **COAT_BASE) for v in (1.3, 1.5, 2.0)])


COAT_TINTS = ((1.0, 1.0, 1.0), (0.9, 0.7, 0.5), (0.5, 0.7, 0.9))


@scene
def coat_tint():
    row([principled(f"CoatTint{i}", Coat_Weight=1.0, Coat_Roughness=0.1, Coat_Tint=t,
                    Base_Color=(0.7, 0.7, 0.7), Roughness=0.5) for i, t in enumerate(COAT_TINTS)])


SHEEN_BASE = dict(Base_Color=(0.1, 0.1, 0.3), Roughness=0.8)


@scene
def sheen_weight():
    row([principled(f"Sheen{v}", Sheen_Weight=v, Sheen_Roughness=0.5, **SHEEN_BASE)
         for v in (0.0, 0.5, 1.0)])


@scene
def sheen_roughness():
    row([principled(f"SheenRough{v}", Sheen_Weight=1.0, Sheen_Roughness=v, **SHEEN_BASE)
         for v in (0.1, 0.5, 1.0)])


@scene
def sheen_tint():
    row([principled(f"SheenTint{i}", Sheen_Weight=1.0, Sheen_Roughness=0.5, Sheen_Tint=t,
                    **SHEEN_BASE) for i, t in enumerate(TINTS)])


EMISSION = (0.0, 1.0, 4.0)


@scene
def emission_strength():
    row([principled(f"Emit{v}", Base_Color=(0.5, 0.5, 0.5), Emission_Color=(1.0, 0.8, 0.6),
                    Emission_Strength=v) for v in EMISSION])


@scene
def alpha():
    row([principled(f"Alpha{v}", Base_Color=RED, Alpha=v) for v in (0.25, 0.5, 0.75)])


@scene
def subsurface_weight():
    row([principled(f"SSS{v}", Base_Color=(0.8, 0.5, 0.4), Subsurface_Weight=v,
                    Subsurface_Scale=0.1) for v in (0.0, 0.5, 1.0)])


COLORS3 = ((0.8, 0.8, 0.8), RED, BLUE)


@scene
def diffuse_bsdf():
    row([shader(f"Diffuse{i}", "ShaderNodeBsdfDiffuse", Color=c, Roughness=0.0)
         for i, c in enumerate(COLORS3)])


@scene
def glossy_bsdf():
    row([shader(f"Glossy{v}", "ShaderNodeBsdfGlossy", Color=GOLD, Roughness=v)
         for v in (0.05, 0.3, 0.7)])


GLASS = ((0.0, 1.5), (0.3, 1.5), (0.0, 1.33))   # (roughness, IOR)


@scene
def glass_bsdf():
    row([shader(f"GlassBSDF{r}_{n}", "ShaderNodeBsdfGlass", Color=(1.0, 1.0, 1.0),
                Roughness=r, IOR=n) for r, n in GLASS])


@scene
def translucent_bsdf():
    row([shader(f"Translucent{i}", "ShaderNodeBsdfTranslucent", Color=c)
         for i, c in enumerate(COLORS3)])


DIFF = ("ShaderNodeBsdfDiffuse", dict(Color=(0.7, 0.7, 0.7), Roughness=0.0))
GLOSS = ("ShaderNodeBsdfGlossy", dict(Color=GOLD, Roughness=0.2))


@scene
def mix_shader():
    row([mix(f"Mix{f}", f, DIFF, GLOSS) for f in (0.3, 0.5, 0.7)])


ADD = (("diffuse+glossy", DIFF, GLOSS),
       ("diffuse+translucent", ("ShaderNodeBsdfDiffuse", dict(Color=(0.4, 0.2, 0.1))),
        ("ShaderNodeBsdfTranslucent", dict(Color=(0.1, 0.3, 0.4)))),
       ("glossy+emission", ("ShaderNodeBsdfGlossy", dict(Color=(0.4, 0.4, 0.4),
                                                               Roughness=0.3)),
        ("ShaderNodeEmission", dict(Color=(0.2, 0.6, 1.0), Strength=1.0))))


@scene
def add_shader():
    row([mix(f"Add{i}", 0.0, a, b, add=True) for i, (_, a, b) in enumerate(ADD)])


INTERP = ("Closest", "Linear", "Cubic")


@scene
def image_base_color():
    img = image("Checker", checker_texels(), "sRGB")
    row([textured(f"Checker{i}", img, "Base Color", interpolation=it)
         for i, it in enumerate(INTERP)])


ROUGH_TEX = ((0.0, (0.5, 0.5, 0.5)), (0.5, GOLD), (1.0, GOLD))   # (metallic, base)


@scene
def image_roughness():
    img = image("RoughStripes", stripe_texels(), "Non-Color")
    row([textured(f"RoughTex{mt}", img, "Roughness", Metallic=mt, Base_Color=b)
         for mt, b in ROUGH_TEX])


NORMAL_STRENGTH = (0.5, 1.0, 2.0)


@scene
def normal_map():
    img = image("Ridges", ridge_normal_texels(), "Non-Color")
    row([textured(f"Normal{s}", img, None, normal_strength=s, Base_Color=(0.6, 0.6, 0.6),
                  Roughness=0.4) for s in NORMAL_STRENGTH])


FILM = (0.0, 250.0, 500.0, 800.0)   # Thin Film Thickness, nm


@scene
def thin_film():
    row([principled(f"Film{d}", Base_Color=DARK, Roughness=0.2, Thin_Film_Thickness=d,
                    Thin_Film_IOR=1.33) for d in FILM])


@scene
def thin_film_metal():
    row([principled(f"FilmMetal{d}", Base_Color=(0.9, 0.9, 0.9), Metallic=1.0, Roughness=0.2,
                    Thin_Film_Thickness=d, Thin_Film_IOR=1.33) for d in FILM])


def _labels(prefix, values):
    return tuple(f"{prefix}{v}" for v in values)


FEATURES = {
    "base_color": Feature(base_color, ("white 0.8", "red", "green", "blue"),
                          "Principled Base Color (roughness 0.5, IOR 1.5, level 0.5)"),
    "metallic": Feature(metallic, _labels("", (0, 0.5, 1)), "Metallic, gold base, roughness 0.3"),
    "roughness_dielectric": Feature(roughness_dielectric, _labels("", ROUGH),
                                    "Roughness, blue dielectric"),
    "roughness_metal": Feature(roughness_metal, _labels("", ROUGH), "Roughness, gold Metallic 1"),
    "ior": Feature(ior, _labels("", (1.2, 1.5, 2.5)), "IOR, grey 0.2 base, roughness 0.2"),
    "specular_ior_level": Feature(specular_ior_level, _labels("", (0, 0.5, 1)),
                                  "Specular IOR Level, green base, roughness 0.2"),
    "specular_tint": Feature(specular_tint, ("white", "orange", "blue"),
                             "Specular Tint, base 0.05, roughness 0.2"),
    "transmission": Feature(transmission, tuple(f"{w} r{r}" for w, r in TRANSMISSION),
                            "Transmission Weight (white glass, IOR 1.5) at roughness 0 and 0.3"),
    "coat_weight": Feature(coat_weight, _labels("", (0, 0.5, 1)),
                           "Coat Weight (coat roughness 0.05) over red roughness 0.5"),
    "coat_roughness": Feature(coat_roughness, _labels("", (0.03, 0.3, 0.7)),
                              "Coat Roughness, Coat Weight 1, over red"),
    "coat_ior": Feature(coat_ior, _labels("", (1.3, 1.5, 2.0)),
                        "Coat IOR, Coat Weight 1, coat roughness 0.1, over red"),
    "coat_tint": Feature(coat_tint, ("white", "(0.9,0.7,0.5)", "(0.5,0.7,0.9)"),
                         "Coat Tint, Coat Weight 1, over grey 0.7"),
    "sheen_weight": Feature(sheen_weight, _labels("", (0, 0.5, 1)),
                            "Sheen Weight (sheen roughness 0.5) on dark blue roughness 0.8"),
    "sheen_roughness": Feature(sheen_roughness, _labels("", (0.1, 0.5, 1.0)),
                               "Sheen Roughness, Sheen Weight 1, on dark blue"),
    "sheen_tint": Feature(sheen_tint, ("white", "orange", "blue"),
                          "Sheen Tint, Sheen Weight 1, on dark blue"),
    "emission_strength": Feature(emission_strength, _labels("", EMISSION),
                                 "Emission Strength, colour (1, 0.8, 0.6), base 0.5"),
    "alpha": Feature(alpha, _labels("", (0.25, 0.5, 0.75)), "Alpha, red Principled"),
    "subsurface_weight": Feature(subsurface_weight, _labels("", (0, 0.5, 1)),
                                 "Subsurface Weight (scale 0.1), skin-ish base"),
    "diffuse_bsdf": Feature(diffuse_bsdf, ("white 0.8", "red", "blue"),
                            "Diffuse BSDF (roughness 0) colours"),
    "glossy_bsdf": Feature(glossy_bsdf, _labels("", (0.05, 0.3, 0.7)),
                           "Glossy BSDF roughness, gold colour"),
    "glass_bsdf": Feature(glass_bsdf, tuple(f"r{r} IOR {n}" for r, n in GLASS),
                          "Glass BSDF roughness / IOR"),
    "translucent_bsdf": Feature(translucent_bsdf, ("white 0.8", "red", "blue"),
                                "Translucent BSDF colours"),
    "mix_shader": Feature(mix_shader, _labels("", (0.3, 0.5, 0.7)),
                          "Mix Shader Fac: Diffuse 0.7 + Glossy gold r 0.2"),
    "add_shader": Feature(add_shader, tuple(a for a, _, _ in ADD), "Add Shader pairs"),
    "image_base_color": Feature(image_base_color, INTERP,
                                "checker Image Texture (sRGB) on Base Color, interpolation"),
    "image_roughness": Feature(image_roughness, ("metallic 0", "metallic 0.5", "metallic 1"),
                               "stripes 0.1 / 0.7 Image Texture (Non-Color) on Roughness"),
    "normal_map": Feature(normal_map, _labels("strength ", NORMAL_STRENGTH),
                          "ridge normal map (Non-Color) through a Normal Map node"),
    "thin_film": Feature(thin_film, _labels("", FILM),
                         "Thin Film Thickness (nm, film IOR 1.33), base 0.05, roughness 0.2"),
    "thin_film_metal": Feature(thin_film_metal, _labels("", FILM),
                               "Thin Film Thickness (nm, film IOR 1.33) on a grey 0.9 metal, "
                               "roughness 0.2"),
}


def build(name, path=None):
    """Build feature scene `name` into the current bpy data; save it to `path` if given."""
    FEATURES[name].build()
    if path:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        bpy.ops.wm.save_as_mainfile(filepath=path, check_existing=False)
    return path


def register(scenes_dict, prefix="feature_"):
    """Add the builders to a scenes.SCENES-like dict as prefix + name (build.py)."""
    for name, f in FEATURES.items():
        scenes_dict.setdefault(prefix + name, f.build)


def sphere_pixels(n=None):
    """Pixel centres (x, y, radius in pixels; y from the top) of the current scene's spheres,
    left to right, projected through its camera."""
    from bpy_extras.object_utils import world_to_camera_view
    scene = bpy.context.scene
    cam = scene.camera
    w, h = scene.render.resolution_x, scene.render.resolution_y
    objs = sorted((o for o in scene.objects if o.name.startswith("Sphere")),
                  key=lambda o: o.location.x)
    out = []
    for o in objs:
        c = world_to_camera_view(scene, cam, o.location)
        # the radius: project a point offset perpendicular to the view ray, in the image plane
        right = cam.matrix_world.to_3x3() @ Vector((1.0, 0.0, 0.0))
        e = world_to_camera_view(scene, cam, o.location + right * RADIUS)
        out.append((c.x * w, (1.0 - c.y) * h, abs(e.x - c.x) * w))
    return out
