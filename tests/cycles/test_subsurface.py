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
- head: Suzanne (open at the eyes) with a Subdivision Surface modifier, Random Walk (Skin),
  under a point light, without and with its eyeballs (separate parts of the mesh); the head
  without them has as negative controls the same head with the radius twice as long and with
  weight 0, which must fail against Cycles' renders of the head;
- parts: a sphere crossed by a smaller sphere of the same mesh, a sphere with a second one
  inside it, and (long) a sphere open towards the camera: the eyeballs' simplest forms, where
  light walks out of one part into another or paths meet the material again. All of these
  failed (the head with eyeballs 1 % dark) while Lantern turned subsurface into a Lambert lobe
  after a bounce, where Cycles 5.0 walks again (docs/subsurface.md, "After a bounce");
- the unsubdivided Suzanne with a diffuse Principled (its shadow terminator).
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
SPP = {"marble": (128, 128), "skin": (128, 128), "slab": (128, 128), "head": (128, 128),
       "parts": (128, 64), "open": (512, 256)}
# negative controls (image, block) the noise affords at these sample counts
# (the head's walks after a bounce, as Cycles 5.0's, leave it able to see about 3 %: 2 % passed)
CONTROLS = {"marble": (0.02, 0.10), "skin": (0.02, 0.10), "slab": (0.02, 0.10),
            "head": (0.03, 0.10)}



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


def test_head_eyeballs():
    """The head with its eyeballs, separate parts of the same mesh sitting in the open eye
    sockets (issue 32's scene): 1 % dark against Cycles while Lantern's paths turned subsurface
    into a Lambert lobe after a bounce, which trapped the light that walked into an eyeball
    (test_intersecting_parts)."""
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


def _spheres(edit, scale):
    """The head's light and camera on a smooth UV sphere (radius 0.7) of Skin with Radius x Scale
    `scale` (red), its mesh changed by edit(bm) (bmesh)."""
    import bmesh
    scene = _reset()
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, segments=32, ring_count=16)
    obj = bpy.context.active_object
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    edit(bm)
    bm.to_mesh(obj.data)
    bm.free()
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(_skin_material(scale))
    _light(scene, "POINT", (1.0, -2.0, 1.5), 300.0, shadow_soft_size=0.2)
    _camera(scene, (0, -3.5, 0.2), (88, 0, 0), lens=45.0)


def _add_sphere(radius, offset, u=16, v=8):
    def edit(bm):
        import bmesh
        small = bmesh.ops.create_uvsphere(bm, u_segments=u, v_segments=v, radius=radius)
        bmesh.ops.translate(bm, vec=offset, verts=small["verts"])
    return edit


def _open_front(bm):
    import bmesh
    bmesh.ops.delete(bm, geom=[f for f in bm.faces if f.calc_center_median().y < -0.55],
                     context="FACES")


def test_intersecting_parts():
    """The eyeballs in their simplest form: a sphere and a smaller sphere crossing its surface
    (half in, half out), one mesh, Skin with Radius x Scale 25 cm red, under the head's point
    light. Light that walks out of one sphere into the other, and the paths that come back to
    either, walk again in Cycles 5.0; where Lantern turned every hit after a bounce into a
    Lambert lobe, the light that walked into a part stayed trapped there: 2 % dark (red 3.5 %)."""
    bpy_stage.compare_with_cycles(
        "intersecting parts", lambda: _spheres(_add_sphere(0.25, (0.25, -0.62, 0.15)), 0.25),
        SPP["head"], CONTROLS["head"], cycles_seed0=900, k_seeds=K, se_floor=SE_FLOOR)


def test_inner_part():
    """A sphere with a second, smaller one wholly inside it (one mesh), Radius x Scale 50 cm red:
    light that walks into the inner sphere leaves it only by walking again (5 % dark in red,
    when Lantern's paths turned subsurface into a Lambert lobe after a bounce)."""
    bpy_stage.compare_with_cycles(
        "inner part", lambda: _spheres(_add_sphere(0.3, (0.0, -0.3, 0.0)), 0.5),
        SPP["parts"], CONTROLS["head"], cycles_seed0=900, k_seeds=K, se_floor=SE_FLOOR)


@pytest.mark.long  # 20 s: the inside of the open sphere is noisy
def test_open_part():
    """A sphere with a hole facing the camera and the light, Radius x Scale 50 cm red: the
    camera sees its inside, where paths bounce between walls that walk (4.4 % bright in red,
    when Lantern turned subsurface into a Lambert lobe after a bounce)."""
    bpy_stage.compare_with_cycles("open part", lambda: _spheres(_open_front, 0.5), SPP["open"],
                                  CONTROLS["head"], cycles_seed0=900, k_seeds=K,
                                  se_floor=SE_FLOOR)
