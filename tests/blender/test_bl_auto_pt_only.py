"""Integrator "auto" and the features only pt renders (addon/export/walk.py integrator): the
export counts auto as pt, so it keeps a holdout, a shadow catcher (over transparent film) and
the world hidden from some rays where it drops them, with a warning, for bdpt, lvc, cis and lt
(export/holdout.py, world.py). That is right only while auto renders each such scene with pt
alone (native/src/integrator/allocation.cpp pt_only_reason): each feature alone, exported under
auto, must reach the scene without a warning and make auto's session pt's, saying why. Were
auto counted as itself, the export would warn and drop them (a holdout: render it as an
ordinary surface) and auto could pick cis (the control: the same export under bdpt does)."""

import bpy
import pytest


def export():
    from lantern_blender.export import export_scene
    return export_scene(bpy.context.evaluated_depsgraph_get())


def holdout(scene):
    from blender_helpers import add_plane, diffuse_material
    add_plane(scene, name="Cutout", material=diffuse_material(0.5)).is_holdout = True
    return lambda s: any(m.get("holdout") for m in s.materials)


def catcher(scene):
    from blender_helpers import add_plane
    add_plane(scene, name="Catcher").is_shadow_catcher = True
    scene.render.film_transparent = True
    return lambda s: any(m.get("shadow_catcher") for m in s.meshes)


def world_hidden(scene):
    world = bpy.data.worlds.new("Vis")
    world.cycles_visibility.glossy = False
    scene.world = world
    return lambda s: s.world.get("visible_glossy") is False


@pytest.mark.parametrize("feature", [holdout, catcher, world_hidden],
                         ids=["holdout", "catcher", "world_hidden"])
def test_auto_keeps_what_only_pt_renders(empty, addon, feature):
    import lantern
    from blender_helpers import add_camera, add_plane, diffuse_material
    if not lantern.native_available():
        pytest.skip("lantern native module not built")
    add_camera(empty)
    add_plane(empty, size=4.0, location=(0, 0, -0.5), name="Floor",
              material=diffuse_material(0.8))
    exported = feature(empty)
    empty.render.resolution_x = 8
    empty.render.resolution_y = 8
    empty.lantern.integrator = "auto"
    scene, report = export()
    assert exported(scene), feature.__name__
    assert not any("pt integrator only" in m for m in report.messages), report.messages
    s = lantern.Session(scene, integrator="auto", seed=1, backend="cpu", threads=1)
    s.step()
    assert s.stats["auto_choice"] == "pt" and s.stats["auto_cis_iterations"] == 0
    assert any("only pt renders" in w for w in s.warnings), s.warnings
    # the control: another integrator's export warns (and drops the catcher; a holdout's copy
    # stays, rendered as an ordinary surface). The world's flags stay: the core hands them to
    # pt with its warning (allocation.cpp world_rays_reason)
    empty.lantern.integrator = "bdpt"
    scene, report = export()
    if feature is world_hidden:
        assert exported(scene)
        s = lantern.Session(scene, integrator="bdpt", seed=1, backend="cpu", threads=1)
        assert any("the world hidden from glossy rays" in w and "with pt" in w
                   for w in s.warnings), s.warnings
        return
    assert any("pt integrator only" in m for m in report.messages), report.messages
    assert feature is holdout or not exported(scene), feature.__name__
