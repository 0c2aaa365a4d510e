"""The Render Properties panel, and Blender's own panels enabled for Lantern."""

import bpy

ENGINE = "LANTERN"


class LANTERN_PT_render(bpy.types.Panel):
    bl_label = "Lantern"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        s = context.scene.lantern
        layout = self.layout
        layout.use_property_split = True
        layout.prop(s, "integrator")
        layout.prop(s, "backend")
        col = layout.column(align=True)
        col.prop(s, "samples")
        col.prop(s, "preview_samples")
        col.prop(s, "time_limit")
        layout.prop(s, "max_depth")
        col = layout.column(align=True)
        col.active = s.integrator in {"lvc", "cis"}
        col.prop(s, "connections")
        col.prop(s, "candidates")
        col.prop(s, "sort")
        col = layout.column(align=True)
        col.prop(s, "seed")
        col.prop(s, "spp_per_iteration")
        col.prop(s, "threads")


_patched = []


def _compatible_panels():
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if isinstance(engines, set) and ({"BLENDER_EEVEE", "BLENDER_EEVEE_NEXT", "CYCLES",
                                          "BLENDER_RENDER"} & engines):
            yield panel


def register():
    bpy.utils.register_class(LANTERN_PT_render)
    for panel in _compatible_panels():
        if ENGINE not in panel.COMPAT_ENGINES:
            panel.COMPAT_ENGINES.add(ENGINE)
            _patched.append(panel)


def unregister():
    for panel in _patched:
        panel.COMPAT_ENGINES.discard(ENGINE)
    _patched.clear()
    bpy.utils.unregister_class(LANTERN_PT_render)
