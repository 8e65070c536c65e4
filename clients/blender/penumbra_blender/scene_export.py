"""Blender scene -> penumbra scene JSON (api/scene.schema.json) and the files it names.

The engine exports into a temporary folder and uploads only the files the server lacks; the
"Export penumbra scene" operator writes the same into a folder that `penumbra render` renders
on its own (the tests compare the two renders bit for bit).
"""
from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional, Tuple

from .camera_export import export_camera, image_size
from .export_context import ExportContext
from .light_export import BLACK_MATERIAL, export_light
from .material_export import DEFAULT, DEFAULT_NAME, export_material
from .mesh_export import export_mesh_data
from .motion_export import FrameSet, sample_motion, shutter
from .world_export import export_world

GEOMETRY = ("MESH", "CURVE", "SURFACE", "META", "FONT")
OUTPUTS = ["albedo", "normal", "depth"]


def _matrix_rows(m) -> list:
    return [float(m[r][c]) for r in range(4) for c in range(4)]


def _relative(rows: list, base: list) -> list:
    """rows . base^-1 for affine 4x4 row-major matrices, in double precision (Blender's own
    matrices are single precision)."""
    a = [base[0:3], base[4:7], base[8:11]]
    t = [base[3], base[7], base[11]]
    det = (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
           - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
           + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
    inv = [[(a[(j + 1) % 3][(i + 1) % 3] * a[(j + 2) % 3][(i + 2) % 3]
             - a[(j + 1) % 3][(i + 2) % 3] * a[(j + 2) % 3][(i + 1) % 3]) / det
            for j in range(3)] for i in range(3)]
    inv_t = [-sum(inv[i][j] * t[j] for j in range(3)) for i in range(3)]
    m = [rows[0:4], rows[4:8], rows[8:12]]
    out = []
    for i in range(3):
        for j in range(3):
            out.append(sum(m[i][k] * inv[k][j] for k in range(3)))
        out.append(sum(m[i][k] * inv_t[k] for k in range(3)) + m[i][3])
    return out + [0.0, 0.0, 0.0, 1.0]


def export_scene(depsgraph, folder: str, *, samples: int, integrator: str, seed: int = 0,
                 max_depth: int = 8, copy_assets: bool = True,
                 frame_set: Optional[FrameSet] = None) -> Tuple[Dict[str, Any], ExportContext]:
    """(scene dict, context with its files and warnings). `frame_set(frame, subframe)` evaluates
    another frame (RenderEngine.frame_set in a render, Scene.frame_set elsewhere); without it
    nothing moves."""
    ctx = ExportContext(folder, copy_assets)
    scene = depsgraph.scene
    if scene.camera is None:
        raise ValueError("the scene has no camera")
    width, height = image_size(scene)
    motion: Dict[str, tuple] = {}
    if scene.render.use_motion_blur and frame_set is not None:
        motion = sample_motion(ctx, depsgraph, frame_set)
    camera = export_camera(ctx, scene, scene.camera)
    if motion:
        camera["shutter"] = list(shutter(scene))
    doc: Dict[str, Any] = {
        "version": 1,
        "render": {"width": width, "height": height, "spp": samples, "max_depth": max_depth,
                   "integrator": integrator, "seed": seed, "outputs": list(OUTPUTS)},
        "camera": camera,
    }
    materials: Dict[str, Any] = {}
    emissions: Dict[str, Optional[list]] = {}
    objects, lights = [], []
    placements: Dict[tuple, list] = {}  # insertion-ordered: objects keep the depsgraph's order
    first_index: Dict[int, int] = {}

    def material_for(obj, index: int) -> Tuple[str, Optional[list]]:
        slots = obj.material_slots
        mat = slots[index].material if index < len(slots) else None
        if mat is None:
            materials.setdefault(DEFAULT_NAME, dict(DEFAULT))
            return DEFAULT_NAME, None
        if mat.name not in materials:
            materials[mat.name], emissions[mat.name] = export_material(ctx, mat)
        return mat.name, emissions[mat.name]

    for inst in depsgraph.object_instances:
        obj = inst.object
        if inst.is_instance and not inst.show_self:
            continue
        # A viewport depsgraph (File > Export) holds objects hidden from renders; F12's does not.
        owner = inst.parent if inst.is_instance and inst.parent is not None else obj
        if owner.original.hide_render:
            continue
        matrix = inst.matrix_world.copy()
        if obj.type == "LIGHT":
            light, quad = export_light(ctx, obj, matrix)
            if light:
                lights.append(light)
            if quad:
                materials.setdefault(BLACK_MATERIAL, {"type": "diffuse", "color": [0, 0, 0]})
                objects.append(quad)
            continue
        if obj.type not in GEOMETRY:
            continue
        if abs(matrix.determinant()) < 1e-18:
            ctx.warn(f"object '{obj.name}': zero scale, skipped")
            continue
        # Objects that share their evaluated mesh (linked duplicates without modifiers,
        # collection and particle instances) and materials share one file.
        mesh_key = obj.data.name if obj.type == "MESH" and not obj.modifiers else obj.name
        key = (obj.type, mesh_key, tuple(slot.material.name if slot.material else ""
                                         for slot in obj.material_slots))
        moving = None if inst.is_instance else motion.get(obj.name)
        placements.setdefault(key, []).append((obj, _matrix_rows(matrix), moving))
    for key, placed in placements.items():
        first = placed[0][0]
        files = export_mesh_data(ctx, first, first.name)
        copies: Dict[int, list] = {}
        for k, (obj, rows, moving) in enumerate(placed):
            for material_index, name in files:
                mat_name, emission = material_for(obj, material_index)
                if k > 0 and not emission and not moving and placed[0][2] is None:
                    # An Embree instance of the first placement's mesh: the copy's transform
                    # applies after the mesh's own (docs/scene-format.md#instances).
                    copies.setdefault(material_index, []).append(
                        {"matrix": _relative(rows, placed[0][1])})
                    continue
                entry: Dict[str, Any] = {"type": "mesh", "file": name, "material": mat_name,
                                         "transform": {"matrix": rows}}
                if emission:
                    entry["emission"] = emission
                if moving:
                    entry["velocity"], entry["acceleration"] = moving
                if k == 0:
                    first_index[material_index] = len(objects)
                objects.append(entry)
        for material_index, transforms in copies.items():
            objects.append({"type": "instances", "mesh": first_index[material_index],
                            "transforms": transforms})
        first_index.clear()
    environment = export_world(ctx, scene.world)
    if environment is not None:
        doc["environment"] = environment
    doc["materials"] = materials
    doc["objects"] = objects
    doc["lights"] = lights
    if not objects and not lights and environment is None:
        ctx.warn("the scene has nothing to render")
    return doc, ctx


def write_scene(doc: Dict[str, Any], folder: str, name: str = "scene.json") -> str:
    path = os.path.join(folder, name)
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=1)
    return path
