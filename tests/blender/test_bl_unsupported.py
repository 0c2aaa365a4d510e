"""Nothing silent: one small scene per scene feature Lantern does not render, each F12 gives
exactly one warning naming the datablock and the feature; an instancer hidden for render does
not render; a warning is printed once per render, also with two view layers."""

import os

import bpy
import numpy as np
import pytest

import lantern
from blender_helpers import add_camera, add_plane, emission_material, render_exr

pytestmark = pytest.mark.skipif(not lantern.session.native_available(),
                                reason="lantern native module not built")


def _base(scene):
    add_camera(scene, location=(0, 0, 5))
    return add_plane(scene, size=4.0, material=emission_material(1.0), name="Subject")


def _material(name, socket, node_type):
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    out = nt.nodes["Material Output"]
    node = nt.nodes.new(node_type)
    nt.links.new(node.outputs[0], out.inputs[socket])
    if socket == "Volume":  # a volume only, as a smoke or fog material is
        nt.nodes.remove(nt.nodes["Principled BSDF"])
    return mat


def _with_material(scene, mat):
    obj = _base(scene)
    obj.data.materials.clear()
    obj.data.materials.append(mat)


def _light(scene, name="Lamp"):
    data = bpy.data.lights.new(name, "POINT")
    obj = bpy.data.objects.new(name, data)
    obj.location = (0, 0, 2)
    scene.collection.objects.link(obj)
    return obj


def motion_blur(s):  # transform and deformation motion render (docs/motion_blur.md): all
    obj = _base(s)     # (lit, not emitting: a deforming emitter stays still, with a warning)
    obj.data.materials.clear()
    obj.data.materials.append(bpy.data.materials.new("Matte"))
    _light(s)
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="Bulge")
    key.data[0].co.z += 1.0
    for frame, value in ((0, 0.0), (2, 1.0)):
        key.value = value
        key.keyframe_insert("value", frame=frame)
    s.frame_set(1)
    s.render.use_motion_blur = True


def volume_material(s):   # a heterogeneous medium: a texture on Density (docs/volumes.md)
    mat = _material("Fog", "Volume", "ShaderNodeVolumePrincipled")
    nt = mat.node_tree
    noise = nt.nodes.new("ShaderNodeTexNoise")
    nt.links.new(noise.outputs["Fac"], nt.nodes["Principled Volume"].inputs["Density"])
    _with_material(s, mat)


def volume_bounces(s):   # a homogeneous medium renders; Cycles' Volume Bounces 0 does not apply
    _with_material(s, _material("Fog", "Volume", "ShaderNodeVolumePrincipled"))


def volume_biased(s):   # Cycles' biased ray marching (its Step Rate): Lantern tracks unbiased
    _with_material(s, _material("Fog", "Volume", "ShaderNodeVolumePrincipled"))
    s.cycles.volume_biased = True


def displacement(s):   # true displacement; the Bump Only method renders (test_bl_nodes.py)
    mat = _material("Bumpy", "Displacement", "ShaderNodeDisplacement")
    mat.displacement_method = "DISPLACEMENT"
    _with_material(s, mat)


def world_volume(s):
    _base(s)
    world = bpy.data.worlds.new("Hazy")
    nt = world.node_tree
    vol = nt.nodes.new("ShaderNodeVolumeScatter")
    vol.phase = "RAYLEIGH"  # Henyey-Greenstein stands for it (blackbody renders since volumes2)
    nt.links.new(vol.outputs[0], nt.nodes["World Output"].inputs["Volume"])
    s.world = world


def particle_hair(s):  # renders since hairwire (docs/curves.md), as Cycles' Linear 3D Curves
    obj = _base(s)
    mod = obj.modifiers.new("Hair", "PARTICLE_SYSTEM")
    mod.particle_system.settings.type = "HAIR"
    mod.particle_system.settings.count = 10
    mod.particle_system.name = "Fur"
    s.cycles_curves.shape = "THICK_LINEAR"


def light_linking(s):
    obj = _base(s)
    obj.light_linking.receiver_collection = bpy.data.collections.new("Receivers")


def shadow_linking(s):
    obj = _base(s)
    obj.light_linking.blocker_collection = bpy.data.collections.new("Blockers")


def glossy_visibility(s):
    _base(s).visible_glossy = False


def diffuse_visibility(s):
    _base(s).visible_diffuse = False


def lamp_visibility(s):  # a lamp's own ray visibility (pt: pt_ray_visibility.h)
    _base(s)
    _light(s).visible_glossy = False


def light_nodes(s):   # a texture on a light (constant trees render: test_bl_nodes.py)
    _base(s)
    lamp = _light(s).data
    lamp.use_nodes = True
    nt = lamp.node_tree
    emit = next(n for n in nt.nodes if n.type == "EMISSION")
    nt.links.new(nt.nodes.new("ShaderNodeTexNoise").outputs["Color"], emit.inputs["Color"])


def ies(s):
    _base(s)
    lamp = _light(s)
    lamp.data.use_nodes = True
    lamp.data.node_tree.nodes.new("ShaderNodeTexIES")


def no_shadow(s):  # rendered by pt (export/light.py) and cis; auto chooses (autowide)
    _base(s)
    _light(s).data.use_shadow = False


def holdout(s):  # rendered by pt (export/holdout.py); the other integrators name it
    _base(s).is_holdout = True
    s.lantern.integrator = "bdpt"


def shadow_catcher(s):
    _base(s).is_shadow_catcher = True


def _object(s, name, data):
    _base(s)
    obj = bpy.data.objects.new(name, data)
    s.collection.objects.link(obj)


def volume_object(s):   # a Volume without a file (generated grids): not rendered
    _object(s, "Cloud", bpy.data.volumes.new("Cloud"))


def _vdb_file():
    """A small smoke grid written by the core's OpenVDB writer (docs/volumes.md)."""
    import tempfile

    import lantern._core as core
    path = os.path.join(tempfile.mkdtemp(), "cloud.vdb")
    c = np.linspace(-1, 1, 8)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    vox = np.ascontiguousarray(np.clip(1 - (x * x + y * y + z * z), 0, None).astype(np.float32))
    core.vdb_write(path, "density", vox, np.diag([0.1, 0.1, 0.1, 1.0]))
    return path


def volume_object_file(s):   # a Volume object of a file: renders (pt)
    vol = bpy.data.volumes.new("Cloud")
    vol.filepath = _vdb_file()
    vol.materials.append(_material("Smoke", "Volume", "ShaderNodeVolumePrincipled"))
    _object(s, "Cloud", vol)


def volume_object_huge(s):   # two voxels 2^20 apart: refused from the file's metadata
    import tempfile

    import lantern._core as core
    path = os.path.join(tempfile.mkdtemp(), "huge.vdb")
    core.vdb_write_sparse(path, "density", np.array([[0, 0, 0], [1 << 20] * 3], np.int32),
                          np.array([1.0, 2.0], np.float32), np.eye(4))
    vol = bpy.data.volumes.new("Cloud")
    vol.filepath = path
    _object(s, "Cloud", vol)


def volume_object_missing(s):   # a Volume object whose file is gone: named, not rendered
    vol = bpy.data.volumes.new("Cloud")
    vol.filepath = "/nonexistent/cloud.vdb"
    _object(s, "Cloud", vol)


def point_cloud(s):
    _object(s, "Points", bpy.data.pointclouds.new("Points"))


def hair_curves(s):  # renders since hairwire (docs/curves.md)
    _base(s)
    data = bpy.data.hair_curves.new("Strands")
    data.add_curves([3, 3])
    data.attributes["position"].data.foreach_set(
        "vector", np.array([0, 0, 0, 0, 0, 0.5, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 1, 0, 1], np.float32))
    _object(s, "Strands", data)
    s.cycles_curves.shape = "THICK_LINEAR"


def material_override(s):
    _base(s)
    s.view_layers[0].material_override = bpy.data.materials.new("Clay")


def _child_collection(s, name):
    col = bpy.data.collections.new(name)
    s.collection.children.link(col)
    obj = _base(s)
    s.collection.objects.unlink(obj)
    col.objects.link(obj)
    return s.view_layers[0].layer_collection.children[name]


def holdout_collection(s):  # its objects are holdouts (export/holdout.py), pt only
    _child_collection(s, "Masked").holdout = True
    s.lantern.integrator = "lvc"


def indirect_only(s):  # renders in every integrator (export/visibility.py camera_visible)
    _child_collection(s, "Bounce").indirect_only = True


def indirect_only_lvc(s):
    indirect_only(s)
    s.lantern.integrator = "lvc"


def multiview(s):
    _base(s)
    s.render.use_multiview = True


def freestyle(s):
    _base(s)
    s.render.use_freestyle = True


def mist_pass(s):
    _base(s)
    s.view_layers[0].use_pass_mist = True


def surfaces_filter(s):
    _base(s)
    s.view_layers[0].use_solid = False


CASES = [  # builder, the name the warning must carry, a word of the feature
    (volume_bounces, "Render settings", "Volume Bounces"),
    (volume_biased, "Render settings", "biased volume ray marching"),
    (displacement, "Material 'Bumpy'", "true displacement"),
    (world_volume, "World 'Hazy'", "phase function 'RAYLEIGH'"),
    (light_nodes, "Light 'Lamp'", "varies over the light"),
    (ies, "Light 'Lamp'", "IES"),
    (holdout, "Object 'Subject'", "pt integrator only"),
    (shadow_catcher, "Object 'Subject'", "shadow catcher"),
    (point_cloud, "Object 'Points'", "point clouds"),
    (material_override, "View layer 'ViewLayer'", "material override"),
    (holdout_collection, "Object 'Subject'", "lvc renders it as an ordinary surface"),
    (multiview, "Render settings", "multi-view"),
    (freestyle, "View layer 'ViewLayer'", "Freestyle"),
    (mist_pass, "View layer 'ViewLayer'", "Mist pass"),
    (surfaces_filter, "View layer 'ViewLayer'", "'Surfaces'"),
]


# Volume objects (export/volume_objects.py): without OpenVDB each says so instead
if lantern.vdb_available():
    CASES += [(volume_object, "Object 'Cloud'", "without a file"),
              (volume_object_missing, "Object 'Cloud'", "cannot be read"),
              (volume_object_huge, "Object 'Cloud'", "above the limit")]
else:
    CASES += [(volume_object_missing, "Object 'Cloud'", "built without OpenVDB")]


# What these builders set up renders now (heterogeneous media: docs/volumes.md; ray visibility,
# light and shadow linking: pt, docs/scene_format.md; particle hair and Curves objects:
# docs/curves.md): no warning may call it unsupported; the
# only notes left are that the automatic integrator renders it with pt (the bidirectional ones
# do not honour it yet) and Cycles' Volume Bounces
RENDERED = [volume_material, light_linking, shadow_linking, glossy_visibility,
            diffuse_visibility, particle_hair, hair_curves, motion_blur, lamp_visibility,
            no_shadow] + (
                [volume_object_file] if lantern.vdb_available() else [])
HANDED_TO_PT = "renders this scene with path tracing"
# media: the automatic integrator chooses between pt and cis itself since auto_media is on
# (docs/auto_integrator.md, "Media"), so it hands nothing over and says nothing; so do strands
# with ordinary BSDFs (the default material here) since cis has vertices on them (docs/curves.md);
# and light and shadow linking, a lamp's Cast Shadow off and motion blur (at the add-on's one
# sample an iteration) since cis renders them and auto weighs them (branch autowide,
# docs/auto_integrator.md), and object and lamp ray visibility on surfaces (branch automis)
AUTO_CHOOSES = {volume_material, volume_object_file, particle_hair, hair_curves, light_linking,
                shadow_linking, no_shadow, motion_blur, glossy_visibility, diffuse_visibility,
                lamp_visibility}


@pytest.mark.parametrize("build", RENDERED, ids=[b.__name__ for b in RENDERED])
def test_rendered_feature_is_not_called_unsupported(empty, tmp_path, errors, build):
    empty.render.resolution_x, empty.render.resolution_y = 8, 8
    empty.lantern.samples = 1
    build(empty)
    assert bpy.ops.render.render() == {"FINISHED"}
    assert not [c for c in errors if c[0] == "ERROR"], errors
    others = [m for kind, m in errors
              if kind == "WARNING" and HANDED_TO_PT not in m and "Volume Bounces" not in m]
    assert not others, others
    if build not in AUTO_CHOOSES:
        assert [m for kind, m in errors if HANDED_TO_PT in m], errors  # and it says it is pt's


@pytest.mark.parametrize("build, who, feature", CASES, ids=[c[0].__name__ for c in CASES])
def test_unsupported_feature_is_named_once(empty, tmp_path, errors, build, who, feature):
    empty.render.resolution_x, empty.render.resolution_y = 8, 8
    empty.lantern.samples = 1
    build(empty)
    assert bpy.ops.render.render() == {"FINISHED"}
    warnings = [m for kind, m in errors if kind == "WARNING"]
    hits = [m for m in warnings if feature in m]
    assert len(hits) == 1, warnings
    assert who in hits[0], hits[0]
    assert not [c for c in errors if c[0] == "ERROR"]


def test_a_plain_scene_has_no_feature_warnings(empty, tmp_path, errors):
    empty.render.resolution_x, empty.render.resolution_y = 8, 8
    empty.lantern.samples = 1
    _base(empty)
    _light(empty)
    render_exr(empty, tmp_path)
    assert not errors


def test_instancer_hidden_for_render_does_not_render(empty, tmp_path, errors):
    """An emissive plane that fills the view instances a small object on its vertices; with
    show_instancer_for_render off, only the instances render (here: out of view)."""
    add_camera(empty, location=(0, 0, 5))
    plane = add_plane(empty, size=100.0, material=emission_material(2.0), name="Instancer")
    child = add_plane(empty, size=0.1, material=emission_material(1.0), name="Child")
    child.parent = plane
    plane.instance_type = "VERTS"
    empty.render.resolution_x, empty.render.resolution_y = 8, 8
    empty.lantern.samples = 1
    px = render_exr(empty, tmp_path, "shown.exr")
    np.testing.assert_allclose(px[..., :3], 2.0, rtol=1e-5)
    plane.show_instancer_for_render = False
    px = render_exr(empty, tmp_path, "hidden.exr")
    assert not px[..., :3].any()


def test_each_warning_printed_once_with_two_view_layers(empty, tmp_path, errors, capfd):
    empty.render.resolution_x, empty.render.resolution_y = 8, 8
    empty.lantern.samples = 1
    ies(empty)
    empty.view_layers.new("Second")
    render_exr(empty, tmp_path)
    out = capfd.readouterr()
    printed = (out.out + out.err).count("reads no IES profiles")
    assert printed == 1, out.out + out.err
    assert sum("IES" in m for kind, m in errors if kind == "WARNING") == 1


# Indirect Only collections render in every integrator (the camera's own ray query skips their
# triangles, as for Camera ray visibility): no warning at all
EVERYWHERE = [indirect_only, indirect_only_lvc]


@pytest.mark.parametrize("build", EVERYWHERE, ids=[b.__name__ for b in EVERYWHERE])
def test_rendered_everywhere_without_warning(empty, tmp_path, errors, build):
    empty.render.resolution_x, empty.render.resolution_y = 8, 8
    empty.lantern.samples = 1
    build(empty)
    assert bpy.ops.render.render() == {"FINISHED"}
    assert not errors, errors
