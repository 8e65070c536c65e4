"""penumbra: renders Blender scenes on a penumbra render service (`penumbra serve`).

Install the zip made by scripts/package-blender-addon.sh (Edit > Preferences > Add-ons >
Install), or put this folder on Blender's script path (scripts/addons). docs/blender.md says
what is exported and how.
"""
bl_info = {
    "name": "penumbra",
    "author": "penumbra contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine > penumbra; File > Export > penumbra scene",
    "description": "Render on a penumbra render service",
    "category": "Render",
}

import bpy  # noqa: E402

from . import engine, export_operator, preferences  # noqa: E402


class PENUMBRA_PT_sampling(bpy.types.Panel):
    bl_label = "penumbra"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {"PENUMBRA"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        settings = context.scene.penumbra
        col = self.layout.column()
        col.prop(settings, "samples")
        col.prop(settings, "seed")
        col.prop(settings, "max_depth")
        col.separator()
        render = context.scene.render
        col.prop(render, "use_motion_blur")
        sub = col.column()
        sub.active = render.use_motion_blur
        sub.prop(render, "motion_blur_shutter")
        url, _ = preferences.server_settings(context)
        col.label(text=f"Server: {url}")


_CLASSES = (preferences.PenumbraPreferences, preferences.PenumbraSceneSettings,
            engine.PenumbraRenderEngine, export_operator.PENUMBRA_OT_export_scene,
            PENUMBRA_PT_sampling)
_panels = []


def register():
    for cls in _CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.penumbra = bpy.props.PointerProperty(type=preferences.PenumbraSceneSettings)
    bpy.types.TOPBAR_MT_file_export.append(export_operator.menu_entry)
    for panel in engine.compatible_panels():
        panel.COMPAT_ENGINES.add("PENUMBRA")
        _panels.append(panel)


def unregister():
    for panel in _panels:
        panel.COMPAT_ENGINES.discard("PENUMBRA")
    _panels.clear()
    bpy.types.TOPBAR_MT_file_export.remove(export_operator.menu_entry)
    del bpy.types.Scene.penumbra
    for cls in reversed(_CLASSES):
        bpy.utils.unregister_class(cls)
