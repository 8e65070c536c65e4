"""Blender materials as penumbra materials. What maps (docs/blender.md has the table):

- Principled BSDF: Metallic >= 0.5 -> conductor (colour = Base Color, roughness);
  Transmission >= 0.5 -> dielectric (IOR, roughness); Specular 0 -> diffuse; else plastic
  (IOR from Specular: f0 = 0.08 * specular, the Principled convention, so 0.5 -> 1.5).
  Emission x Emission Strength becomes the object's emission.
- Diffuse BSDF -> diffuse; Glossy BSDF -> conductor; Glass BSDF -> dielectric;
  Emission -> black diffuse with emission.
- A colour from an Image Texture node (uv of the active map) -> a penumbra texture with the
  image's colour space, interpolation (Closest -> nearest) and extension (Extend -> clamp).
- Anything else (other shader nodes, linked inputs we do not read) -> grey diffuse (0.8, as
  Blender's default material) or the input's unlinked value, with a warning in Blender's report.
"""
from __future__ import annotations

import math
from typing import Any, Dict, Optional, Tuple

from .export_context import ExportContext
from .image_export import colorspace, image_file
from .node_tree import output_shader

DEFAULT_NAME = "__blender_default"
DEFAULT = {"type": "diffuse", "color": [0.8, 0.8, 0.8]}


def _clamp01(x: float) -> float:
    return min(max(float(x), 0.0), 1.0)


def _rgb(value) -> list:
    return [_clamp01(value[0]), _clamp01(value[1]), _clamp01(value[2])]


def _output_shader(material):
    if not material.use_nodes:
        return None
    return output_shader(material.node_tree, "ShaderNodeOutputMaterial")


class _Reader:
    def __init__(self, ctx: ExportContext, material):
        self.ctx, self.material = ctx, material
        self.where = f"material '{material.name}'"

    def value(self, node, name: str) -> float:
        socket = node.inputs[name]
        if socket.is_linked:
            self.ctx.warn(f"{self.where}: '{node.name}' input '{name}' is linked to something "
                          f"penumbra does not read; its own value {socket.default_value:.3g} "
                          "is used")
        return float(socket.default_value)

    def scalar(self, node, name: str) -> Any:
        """A number, or for an Image Texture node's Color a single-channel texture (channel 0,
        read linearly: a roughness map is data, as Blender's Non-Color setting says)."""
        socket = node.inputs[name]
        if socket.is_linked:
            link = socket.links[0]
            src = link.from_node
            if src.bl_idname == "ShaderNodeTexImage" and src.image is not None and \
                    link.from_socket.name == "Color" and not src.inputs["Vector"].is_linked:
                name_in_scene = image_file(self.ctx, src.image, self.where)
                if name_in_scene is not None:
                    tex = {"texture": name_in_scene, "colorspace": "linear", "channel": 0}
                    if src.image.colorspace_settings.name == "sRGB" and not src.image.is_float:
                        self.ctx.warn(f"{self.where}: '{src.name}' feeds '{name}' with colour "
                                      "space sRGB; penumbra reads it as data (Non-Color)")
                    if src.interpolation == "Closest":
                        tex["filter"] = "nearest"
                    if src.extension in ("EXTEND", "CLIP"):
                        tex["wrap"] = "clamp"
                    return tex
        return _clamp01(self.value(node, name))

    def color(self, node, name: str, scale=None) -> Any:
        """An RGB list, or a texture dict for an Image Texture node."""
        socket = node.inputs[name]
        if socket.is_linked:
            src = socket.links[0].from_node
            if src.bl_idname == "ShaderNodeTexImage" and src.image is not None:
                if src.inputs["Vector"].is_linked:
                    self.ctx.warn(f"{self.where}: '{src.name}' has a linked Vector input; "
                                  "penumbra reads the active uv map")
                name_in_scene = image_file(self.ctx, src.image, self.where)
                if name_in_scene is not None:
                    tex = {"texture": name_in_scene}
                    if not src.image.is_float:
                        tex["colorspace"] = colorspace(src.image)
                    if src.interpolation == "Closest":
                        tex["filter"] = "nearest"
                    if src.extension in ("EXTEND", "CLIP"):
                        tex["wrap"] = "clamp"
                    if scale is not None:
                        tex["scale"] = scale
                    return tex
            else:
                self.ctx.warn(f"{self.where}: '{name}' comes from '{src.name}' "
                              f"({src.bl_idname}), which penumbra does not read; its own value "
                              "is used")
        return _rgb(socket.default_value)


def _normal_map(r: "_Reader", node) -> Optional[Dict[str, Any]]:
    """penumbra's `normal_map` from a Normal Map node (tangent space, the active uv map) fed by
    an Image Texture. Both read the texel as 2 rgb - 1 in the frame of the uv tangent, the
    bitangent n x t and the normal (Blender's "OpenGL" convention, green = +v), so the image is
    used as it is; the v flip of the uvs flips the rows the same way for both."""
    socket = node.inputs.get("Normal")
    if socket is None or not socket.is_linked:
        return None
    src = socket.links[0].from_node
    color = src.inputs["Color"] if src.bl_idname == "ShaderNodeNormalMap" else None
    if color is None or not color.is_linked or \
            color.links[0].from_node.bl_idname != "ShaderNodeTexImage" or \
            color.links[0].from_node.image is None:
        r.ctx.warn(f"{r.where}: the Normal input of '{node.name}' is not a Normal Map node fed "
                   "by an Image Texture; ignored")
        return None
    if src.space != "TANGENT":
        r.ctx.warn(f"{r.where}: '{src.name}' is in {src.space} space; penumbra reads tangent "
                   "space only, ignored")
        return None
    if src.uv_map:
        r.ctx.warn(f"{r.where}: '{src.name}' names uv map '{src.uv_map}'; the active one is used")
    strength = src.inputs["Strength"]
    if strength.is_linked or abs(float(strength.default_value) - 1.0) > 1e-6:
        r.ctx.warn(f"{r.where}: normal map strength {strength.default_value:.3g} read as 1")
    tex_node = color.links[0].from_node
    name = image_file(r.ctx, tex_node.image, r.where)
    if name is None:
        return None
    out: Dict[str, Any] = {"texture": name}
    if tex_node.interpolation == "Closest":
        out["filter"] = "nearest"
    if tex_node.extension in ("EXTEND", "CLIP"):
        out["wrap"] = "clamp"
    return out


def export_material(ctx: ExportContext, material) -> Tuple[Dict[str, Any], Optional[list]]:
    """(penumbra material, emission RGB or None) of a Blender material."""
    material_dict, emission = _export_shader(ctx, material)
    shader = _output_shader(material)
    if shader is not None and "Normal" in shader.inputs and \
            shader.bl_idname != "ShaderNodeBsdfPrincipled" and shader.inputs["Normal"].is_linked:
        normal_map = _normal_map(_Reader(ctx, material), shader)
        if normal_map is not None:
            material_dict["normal_map"] = normal_map
    return material_dict, emission


def _export_shader(ctx: ExportContext, material) -> Tuple[Dict[str, Any], Optional[list]]:
    r = _Reader(ctx, material)
    shader = _output_shader(material)
    if shader is None:
        if material.use_nodes:
            ctx.warn(f"{r.where}: no shader connected to the Material Output; grey diffuse")
            return dict(DEFAULT), None
        return {"type": "diffuse", "color": _rgb(material.diffuse_color)}, None
    kind = shader.bl_idname
    if kind == "ShaderNodeBsdfPrincipled":
        return _principled(r, shader)
    if kind == "ShaderNodeBsdfDiffuse":
        return {"type": "diffuse", "color": r.color(shader, "Color")}, None
    if kind == "ShaderNodeBsdfGlossy":
        return {"type": "conductor", "color": r.color(shader, "Color"),
                "roughness": r.scalar(shader, "Roughness")}, None
    if kind == "ShaderNodeBsdfGlass":
        return {"type": "dielectric", "ior": max(r.value(shader, "IOR"), 1e-3),
                "roughness": r.scalar(shader, "Roughness")}, None
    if kind == "ShaderNodeEmission":
        strength = r.value(shader, "Strength")
        color = shader.inputs["Color"].default_value
        return {"type": "diffuse", "color": [0, 0, 0]}, \
            [max(0.0, float(c)) * max(0.0, strength) for c in color[:3]]
    ctx.warn(f"{r.where}: shader '{shader.name}' ({kind}) has no penumbra equivalent; "
             "grey diffuse")
    return dict(DEFAULT), None


def _principled(r: _Reader, node) -> Tuple[Dict[str, Any], Optional[list]]:
    base = r.color(node, "Base Color")
    roughness = r.scalar(node, "Roughness")
    metallic = r.value(node, "Metallic")
    transmission = r.value(node, "Transmission")
    ior = max(r.value(node, "IOR"), 1e-3)
    specular = r.value(node, "Specular")
    if 0.0 < metallic < 1.0 or 0.0 < transmission < 1.0:
        r.ctx.warn(f"{r.where}: Metallic {metallic:.2f} / Transmission {transmission:.2f} are "
                   "rounded to 0 or 1 (penumbra has no blend of the two)")
    if metallic >= 0.5:
        material = {"type": "conductor", "color": base, "roughness": roughness}
    elif transmission >= 0.5:
        if isinstance(base, dict) or base != [1.0, 1.0, 1.0]:
            r.ctx.warn(f"{r.where}: a glass's Base Color tints Cycles' transmission; penumbra's "
                       "dielectric is clear")
        material = {"type": "dielectric", "ior": ior, "roughness": roughness}
    elif specular <= 0.0:
        material = {"type": "diffuse", "color": base}
    else:
        # Principled: f0 = 0.08 * specular; f0 = ((n - 1) / (n + 1))^2 solved for n.
        s = math.sqrt(min(0.08 * specular, 0.99))
        if isinstance(roughness, dict):
            r.ctx.warn(f"{r.where}: a plastic's roughness cannot be a texture in penumbra; "
                       f"{node.inputs['Roughness'].default_value:.3g} is used")
            roughness = _clamp01(node.inputs["Roughness"].default_value)
        material = {"type": "plastic", "color": base, "ior": (1 + s) / (1 - s),
                    "roughness": roughness}
    _warn_unread(r, node)
    normal_map = _normal_map(r, node)
    if normal_map is not None:
        material["normal_map"] = normal_map
    emission = None
    strength = max(0.0, float(node.inputs["Emission Strength"].default_value))
    color = node.inputs["Emission"]
    if strength > 0 and color.is_linked:
        value = r.color(node, "Emission", scale=strength)
        if isinstance(value, dict):
            return material, value  # an emission texture: image x strength
    if strength > 0 and any(c > 0 for c in color.default_value[:3]):
        emission = [max(0.0, float(c)) * strength for c in color.default_value[:3]]
    return material, emission


# Principled inputs penumbra has no counterpart for, with the value at which they do nothing.
_UNREAD = (("Subsurface", 0.0), ("Sheen", 0.0), ("Clearcoat", 0.0), ("Alpha", 1.0))


def _warn_unread(r: _Reader, node) -> None:
    for name, neutral in _UNREAD:
        socket = node.inputs.get(name)
        if socket is not None and (socket.is_linked or float(socket.default_value) != neutral):
            r.ctx.warn(f"{r.where}: Principled '{name}' is ignored")
