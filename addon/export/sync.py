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

`counts` says what the last sync exported (the tests check it). The walk is export_scene's
own (export/walk.py: hair, hidden instancers, warnings, holdouts, linking, ray visibility),
with this class as its source of geometry: placed meshes and strands come from the caches
above, decorated afresh by each walk. Motion blur stays off in the viewport (as Cycles')."""

import numpy as np

from . import changes as ch
from .holdout import Holdouts
from .material import MaterialTable
from .mesh import MeshExporter, _needs_tangents
from .strands import StrandExporter
from .volume_objects import VolumeObjects, add_grids
from .walk import Walk, integrator, object_settings, scene_warnings
from .world import export_world


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
        self._channels = 0        # attribute channels the placed meshes were finished with
        self._holdouts = None     # export/holdout.py: its material copies kept across syncs
        self._strands = None      # export/strands.py, and its sets by instance key:
        self._strand_cache = {}   # instance key -> (matrix bytes, [strand set dicts])
        self._settings = {}       # object name -> walk.object_settings as the last walk read
        self._next = None         # the caches the running walk fills

    def note(self, changes):
        """Changes from a view_update, applied at the next sync."""
        for name in changes.images:
            self.texture_cache.pop(name, None)
        self.pending |= changes

    def needs_sync(self):
        return self.scene is None or bool(self.pending.flags & ~ch.VIEW) or \
            bool(self.pending.objects)

    def sync(self, depsgraph, view, report):
        """Bring self.scene up to date with the pending changes; returns the Changes applied.
        `view` is the camera.ViewportView to render; the scene's film and camera follow it."""
        from ..native import import_lantern
        lantern = import_lantern()
        todo, self.pending = self.pending, ch.Changes()
        self.syncs += 1
        self.counts = {"meshes_extracted": 0, "meshes_placed": 0, "materials": 0,
                       "world": 0, "lights": 0, "strands": 0}
        if self.scene is None or todo.has(ch.IMAGES) or todo.all_materials:
            todo.flags |= ch.FULL
        if todo.has(ch.MATERIALS) and self._vol_slots:
            todo.flags |= ch.FULL   # a Volume object's material is converted with its grid
        if todo.has(ch.FULL):
            self._materials = MaterialTable(report, self.texture_cache)
            self._meshes = MeshExporter(self._materials, report)
            bscene = depsgraph.scene_eval
            self._holdouts = Holdouts(self._materials, report, integrator(bscene),
                                      depsgraph.view_layer, None)  # None: the viewport's film
            self._strands = StrandExporter(bscene, self._materials, report, final=False)
            self._placed, self._strand_cache = {}, {}
            self.scene = None
            self._volumes = VolumeObjects(report, lantern, self._materials.attributes)
            self._vol_cache, self._vol_slots = {}, {}
        self._materials.report = self._meshes.report = self._volumes.report = report
        self._holdouts.report = self._strands.report = report
        self._holdouts.integrator = integrator(depsgraph.scene_eval)
        known = _converted(self._materials)
        if todo.has(ch.MATERIALS) and not todo.has(ch.FULL):
            for name in sorted(todo.materials):
                material = _find_material(depsgraph, name)
                if material is None or not _reconvert(self._materials, material):
                    self.pending = ch.Changes(ch.FULL)  # cannot patch it: export everything
                    return self.sync(depsgraph, view, report)
                self.counts["materials"] += 1
        self._holdouts.refresh()  # holdout copies of the materials converted again
        if todo.objects and not todo.has(ch.FULL):
            self._objects_changed(depsgraph, todo)
        for name in todo.geometry:
            for key in [k for k in self._meshes._cache if k[0] == name]:
                del self._meshes._cache[key]
            for key in [k for k in self._vol_cache if k[0] == name]:
                del self._vol_cache[key]   # its file, frame or grids: read again
                self._volumes._read.clear()
            for key in [k for k in self._strand_cache if k[0] == name]:
                del self._strand_cache[key]  # an emitter moved or its particles edited
        scene = self.scene if self.scene is not None else lantern.Scene()
        scene.film, scene.camera = view.film(), view.camera()
        bscene = depsgraph.scene_eval
        if todo.flags & (ch.FULL | ch.WORLD | ch.SETTINGS):
            scene.world = export_world(bscene.world, report, self.texture_cache,
                                       integrator(bscene))
            self.counts["world"] = 1
        walk = None
        if todo.flags & ~(ch.VIEW | ch.WORLD | ch.MATERIALS):
            walk = self._walk_instances(depsgraph, scene, report)
        self.counts["materials"] += _converted(self._materials) - known
        attrs = self._materials.attributes
        if not todo.has(ch.FULL) and len(attrs.names) != self._channels:
            # an edited material reads a mesh attribute (Generated, a colour attribute, ...)
            # that the meshes placed earlier were not exported with: export everything
            self.pending = ch.Changes(ch.FULL)
            return self.sync(depsgraph, view, report)
        if walk is not None:
            walk.finish()  # attribute channels, materials, warnings: as export_scene
        else:  # the meshes as the last walk finished them; the materials patched
            scene.materials = self._materials.materials
            scene.textures = self._materials.textures
            scene_warnings(bscene, scene, report)
        self._channels = len(attrs.names)
        self.scene = scene
        return todo

    def _objects_changed(self, depsgraph, todo):
        """OBJECTS where an object tagged for shading only (changes.py) now reads otherwise
        than the last walk read it; its placed meshes are placed again where the per-object
        values they carry changed. A material edit tags its objects the same way: unchanged
        settings keep it a material edit (the running session takes it in place)."""
        import bpy
        from .node_attributes import INSTANCE
        carried = any(n in INSTANCE for n in self._materials.attributes.names)
        for name in todo.objects:
            old = self._settings.get(name)
            if old is None:
                continue  # no mesh or strands of it in the scene (a light: LIGHTS; a camera)
            obj = bpy.data.objects.get(name)
            now = object_settings(obj.evaluated_get(depsgraph)) if obj is not None else None
            placement = now is None or (carried and now[1] != old[1])
            if now is not None and now[0] == old[0] and not placement:
                continue
            todo.flags |= ch.OBJECTS
            if placement:
                for key in [k for k in self._placed if k[0] == name]:
                    del self._placed[key]

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
        if self.base is None or self.base[0] != self._order or self.counts.get("strands"):
            return None  # (strands read again: the session moves meshes only)
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
        """export_scene's walk (export/walk.py) over the instances, this object its source."""
        self._next = ({}, [], {}, {})   # placed, order, strands, settings of this walk
        scene.grids = []
        walk = Walk(depsgraph, scene, self._materials, self._holdouts, report)
        for inst in depsgraph.object_instances:
            walk.instance(inst, self)
        (self._placed, self._order, self._strand_cache, self._settings), self._next = \
            self._next, None
        self.counts["lights"] = len(scene.lights)
        return walk

    # ---- the walk's source (export/walk.py): geometry from the caches ----
    def mesh(self, inst):
        """The instance's placed mesh: the one placed before where its matrix is the same
        (a dict the walk copies, never changes), else placed again (extracted again only
        where its object's geometry changed)."""
        placed, order, _, settings = self._next
        settings[inst.object.name_full] = object_settings(inst.object)
        key = _instance_key(inst)
        matrix = np.array(inst.matrix_world, dtype=np.float64).tobytes()
        old = self._placed.get(key)
        if old is not None and old[0] == matrix:
            mesh = old[1]
        else:
            if _local_key(inst.object) not in self._meshes._cache:
                self.counts["meshes_extracted"] += 1
            mesh = self._meshes.export(inst)
            self.counts["meshes_placed"] += 1
        placed[key] = (matrix, mesh)
        if mesh is not None:
            order.append(key)
        return mesh

    def corners(self, obj):
        return None  # no motion blur in the viewport

    def strands(self, inst):
        """The instance's strand sets, read again where its matrix or geometry changed."""
        key = _instance_key(inst)
        matrix = np.array(inst.matrix_world, dtype=np.float64).tobytes()
        old = self._strand_cache.get(key)
        if old is None or old[0] != matrix:
            old = (matrix, self._strands.sets_of(inst))
            self.counts["strands"] += len(old[1])
        self._next[2][key] = old
        if old[1]:
            self._next[3][inst.object.name_full] = object_settings(inst.object)
        return old[1]

    def volume(self, inst, scene):
        mesh = self._volume(inst, scene)
        if mesh is not None:
            placed, order = self._next[:2]
            key = _instance_key(inst)
            placed[key] = (np.array(inst.matrix_world, np.float64).tobytes(), mesh)
            scene.meshes.append(mesh)
            order.append(key)

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
