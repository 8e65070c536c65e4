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
    mesh_files: Dict[str, list] = {}

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
        files = mesh_files.get(obj.name)
        if files is None:
            files = mesh_files[obj.name] = export_mesh_data(ctx, obj, obj.name)
        for material_index, name in files:
            mat_name, emission = material_for(obj, material_index)
            entry: Dict[str, Any] = {"type": "mesh", "file": name, "material": mat_name,
                                     "transform": {"matrix": _matrix_rows(matrix)}}
            if emission:
                entry["emission"] = emission
            if not inst.is_instance and obj.name in motion:
                entry["velocity"], entry["acceleration"] = motion[obj.name]
            objects.append(entry)
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
