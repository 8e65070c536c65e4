"""The World as penumbra's environment: a Background node's colour x strength as a constant
radiance, or an Environment Texture (equirectangular) as `map` with `scale` = strength and the
rotation of a Mapping node in front of it.

Orientation, checked by rendering a coordinate-coded map with Cycles: Blender looks up world
direction w at u = 1/2 - atan2(w.y, w.x) / 2 pi, and the image's top row is +z. penumbra's map
space direction m looks up u = atan2(m.x, -m.z) / 2 pi, top row +y (docs/scene-format.md).
They agree when m = (w.y, w.z, w.x), so penumbra's map-to-world matrix is the transpose of that
permutation, times the inverse of the Mapping node's rotation (which turns the lookup vector).
"""
from __future__ import annotations

from typing import Any, Dict, Optional

from .export_context import ExportContext
from .image_export import image_file
from .node_tree import output_shader


def _mapping_rotation(ctx: ExportContext, tex):
    """The 3x3 matrix the lookup vector is multiplied with before the texture reads it."""
    from mathutils import Euler, Matrix
    socket = tex.inputs["Vector"]
    if not socket.is_linked:
        return Matrix.Identity(3)
    node = socket.links[0].from_node
    if node.bl_idname == "ShaderNodeTexCoord":
        return Matrix.Identity(3)
    if node.bl_idname != "ShaderNodeMapping":
        ctx.warn(f"world: the environment's Vector comes from '{node.name}', which penumbra does "
                 "not read; no rotation")
        return Matrix.Identity(3)
    if any(abs(s - 1) > 1e-6 for s in node.inputs["Scale"].default_value) or \
            node.inputs["Rotation"].is_linked:
        ctx.warn("world: the Mapping node's scale (or a linked rotation) is ignored")
    rot = Euler(node.inputs["Rotation"].default_value, "XYZ").to_matrix()
    if node.vector_type == "TEXTURE":
        return rot.transposed()
    if node.vector_type not in ("POINT", "VECTOR"):
        ctx.warn(f"world: Mapping type {node.vector_type} read as Point")
    return rot


def environment_matrix(rotation) -> list:
    """penumbra's map-to-world matrix (16 numbers, row-major) for a Blender lookup rotation."""
    from mathutils import Matrix
    to_map = Matrix(((0, 1, 0), (0, 0, 1), (1, 0, 0))) @ rotation  # world -> penumbra map space
    m = to_map.transposed()
    return [m[0][0], m[0][1], m[0][2], 0.0, m[1][0], m[1][1], m[1][2], 0.0,
            m[2][0], m[2][1], m[2][2], 0.0, 0.0, 0.0, 0.0, 1.0]


def export_world(ctx: ExportContext, world) -> Optional[Dict[str, Any]]:
    if world is None:
        return None
    if not world.use_nodes or world.node_tree is None:
        return {"radiance": [max(0.0, c) for c in world.color[:3]]}
    shader = output_shader(world.node_tree, "ShaderNodeOutputWorld")
    if shader is None:
        return None
    if shader.bl_idname != "ShaderNodeBackground":
        ctx.warn(f"world: '{shader.name}' ({shader.bl_idname}) is not a Background node; black "
                 "environment")
        return None
    strength = max(0.0, float(shader.inputs["Strength"].default_value))
    if shader.inputs["Strength"].is_linked:
        ctx.warn("world: a linked Strength is read as its own value")
    color = shader.inputs["Color"]
    if color.is_linked:
        src = color.links[0].from_node
        if src.bl_idname == "ShaderNodeTexEnvironment" and src.image is not None:
            if src.projection != "EQUIRECTANGULAR":
                ctx.warn(f"world: {src.projection} projection read as equirectangular")
            name = image_file(ctx, src.image, "world")
            if name is not None:
                return {"map": name, "scale": strength,
                        "matrix": environment_matrix(_mapping_rotation(ctx, src))}
        else:
            ctx.warn(f"world: the background colour comes from '{src.name}' "
                     f"({src.bl_idname}), which penumbra does not read; its own colour is used")
    return {"radiance": [max(0.0, float(c)) * strength for c in color.default_value[:3]]}
