"""Object motion for motion blur, as penumbra's per-object velocity and acceleration.

penumbra moves an object by p(t) = p(0) + v t + a t^2 / 2 (world space; here t is in frames,
t = 0 the frame being rendered). From the object's positions at frames f - 1, f, f + 1 the
central differences v = (p+ - p-) / 2 and a = p+ - 2 p0 + p- reproduce those three positions
exactly (and any motion of constant acceleration). Only translation moves: a change of rotation
or scale between the frames is reported and ignored, as is camera motion.

The shutter is Blender's Motion Blur "Shutter" (in frames) placed as its "Position" says:
Center [-s/2, s/2], Start [0, s], End [-s, 0].
"""
from __future__ import annotations

from typing import Callable, Dict, Tuple

from .export_context import ExportContext

FrameSet = Callable[[int, float], None]


def shutter(scene) -> Tuple[float, float]:
    s = max(0.0, float(scene.render.motion_blur_shutter))
    position = getattr(scene.render, "motion_blur_position", None)
    if position is None and hasattr(scene, "cycles"):
        position = getattr(scene.cycles, "motion_blur_position", "CENTER")
    if position == "START":
        return 0.0, s
    if position == "END":
        return -s, 0.0
    return -s / 2, s / 2


def sample_motion(ctx: ExportContext, depsgraph, frame_set: FrameSet) -> Dict[str, tuple]:
    """{object name: (velocity, acceleration)} of the objects that move around the current
    frame. Leaves the scene at its current frame."""
    scene = depsgraph.scene
    frame, subframe = scene.frame_current, scene.frame_subframe
    samples: Dict[str, list] = {}
    for df in (-1, 1, 0):
        frame_set(frame + df, subframe)
        for obj in depsgraph.objects:
            if obj.type in ("MESH", "CURVE", "SURFACE", "META", "FONT", "CAMERA"):
                samples.setdefault(obj.name, {})[df] = obj.matrix_world.copy()
    moving: Dict[str, tuple] = {}
    for name, mats in samples.items():
        if len(mats) != 3:
            continue
        m0, mm, mp = mats[0], mats[-1], mats[1]
        p0, pm, pp = m0.translation, mm.translation, mp.translation
        velocity = (pp - pm) / 2
        acceleration = pp - 2 * p0 + pm
        linear_changes = any(abs(a - b) > 1e-6 for m in (mm, mp)
                             for ra, rb in zip(m.to_3x3(), m0.to_3x3()) for a, b in zip(ra, rb))
        if scene.camera is not None and name == scene.camera.name:
            if velocity.length > 0 or linear_changes:
                ctx.warn(f"camera '{name}': camera motion blur is not supported")
            continue
        if linear_changes:
            ctx.warn(f"object '{name}': rotation/scale motion ignored (translation only)")
        if velocity.length > 0 or acceleration.length > 0:
            moving[name] = (list(velocity), list(acceleration))
    return moving
