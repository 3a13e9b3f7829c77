"""The add-on's panel (Properties > Render > PIS set), the role fields on Object properties,
and the operator that renders the set."""

import bpy

from . import export, scene_file, space


class PIS_OT_render_set(bpy.types.Operator):
    bl_idname = "pis.render_set"
    bl_label = "Render PIS set"
    bl_description = "Render every point of the parameter space with Cycles into a PIS ray-traced set"

    def execute(self, context):
        scene = context.scene
        out = bpy.path.abspath(scene.pis.output_dir)
        wm = context.window_manager
        wm.progress_begin(0, 1)

        def progress(line, done):
            self.report({"INFO"}, line)
            wm.progress_update(done)

        try:
            report = export.export_set(scene, out, progress=progress)
        except (scene_file.ExportError, space.SpaceError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        for note in report.get("notes", []):
            self.report({"WARNING"}, note)
        self.report({"INFO"}, f"PIS set: {report['points']} points, {report['renders']} renders in {report['seconds']} s: {out}")
        return {"FINISHED"}


class PIS_PT_set(bpy.types.Panel):
    bl_label = "PIS set"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    def draw(self, context):
        s, col = context.scene.pis, self.layout.column()
        for name in ("output_dir", "spp", "seed", "filter_sigma_px", "caustics", "denoise", "pis_trace"):
            col.prop(s, name)
        for prefix, fields in (
            ("light_path", ("name", "light", "curve", "samples", "range")),
            ("frames", ("name", "range", "samples", "kind")),
            ("orbit", ("name", "target", "radius", "elevation_deg", "azimuth_deg", "samples", "periodic")),
        ):
            box = col.box()
            box.prop(s, f"{prefix}_on")
            if getattr(s, f"{prefix}_on"):
                for f in fields:
                    box.prop(s, f"{prefix}_{f}")
        col.operator(PIS_OT_render_set.bl_idname)


class PIS_PT_object(bpy.types.Panel):
    bl_label = "PIS"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    def draw(self, context):
        obj = context.object
        self.layout.prop(obj, "pis_role")
        self.layout.prop(obj, "pis_reflector")


CLASSES = (PIS_OT_render_set, PIS_PT_set, PIS_PT_object)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
