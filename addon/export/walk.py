"""One depsgraph walk's per-instance work, written once for export_scene (export/__init__.py,
F12) and the viewport's incremental sync (export/sync.py), so that the viewport renders the
scene a fresh export makes: hair (export/strands.py), instancers hidden for this kind of render
(inst.show_self), the unsupported-feature warnings, lights, meshes with their per-walk fields
(ray visibility, holdouts and shadow catchers, light and shadow linking, motion), Volume
objects, and at the end the attribute channels and the mixed-kind warnings.

Where the geometry comes from is the caller's `source` (fresh for export_scene, cached by
the sync): source.mesh(inst) -> a placed mesh dict (never changed here: the walk decorates a
shallow copy, so a dict the sync reuses across walks is decorated afresh each time),
source.strands(inst) -> strand set dicts (likewise copied), source.volume(inst, scene) appends a
Volume object's box mesh, grid and material, source.corners(obj) for deformation blur."""

from .light import export_light
from .linking import LightLinking
from .unsupported import UnsupportedFeatures
from .visibility import camera_visible, mesh_ray_visibility, mixed_kind_lamp_warning, \
    mixed_kind_warning
from .world import mixed_lobe_warning

MESH_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT"}   # CURVES: strands
STRAND_TYPES = {"MESH", "CURVES"}   # hair: even on an emitter not rendered itself


def mesh_flags(inst, view_layer):
    """The fields of a placed mesh that follow the object's settings rather than its geometry
    (export/visibility.py): set at every walk, so that a reused mesh never keeps stale ones."""
    obj = inst.object
    return {"visible_camera": camera_visible(inst, view_layer),
            "cast_shadow": bool(getattr(obj, "visible_shadow", True)),
            "terminator_offset": terminator_offset(obj),
            **mesh_ray_visibility(obj)}


def terminator_offset(obj):
    """Object > Shading > Shadow Terminator > Geometry Offset (Blender's default 0.1), which
    lifts smooth-shaded triangles' shadow rays as Cycles does (docs/materials.md "Shadow
    terminator"); non-mesh objects (text, curves) carry it too."""
    t = float(getattr(obj, "shadow_terminator_geometry_offset", 0.1))
    return min(max(t, 0.0), 1.0)


def object_settings(obj):
    """What a walk reads from an object's own settings rather than its geometry, as (the
    fields set on each walk's copies, the per-object values placed meshes carry: Object Info
    colour and pass index, export/node_attributes.py). Blender tags an edit of any of them as a
    shading update of the object alone, as it tags the objects of an edited material: the sync
    compares them to tell the two apart (export/changes.py)."""
    flags = tuple(bool(getattr(obj, p, True)) for p in (
        "visible_camera", "visible_shadow", "visible_diffuse", "visible_glossy",
        "visible_transmission", "visible_volume_scatter", "is_holdout", "is_shadow_catcher"))
    flags += (terminator_offset(obj),)
    return flags, (int(getattr(obj, "pass_index", 0)),
                   tuple(float(c) for c in getattr(obj, "color", ())))


class Walk:
    """The collectors of one walk over depsgraph.object_instances into `scene` (its meshes,
    lights and curves start empty); instance() per instance, then finish()."""

    def __init__(self, depsgraph, scene, materials, holdouts, report, motion=None):
        self.scene, self.materials, self.report = scene, materials, report
        self.holdouts = holdouts            # export/holdout.py Holdouts
        self.motion = motion                # export/motion.py MotionRecorder (F12 only)
        self.view_layer, self.bscene = depsgraph.view_layer, depsgraph.scene_eval
        self.features = UnsupportedFeatures(report)
        self.features.scene(depsgraph)
        self.linking = LightLinking(report)
        self.placed = []                    # (source's mesh, its decorated copy in the scene)
        scene.meshes, scene.lights, scene.curves = [], [], []

    def instance(self, inst, source):
        obj = inst.object
        if obj.type in STRAND_TYPES:
            # its object's flags: particle hair its emitter's (Cycles syncs the hair as a
            # second object of the emitter, with the emitter's ray visibility), Curves their own
            sets = [dict(st, visible_camera=bool(getattr(obj, "visible_camera", True)),
                         cast_shadow=bool(getattr(obj, "visible_shadow", True)),
                         **mesh_ray_visibility(obj))
                    for st in source.strands(inst)]
            self.scene.curves.extend(sets)
            self.linking.curves(obj, sets)  # its object's receiver and blocker sets
            if self.motion is not None and sets:  # motion blur of the strands (motion.py)
                self.motion.strands(inst, sets, source.strands)
        if not inst.show_self:  # an instancer hidden (show_instancer_for_render / _viewport)
            return
        self.features.object(obj)
        if obj.type == "LIGHT":
            light = export_light(obj, inst.matrix_world, self.report)
            if light is not None:
                self.linking.light(obj, light)  # export/linking.py
                self.scene.lights.append(light)
        elif obj.type in MESH_TYPES:
            placed = source.mesh(inst)
            if placed is not None:
                mesh = dict(placed, **mesh_flags(inst, self.view_layer))
                self.holdouts.mesh(obj, mesh)  # export/holdout.py
                if self.motion is not None:
                    self.motion.mesh(inst, mesh, source.corners(obj))
                self.linking.mesh(obj, mesh)
                self.scene.meshes.append(mesh)
                self.placed.append((placed, mesh))
        elif obj.type == "VOLUME":
            source.volume(inst, self.scene)

    def finish(self):
        """Linking sets, attribute channels, the materials and textures, the warnings that
        need the whole scene. The attribute arrays are handed back to the source's meshes, so
        that a reused mesh is not finished again."""
        scene, materials = self.scene, self.materials
        self.linking.finish()
        scene.attribute_channels = materials.attributes.finish(scene.meshes)
        for placed, mesh in self.placed:
            if placed.pop("_attributes", None) is not None and "attributes" in mesh:
                placed["attributes"] = mesh["attributes"]
        scene.materials = materials.materials
        scene.textures = materials.textures
        self.warnings()

    def warnings(self):
        scene_warnings(self.bscene, self.scene, self.report)


def scene_warnings(bscene, scene, report):
    """The warnings that need the whole scene: materials of mixed lobes under a world or an
    object hidden from some rays."""
    used = used_materials(scene)
    mixed_lobe_warning(bscene.world, scene.world, used, report)  # world.py
    mixed_kind_warning(list(scene.meshes) + list(scene.curves), used, report)  # visibility.py
    mixed_kind_lamp_warning(scene.lights, used, report)


def integrator(bscene):
    """The integrator whose features the export checks (holdouts, shadow catchers:
    export/holdout.py drops them with a warning for any but pt; the world's ray visibility is
    exported for every integrator, the core hands it to pt):
    "auto" counts as pt, since it renders every scene with one of them with pt alone, on the
    CPU and the GPU (native/src/integrator/allocation.cpp pt_only_reason: a holdout material,
    a shadow catcher, the world hidden from some rays)."""
    settings = getattr(getattr(bscene, "original", bscene), "lantern", None)
    name = str(getattr(settings, "integrator", "pt")).lower()
    return "pt" if name == "auto" else name


def used_materials(scene):
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
