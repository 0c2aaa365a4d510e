"""Load addon/ into bpy 5.0.1 as the package `lantern_blender` and register it once."""

import importlib.util
import sys
from pathlib import Path

import pytest

bpy = pytest.importorskip("bpy")
import numpy as np  # noqa: E402

ADDON = Path(__file__).resolve().parents[2] / "addon"


def _load_addon():
    if "lantern_blender" in sys.modules:
        return sys.modules["lantern_blender"]
    spec = importlib.util.spec_from_file_location(
        "lantern_blender", ADDON / "__init__.py", submodule_search_locations=[str(ADDON)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["lantern_blender"] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def addon():
    module = _load_addon()
    module.register()
    yield module
    module.unregister()


@pytest.fixture
def empty(addon):
    """An empty scene (factory settings), Lantern selected, a tiny resolution."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "LANTERN"
    scene.render.resolution_x, scene.render.resolution_y = 32, 24
    scene.render.resolution_percentage = 100
    return scene


@pytest.fixture
def default_scene(addon):
    """Blender's default scene: cube, light, camera."""
    bpy.ops.wm.read_factory_settings(use_empty=False)
    bpy.context.scene.render.engine = "LANTERN"
    return bpy.context.scene


def add_camera(scene, location=(0, 0, 5), rotation=(0, 0, 0), lens=50.0, name="Camera"):
    data = bpy.data.cameras.new(name)
    data.lens = lens
    obj = bpy.data.objects.new(name, data)
    obj.location, obj.rotation_euler = location, rotation
    scene.collection.objects.link(obj)
    scene.camera = obj
    return obj


def add_plane(scene, size=2.0, location=(0, 0, 0), material=None, name="Plane"):
    mesh = bpy.data.meshes.new(name)
    h = size / 2
    mesh.from_pydata([(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [], [(0, 1, 2, 3)])
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    if material is not None:
        mesh.materials.append(material)
    scene.collection.objects.link(obj)
    return obj


def emission_material(strength, color=(1, 1, 1)):
    mat = bpy.data.materials.new("Emit")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    bsdf = nodes["Principled BSDF"]
    nodes.remove(bsdf)
    emit = nodes.new("ShaderNodeEmission")
    emit.inputs["Color"].default_value = (*color, 1)
    emit.inputs["Strength"].default_value = strength
    mat.node_tree.links.new(emit.outputs[0], nodes["Material Output"].inputs["Surface"])
    return mat


def diffuse_material(albedo):
    mat = bpy.data.materials.new("Diffuse")
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (albedo, albedo, albedo, 1)
    return mat


def render_exr(scene, tmp_path, name="out.exr"):
    """F12 to an EXR, then the written file's float pixels, top row first (H, W, 4)."""
    path = str(tmp_path / name)
    scene.render.filepath = path
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    image = bpy.data.images.load(path)
    w, h = image.size
    pixels = np.empty(w * h * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(h, w, 4)[::-1]


@pytest.fixture
def errors(addon, monkeypatch):
    """Records every error and warning the engine reports (and still reports them)."""
    calls = []
    engine = addon.engine
    orig_error, orig_warn = engine._report_error, engine._report_warnings

    def report_error(eng, what, error):
        calls.append(("ERROR", f"{what}: {error}"))
        orig_error(eng, what, error)

    def report_warnings(eng, messages):
        calls.extend(("WARNING", m) for m in messages)
        orig_warn(eng, messages)

    monkeypatch.setattr(engine, "_report_error", report_error)
    monkeypatch.setattr(engine, "_report_warnings", report_warnings)
    return calls
