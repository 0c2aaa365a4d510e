"""Depsgraph -> lantern.Scene. Everything here runs on Blender's main thread; the scene it
returns holds only numpy arrays and plain values, safe to hand to a render thread."""

from .camera import camera_to_world, export_camera, export_film, film_unsupported
from .holdout import Holdouts
from .material import MaterialTable
from .mesh import MeshExporter
from .motion import MotionRecorder
from .strands import StrandExporter
from .volume_objects import VolumeObjects
from .walk import Walk, integrator as _integrator
from .world import export_world

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
    holdouts = Holdouts(materials, report, _integrator(bscene), depsgraph.view_layer,
                        None if region_view else bool(scene.film.get("transparent", False)))
    motion = MotionRecorder(depsgraph, report, frame_set, final=region_view is None)
    source = _Fresh(meshes, StrandExporter(bscene, materials, report, final=region_view is None,
                                             viewport_cache=getattr(depsgraph, "mode", "RENDER")
                                             == "VIEWPORT"),
                    VolumeObjects(report, lantern, materials.attributes), materials)
    walk = Walk(depsgraph, scene, materials, holdouts, report, motion)  # export/walk.py
    for inst in depsgraph.object_instances:
        walk.instance(inst, source)
    meshes.clear()
    if region_view is None and bscene.camera is not None:
        motion.finish(scene, bscene.camera, camera_to_world)
    walk.finish()
    return scene, report


class _Fresh:
    """Every instance's geometry exported afresh (walk.py's `source`)."""

    def __init__(self, meshes, strands, volumes, materials):
        self.mesh, self.corners = meshes.export, meshes.corners  # export/mesh.py
        self.strands = strands.sets_of                          # export/strands.py
        self._volumes, self._materials = volumes, materials

    def volume(self, inst, scene):
        self._volumes.export(inst, scene, self._materials.materials)  # export/volume_objects.py
