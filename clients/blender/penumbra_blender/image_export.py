"""Blender images as files penumbra can read: the image's own file when it has one, the packed
bytes when it is packed, else (generated or edited in Blender) a float EXR written from its
pixels."""
from __future__ import annotations

import os

import bpy

from .export_context import ExportContext, safe_name


def image_file(ctx: ExportContext, image: "bpy.types.Image", where: str):
    """The scene name of the image's file, or None (with a warning) when there is none."""
    if image.packed_file is not None:
        ext = os.path.splitext(image.filepath)[1] or ".png"
        name, path = ctx.new_file("textures/" + safe_name(image.name) + ext.lower())
        with open(path, "wb") as f:
            f.write(image.packed_file.data)
        return name
    if image.source == "FILE" and not image.is_dirty:
        path = bpy.path.abspath(image.filepath, library=image.library)
        if os.path.isfile(path):
            base = os.path.basename(path)
            stem, ext = os.path.splitext(base)
            return ctx.add_existing(path, "textures/" + safe_name(stem) + ext.lower())
        ctx.warn(f"{where}: image '{image.name}' file {path!r} not found")
        return None
    if image.size[0] == 0 or image.size[1] == 0 or not image.has_data:
        ctx.warn(f"{where}: image '{image.name}' has no pixels")
        return None
    # Generated or edited: write what Blender holds (linear float) as an EXR.
    name, path = ctx.new_file("textures/" + safe_name(image.name) + ".exr")
    copy = image.copy()
    try:
        copy.filepath_raw = path
        copy.file_format = "OPEN_EXR"
        copy.save()
    finally:
        bpy.data.images.remove(copy)
    return name


def colorspace(image: "bpy.types.Image") -> str:
    """penumbra's colorspace of an image Blender decodes with its colour-space setting."""
    space = image.colorspace_settings.name
    if space == "sRGB":
        return "srgb"
    return "linear"
