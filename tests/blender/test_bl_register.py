import bpy


def test_engine_registered(addon):
    engines = {cls.bl_idname for cls in bpy.types.RenderEngine.__subclasses__()
               if hasattr(cls, "bl_idname")}
    assert "LANTERN" in engines
    assert addon.LanternRenderEngine.bl_label == "Lantern"


def test_settings_defaults(empty):
    s = empty.lantern
    assert (s.samples, s.preview_samples, s.max_depth, s.integrator) == (64, 1024, 12, "auto")
    assert (s.connections, s.candidates, s.seed, s.spp_per_iteration, s.threads) == (5, 10, 0, 1, 0)
    assert s.backend == "auto" and s.time_limit == 0.0 and s.sort == "auto"


SHOWN = ("RENDER_PT_format", "RENDER_PT_output", "DATA_PT_lens", "DATA_PT_EEVEE_light",
         "DATA_PT_spot", "EEVEE_MATERIAL_PT_surface", "EEVEE_WORLD_PT_surface",
         "OBJECT_PT_visibility", "LANTERN_PT_object_visibility")
HIDDEN = ("RENDER_PT_eevee_sampling", "CYCLES_RENDER_PT_sampling", "CYCLES_LIGHT_PT_light",
          "DATA_PT_EEVEE_light_shadow")


def test_standard_panels_show_for_lantern(addon):
    for name in SHOWN:
        assert "LANTERN" in getattr(bpy.types, name).COMPAT_ENGINES, name
    for name in HIDDEN:
        panel = getattr(bpy.types, name, None)
        if panel is not None:
            assert "LANTERN" not in panel.COMPAT_ENGINES, name


def test_unregister_restores_panels(addon):
    addon.unregister()
    try:
        assert "LANTERN" not in bpy.types.RENDER_PT_format.COMPAT_ENGINES
        assert not hasattr(bpy.types.Scene, "lantern")
    finally:
        addon.register()
    assert "LANTERN" in bpy.types.RENDER_PT_format.COMPAT_ENGINES


def test_panel_names_the_gpu_or_why_not(addon):
    import lantern
    from lantern_blender import ui
    ui._gpu_label = None
    label = ui.gpu_label()
    reason = lantern.session.backend_unavailable("cuda")
    if reason:
        assert label.startswith("No GPU: ") and "CPU" in label, label
    else:
        assert label.startswith("GPU: ") and lantern.cuda_info()["name"] in label, label
