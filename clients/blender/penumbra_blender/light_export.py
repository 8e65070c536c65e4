"""Blender lights as penumbra lights. penumbra has point and directional lights and emitting
surfaces; Blender's Watts convert as Cycles does:

- Point (power P, colour c): point light, intensity c * P / (4 pi) W/sr. Its radius (soft
  shadows) is ignored, with a warning.
- Spot: a point light of the same intensity (penumbra has no cone): warning.
- Sun (strength E): directional light, irradiance c * E, travelling along the light's -Z.
  Its angle is ignored, with a warning.
- Area (square or rectangle): an emitting quad facing the light's -Z (one-sided, as penumbra's
  emission), radiance c * P / (4 area): what Cycles 3.4 gives, measured (a floor lit by it is
  as bright in both, tests/blender); a Lambertian emitter of radiant flux P would have
  P / (pi area), so Blender's area-light Watts are pi/4 of radiometric ones. Disk and ellipse
  become the rectangle of the same size with the same flux (the same formula), with a warning.
  Unlike Cycles' light, the quad is an object: the camera sees it (its back dark) and it casts
  shadows.
"""
from __future__ import annotations

import math
from typing import Any, Dict, Optional, Tuple

from .export_context import ExportContext

BLACK_MATERIAL = "__blender_light_black"


def export_light(ctx: ExportContext, obj, matrix) -> Tuple[Optional[Dict[str, Any]],
                                                         Optional[Dict[str, Any]]]:
    """(penumbra light or None, emitting quad object or None)."""
    light = obj.data
    where = f"light '{obj.name}'"
    color = [max(0.0, float(c)) for c in light.color[:3]]
    if light.type in ("POINT", "SPOT"):
        if light.type == "SPOT":
            ctx.warn(f"{where}: spot cone ignored (penumbra has no spot light): a point light")
        if light.shadow_soft_size > 0:
            ctx.warn(f"{where}: radius {light.shadow_soft_size:.3g} ignored (a point light)")
        power = max(0.0, light.energy) / (4 * math.pi)
        return {"type": "point", "position": list(matrix.translation),
                "intensity": [c * power for c in color]}, None
    if light.type == "SUN":
        if light.angle > 0:
            ctx.warn(f"{where}: sun angle ignored (a directional light)")
        direction = -(matrix.to_3x3() @ _z()).normalized()
        return {"type": "directional", "direction": list(direction),
                "irradiance": [c * max(0.0, light.energy) for c in color]}, None
    if light.type == "AREA":
        sx = light.size
        sy = light.size_y if light.shape in ("RECTANGLE", "ELLIPSE") else light.size
        if light.shape in ("DISK", "ELLIPSE"):
            ctx.warn(f"{where}: {light.shape.lower()} area light rendered as a rectangle")
        m3 = matrix.to_3x3()
        ex = m3 @ _vec(sx, 0, 0)
        ey = m3 @ _vec(0, sy, 0)
        area = ex.cross(ey).length
        if area <= 0:
            ctx.warn(f"{where}: zero area, skipped")
            return None, None
        radiance = max(0.0, light.energy) / (4.0 * area)
        origin = matrix @ _vec(-sx / 2, -sy / 2, 0)
        # u x v must point along the light's -Z (the side Cycles' area light emits to).
        quad = {"type": "quad", "origin": list(origin), "u": list(ey), "v": list(ex),
                "material": BLACK_MATERIAL, "emission": [c * radiance for c in color]}
        return None, quad
    ctx.warn(f"{where}: light type {light.type} not supported; skipped")
    return None, None


def _vec(x, y, z):
    from mathutils import Vector
    return Vector((x, y, z))


def _z():
    return _vec(0, 0, 1)
