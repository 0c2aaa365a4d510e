import bpy


def test_engine_registered(addon):
    engines = {cls.bl_idname for cls in bpy.types.RenderEngine.__subclasses__()
               if hasattr(cls, "bl_idname")}
    assert "LANTERN" in engines
    assert addon.LanternRenderEngine.bl_label == "Lantern"


def test_settings_defaults(empty):
    s = empty.lantern
    assert (s.samples, s.preview_samples, s.max_depth, s.integrator) == (64, 1024, 12, "pt")
    assert (s.connections, s.candidates, s.seed, s.spp_per_iteration, s.threads) == (5, 10, 0, 1, 0)
    assert s.backend == "auto" and s.time_limit == 0.0


def test_standard_panels_show_for_lantern(addon):
    for name in ("RENDER_PT_format", "DATA_PT_light", "DATA_PT_camera", "EEVEE_MATERIAL_PT_surface"):
        panel = getattr(bpy.types, name, None)
        if panel is not None and hasattr(panel, "COMPAT_ENGINES"):
            assert "LANTERN" in panel.COMPAT_ENGINES, name
    assert "LANTERN" in bpy.types.RENDER_PT_format.COMPAT_ENGINES
