"""File > Export > penumbra scene: the scene JSON the engine would submit, with its meshes and
copies of its images, in a folder that `penumbra render FOLDER/scene.json` renders on its own
(the same image as F12 for the same seed)."""
from __future__ import annotations

import os

import bpy

from . import preferences
from .scene_export import export_scene, write_scene


class PENUMBRA_OT_export_scene(bpy.types.Operator):
    """Export the scene as a penumbra scene folder (scene.json, meshes, textures)"""
    bl_idname = "export_scene.penumbra"
    bl_label = "Export penumbra scene"
    bl_options = {"REGISTER"}

    directory: bpy.props.StringProperty(subtype="DIR_PATH")

    def execute(self, context):
        if not self.directory:
            self.report({"ERROR"}, "no folder given")
            return {"CANCELLED"}
        folder = bpy.path.abspath(self.directory)
        os.makedirs(folder, exist_ok=True)
        scene = context.scene
        samples, integrator, seed, max_depth = preferences.render_settings(scene, context)
        depsgraph = context.evaluated_depsgraph_get()
        frame = scene.frame_current

        def frame_set(f, subframe):
            scene.frame_set(f, subframe=subframe)

        try:
            doc, ctx = export_scene(depsgraph, folder, samples=samples, integrator=integrator,
                                    seed=seed, max_depth=max_depth, copy_assets=True,
                                    frame_set=frame_set)
        finally:
            scene.frame_set(frame)
        for warning in ctx.warnings:
            self.report({"WARNING"}, warning)
        path = write_scene(doc, folder)
        self.report({"INFO"}, f"penumbra scene written to {path}")
        return {"FINISHED"}

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}


def menu_entry(self, context):
    self.layout.operator(PENUMBRA_OT_export_scene.bl_idname, text="penumbra scene (folder)")
