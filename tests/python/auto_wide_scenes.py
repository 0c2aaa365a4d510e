"""Scenes of lantern.scenes with one feature that `auto` used to give to pt alone
(native/src/integrator/allocation.cpp pt_only_reason; branch autowide): tests/python/
test_auto_wide.py and bench/auto_wide.py. Each builder takes (width, height)."""
import numpy as np

from lantern import scenes


def _mesh(scene, name):
    for m in scene.meshes:
        if m.get("name") == name:
            return m
    raise KeyError(name)


def slide(scene, name, dx):
    """Mesh `name` (world-space vertices) slides by +-dx along x over the shutter."""
    steps = []
    for t in (0.0, 0.5, 1.0):
        m = np.eye(4)
        m[0, 3] = dx * (2.0 * t - 1.0)
        steps.append(m)
    mesh = _mesh(scene, name)
    mesh["motion"] = steps
    mesh["motion_base"] = np.eye(4)
    return scene


def cornell_motion(width, height):
    """The Cornell box, its tall box sliding 0.6 m (cis ~0.5x pt's efficiency, still)."""
    return slide(scenes.cornell_box(width, height), "tall_box", 0.3)


def lantern_motion(width, height):
    """The glass lantern (a bulb in a closed glass cube), the tall box under it sliding 0.6 m
    (cis many times pt's efficiency, still)."""
    return slide(scenes.glass_lantern(width, height), "tall_box", 0.3)


def glossy_motion(width, height):
    """The glossy box (metal floor, a tiny sphere light), its short box sliding 0.6 m (cis
    ~2-3x pt's efficiency, still: bench/results/2026-12-04-auto4)."""
    return slide(scenes.glossy_box(width, height), "short_box", 0.3)


def _lantern_with_lamp(width, height, power=5.0):
    """The glass lantern with the Cornell box's ceiling light added, weak (light 1)."""
    scene = scenes.glass_lantern(width, height)
    scenes._ceiling_light(scene, power)
    return scene


def cornell_light_link(width, height):
    """Light linking: the ceiling light lights every surface but the tall box."""
    scene = scenes.cornell_box(width, height)
    _mesh(scene, "tall_box")["light_set"] = 1
    scene.lights[0]["receivers"] = [0]
    return scene


def lantern_light_link(width, height):
    """Light linking: the weak ceiling light lights the tall box alone (the bulb all)."""
    scene = _lantern_with_lamp(width, height)
    _mesh(scene, "tall_box")["light_set"] = 1
    scene.lights[1]["receivers"] = [1]
    return scene


def cornell_shadow_link(width, height):
    """Shadow linking: the ceiling light's shadows are cast by the short box alone."""
    scene = scenes.cornell_box(width, height)
    _mesh(scene, "short_box")["shadow_set"] = 1
    scene.lights[0]["blockers"] = [1]
    return scene


def lantern_shadow_link(width, height):
    """Shadow linking: the bulb's shadows are cast by its glass alone (not the tall box)."""
    scene = scenes.glass_lantern(width, height)
    _mesh(scene, "lantern_glass")["shadow_set"] = 1
    scene.lights[0]["blockers"] = [1]
    return scene


def cornell_lamp_noshadow(width, height):
    """The ceiling light's Cast Shadow off."""
    scene = scenes.cornell_box(width, height)
    scene.lights[0]["cast_shadow"] = False
    return scene


def lantern_lamp_noshadow(width, height):
    """The glass lantern and a weak ceiling light whose Cast Shadow is off."""
    scene = _lantern_with_lamp(width, height)
    scene.lights[1]["cast_shadow"] = False
    return scene


def cornell_object_noshadow(width, height):
    """The tall box's Cast Shadow off."""
    scene = scenes.cornell_box(width, height)
    _mesh(scene, "tall_box")["cast_shadow"] = False
    return scene


def lantern_object_noshadow(width, height):
    """The glass lantern, the tall box under it with Cast Shadow off."""
    scene = scenes.glass_lantern(width, height)
    _mesh(scene, "tall_box")["cast_shadow"] = False
    return scene


def _glossy(width, height, feature):
    """The glossy box (cis ~2-3x pt) with `feature` on its tiny light (light 0) or short box:
    "light": the light lights every surface but the left wall; "shadow": its shadows are cast by
    the walls alone (not the short box); "lamp": its Cast Shadow off; "object": the short box's
    Cast Shadow off. Each lights the floor under the short box or darkens the left wall."""
    scene = scenes.glossy_box(width, height)
    if feature == "light":
        _mesh(scene, "left")["light_set"] = 1
        scene.lights[0]["receivers"] = [0]
    elif feature == "shadow":
        for wall in ("floor", "ceiling", "back", "left", "right"):
            _mesh(scene, wall)["shadow_set"] = 1
        scene.lights[0]["blockers"] = [1]
    elif feature == "lamp":
        scene.lights[0]["cast_shadow"] = False
    elif feature == "object":
        _mesh(scene, "short_box")["cast_shadow"] = False
    return scene


def quad(z, half, cx=0.0, cy=0.0):
    v = np.array([[cx - half, cy - half, z], [cx + half, cy - half, z],
                  [cx + half, cy + half, z], [cx - half, cy + half, z]], np.float32)
    return v, np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def slab_stage(feature=None, big=False, size=16):
    """A floor (mesh 0) and a red slab 0.5 m above it (mesh 1) under one light 1.2 m up: a 1.5
    m square area light (`big`) or a 3 cm sphere (soft falloff off), hidden from the camera,
    which looks down at the slab's shadow; world black. `feature` as _glossy's, on the slab:
    "light" (the light lights the floor alone), "shadow" (its shadows cast by the slab alone:
    the same image; every segment to the light is free of surfaces or blocked, so pt keeps its
    two techniques: pt_light_linking.h), "shadow_passed" (as "shadow", with a 3 m sheet 0.9 m
    up, hidden from the camera, that casts the light no shadow: the same image, and every
    segment from the floor or the slab to the light passes it, where pt's next-event
    estimation is its only technique of the light), "glossy_hidden" (the slab hidden from
    glossy rays: the same image, as the stage's materials are diffuse, but paths whose bounce
    lands on the slab are restricted, made by pt's two techniques alone:
    bidir_ray_visibility.h), "diffuse_hidden" (hidden from diffuse rays: BSDF sampling passes
    the slab, next-event estimation's shadow ray does not), "lamp", "object"."""
    from lantern import Scene
    s = Scene()
    s.film.update(width=size, height=size)
    s.look_at((0.0, -2.5, 2.0), (0.0, 0.0, 0.0), up=(0, 0, 1), fov=50.0)
    white = s.add_material("white", base_color=(0.8, 0.8, 0.8))
    red = s.add_material("red", base_color=(0.8, 0.3, 0.2))
    s.add_mesh(*quad(0.0, 3.0), material=white, name="floor")
    s.add_mesh(*quad(0.5, 0.35, 0.2, 0.1), material=red, name="slab")
    if big:
        s.add_light("area", to_world=[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1.2], [0, 0, 0, 1]],
                    shape="square", size=[1.5, 1.5], power=[60.0] * 3, name="lamp",
                    visible_camera=False)
    else:
        s.add_light("point", position=[0.0, 0.0, 1.2], radius=0.03, power=[30.0] * 3,
                    soft_falloff=False, visible_camera=False, name="lamp")
    s.world = {"color": [0.0] * 3}
    if feature == "light":
        s.meshes[1]["light_set"] = 1
        s.lights[0]["receivers"] = [0]
    elif feature in ("shadow", "shadow_passed"):
        s.meshes[1]["shadow_set"] = 1
        s.lights[0]["blockers"] = [1]
        if feature == "shadow_passed":
            s.add_mesh(*quad(0.9, 1.5), material=white, name="sheet")
            s.meshes[2].update(shadow_set=2, visible_camera=False)
    elif feature in ("glossy_hidden", "diffuse_hidden"):  # the slab hidden from those rays
        s.meshes[1]["visible_" + feature.split("_")[0]] = False
    elif feature == "lamp":
        s.lights[0]["cast_shadow"] = False
    elif feature == "object":
        s.meshes[1]["cast_shadow"] = False
    return s


def _skin(scene, name, method="random_walk"):
    """Mesh `name` in a principled material with Random Walk subsurface (radius 0.2, 0.1, 0.05
    m), an orange base."""
    m = scene.add_material("skin", type="principled", base_color=(0.8, 0.55, 0.4),
                           roughness=0.5, subsurface={"weight": 1.0, "radius": [0.2, 0.1, 0.05],
                                                      "method": method})
    mesh = _mesh(scene, name)
    mesh["material_ids"] = np.full(len(mesh["material_ids"]), m, dtype=np.uint32)
    return scene


def cornell_sss(width, height):
    """The Cornell box, its tall box of Random Walk subsurface."""
    return _skin(scenes.cornell_box(width, height), "tall_box")


def lantern_sss(width, height):
    """The glass lantern, the tall box under it of Random Walk subsurface."""
    return _skin(scenes.glass_lantern(width, height), "tall_box")


def glossy_sss(width, height):
    """The glossy box, its short box of Random Walk subsurface."""
    return _skin(scenes.glossy_box(width, height), "short_box")


def hidden(make, what, kind):
    """Scene `make` with mesh `what` (or light 0: "lamp") hidden from `kind` rays ("glossy",
    "diffuse", "transmission"): object and lamp ray visibility (bidir_ray_visibility.h)."""
    def scene_of(width, height):
        scene = make(width, height)
        (scene.lights[0] if what == "lamp" else _mesh(scene, what))["visible_" + kind] = False
        return scene
    return scene_of


SCENES = {
    "cornell_motion": cornell_motion,
    "lantern_motion": lantern_motion,
    "glossy_motion": glossy_motion,
    "glossy_light_link": lambda w, h: _glossy(w, h, "light"),
    "glossy_shadow_link": lambda w, h: _glossy(w, h, "shadow"),
    "glossy_lamp_noshadow": lambda w, h: _glossy(w, h, "lamp"),
    "glossy_object_noshadow": lambda w, h: _glossy(w, h, "object"),
    "cornell_light_link": cornell_light_link,
    "cornell_sss": cornell_sss,
    "lantern_sss": lantern_sss,
    "glossy_sss": glossy_sss,
    "lantern_light_link": lantern_light_link,
    "cornell_shadow_link": cornell_shadow_link,
    "lantern_shadow_link": lantern_shadow_link,
    "cornell_lamp_noshadow": cornell_lamp_noshadow,
    "lantern_lamp_noshadow": lantern_lamp_noshadow,
    "cornell_object_noshadow": cornell_object_noshadow,
    "lantern_object_noshadow": lantern_object_noshadow,
    # ray visibility (branch automis): the all-diffuse Cornell box's image is unchanged by a
    # box hidden from glossy rays (paths that land on it are restricted in cis), changed by one
    # hidden from diffuse rays; the glossy box's short box, or its lamp, hidden from glossy rays
    # (the metal floor does not reflect it); the glass lantern's tall box hidden from glossy
    "cornell_glossy_hidden": hidden(scenes.cornell_box, "tall_box", "glossy"),
    "cornell_diffuse_hidden": hidden(scenes.cornell_box, "tall_box", "diffuse"),
    "glossy_glossy_hidden": hidden(scenes.glossy_box, "short_box", "glossy"),
    "glossy_lamp_glossy_hidden": hidden(scenes.glossy_box, "lamp", "glossy"),
    "lantern_glossy_hidden": hidden(scenes.glass_lantern, "tall_box", "glossy"),
    # light linking beside subsurface scattering (branch automis): the glossy box's light
    # lighting every surface but the left wall, its short box of Random Walk subsurface; the
    # Cornell box's light lighting every surface but the tall box, its short box of it
    "glossy_sss_light_link": lambda w, h: _skin(_glossy(w, h, "light"), "short_box"),
    "cornell_sss_light_link": lambda w, h: _skin(cornell_light_link(w, h), "short_box"),
}
