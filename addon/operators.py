"""File > Export > Lantern Scene (.lantern): the evaluated depsgraph written with Scene.save."""

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ExportHelper


class LANTERN_OT_export_scene(bpy.types.Operator, ExportHelper):
    """Export the scene, as Lantern renders it, to a self-contained .lantern file"""
    bl_idname = "export_scene.lantern"
    bl_label = "Export Lantern Scene"
    bl_options = {"PRESET"}

    filename_ext = ".lantern"
    filter_glob: StringProperty(default="*.lantern", options={"HIDDEN"})

    def execute(self, context):
        from .export import export_scene
        try:
            depsgraph = context.evaluated_depsgraph_get()
            scene, report = export_scene(depsgraph)
            for message in report.messages:
                self.report({"WARNING"}, message)
            scene.save(self.filepath)
        except Exception as e:  # report, never crash the UI
            import traceback
            traceback.print_exc()
            self.report({"ERROR"}, f"Lantern export failed: {e}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Exported {self.filepath}")
        return {"FINISHED"}


def menu_func_export(self, context):
    self.layout.operator(LANTERN_OT_export_scene.bl_idname, text="Lantern Scene (.lantern)")
