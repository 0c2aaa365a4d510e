"""Export cases the differential tester (issue 28) found against Cycles, each on a minimal
scene of node_stage.py: emission-only cases at the pixel centres (1 spp, no bounce: the image is
the exported emission, exact up to float rounding, as in test_nodes.py), lit cases as K seeds a
side compared by lantern.metrics.assert_agreement with its negative controls."""

import math

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)
import lantern  # noqa: E402

import node_stage as st  # noqa: E402
from lantern import metrics  # noqa: E402

SIZE = 24
FILTER_PX = 1e-6
TOL = 1e-4      # relative per pixel channel (0.05 floor): float rounding (test_nodes.py)
K, SPP, ALPHA = 8, 16, 1e-3


@pytest.fixture(scope="module", autouse=True)
def _addon():
    st.addon()


def lantern_centres(max_depth=1):
    """Lantern's image at the pixel centres and the export's warnings."""
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    scene.film["filter_width"] = FILTER_PX
    img = lantern.render(scene, spp=1, integrator="pt", max_depth=max_depth, seed=1, threads=1)
    return np.asarray(img, np.float64), list(report.messages)


def cycles_centres(sc, tmp_path):
    for mat in bpy.data.materials:
        mat.cycles.emission_sampling = "NONE"
    sc.render.threads_mode = "FIXED"
    sc.render.threads = 1
    return st.render_cycles(sc, tmp_path / "c.exr", spp=1, bounces=0, seed=0)


def assert_exact(name, img_l, ref, tol=TOL, floor=0.05):
    """Every pixel channel within tol of ref (relative, floor near 0); Lantern's image x 1.01
    and x 0.99 must fail that, and the image must vary (a constant would pass anything)."""
    def worst(img):
        return float(st.relative_error(img, ref, floor).max())
    w = worst(img_l)
    print(f"{name}: worst pixel channel {w:.2e}, means {img_l.mean():.5f} Lantern, "
          f"{ref.mean():.5f} Cycles")
    assert w <= tol, f"{name}: worst pixel channel off by {w:.2e} > {tol:.0e}"
    assert ref.std() > 1e-2 * max(ref.mean(), 1e-3), f"{name}: the image does not vary"
    for gain in (1.01, 0.99):
        assert worst(img_l * gain) > tol, f"{name}: control x {gain} passed"


def _shader(nt, idname, **inputs):
    n = nt.nodes.new(idname)
    for k, v in inputs.items():
        n.inputs[k].default_value = v
    return n


def _gradient(nt):
    """A Gradient Texture over Generated X: 0 at the plane's left edge, 1 at its right."""
    tc = nt.nodes.new("ShaderNodeTexCoord")
    g = nt.nodes.new("ShaderNodeTexGradient")
    nt.links.new(tc.outputs["Generated"], g.inputs["Vector"])
    return g


# ---- D9: a Mix Shader whose Fac is a node graph mixes its leaves' emission by that graph ----

@pytest.mark.parametrize("leaves", ["emission_emission", "principled_diffuse"])
def test_graph_mix_factor_mixes_emission(leaves, tmp_path):
    """Mix(a, b, Fac = gradient): Cycles emits (1 - f) E_a + f E_b at each point; Lantern used
    the Fac socket's own value (0.5) for the emission (difftest D9: -50 %)."""
    sc, nt, emit = st.stage("plane", SIZE)
    out = nt.nodes["Material Output"]
    nt.nodes.remove(emit)
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.5
    if leaves == "emission_emission":
        a = _shader(nt, "ShaderNodeEmission", Color=(1.0, 0.2, 0.1, 1.0), Strength=1.0)
        b = _shader(nt, "ShaderNodeEmission", Color=(0.1, 0.6, 1.0, 1.0), Strength=2.0)
    else:
        a = _shader(nt, "ShaderNodeBsdfPrincipled", **{
            "Emission Color": (1.0, 0.5, 0.2, 1.0), "Emission Strength": 1.6})
        b = _shader(nt, "ShaderNodeBsdfDiffuse")
    nt.links.new(a.outputs[0], mix.inputs[1])
    nt.links.new(b.outputs[0], mix.inputs[2])
    nt.links.new(_gradient(nt).outputs["Fac"], mix.inputs["Fac"])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    img, warnings = lantern_centres()
    assert warnings == []
    assert_exact(f"mix emission {leaves}", img, cycles_centres(sc, tmp_path))


# ---- D1: a colour on a float socket (Emission Strength) is its luminance ----

@pytest.mark.parametrize("shader", ["principled", "emission"])
def test_colour_into_emission_strength_is_its_luminance(shader, tmp_path):
    """A Checker's Color on Emission Strength: Blender converts the colour to a float (its
    luminance) for the socket; Lantern scaled each channel by it (difftest D1: -33 % red,
    +13 % green)."""
    sc, nt, emit = st.stage("plane", SIZE)
    if shader == "principled":
        nt.nodes.remove(emit)
        emit = _shader(nt, "ShaderNodeBsdfPrincipled", **{"Emission Color": (1, 1, 1, 1)})
        nt.links.new(emit.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
        strength = emit.inputs["Emission Strength"]
    else:
        emit.inputs["Color"].default_value = (0.9, 0.7, 0.3, 1.0)
        strength = emit.inputs["Strength"]
    checker = _shader(nt, "ShaderNodeTexChecker", Color1=(0.9, 0.2, 0.1, 1.0),
                      Color2=(0.18, 0.97, 0.25, 1.0), Scale=3.0)
    nt.links.new(checker.outputs["Color"], strength)
    img, warnings = lantern_centres()
    assert warnings == []
    # 2e-4: the colour's luminance is computed twice, 8.3e-5 apart at most (measured); the
    # controls are 1 %
    assert_exact(f"colour on strength {shader}", img, cycles_centres(sc, tmp_path), tol=2e-4)


# ---- lit cases: K seeds a side, the agreement test ----

def lit_stage(world=0.8):
    """node_stage's plane, its material's emission removed, under a uniform grey world."""
    sc, nt, emit = st.stage("plane", SIZE)
    nt.nodes.remove(emit)
    sc.world.node_tree.nodes["Background"].inputs["Color"].default_value = (world,) * 3 + (1,)
    sc.render.filter_size = sc.cycles.filter_width = 1.5
    return sc, nt


def assert_lit_agreement(name, sc, tmp_path, bounces=1, integrator="pt", warns=0, spp=SPP,
                         **kwargs):
    """K renders a side (Lantern max_depth bounces + 2, Cycles `bounces`), compared by
    metrics.assert_agreement (8 x 8 blocks and the image mean, its negative controls); the
    export warns `warns` times."""
    from lantern_blender.export import export_scene
    scene, report = export_scene(bpy.context.evaluated_depsgraph_get())
    lan = [np.asarray(lantern.render(scene, spp=spp, integrator=integrator,
                                     max_depth=bounces + 2, seed=11 + k, threads=1), np.float64)
           for k in range(K)]
    sc.render.threads_mode = "FIXED"
    sc.render.threads = 1
    cyc = [st.render_cycles(sc, tmp_path / f"c{k}.exr", spp=spp, bounces=bounces, seed=300 + k)
           for k in range(K)]
    res = metrics.assert_agreement(name, lan, cyc, block=8, alpha=ALPHA, **kwargs)
    assert len(report.messages) == warns, report.messages
    return res


# ---- D4: a node graph on Metallic keeps the principled type whatever the socket's value ----

def test_graph_on_metallic_with_socket_at_one(tmp_path):
    """Metallic 1 with a Gradient on it: the graph drives the metal share; Lantern exported the
    pure conductor and dropped the graph (difftest D4)."""
    sc, nt = lit_stage()
    bsdf = _shader(nt, "ShaderNodeBsdfPrincipled", Metallic=1.0, Roughness=0.3,
                   **{"Base Color": (0.9, 0.5, 0.2, 1.0)})
    nt.links.new(_gradient(nt).outputs["Fac"], bsdf.inputs["Metallic"])
    nt.links.new(bsdf.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    assert_lit_agreement("graph on metallic", sc, tmp_path)


# ---- D2: an object without a material is Blender's default surface ----

def test_no_material_renders_as_cycles(tmp_path):
    """The plane without a material under a grey world and a sun: Cycles renders Blender's
    default surface material (a default Principled BSDF), where Lantern rendered Lambert 0.8
    (difftest D2: +4.9 %)."""
    sc, nt = lit_stage(0.5)
    plane = next(o for o in sc.objects if o.type == "MESH")
    plane.data.materials.clear()
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 2.0
    sun.rotation_euler = (0.5, 0.3, 0.0)
    sc.collection.objects.link(sun)
    assert_lit_agreement("no material", sc, tmp_path)


# ---- D8: Add Shader of Transparent and a BSDF keeps the BSDF ----

def test_add_transparent_keeps_the_bsdf(tmp_path):
    """Add(Transparent, Diffuse) on a plane under a sun, nothing behind it and a black world:
    Cycles renders the whole diffuse reflection (and passes every ray, which sees black).
    Lantern made the surface fully transparent and dropped the diffuse (difftest D8: black).
    Transparency and BSDFs above weight 1 in all are normalised (a warning): the reflected
    light is exact, the passed light 1 / (t + W) of Cycles' (not seen here)."""
    sc, nt = lit_stage(0.0)
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(nt.nodes.new("ShaderNodeBsdfTransparent").outputs[0], add.inputs[0])
    nt.links.new(_shader(nt, "ShaderNodeBsdfDiffuse", Color=(0.7, 0.5, 0.3, 1.0)).outputs[0],
                 add.inputs[1])
    nt.links.new(add.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 2.0
    sun.rotation_euler = (0.5, 0.3, 0.0)
    sc.collection.objects.link(sun)
    # the coverage test's noise (half the rays pass, to black): 16x the samples
    assert_lit_agreement("add transparent", sc, tmp_path, warns=1, spp=16 * SPP)


# ---- D13: an albedo above 1 (Diffuse BSDF colour) is used as given ----

def _sun(sc, energy=2.0):
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = energy
    sun.rotation_euler = (0.5, 0.3, 0.0)
    sc.collection.objects.link(sun)


@pytest.mark.parametrize("case", ["graph", "constant", "principled_level0", "principled",
                                  "principled_graph"])
def test_albedo_above_one(case, tmp_path):
    """A Diffuse BSDF colour above 1 (a node graph's, or the socket's own): Cycles uses it as
    the closure weight, unclamped (svm closure: Diffuse's weight is its colour; the Principled
    diffuse base is clamped below only); Lantern clamped it to 1 (difftest D13: -76 %). Under
    a sun with a black world and no bounce every path's energy is finite (Cycles' and
    Lantern's depth limits bound it in any scene)."""
    sc, nt = lit_stage(0.0)
    if case.startswith("principled"):
        # level 0: exported as Lambert; else the principled type, no metal or glass (D14)
        level = 0.0 if case == "principled_level0" else 0.5
        bsdf = _shader(nt, "ShaderNodeBsdfPrincipled", **{"Specular IOR Level": level})
        sock = bsdf.inputs["Base Color"]
    else:
        bsdf = _shader(nt, "ShaderNodeBsdfDiffuse")
        sock = bsdf.inputs["Color"]
    if case.endswith("graph"):
        times = _shader(nt, "ShaderNodeMath", Value_001=2.5)
        times.operation = "MULTIPLY"
        nt.links.new(_gradient(nt).outputs["Fac"], times.inputs[0])
        nt.links.new(times.outputs[0], sock)
    else:
        sock.default_value = (1.6, 1.2, 0.5, 1.0)
    nt.links.new(bsdf.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    _sun(sc)
    assert_lit_agreement(f"albedo above one, {case}", sc, tmp_path)


# ---- D19: Texture Coordinate Normal on back faces faces the viewer ----

def test_texcoord_normal_on_back_faces(tmp_path):
    """The camera inside the sphere sees only back faces: Cycles' Normal coordinate is its N,
    flipped towards the ray, in object space; Lantern read the vertex normal unflipped
    (difftest D19). Shown as N / 2 + 1/2 (emission is not negative)."""
    sc, nt, emit = st.stage("sphere", SIZE)
    sc.camera.location = (0.0, 0.3, 0.1)
    sc.camera.data.lens = 20.0
    tc = nt.nodes.new("ShaderNodeTexCoord")
    half = nt.nodes.new("ShaderNodeVectorMath")
    half.operation = "MULTIPLY_ADD"
    half.inputs[1].default_value = half.inputs[2].default_value = (0.5, 0.5, 0.5)
    nt.links.new(tc.outputs["Normal"], half.inputs[0])
    nt.links.new(half.outputs[0], emit.inputs["Color"])
    img, warnings = lantern_centres()
    assert warnings == []
    ref = cycles_centres(sc, tmp_path)
    assert ref.min() > 0.0, "a pixel misses the sphere"
    assert_exact("texcoord normal, back faces", img, ref)


# ---- D10: an unlinked Tangent input is Cycles' radial tangent about the object's Z ----

@pytest.mark.parametrize("kind", ["principled", "glossy", "radial_z_node"])
def test_default_anisotropy_tangent_is_radial(kind, tmp_path):
    """An anisotropic metal plane under a sun, seen from above: with the Tangent input
    unlinked Cycles' tangent turns about the object's Z axis through the Generated centre (a
    radial Tangent node, its default), so the highlight changes round the centre; Lantern used
    the uv tangent, the same everywhere (difftest D10: +8.6 %). radial_z_node: that Tangent
    node linked (about X or Y it would be the plane's normal here: degenerate in both)."""
    sc, nt = lit_stage(0.0)
    if kind == "glossy":
        bsdf = _shader(nt, "ShaderNodeBsdfGlossy", Color=(0.9, 0.8, 0.6, 1.0), Roughness=0.35,
                       Anisotropy=0.6)
    else:
        bsdf = _shader(nt, "ShaderNodeBsdfPrincipled", Metallic=1.0, Roughness=0.35,
                       Anisotropic=0.8, **{"Base Color": (0.9, 0.8, 0.6, 1.0)})
    if kind == "radial_z_node":
        t = nt.nodes.new("ShaderNodeTangent")
        t.direction_type, t.axis = "RADIAL", "Z"
        nt.links.new(t.outputs[0], bsdf.inputs["Tangent"])
    nt.links.new(bsdf.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 3.0, 0.0   # a delta sun: next-event only, little noise
    sun.rotation_euler = (0.45, 0.2, 0.0)
    sc.collection.objects.link(sun)
    assert_lit_agreement(f"default tangent, {kind}", sc, tmp_path)
