"""Lantern for Blender: register the render engine, its settings, panels and the exporter.

The RenderEngine here is thin: every callback forwards to engine.py, which owns the work."""

import bpy

from . import engine, properties, ui
from .operators import LANTERN_OT_export_scene, menu_func_export


class LanternRenderEngine(bpy.types.RenderEngine):
    bl_idname = "LANTERN"
    bl_label = "Lantern"
    bl_use_preview = False
    bl_use_shading_nodes_custom = False
    bl_use_eevee_viewport = False

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._lantern = engine.EngineState()

    def __del__(self):
        try:
            state = self._lantern
        except (AttributeError, ReferenceError):  # the RNA struct may already be gone
            return
        state.free()

    def render(self, depsgraph):
        engine.render(self, depsgraph)

    def update_render_passes(self, scene=None, renderlayer=None):
        from .passes import register_passes
        register_passes(self, scene, renderlayer)

    def view_update(self, context, depsgraph):
        engine.view_update(self, context, depsgraph)

    def view_draw(self, context, depsgraph):
        engine.view_draw(self, context, depsgraph)


_classes = (LanternRenderEngine, LANTERN_OT_export_scene)


def register():
    properties.register()
    for cls in _classes:
        bpy.utils.register_class(cls)
    ui.register()
    bpy.types.TOPBAR_MT_file_export.append(menu_func_export)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(menu_func_export)
    engine.stop_all()
    ui.unregister()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
    properties.unregister()
