"""The Render Properties panel, and Blender's own panels enabled for Lantern."""

import bpy

ENGINE = "LANTERN"

_gpu_label = None


def gpu_label():
    """One line about the GPU, asked once per Blender session (the driver query is not free)."""
    global _gpu_label
    if _gpu_label is None:
        try:
            import lantern
            info = lantern.cuda_info()
        except Exception as e:  # the package is missing or broken: the render reports it
            info = {"available": False, "reason": str(e)}
        if info.get("available"):
            gib = info.get("memory_bytes", 0) / 2 ** 30
            _gpu_label = f"GPU: {info.get('name') or 'CUDA device'} ({gib:.0f} GB)"
        else:
            _gpu_label = f"No GPU: {info.get('reason') or 'unknown reason'}; renders on the CPU"
    return _gpu_label


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
        if s.integrator == "auto":
            from .engine import LAST_AUTO
            if LAST_AUTO["text"]:
                row = layout.row()
                row.alignment = "RIGHT"
                row.label(text=f"Last render: {LAST_AUTO['text'][len('Auto: '):]}")
        layout.prop(s, "backend")
        if s.backend != "cpu":
            row = layout.row()
            row.alignment = "RIGHT"
            row.label(text=gpu_label())
        col = layout.column(align=True)
        col.prop(s, "samples")
        col.prop(s, "preview_samples")
        col.prop(s, "time_limit")
        layout.prop(s, "max_depth")
        col = layout.column(align=True)
        col.active = s.integrator in {"auto", "bdpt", "lvc", "cis"}
        sub = col.column(align=True)
        sub.active = s.integrator in {"auto", "lvc", "cis"}
        sub.prop(s, "connections")
        sub2 = col.column(align=True)
        sub2.active = s.integrator in {"auto", "cis"}
        sub2.prop(s, "candidates")
        col.prop(s, "sort")
        col = layout.column(align=True)
        col.prop(s, "seed")
        col.prop(s, "spp_per_iteration")
        col.prop(s, "threads")


class LANTERN_PT_sampling_noise(bpy.types.Panel):
    bl_label = "Noise Threshold"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    bl_parent_id = "LANTERN_PT_render"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw_header(self, context):
        self.layout.prop(context.scene.lantern, "use_adaptive_sampling", text="")

    def draw(self, context):
        s = context.scene.lantern
        layout = self.layout
        layout.use_property_split = True
        layout.active = s.use_adaptive_sampling
        col = layout.column(align=True)
        col.prop(s, "adaptive_threshold", text="Threshold")
        col.prop(s, "adaptive_min_samples")


class LANTERN_PT_layer_passes(bpy.types.Panel):
    """The passes Lantern writes, with Cycles' names (Cycles' own panels stay hidden)."""
    bl_label = "Passes"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "view_layer"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        vl = context.view_layer
        col = layout.column(heading="Data", align=True)
        col.prop(vl, "use_pass_combined")
        col.prop(vl, "use_pass_z")
        col.prop(vl, "use_pass_normal")
        col = layout.column(heading="Light", align=True)
        col.prop(vl, "use_pass_diffuse_color", text="Diffuse Color")
        col.prop(vl, "use_pass_emit", text="Emission")
        col = layout.column(heading="Denoising", align=True)
        col.prop(vl.lantern, "denoising_store_passes")
        col = layout.column(heading="Debug", align=True)
        col.prop(vl.lantern, "pass_sample_count")


class LANTERN_PT_object_visibility(bpy.types.Panel):
    bl_label = "Ray Visibility (Lantern)"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES and context.object is not None and \
            context.object.type in {"MESH", "CURVE", "SURFACE", "META", "FONT", "CURVES", "LIGHT"}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        col = layout.column(heading="Ray Visibility")
        col.prop(context.object, "visible_camera", text="Camera")
        if context.object.type != "LIGHT":
            col.prop(context.object, "visible_shadow", text="Shadow")
        elif context.object.data is not None:  # a light's own Cast Shadow, as Cycles reads it
            col.prop(context.object.data, "use_shadow", text="Cast Shadow")


_patched = []

# Blender's own panels that list EEVEE or Cycles and show engine-neutral data (render format and
# output, camera, light, material and world surface, object visibility). Engine-specific panels
# (EEVEE's sampling, light probes, Cycles' own settings) stay hidden for Lantern.
_ALLOW = {"EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface",
          "EEVEE_WORLD_PT_surface", "DATA_PT_EEVEE_light"}


def _compatible_panels():
    for panel in bpy.types.Panel.__subclasses__():
        engines = panel.__dict__.get("COMPAT_ENGINES")  # own set only, never a shared base's
        if not isinstance(engines, set) or not {"BLENDER_EEVEE", "CYCLES"} & engines:
            continue
        name = panel.__name__
        lname = name.lower()
        if name not in _ALLOW and (name.startswith("CYCLES") or "eevee" in lname
                                   or "lightprobe" in lname or "light_probe" in lname):
            continue
        yield panel


def register():
    bpy.utils.register_class(LANTERN_PT_render)
    bpy.utils.register_class(LANTERN_PT_sampling_noise)
    bpy.utils.register_class(LANTERN_PT_layer_passes)
    bpy.utils.register_class(LANTERN_PT_object_visibility)
    for panel in _compatible_panels():
        if ENGINE not in panel.COMPAT_ENGINES:
            panel.COMPAT_ENGINES.add(ENGINE)
            _patched.append(panel)


def unregister():
    for panel in _patched:
        panel.COMPAT_ENGINES.discard(ENGINE)
    _patched.clear()
    bpy.utils.unregister_class(LANTERN_PT_object_visibility)
    bpy.utils.unregister_class(LANTERN_PT_layer_passes)
    bpy.utils.unregister_class(LANTERN_PT_sampling_noise)
    bpy.utils.unregister_class(LANTERN_PT_render)
