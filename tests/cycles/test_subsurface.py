"""Random-walk subsurface scattering against Cycles through the add-on (docs/subsurface.md),
CI-sized: three small scenes built here in bpy, each rendered with K seeds by Cycles (CPU) and by
Lantern (pt) with tools/render_compare.py's settings, compared by lantern.metrics.assert_agreement
(Welch t per 8x8 block and channel, the image and block means within the bias cap plus noise, and
negative controls that must fail):

- marble: a sphere of Principled BSDF with Subsurface Weight 1 (Random Walk, a long radius) on a
  floor under an area light;
- skin: a smooth torus with Random Walk (Skin), a reddish radius, lit by a point light;
- slab: a thin slab lit from behind by an area light, seen from the front (only light that
  walked through the slab reaches the camera: an ear against the light);
- head: Suzanne (open at the eyes, the eyeballs separate parts) with a Subdivision Surface
  modifier, Random Walk (Skin), under a point light; its negative control is the same head with
  the radius 20 % longer, which must fail against Cycles' renders of the head.
Strict expected failures record what is left (docs/subsurface.md): the head with its eyeballs
(1 % dark), its simplest form (a sphere crossed by a smaller sphere of the same mesh, 2 % dark),
and the unsubdivided Suzanne, 4 % dark against Cycles with no subsurface at all.
Before subsurface scattering, Lantern rendered these as the diffuse base (a warning), which
fails each comparison by far more than the noise."""

import os
import sys

import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402
from bpy_stage import camera as _camera, cube as _cube, light as _light  # noqa: E402

K = 6
SIZE = 32
SE_FLOOR = 1e-6
SPP = {"marble": (128, 128), "skin": (128, 128), "slab": (128, 128), "head": (128, 128)}
# negative controls (image, block) the noise affords at these sample counts
CONTROLS = {"marble": (0.02, 0.10), "skin": (0.02, 0.10), "slab": (0.02, 0.10),
            "head": (0.02, 0.10)}



def _reset():
    return bpy_stage.reset(SIZE)


def _material(name, color=(0.8, 0.8, 0.8), roughness=1.0, sss=0.0, radius=(1.0, 0.2, 0.1),
              scale=0.05, method="RANDOM_WALK", ior=1.4, anisotropy=0.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*color, 1.0)
    p.inputs["Roughness"].default_value = roughness
    p.inputs["Subsurface Weight"].default_value = sss
    p.inputs["Subsurface Radius"].default_value = radius
    p.inputs["Subsurface Scale"].default_value = scale
    p.inputs["Subsurface Anisotropy"].default_value = anisotropy
    p.subsurface_method = method
    if method == "RANDOM_WALK_SKIN":  # Random Walk enters with the main IOR (the socket is off)
        p.inputs["Subsurface IOR"].default_value = ior
    return m





def marble():
    scene = _reset()
    _cube("floor", (0, 0, -0.05), 1.0, _material("floor", (0.5, 0.5, 0.5)), scale=(6, 6, 0.1))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(0, 0, 0.6), segments=32,
                                         ring_count=16)
    obj = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(_material("marble", (0.9, 0.88, 0.85), roughness=0.3, sss=1.0,
                                        radius=(1.0, 0.8, 0.6), scale=0.1))
    _light(scene, "AREA", (1.2, -1.0, 2.2), 200.0, rotation=(35, 30, 0), size=1.0)
    _camera(scene, (0, -3.2, 1.2), (78, 0, 0), lens=40.0)


def skin():
    # a smooth torus: closed and concave (light leaves one part and enters another); the head
    # below is the open mesh with separate parts
    scene = _reset()
    bpy.ops.mesh.primitive_torus_add(major_radius=0.6, minor_radius=0.25, rotation=(1.2, 0, 0))
    obj = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(_material("skin", (0.8, 0.55, 0.45), roughness=0.5, sss=1.0,
                                        radius=(1.0, 0.35, 0.2), scale=0.08,
                                        method="RANDOM_WALK_SKIN"))
    _light(scene, "POINT", (1.0, -2.0, 1.5), 300.0, shadow_soft_size=0.2)
    _camera(scene, (0, -3.5, 0.2), (88, 0, 0), lens=45.0)


def slab():
    scene = _reset()
    # 2 cm thick, mean free paths 2.4 / 1.6 / 1.2 cm (Radius x Scale / 4 pi): every channel
    # comes through; it fills the view, the light behind it faces the camera
    _cube("slab", (0, 0, 0), 1.0, _material("ear", (0.9, 0.75, 0.7), roughness=0.5, sss=1.0,
                                            radius=(1.0, 0.65, 0.5), scale=0.3),
          scale=(1.6, 0.02, 1.6))
    _light(scene, "AREA", (0, 1.0, 0), 150.0, rotation=(-90, 0, 0), size=1.0)  # faces -Y
    _camera(scene, (0, -2.0, 0), (90, 0, 0), lens=50.0)


def _skin_material(scale=0.08):
    return _material("skin", (0.8, 0.55, 0.45), roughness=0.5, sss=1.0, radius=(1.0, 0.35, 0.2),
                     scale=scale, method="RANDOM_WALK_SKIN")


def _suzanne(material, levels, eyeballs=True):
    """Suzanne under a point light; material() makes its material (after the reset); without
    eyeballs: its two smaller loose parts deleted (the head alone, open at the eyes)."""
    scene = _reset()
    bpy.ops.mesh.primitive_monkey_add()
    obj = bpy.context.active_object
    if not eyeballs:
        import bmesh
        bm = bmesh.new()
        bm.from_mesh(obj.data)
        parts, seen = [], set()
        for f in bm.faces:
            if f in seen:
                continue
            part, stack = [], [f]
            seen.add(f)
            while stack:
                g = stack.pop()
                part.append(g)
                for e in g.edges:
                    for h in e.link_faces:
                        if h not in seen:
                            seen.add(h)
                            stack.append(h)
            parts.append(part)
        parts.sort(key=len)
        assert [len(p) for p in parts] == [32, 32, 436], [len(p) for p in parts]
        bmesh.ops.delete(bm, geom=parts[0] + parts[1], context="FACES")
        bm.to_mesh(obj.data)
        bm.free()
    bpy.ops.object.shade_smooth()
    if levels:
        sub = obj.modifiers.new("subdivision", "SUBSURF")
        sub.levels = sub.render_levels = levels
    obj.data.materials.append(material())
    _light(scene, "POINT", (1.0, -2.0, 1.5), 300.0, shadow_soft_size=0.2)
    _camera(scene, (0, -3.5, 0.2), (88, 0, 0), lens=45.0)
    return obj


def head(eyeballs=False):
    # Suzanne: open at the eyes, thin ears; its eyeballs (separate parts of the same mesh) only
    # in test_head_eyeballs. Subdivided twice (the unsubdivided mesh: test_coarse_head_diffuse).
    # Radius x Scale 25 cm red: the torus's 8 cm is under a pixel here and renders as its
    # diffuse base within noise
    _suzanne(lambda: _skin_material(0.25), 2, eyeballs)


SCENES = {"marble": marble, "skin": skin, "slab": slab}


@pytest.mark.parametrize("name", list(SCENES))
def test_subsurface_matches_cycles(name):
    bpy_stage.compare_with_cycles(name, SCENES[name], SPP[name], CONTROLS[name],
                                  cycles_seed0=900, k_seeds=K, se_floor=SE_FLOOR)


def test_head_matches_cycles():
    """The head (open at the eyes, no eyeballs) against Cycles, then its negative controls, which
    must not pass against Cycles' renders of the head as it was: the same head with Radius x
    Scale twice as long, and with Subsurface Weight 0 (the diffuse base). (A radius 20 % longer
    passes at this size: docs/subsurface.md.)"""
    name = "head"
    cyc = bpy_stage.compare_with_cycles(name, head, SPP[name], CONTROLS[name],
                                        cycles_seed0=900, k_seeds=K, se_floor=SE_FLOOR)
    p = bpy.data.materials["skin"].node_tree.nodes["Principled BSDF"]
    p.inputs["Subsurface Scale"].default_value *= 2.0
    bpy_stage.control_differs("head, radius x2", cyc, K, SPP[name][1], SE_FLOOR)
    p.inputs["Subsurface Weight"].default_value = 0.0
    bpy_stage.control_differs("head, weight 0", cyc, K, SPP[name][1], SE_FLOOR)


@pytest.mark.long  # 8 s of CI for a known gap (docs/subsurface.md)
@pytest.mark.xfail(strict=True, reason="docs/subsurface.md: Suzanne with its eyeballs renders "
                   "1 % dark against Cycles (without them it agrees)")
def test_head_eyeballs():
    """The head with its eyeballs, separate parts of the same mesh sitting in the open eye
    sockets: 1 % dark against Cycles, where the same head without them agrees; strict, so it
    reports when that difference is found and fixed."""
    bpy_stage.compare_with_cycles("head with eyeballs", lambda: head(eyeballs=True), SPP["head"],
                                  CONTROLS["head"], cycles_seed0=900, k_seeds=K,
                                  se_floor=SE_FLOOR)


def test_coarse_head_diffuse():
    """The head without subdivision, smooth shaded, with a plain diffuse Principled (roughness 1,
    Specular IOR Level 0, no subsurface): its coarse triangles' shadow terminator, lifted as
    Cycles lifts it (Shadow Terminator Geometry Offset, Blender's default 0.1: docs/materials.md
    "Shadow terminator"; 4.2 % dark before). Its negative control: the same head with the
    offset 0 in Lantern's scene alone (what Lantern rendered before), against Cycles' renders
    with 0.1."""
    def diffuse():
        m = _material("diffuse", (0.8, 0.55, 0.45), roughness=1.0)
        m.node_tree.nodes["Principled BSDF"].inputs["Specular IOR Level"].default_value = 0.0
        return m
    cyc = bpy_stage.compare_with_cycles("coarse head, diffuse", lambda: _suzanne(diffuse, 0),
                                        (128, 128), CONTROLS["head"], cycles_seed0=900, k_seeds=K,
                                        se_floor=SE_FLOOR)
    for o in bpy.data.objects:
        if o.type == "MESH":
            o.shadow_terminator_geometry_offset = 0.0
    bpy_stage.control_differs("coarse head, no terminator offset", cyc, K, 128, SE_FLOOR)


@pytest.mark.xfail(strict=True, reason="docs/subsurface.md: a closed part crossing the surface of "
                   "another in the same mesh renders dark against Cycles")
def test_intersecting_parts():
    """The eyeballs' difference in its simplest form: a sphere and a smaller sphere crossing its
    surface (half in, half out), one mesh, Skin with Radius x Scale 25 cm red, under the head's
    point light: 2 % dark against Cycles (red 3.3-3.6 %), where the big sphere alone agrees
    (docs/subsurface.md has the neighbouring cases); strict, so it reports when fixed."""
    import bmesh

    def build():
        scene = _reset()
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, segments=32, ring_count=16)
        obj = bpy.context.active_object
        bm = bmesh.new()
        bm.from_mesh(obj.data)
        small = bmesh.ops.create_uvsphere(bm, u_segments=16, v_segments=8, radius=0.25)
        bmesh.ops.translate(bm, vec=(0.25, -0.62, 0.15), verts=small["verts"])
        bm.to_mesh(obj.data)
        bm.free()
        bpy.ops.object.shade_smooth()
        obj.data.materials.append(_skin_material(0.25))
        _light(scene, "POINT", (1.0, -2.0, 1.5), 300.0, shadow_soft_size=0.2)
        _camera(scene, (0, -3.5, 0.2), (88, 0, 0), lens=45.0)

    bpy_stage.compare_with_cycles("intersecting parts", build, SPP["head"], CONTROLS["head"],
                                  cycles_seed0=900, k_seeds=K, se_floor=SE_FLOOR)
