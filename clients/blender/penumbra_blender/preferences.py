"""Add-on preferences (Edit > Preferences > Add-ons > penumbra) and the per-scene settings.

The server URL and token fall back to $PENUMBRA_URL and $PENUMBRA_TOKEN when left empty, so a
render farm sets them in the environment of `blender -b` and never stores a token in a .blend.
"""
from __future__ import annotations

import os

import bpy

INTEGRATORS = [("path", "Path", "Unidirectional path tracing with next-event estimation and MIS"),
               ("distributed", "Distributed", "Cook-style distributed ray tracing")]


class PenumbraPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    server_url: bpy.props.StringProperty(
        name="Server URL", default="",
        description="URL of `penumbra serve`; empty: $PENUMBRA_URL, else http://127.0.0.1:8080")
    token: bpy.props.StringProperty(
        name="Token", default="", subtype="PASSWORD",
        description="Bearer token of the server; empty: $PENUMBRA_TOKEN")
    samples: bpy.props.IntProperty(
        name="Samples", default=64, min=1, max=1 << 20,
        description="Samples per pixel of scenes that do not set their own")
    integrator: bpy.props.EnumProperty(name="Integrator", items=INTEGRATORS, default="path")

    def draw(self, context):
        col = self.layout.column()
        col.prop(self, "server_url")
        col.prop(self, "token")
        col.prop(self, "samples")
        col.prop(self, "integrator")


class PenumbraSceneSettings(bpy.types.PropertyGroup):
    samples: bpy.props.IntProperty(
        name="Samples", default=0, min=0, max=1 << 20,
        description="Samples per pixel; 0 uses the add-on preferences' value")
    seed: bpy.props.IntProperty(name="Seed", default=0, min=0,
                                description="Sampler seed: the same seed gives the same image")
    max_depth: bpy.props.IntProperty(name="Max Depth", default=8, min=1, max=1024,
                                     description="Path segments from the camera")


def preferences(context=None):
    """The add-on's preferences, or None when the add-on is imported without being enabled."""
    context = context or bpy.context
    addon = context.preferences.addons.get(__package__)
    return addon.preferences if addon else None


def server_settings(context=None):
    """(url, token) from the preferences, falling back to the environment."""
    prefs = preferences(context)
    url = (prefs.server_url if prefs else "") or os.environ.get("PENUMBRA_URL") or \
        "http://127.0.0.1:8080"
    token = (prefs.token if prefs else "") or os.environ.get("PENUMBRA_TOKEN") or None
    return url, token


def render_settings(scene, context=None):
    """(samples, integrator, seed, max_depth) for a scene."""
    prefs = preferences(context)
    settings = scene.penumbra
    samples = settings.samples or (prefs.samples if prefs else 64)
    integrator = prefs.integrator if prefs else "path"
    return samples, integrator, settings.seed, settings.max_depth
