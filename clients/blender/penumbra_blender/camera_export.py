"""The scene camera as penumbra's thin-lens camera.

penumbra's `fov` is vertical. Blender fits its sensor to the image: sensor fit Auto fits the
sensor width to the larger image side, Horizontal the width to the image width, Vertical the
sensor height to the image height; so the vertical half-angle is atan(s / 2 / focal length)
with s the sensor size along the fitted side, scaled by the aspect ratio when that side is the
width. Depth of field as Cycles: aperture radius = focal length / (2 f-stop) (focal length in
scene units: millimetres / 1000 / the scene's unit scale); focus distance along the view axis.
"""
from __future__ import annotations

import math
from typing import Any, Dict

from .export_context import ExportContext


def image_size(scene):
    r = scene.render
    return (max(1, int(r.resolution_x * r.resolution_percentage / 100)),
            max(1, int(r.resolution_y * r.resolution_percentage / 100)))


def vertical_fov(cam_data, width: int, height: int, pixel_aspect: float) -> float:
    """Vertical field of view in degrees of a perspective Blender camera."""
    aspect = width * pixel_aspect / height
    fit = cam_data.sensor_fit
    if fit == "AUTO":
        fit = "HORIZONTAL" if aspect >= 1 else "VERTICAL"
        sensor = cam_data.sensor_width
    else:
        sensor = cam_data.sensor_width if fit == "HORIZONTAL" else cam_data.sensor_height
    half = sensor / 2 / cam_data.lens
    if fit == "HORIZONTAL":
        half /= aspect
    return math.degrees(2 * math.atan(half))


def export_camera(ctx: ExportContext, scene, cam_obj) -> Dict[str, Any]:
    data = cam_obj.data
    where = f"camera '{cam_obj.name}'"
    if data.type != "PERSP":
        ctx.warn(f"{where}: {data.type} cameras are not supported; rendered as perspective "
                 "with the same focal length")
    if data.shift_x or data.shift_y:
        ctx.warn(f"{where}: lens shift is ignored")
    width, height = image_size(scene)
    r = scene.render
    pixel_aspect = r.pixel_aspect_x / r.pixel_aspect_y
    if abs(pixel_aspect - 1) > 1e-6:
        ctx.warn(f"{where}: non-square pixels are rendered square")
    m = cam_obj.matrix_world.normalized()
    position = m.translation
    forward = -m.col[2].xyz.normalized()
    up = m.col[1].xyz.normalized()
    focus = None
    if data.dof.use_dof:
        if data.dof.focus_object is not None:
            focus = (data.dof.focus_object.matrix_world.translation - position).dot(forward)
        else:
            focus = data.dof.focus_distance
        if focus <= 0:
            ctx.warn(f"{where}: focus distance {focus:.3g} is not in front of the camera; "
                     "depth of field is off")
            focus = None
    camera = {"position": list(position), "look_at": list(position + forward * (focus or 1.0)),
              "up": list(up), "fov": vertical_fov(data, width, height, pixel_aspect)}
    if focus is not None:
        unit = scene.unit_settings.scale_length or 1.0
        radius = data.lens / 1000.0 / unit / (2.0 * data.dof.aperture_fstop)
        camera["aperture_radius"] = radius
        camera["focus_distance"] = focus
    return camera
