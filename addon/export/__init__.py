"""Depsgraph -> lantern.Scene. Everything here runs on Blender's main thread; the scene it
returns holds only numpy arrays and plain values, safe to hand to a render thread."""

from .camera import camera_to_world, export_camera, export_film, film_unsupported
from .holdout import Holdouts
from .light import export_light
from .linking import LightLinking
from .material import MaterialTable
from .mesh import MeshExporter
from .strands import StrandExporter
from .motion import MotionRecorder
from .unsupported import UnsupportedFeatures
from .visibility import mixed_kind_lamp_warning, mixed_kind_warning
from .volume_objects import VolumeObjects
from .world import export_world, mixed_lobe_warning

__all__ = ["export_scene", "ExportReport"]


class ExportReport:
    """Warnings collected during an export, each once, for the engine to report."""

    def __init__(self):
        self.messages = []

    def warn(self, message):
        if message not in self.messages:
            self.messages.append(message)


def export_scene(depsgraph, region_view=None, report=None, texture_cache=None, frame_set=None):
    """Build a lantern.Scene from an evaluated depsgraph.

    texture_cache: a dict kept between viewport exports (image pixels by image name, see
    export/texture.py), or None to read every image afresh (final renders).
    region_view: None for a final render (scene camera, render resolution), else a
    camera.ViewportView describing the 3D viewport to render.
    frame_set: how to move the scene to a subframe for motion blur's steps (the render
    engine's frame_set during a render; default the scene's), export/motion.py."""
    from ..native import import_lantern
    lantern = import_lantern()

    report = report or ExportReport()
    bscene = depsgraph.scene_eval
    scene = lantern.Scene()
    if region_view is None:
        scene.film = export_film(bscene)
        scene.camera = export_camera(bscene, bscene.camera, scene.film, report)
        film_unsupported(bscene, report)
    else:
        scene.film = region_view.film()
        scene.camera = region_view.camera()
    scene.world = export_world(bscene.world, report, texture_cache, _integrator(bscene))
    materials = MaterialTable(report, texture_cache)
    meshes = MeshExporter(materials, report)
    meshes.view_layer = depsgraph.view_layer  # Indirect Only (visibility.camera_visible)
    features = UnsupportedFeatures(report)
    holdouts = Holdouts(materials, report, _integrator(bscene), depsgraph.view_layer,
                        None if region_view else bool(scene.film.get("transparent", False)))
    features.scene(depsgraph)
    motion = MotionRecorder(depsgraph, report, frame_set, final=region_view is None)
    linking = LightLinking(report)
    strands = StrandExporter(bscene, materials, report, final=region_view is None)
    volumes = VolumeObjects(report, lantern)  # export/volume_objects.py
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type in {"MESH", "CURVES"}:  # hair: even on an emitter not rendered itself
            strands.export(inst)  # export/strands.py
        if not inst.show_self:  # an instancer hidden for render (show_instancer_for_render)
            continue
        features.object(obj)
        if obj.type == "LIGHT":
            light = export_light(obj, inst.matrix_world, report)
            if light is not None:
                linking.light(obj, light)  # export/linking.py
                scene.lights.append(light)
        elif obj.type in {"MESH", "CURVE", "SURFACE", "META", "FONT"}:  # CURVES: strands
            mesh = meshes.export(inst)
            if mesh is not None:
                holdouts.mesh(obj, mesh)  # export/holdout.py
                motion.mesh(inst, mesh, meshes.corners(obj))
                linking.mesh(obj, mesh)
                scene.meshes.append(mesh)
        elif obj.type == "VOLUME":
            volumes.export(inst, scene, materials.materials)
    scene.curves = strands.sets
    meshes.clear()
    linking.finish()
    if region_view is None and bscene.camera is not None:
        motion.finish(scene, bscene.camera, camera_to_world)
    scene.attribute_channels = materials.attributes.finish(scene.meshes)
    scene.materials = materials.materials
    scene.textures = materials.textures
    used = _used_materials(scene)
    mixed_lobe_warning(bscene.world, scene.world, used, report)  # world.py
    mixed_kind_warning(scene.meshes, used, report)  # visibility.py
    mixed_kind_lamp_warning(scene.lights, used, report)
    return scene, report


def _used_materials(scene):
    """The materials some mesh's triangles use, with their mix leaves (the default material 0,
    a Principled for objects without one, is always exported and often unused)."""
    import numpy as np
    used, todo = set(), []
    for mesh in list(scene.meshes) + list(scene.curves):
        ids = mesh.get("material_ids")
        if ids is not None:
            todo += [int(i) for i in np.unique(np.asarray(ids)).tolist()]
    while todo:
        i = todo.pop()
        if i in used or not 0 <= i < len(scene.materials):
            continue
        used.add(i)
        todo += [int(leaf) for leaf, _ in scene.materials[i].get("mix", [])]
    return [scene.materials[i] for i in sorted(used)]


def _integrator(bscene):
    """The integrator whose features the export checks: "auto" renders holdouts, shadow
    catchers and a world hidden from some rays with pt (native/src/integrator/allocation.h)."""
    settings = getattr(getattr(bscene, "original", bscene), "lantern", None)
    integrator = str(getattr(settings, "integrator", "pt")).lower()
    return "pt" if integrator == "auto" else integrator
