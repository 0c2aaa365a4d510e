"""Scene features Lantern does not render, each named in one warning (object, material, light,
world, view layer or render setting, and the feature), never dropped silently. Shader nodes are
material.py's, the world's surface and the camera world.py's / camera.py's; this file covers
the rest. Every check reads settings only (cheap), once per datablock per export."""

from .volume import volume_settings

# object types that have no surface Lantern renders
# (Volume objects: export/volume_objects.py, which warns where one is not rendered)
_NO_SURFACE = {"POINTCLOUD": "point clouds are not rendered",
               "GREASEPENCIL": "Grease Pencil strokes are not rendered",
               "GPENCIL": "Grease Pencil strokes are not rendered"}


def _linked(node_tree, output_type, socket):
    """Whether the active output node of `output_type` has `socket` linked."""
    if node_tree is None:
        return False
    outputs = [n for n in node_tree.nodes if n.type == output_type]
    active = [n for n in outputs if getattr(n, "is_active_output", False)] or outputs
    for node in active[:1]:
        s = node.inputs.get(socket)
        if s is not None and s.is_linked:
            return True
    return False


class UnsupportedFeatures:
    """Collects the warnings of one export into `report`, each datablock checked once."""

    def __init__(self, report):
        self.report = report
        self._seen = set()
        self._scene = None

    def _once(self, key):
        if key in self._seen:
            return False
        self._seen.add(key)
        return True

    # ---- the scene, its render settings and the view layer ----
    def scene(self, depsgraph):
        scene, layer = depsgraph.scene_eval, depsgraph.view_layer_eval
        self._scene = scene
        r = scene.render
        warn = self.report.warn
        # motion blur: export/motion.py (transform and deformation motion; what it cannot, it warns)
        if getattr(r, "use_multiview", False):
            warn("Render settings: stereoscopy / multi-view is not rendered (one view)")
        if getattr(r, "use_freestyle", False) and getattr(layer, "use_freestyle", True):
            warn(f"View layer '{layer.name}': Freestyle lines are not rendered")
        if getattr(layer, "material_override", None) is not None:
            warn(f"View layer '{layer.name}': the material override "
                 f"'{layer.material_override.name}' is not applied (own materials render)")
        for attr, what in (("use_solid", "Surfaces"), ("use_sky", "Environment")):
            if not getattr(layer, attr, True):
                warn(f"View layer '{layer.name}': the filter '{what}' switched off is not "
                     f"honoured ({what.lower()} render)")
        # Indirect Only collections render: export/visibility.py (camera_visible)
        self.world(scene.world)

    def world(self, world):
        if world is not None and self._once(("world", world.name)) and \
                _linked(world.node_tree, "OUTPUT_WORLD", "Volume"):
            self._volumes()  # the volume itself: export/volume.py

    def _volumes(self):
        if self._scene is not None and self._once(("volume settings",)):
            volume_settings(self._scene, self.report)

    # ---- objects ----
    def object(self, obj):
        """Every evaluated object the depsgraph instances (checked once per name)."""
        if not self._once(("object", obj.name)):
            return
        warn = self.report.warn
        what = _NO_SURFACE.get(obj.type)
        if what:
            warn(f"Object '{obj.name}': {what}")
        # a lamp's own ray visibility: export/light.py (pt renders it)
        # shadow catchers: export/holdout.py
        # light and shadow linking: export/linking.py
        # particle hair and Curves objects: export/strands.py
        if obj.type == "LIGHT":
            self._light(obj)
        if float(getattr(obj, "shadow_terminator_shading_offset", 0.0)) > 0.0:
            warn(f"Object '{obj.name}': Shadow Terminator Shading Offset is not rendered (the "
                 "Geometry Offset is: docs/materials.md \"Shadow terminator\")")
        for slot in getattr(obj, "material_slots", ()):
            if slot.material is not None:
                self.material(slot.material)

    def _light(self, obj):
        # Cast Shadow off: export/light.py (pt renders it)
        light, warn = obj.data, self.report.warn
        tree = getattr(light, "node_tree", None)
        if getattr(light, "use_nodes", False) and tree is not None:   # the rest: node_light.py
            for n in tree.nodes:
                if n.type == "TEX_IES":
                    warn(f"Light '{obj.name}': IES Texture '{n.name}' is not rendered (Lantern "
                         "reads no IES profiles: the light emits as it would without it)")

    # ---- materials ----
    def material(self, mat):
        if not self._once(("material", mat.name)):
            return
        tree = mat.node_tree
        if _linked(tree, "OUTPUT_MATERIAL", "Volume"):
            self._volumes()  # the volume itself: export/volume.py
        method = getattr(mat, "displacement_method", "BUMP")
        if _linked(tree, "OUTPUT_MATERIAL", "Displacement") and method != "BUMP":
            self.report.warn(f"Material '{mat.name}': true displacement (Displacement method "
                             f"'{method}') is not rendered; the Displacement output renders "
                             "as bump (export/node_bump.py)")
