"""The viewport's incremental export: a lantern.Scene kept between syncs and patched from what
changed (changes.py), on Blender's main thread.

- a view or camera move exports nothing (the session replaces its camera);
- a material edit converts that material again, in its slot (its meshes keep their ids);
- a world edit exports the world; lights (cheap) are exported at every scene-level sync;
- meshes: the local arrays of each object (the foreach_get extraction, export/mesh.py) are
  kept until its geometry changes, the placed world-space arrays of each instance until its
  matrix changes; objects added, hidden or removed show up because every scene-level sync
  walks the depsgraph's instances (dictionary look-ups for unchanged ones).

- a transform edit places the moved instances' arrays again (numpy, no extraction), so the
  scene stays a full export; session_moves() gives the running session's move_instance
  calls (two-level instancing in the core: no mesh sent, no bottom-level BVH built), each
  matrix relative to the instance's placement in that session's scene (session_base()).

`counts` says what the last sync exported (the tests check it). The loop mirrors
export_scene (export/__init__.py), which final renders use: keep the two in step."""

import numpy as np

from . import changes as ch
from .light import export_light
from .material import MaterialTable
from .mesh import MeshExporter, _needs_tangents
from .volume_objects import VolumeObjects, add_grids
from .world import export_world

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES"}


def _local_key(obj):
    data = getattr(obj, "data", None)
    return (obj.name_full, data.name_full if data is not None else None)


def _instance_key(inst):
    obj = inst.object
    pid = tuple(inst.persistent_id) if inst.is_instance else ()
    parent = inst.parent.name_full if inst.is_instance and inst.parent else ""
    return _local_key(obj) + (parent, pid)


def _reconvert(table, material):
    """Convert `material` again into its slot of `table`. False when that cannot be done in
    place (a table without slots by name, or the material's need for tangents changed: its
    meshes would need extracting again): then the caller exports everything."""
    try:
        from .material import convert_material
        index, add_leaf = table._index, table._add_leaf
    except (ImportError, AttributeError):
        return False
    slot = index.get(material.name_full)
    if slot is None:
        return True  # not in use yet: converted when a mesh asks for it
    old = table.materials[slot]
    new = convert_material(material, table.report, table.texture_table, add_leaf)
    table.materials[slot] = new
    return _needs_tangents(old) == _needs_tangents(new)


class ViewportSync:
    def __init__(self):
        self.scene = None
        self.texture_cache = {}   # image pixels by image name (export/texture.py)
        self.pending = ch.Changes(ch.FULL)
        self.counts = {}
        self.syncs = 0
        self._materials = None
        self._meshes = None
        self._placed = {}         # instance key -> (matrix bytes, exported mesh dict)
        self._order = []          # instance keys of scene.meshes, in order
        self.base = None          # session_base() of the running session's scene
        self._volumes = None      # Volume objects (export/volume_objects.py): the converter,
        self._vol_cache = {}      # instance key -> (matrix bytes, (grid, mesh, material))
        self._vol_slots = {}      # instance key -> its material's slot in the table's list

    def note(self, changes):
        """Changes from a view_update, applied at the next sync."""
        for name in changes.images:
            self.texture_cache.pop(name, None)
        self.pending |= changes

    def needs_sync(self):
        return self.scene is None or bool(self.pending.flags & ~ch.VIEW)

    def sync(self, depsgraph, view, report):
        """Bring self.scene up to date with the pending changes; returns the Changes applied.
        `view` is the camera.ViewportView to render; the scene's film and camera follow it."""
        from ..native import import_lantern
        lantern = import_lantern()
        todo, self.pending = self.pending, ch.Changes()
        self.syncs += 1
        self.counts = {"meshes_extracted": 0, "meshes_placed": 0, "materials": 0,
                       "world": 0, "lights": 0}
        if self.scene is None or todo.has(ch.IMAGES) or todo.all_materials:
            todo.flags |= ch.FULL
        if todo.has(ch.MATERIALS) and self._vol_slots:
            todo.flags |= ch.FULL   # a Volume object's material is converted with its grid
        if todo.has(ch.FULL):
            self._materials = MaterialTable(report, self.texture_cache)
            self._meshes = MeshExporter(self._materials, report)
            self._meshes.view_layer = depsgraph.view_layer  # Indirect Only
            self._placed = {}
            self.scene = None
            self._volumes = VolumeObjects(report, lantern)
            self._vol_cache, self._vol_slots = {}, {}
        self._materials.report = self._meshes.report = self._volumes.report = report
        known = _converted(self._materials)
        if todo.has(ch.MATERIALS) and not todo.has(ch.FULL):
            for name in sorted(todo.materials):
                material = _find_material(depsgraph, name)
                if material is None or not _reconvert(self._materials, material):
                    self.pending = ch.Changes(ch.FULL)  # cannot patch it: export everything
                    return self.sync(depsgraph, view, report)
                self.counts["materials"] += 1
        for name in todo.geometry:
            for key in [k for k in self._meshes._cache if k[0] == name]:
                del self._meshes._cache[key]
            for key in [k for k in self._vol_cache if k[0] == name]:
                del self._vol_cache[key]   # its file, frame or grids: read again
                self._volumes._read.clear()
        scene = self.scene if self.scene is not None else lantern.Scene()
        scene.film, scene.camera = view.film(), view.camera()
        if todo.flags & (ch.FULL | ch.WORLD | ch.SETTINGS):
            scene.world = export_world(depsgraph.scene_eval.world, report, self.texture_cache)
            self.counts["world"] = 1
        if todo.flags & ~(ch.VIEW | ch.WORLD | ch.MATERIALS):
            self._walk_instances(depsgraph, scene, report)
        self.counts["materials"] += _converted(self._materials) - known
        scene.materials = self._materials.materials
        scene.textures = self._materials.textures
        self.scene = scene
        return todo

    def session_base(self):
        """The instances' placements in the current scene; set `base` to it when a new
        session of this scene starts: later moves are relative to it."""
        mats = {k: self._placed[k][0] for k in self._order}
        return (list(self._order), mats, dict(mats))  # order, placed in its scene, now there

    def session_moves(self):
        """[(mesh index, 4x4)] that take the running session (base) to the current scene by
        moving instances alone (each instance whose placement differs from what the session
        has now, a move back included), or None when more than transforms differ. The
        session's placements count as updated: call it only to apply the moves."""
        if self.base is None or self.base[0] != self._order:
            return None
        out = []
        for k, key in enumerate(self._order):
            given, applied, now = self.base[1][key], self.base[2][key], self._placed[key][0]
            if applied == now:
                continue
            if given == now:  # back where the session's scene has it: exactly
                out.append((k, np.eye(4)))
                continue
            a = np.frombuffer(given, dtype=np.float64).reshape(4, 4)
            b = np.frombuffer(now, dtype=np.float64).reshape(4, 4)
            if abs(np.linalg.det(a[:3, :3])) < 1e-30:
                return None
            out.append((k, b @ np.linalg.inv(a)))
        for key in self._order:
            self.base[2][key] = self._placed[key][0]
        return out

    def _walk_instances(self, depsgraph, scene, report):
        meshes, lights, placed, order = [], [], {}, []
        scene.grids = []
        for inst in depsgraph.object_instances:
            obj = inst.object
            if obj.type == "LIGHT":
                light = export_light(obj, inst.matrix_world, report)
                if light is not None:
                    lights.append(light)
                continue
            if obj.type == "VOLUME":
                mesh = self._volume(inst, scene)
                if mesh is not None:
                    key = _instance_key(inst)
                    placed[key] = (np.array(inst.matrix_world, np.float64).tobytes(), mesh)
                    meshes.append(mesh)
                    order.append(key)
                continue
            if obj.type not in GEOMETRY_TYPES:
                continue
            key = _instance_key(inst)
            matrix = np.array(inst.matrix_world, dtype=np.float64).tobytes()
            old = self._placed.get(key)
            if old is not None and old[0] == matrix:
                mesh = old[1]
            else:
                if _local_key(obj) not in self._meshes._cache:
                    self.counts["meshes_extracted"] += 1
                mesh = self._meshes.export(inst)
                self.counts["meshes_placed"] += 1
            placed[key] = (matrix, mesh)
            if mesh is not None:
                meshes.append(mesh)
                order.append(key)
        self._placed, self._order = placed, order
        self.counts["lights"] = len(lights)
        scene.meshes, scene.lights = meshes, lights

    def _volume(self, inst, scene):
        """The box mesh of Volume object instance `inst`, its grid appended to scene.grids and
        its material in the slot kept for it (converted again when its matrix changed: the
        grid's placement and the object-space density follow it); None when not rendered."""
        key = _instance_key(inst)
        matrix = np.array(inst.matrix_world, np.float64).tobytes()
        old = self._vol_cache.get(key)
        if old is None or old[0] != matrix:
            old = (matrix, self._volumes.convert(inst))
            self._vol_cache[key] = old
        if old[1] is None:
            return None
        grid, mesh, mat = old[1]
        table = self._materials.materials
        if key not in self._vol_slots:
            table.append(None)
            self._vol_slots[key] = len(table) - 1
        slot = self._vol_slots[key]
        table[slot] = add_grids(scene, mat, grid)  # density, temperature, flame
        return dict(mesh, material_ids=np.full(len(mesh["indices"]), slot, np.uint32))


def _converted(table):
    """How many Blender materials `table` has converted (0 when it does not say)."""
    return len(getattr(table, "_index", ()))


def _find_material(depsgraph, name):
    import bpy
    material = bpy.data.materials.get(name)
    if material is None:
        return None
    return material.evaluated_get(depsgraph) if hasattr(material, "evaluated_get") else material
