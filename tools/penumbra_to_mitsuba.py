#!/usr/bin/env python3
"""Convert a penumbra scene (format v1, JSON) into a Mitsuba 3 scene.

The conversion keeps every semantic of the format (issue 2, docs/accuracy.md has the table):

* camera: ``perspective`` (or ``thinlens`` when ``aperture_radius > 0``) with ``fov_axis: 'y'``
  and a ``look_at`` transform; an ``hdrfilm`` with a box pixel filter and linear RGB float output.
* opaque materials (diffuse, conductor, plastic) are wrapped in ``twosided``; GGX with
  alpha = roughness^2 and visible-normal sampling; conductor = constant reflectance
  (``material: 'none'`` scaled by ``specular_reflectance``); plastic is not ``nonlinear``.
* ``dielectric.absorption`` becomes an interior ``homogeneous`` medium with albedo 0 and
  sigma_t = absorption, rendered with ``volpath``; other scenes use ``path``. Both with the
  scene's ``max_depth`` and Russian roulette from depth 5.
* emission is an ``area`` emitter on the shape (one-sided: quad front = u x v, sphere outside,
  mesh counter-clockwise); point lights, directional lights and the constant environment map
  onto ``point``, ``directional`` and ``constant``.
* an environment ``map`` becomes an ``envmap`` with the same ``scale`` and, as ``to_world``, the
  same rotation: both renderers look a world direction d up at to_world^-1 d with the same
  lat-long convention (:func:`convert_environment`). Mitsuba finds the file through its file
  resolver, to which :func:`use_scene_folder` adds the scene's folder.
* textures (``{"texture": ...}`` colours, roughness, emission; ``normal_map``) become ``bitmap``
  textures of linear float EXRs baked with penumbra's decoding, scale and channel (sRGB decoded
  by Mitsuba's own Bitmap), ``raw``, with the same ``filter_type`` and ``wrap_mode``; a normal
  map wraps the BSDF in ``normalmap`` inside ``twosided`` (see :class:`TextureBaker`).

* an ``instances`` object becomes a ``shapegroup`` holding the mesh it names (converted as that
  object is, its own ``transform`` included) and one ``instance`` per transform, whose
  ``to_world`` is that transform: both apply the copy's transform after the mesh's own
  (:func:`convert_instances`). The mesh is also converted where it stands, as penumbra draws it.

Mitsuba 3.9 has no moving shapes. :func:`to_mitsuba` therefore builds the scene at one instant
``time``; a motion-blurred reference is the average of renders at many instants spread over the
shutter (see :func:`shutter_instants` and tools/make_references.py).

Usage as a script (writes a quick preview EXR)::

    python tools/penumbra_to_mitsuba.py scene.json -o out.exr --spp 64
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
from typing import Any

import numpy as np

#: Where Debian 12's libllvm19 puts the library; llvm_ad_rgb needs LLVM >= 16 here.
DEBIAN_LIBLLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"

#: Russian roulette starts at this depth unless render.rr_depth says otherwise (penumbra's and
#: Mitsuba's default).
RR_DEPTH = 5

#: Default reflectance of each material type when ``color`` is absent (docs/scene-format.md).
DEFAULT_COLOR = {"diffuse": [0.5, 0.5, 0.5], "conductor": [1.0, 1.0, 1.0], "plastic": [0.5, 0.5, 0.5]}


def import_mitsuba(variant: str):
    """Import mitsuba and select ``variant``, pointing Dr.Jit at libLLVM 19 when it is present.

    Dr.Jit would otherwise pick Debian's LLVM 15, with which llvm_ad_rgb renders abort.
    """
    if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(DEBIAN_LIBLLVM):
        os.environ["DRJIT_LIBLLVM_PATH"] = DEBIAN_LIBLLVM
    import mitsuba as mi

    mi.set_variant(variant)
    return mi


# --------------------------------------------------------------------------------------------
# Small geometry helpers (numpy, double precision)
# --------------------------------------------------------------------------------------------

def vec(values, n: int = 3) -> np.ndarray:
    """A float64 vector of length ``n`` from a JSON list (a scalar is broadcast)."""
    a = np.asarray(values, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.shape != (n,):
        raise ValueError(f"expected {n} numbers, got {values!r}")
    return a


def rotation_matrix(axis, degrees: float) -> np.ndarray:
    """3x3 right-handed rotation by ``degrees`` about ``axis`` (Rodrigues' formula)."""
    k = vec(axis)
    k = k / np.linalg.norm(k)
    theta = math.radians(degrees)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(theta) * kx + (1 - math.cos(theta)) * (kx @ kx)


def object_matrix(transform: dict | None) -> np.ndarray:
    """4x4 object-to-world matrix of a penumbra ``transform``.

    Either ``matrix`` (16 numbers, row-major) or scale, then rotate, then translate:
    M = T * R * S applied to column vectors.
    """
    m = np.eye(4)
    if not transform:
        return m
    if "matrix" in transform:
        return np.asarray(transform["matrix"], dtype=np.float64).reshape(4, 4)
    if "scale" in transform:
        m[:3, :3] = np.diag(vec(transform["scale"])) @ m[:3, :3]
    if "rotate" in transform:
        r = transform["rotate"]
        m[:3, :3] = rotation_matrix(r["axis"], r["degrees"]) @ m[:3, :3]
    if "translate" in transform:
        m[:3, 3] += vec(transform["translate"])
    return m


def apply_point(m: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Transform points (..., 3) by the affine 4x4 matrix ``m``."""
    return p @ m[:3, :3].T + m[:3, 3]


def apply_vector(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Transform direction vectors (..., 3) by the linear part of ``m``."""
    return v @ m[:3, :3].T


def apply_normal(m: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Transform normals (..., 3) by the inverse transpose of ``m``, renormalised."""
    out = n @ np.linalg.inv(m[:3, :3])
    return out / np.linalg.norm(out, axis=-1, keepdims=True)


def motion_offset(obj: dict, time: float) -> np.ndarray:
    """Displacement of an object at ``time``: v*t + a*t^2/2 (zero at t = 0)."""
    v = vec(obj.get("velocity", [0, 0, 0]))
    a = vec(obj.get("acceleration", [0, 0, 0]))
    return v * time + 0.5 * a * time * time


def shutter_instants(scene: dict, count: int) -> list[float]:
    """``count`` instants at the midpoints of equal strata of the camera shutter.

    Penumbra draws the time of each camera sample uniformly in [open, close]; the image is the
    time average of the instantaneous images. For a box-filtered pixel the instantaneous value
    is continuous and piecewise smooth in t, so the midpoint rule converges fast (O(1/n^2) away
    from kinks). A scene without blur (open == close, the default) gets one instant.
    """
    t0, t1 = scene.get("camera", {}).get("shutter", [0.0, 0.0])
    if t0 == t1 or not has_motion(scene):
        return [float(t0)]
    return [t0 + (i + 0.5) * (t1 - t0) / count for i in range(count)]


def has_motion(scene: dict) -> bool:
    """True if any object has a non-zero velocity or acceleration."""
    for obj in scene.get("objects", []):
        if np.any(vec(obj.get("velocity", [0, 0, 0]))) or np.any(vec(obj.get("acceleration", [0, 0, 0]))):
            return True
    return False


def uses_absorption(scene: dict) -> bool:
    """True if any dielectric material has a non-zero absorption coefficient."""
    return any(
        m.get("type") == "dielectric" and np.any(vec(m.get("absorption", [0, 0, 0])))
        for m in scene.get("materials", {}).values()
    )


# --------------------------------------------------------------------------------------------
# Scene pieces -> Mitsuba dictionaries
# --------------------------------------------------------------------------------------------

def rgb(values) -> dict:
    """A Mitsuba RGB spectrum dictionary."""
    return {"type": "rgb", "value": [float(x) for x in vec(values)]}


def ggx(alpha) -> dict:
    """Microfacet parameters shared by the rough plugins: GGX, visible-normal sampling.
    ``alpha`` is a number or a texture dictionary."""
    return {"distribution": "ggx", "alpha": alpha if isinstance(alpha, dict) else float(alpha),
            "sample_visible": True}


def convert_material(mat: dict, textures: TextureBaker | None = None) -> dict:
    """A penumbra material -> Mitsuba BSDF dictionary (opaque ones wrapped in ``twosided``).

    The interior medium of an absorbing dielectric is attached to the shape, not the BSDF
    (see :func:`convert_medium`). Textured parameters and normal maps need ``textures``.
    """
    kind = mat["type"]
    color = mat.get("color", DEFAULT_COLOR.get(kind))
    roughness = mat.get("roughness", 0.0)
    if is_texture(color) or is_texture(roughness) or "normal_map" in mat:
        if textures is None:
            raise ValueError("a textured material needs a TextureBaker")
        color_value = textures.spectrum(color, "color") if color is not None else None
        alpha = textures.alpha(roughness)
    else:
        color_value = rgb(color) if color is not None else None
        alpha = float(roughness) ** 2  # glTF convention, as in penumbra
    rough = isinstance(alpha, dict) or alpha > 0
    if kind == "diffuse":
        bsdf = {"type": "diffuse", "reflectance": color_value}
    elif kind == "conductor":
        # material 'none' = a perfect reflector (F = 1) that specular_reflectance scales:
        # a constant Fresnel reflectance equal to the colour.
        bsdf = {"type": "conductor", "material": "none", "specular_reflectance": color_value}
        if rough:
            bsdf.update(type="roughconductor", **ggx(alpha))
    elif kind == "plastic":
        bsdf = {
            "type": "plastic",
            "diffuse_reflectance": color_value,
            "int_ior": float(mat.get("ior", 1.5)),
            "ext_ior": 1.0,
            "nonlinear": False,
        }
        if rough:
            bsdf.update(type="roughplastic", **ggx(alpha))
    elif kind == "dielectric":
        bsdf = {"type": "dielectric", "int_ior": float(mat.get("ior", 1.5)), "ext_ior": 1.0}
        if rough:
            bsdf.update(type="roughdielectric", **ggx(alpha))
        # transmissive: the surface orientation matters, no twosided
        return textures.normal_mapped(bsdf, mat["normal_map"]) if "normal_map" in mat else bsdf
    else:
        raise ValueError(f"unknown material type {kind!r}")
    if "normal_map" in mat:
        # twosided outside: the side is judged by the unperturbed normal, and the back is the
        # mirrored front, as penumbra's SurfaceBsdf.
        bsdf = textures.normal_mapped(bsdf, mat["normal_map"])
    return {"type": "twosided", "material": bsdf}


# --------------------------------------------------------------------------------------------
# Textures
# --------------------------------------------------------------------------------------------

def is_texture(value) -> bool:
    """True for penumbra's ``{"texture": PATH, ...}`` form of a parameter."""
    return isinstance(value, dict) and "texture" in value


def srgb_to_linear(v: np.ndarray) -> np.ndarray:
    """IEC 61966-2-1 decoding (for values the user declares sRGB that are not colours)."""
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


class TextureBaker:
    """Penumbra textures as Mitsuba ``bitmap`` textures.

    Every texture is decoded as penumbra decodes it (docs/scene-format.md, "Textures"): sRGB for
    colours read from integer images unless ``colorspace`` is ``linear``, linear otherwise;
    ``scale`` multiplied in; one ``channel`` for single values; grey images as grey RGB. The
    linear values are written to a float EXR in a temporary folder and handed to Mitsuba with
    ``raw = true`` and the same ``filter_type`` and ``wrap_mode``, so Mitsuba interpolates exactly
    the values penumbra interpolates. The sRGB decoding itself is Mitsuba's (``Bitmap.convert``).

    Roughness r becomes GGX alpha = (scale r)^2 per texel, which only nearest filtering keeps
    exact (penumbra squares after interpolating); a bilinear roughness texture is refused.
    """

    def __init__(self, mi, assets: str):
        import tempfile

        self.mi = mi
        self.assets = assets
        self.folder = tempfile.mkdtemp(prefix="penumbra_textures_")
        self.count = 0

    def _pixels(self, spec: dict, color: bool) -> np.ndarray:
        """The image as float64 (h, w, c) linear values (before scale)."""
        mi = self.mi
        path = os.path.join(self.assets, spec["texture"])
        bitmap = mi.Bitmap(path)
        is_float = bitmap.component_format() in (mi.Struct.Type.Float16, mi.Struct.Type.Float32,
                                                  mi.Struct.Type.Float64)
        colorspace = spec.get("colorspace", "srgb" if color and not is_float else "linear")
        raw = np.array(bitmap, dtype=np.float64)
        if raw.ndim == 2:
            raw = raw[:, :, None]
        if not is_float:
            raw /= float(np.iinfo(np.array(bitmap).dtype).max)
        if colorspace == "srgb" and color:
            # Mitsuba's own decoding of the colour channels (alpha stays linear).
            bitmap.set_srgb_gamma(True)
            fmt = mi.Bitmap.PixelFormat.RGB if raw.shape[2] >= 3 else mi.Bitmap.PixelFormat.Y
            decoded = np.array(bitmap.convert(fmt, mi.Struct.Type.Float32, srgb_gamma=False), dtype=np.float64)
            return decoded if decoded.ndim == 3 else decoded[:, :, None]
        if colorspace == "srgb":
            return srgb_to_linear(raw)
        return raw

    def _bitmap(self, values: np.ndarray, spec: dict) -> dict:
        """Write linear values (h, w, 1 or 3) to an EXR and return the bitmap dictionary."""
        self.count += 1
        path = os.path.join(self.folder, f"texture{self.count}.exr")
        fmt = self.mi.Bitmap.PixelFormat.RGB if values.shape[2] == 3 else self.mi.Bitmap.PixelFormat.Y
        self.mi.Bitmap(np.ascontiguousarray(values, dtype=np.float32), fmt).write(path)
        return {"type": "bitmap", "filename": path, "raw": True,
                "filter_type": spec.get("filter", "bilinear"), "wrap_mode": spec.get("wrap", "repeat")}

    def spectrum(self, value, role: str) -> dict:
        """A colour (``role`` 'color') or radiance ('emission'): RGB constant or bitmap."""
        if not is_texture(value):
            return rgb(value)
        pixels = self._pixels(value, color=True)
        rgb_pixels = pixels[:, :, :3] if pixels.shape[2] >= 3 else np.repeat(pixels[:, :, :1], 3, axis=2)
        if role == "color":
            rgb_pixels = np.clip(rgb_pixels, 0.0, 1.0)  # penumbra clamps reflectance texels
        else:
            rgb_pixels = np.maximum(rgb_pixels, 0.0)
        return self._bitmap(rgb_pixels * vec(value.get("scale", 1.0)), value)

    def alpha(self, roughness):
        """GGX alpha = roughness^2: a number, or a bitmap of squared texels (nearest only)."""
        if not is_texture(roughness):
            return float(roughness) ** 2
        if roughness.get("filter", "bilinear") != "nearest":
            raise ValueError("a roughness texture converts to Mitsuba exactly only with filter "
                             "'nearest' (penumbra squares the interpolated roughness)")
        pixels = self._pixels(roughness, color=False)
        r = np.clip(pixels[:, :, int(roughness.get("channel", 0))], 0.0, 1.0) * float(roughness.get("scale", 1.0))
        return self._bitmap((r * r)[:, :, None], roughness)

    def normal_mapped(self, bsdf: dict, normal_map) -> dict:
        """``bsdf`` under a normal map (a file name or a texture object), read linearly."""
        spec = {"texture": normal_map} if isinstance(normal_map, str) else normal_map
        pixels = self._pixels(spec, color=False)
        rgb_pixels = pixels[:, :, :3] if pixels.shape[2] >= 3 else np.repeat(pixels[:, :, :1], 3, axis=2)
        return {"type": "normalmap", "normalmap": self._bitmap(rgb_pixels, spec), "bsdf": bsdf}


def convert_medium(mat: dict) -> dict | None:
    """The interior medium of a dielectric with absorption, or None.

    Beer-Lambert absorption = a homogeneous medium that only absorbs: albedo 0 and
    sigma_t = sigma_a. Mitsuba's 'rgb' spectrum must lie in [0, 1], so the coefficient is
    normalised and its maximum goes into ``scale``.
    """
    if mat.get("type") != "dielectric":
        return None
    sigma_a = vec(mat.get("absorption", [0, 0, 0]))
    peak = float(sigma_a.max())
    if peak <= 0:
        return None
    return {"type": "homogeneous", "albedo": 0.0, "sigma_t": rgb(sigma_a / peak), "scale": peak}


def quad_to_world(origin: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """4x4 matrix mapping Mitsuba's rectangle ([-1,1]^2 at z = 0, normal +z) onto the
    parallelogram origin + s*u + t*v, s,t in [0,1], with its normal along u x v.

    Columns: x -> u/2, y -> v/2, z -> unit(u x v), translation = the centre. For orthogonal
    u, v this is what Mitsuba's rectangle expects; see :func:`convert_object` for the rest.
    """
    n = np.cross(u, v)
    m = np.eye(4)
    m[:3, 0] = 0.5 * u
    m[:3, 1] = 0.5 * v
    m[:3, 2] = n / np.linalg.norm(n)
    m[:3, 3] = origin + 0.5 * u + 0.5 * v
    return m


def mesh_arrays(obj: dict, matrix: np.ndarray, offset: np.ndarray):
    """World-space (positions, faces, normals or None) of a mesh object as numpy arrays."""
    positions = np.asarray(obj["positions"], dtype=np.float64).reshape(-1, 3)
    faces = np.asarray(obj["indices"], dtype=np.uint32).reshape(-1, 3)
    positions = apply_point(matrix, positions) + offset
    normals = None
    if obj.get("normals"):
        normals = np.asarray(obj["normals"], dtype=np.float64).reshape(-1, 3)
        zero = np.linalg.norm(normals, axis=1) == 0
        normals = apply_normal(matrix, np.where(zero[:, None], 1.0, normals))
        if zero.any():  # as penumbra's loader: the area-weighted normal of the adjacent triangles
            normals[zero] = area_weighted_normals(positions, faces)[zero]
    return positions, faces, normals


def area_weighted_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Per-vertex sums of the (area-weighted) normals of adjacent triangles, normalised."""
    p = positions[faces]
    face_n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    n = np.zeros_like(positions)
    for k in range(3):
        np.add.at(n, faces[:, k], face_n)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)


def build_mesh(mi, name: str, positions, faces, normals, children: dict, uvs=None):
    """A Mitsuba mesh from numpy arrays; ``children`` are instantiated plugins (bsdf, emitter,
    interior) attached through the mesh's Properties. Without normals Mitsuba uses face normals.
    ``uvs`` (one pair per vertex) carry over as they are: both formats put uv (0, 0) at an
    image's top-left corner.
    """
    props = mi.Properties()
    for key, value in children.items():
        props[key] = value
    mesh = mi.Mesh(name, len(positions), len(faces), props, has_vertex_normals=normals is not None,
                   has_vertex_texcoords=uvs is not None)
    params = mi.traverse(mesh)
    # The buffers' own types (dynamic arrays in every variant, scalar_rgb included).
    float_buffer = type(params["vertex_positions"])
    params["vertex_positions"] = float_buffer(positions.astype(np.float32).ravel())
    params["faces"] = type(params["faces"])(faces.astype(np.uint32).ravel())
    if normals is not None:
        params["vertex_normals"] = float_buffer(normals.astype(np.float32).ravel())
    if uvs is not None:
        params["vertex_texcoords"] = float_buffer(np.asarray(uvs, dtype=np.float32).ravel())
    params.update()
    return mesh


def convert_object(mi, index: int, obj: dict, materials: dict, time: float,
                   textures: TextureBaker | None = None):
    """One penumbra object at ``time`` -> a Mitsuba shape (a dict, or a Mesh instance)."""
    matrix = object_matrix(obj.get("transform"))
    offset = motion_offset(obj, time)
    mat = materials[obj["material"]]
    children: dict[str, Any] = {"bsdf": convert_material(mat, textures)}
    medium = convert_medium(mat)
    if medium is not None:
        children["interior"] = medium
    emission = obj.get("emission", [0, 0, 0])
    if is_texture(emission):
        if textures is None:
            raise ValueError("a textured emission needs a TextureBaker")
        children["emitter"] = {"type": "area", "radiance": textures.spectrum(emission, "emission")}
    elif np.any(vec(emission) > 0):
        children["emitter"] = {"type": "area", "radiance": rgb(emission)}

    kind = obj["type"]
    if kind == "sphere":
        linear = matrix[:3, :3]
        scales = np.linalg.svd(linear, compute_uv=False)
        if not np.allclose(scales, scales[0], rtol=1e-6):
            raise ValueError(f"object {index}: a sphere's transform must scale uniformly")
        center = apply_point(matrix, vec(obj["center"])) + offset
        return {"type": "sphere", "center": center.tolist(), "radius": float(obj["radius"]) * float(scales[0]),
                **children}
    if kind == "quad":
        origin = apply_point(matrix, vec(obj["origin"])) + offset
        u = apply_vector(matrix, vec(obj["u"]))
        v = apply_vector(matrix, vec(obj["v"]))
        if abs(np.dot(u, v)) <= 1e-9 * np.linalg.norm(u) * np.linalg.norm(v):
            return {"type": "rectangle", "to_world": mi.ScalarTransform4f(quad_to_world(origin, u, v)), **children}
        # Mitsuba's rectangle builds its shading frame from the transformed axes, which assumes
        # they are orthogonal; a sheared parallelogram is two triangles instead (same surface,
        # same area sampling, same front side).
        positions = np.array([origin, origin + u, origin + u + v, origin + v])
        faces = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
        return build_mesh(mi, f"quad{index}", positions, faces, None, instantiate(mi, children))
    if kind == "mesh" and "file" in obj:
        return mesh_file_shape(mi, obj, matrix, offset, children)
    if kind == "mesh":
        positions, faces, normals = mesh_arrays(obj, matrix, offset)
        uvs = np.asarray(obj["uvs"], dtype=np.float64).reshape(-1, 2) if obj.get("uvs") else None
        return build_mesh(mi, f"mesh{index}", positions, faces, normals, instantiate(mi, children), uvs)
    raise ValueError(f"object {index}: unknown type {kind!r}")


# --------------------------------------------------------------------------------------------
# Mesh files ("file" on a mesh object)
# --------------------------------------------------------------------------------------------

def mesh_file_shape(mi, obj: dict, matrix: np.ndarray, offset: np.ndarray, children: dict) -> dict:
    """A mesh object with ``"file"`` -> Mitsuba's own ``ply`` or ``obj`` plugin on the same file,
    so that the reference also checks penumbra's readers.

    The object transform (and the motion offset at this instant) becomes ``to_world``. Mitsuba
    computes smooth vertex normals for a file without any, where penumbra shades such a mesh
    with its face normals (flat, as an inline mesh without normals): ``face_normals`` says which.
    Both flip OBJ's v on load. The path must already be resolved (:func:`load_json` does it).
    """
    path = obj["file"]
    kind = os.path.splitext(path)[1].lower().lstrip(".")
    if kind not in ("ply", "obj"):
        raise ValueError(f"unknown mesh file type {path!r}")
    to_world = matrix.copy()
    to_world[:3, 3] += offset
    return {"type": kind, "filename": path, "to_world": mi.ScalarTransform4f(to_world),
            "face_normals": not mesh_file_has_normals(path), **children}


def mesh_file_has_normals(path: str) -> bool:
    """Whether penumbra shades the file with its vertex normals: a PLY whose vertex element has
    nx, ny, nz; an OBJ whose every face corner names a normal (``v//vn`` or ``v/vt/vn``)."""
    with open(path, "rb") as f:
        data = f.read()
    if path.lower().endswith(".ply"):
        header = data[:data.index(b"end_header")].decode("ascii", "replace").split("\n")
        element, names = None, set()
        for line in header:
            words = line.split()
            if words[:1] == ["element"]:
                element = words[1]
            elif words[:1] == ["property"] and element == "vertex":
                names.add(words[-1])
        return {"nx", "ny", "nz"} <= names
    corners = [c for line in data.decode("utf-8", "replace").splitlines() if line.split()[:1] == ["f"]
               for c in line.split()[1:]]
    return bool(corners) and all(c.count("/") == 2 and not c.endswith("/") for c in corners)


def resolve_mesh_files(scene: dict, folder: str) -> dict:
    """Mesh ``"file"`` paths made absolute, relative to the scene file's folder as penumbra's
    CLI reads them."""
    for obj in scene.get("objects", []):
        if obj.get("type") == "mesh" and "file" in obj:
            obj["file"] = os.path.join(folder, obj["file"])
    return scene


def convert_instances(mi, index: int, obj: dict, objects: list, materials: dict, time: float,
                      textures, out: dict) -> None:
    """Add a penumbra ``instances`` object to the scene dictionary ``out``: the shape group of the
    mesh it names (once per mesh) and an ``instance`` of it per transform.

    Penumbra refuses copies of emitting meshes, and Mitsuba's shape groups cannot hold emitters,
    so the group's shape has none. The group holds a second conversion of the mesh (the first is
    drawn where it stands): one Mitsuba shape cannot belong to two parents.
    """
    mesh_index = int(obj["mesh"])
    group = f"group{mesh_index}"
    if group not in out:
        out[group] = {"type": "shapegroup",
                      "shape": convert_object(mi, mesh_index, objects[mesh_index], materials, time,
                                              textures)}
    for k, transform in enumerate(obj["transforms"]):
        out[f"object{index}_{k}"] = {"type": "instance", "shapegroup": {"type": "ref", "id": group},
                                     "to_world": mi.ScalarTransform4f(object_matrix(transform))}


def instantiate(mi, children: dict) -> dict:
    """Load plugin dictionaries into objects (what a Mesh's Properties need)."""
    return {key: mi.load_dict(value) for key, value in children.items()}


def convert_light(light: dict) -> dict:
    """A penumbra point or directional light -> a Mitsuba emitter dictionary."""
    if light["type"] == "point":
        return {"type": "point", "position": vec(light["position"]).tolist(), "intensity": rgb(light["intensity"])}
    if light["type"] == "directional":
        # Both formats: 'direction' is where the light travels, irradiance on a facing surface.
        return {"type": "directional", "direction": vec(light["direction"]).tolist(),
                "irradiance": rgb(light["irradiance"])}
    raise ValueError(f"unknown light type {light['type']!r}")


def convert_environment(mi, env: dict | None) -> dict | None:
    """A penumbra ``environment`` -> a Mitsuba emitter dictionary, or None when it is black.

    ``radiance`` -> ``constant``. ``map`` -> ``envmap``: penumbra follows Mitsuba 3's envmap
    (lat-long, +y the top row, +z the centre column, bilinear lookup), so the file, ``scale`` and
    the map-to-world rotation carry over unchanged; ``matrix`` is row-major as Mitsuba's
    ScalarTransform4f takes it. The relative file name is resolved by Mitsuba's file resolver
    (see :func:`use_scene_folder`).
    """
    if env is None:
        return None
    if "map" not in env:
        if np.any(vec(env.get("radiance", [0, 0, 0])) > 0):
            return {"type": "constant", "radiance": rgb(env["radiance"])}
        return None
    to_world = np.eye(4)
    if "matrix" in env:
        to_world = np.asarray(env["matrix"], dtype=np.float64).reshape(4, 4)
    elif "rotate" in env:
        to_world[:3, :3] = rotation_matrix(env["rotate"]["axis"], env["rotate"]["degrees"])
    return {"type": "envmap", "filename": env["map"], "scale": float(env.get("scale", 1.0)),
            "to_world": mi.ScalarTransform4f(to_world)}


def use_scene_folder(mi, scene_path: str) -> None:
    """Let Mitsuba find the files a scene names (environment maps) relative to its folder, as
    penumbra does."""
    mi.file_resolver().prepend(os.path.dirname(os.path.abspath(scene_path)))


def convert_sensor(mi, scene: dict, spp: int, width: int | None = None, height: int | None = None,
                   sampler: str = "independent") -> dict:
    """Camera, film (box filter, linear float RGB) and sampler (Mitsuba's ``independent`` by
    default; the benchmark also measures its low-discrepancy ones, e.g. ``ldsampler``)."""
    cam = scene["camera"]
    render = scene.get("render", {})
    to_world = mi.ScalarTransform4f().look_at(
        origin=vec(cam["position"]).tolist(), target=vec(cam["look_at"]).tolist(),
        up=vec(cam.get("up", [0, 1, 0])).tolist())
    sensor = {"type": "perspective", "fov": float(cam.get("fov", 40.0)), "fov_axis": "y", "to_world": to_world}
    aperture = float(cam.get("aperture_radius", 0.0))
    if aperture > 0:
        # Default: the distance to look_at, as in penumbra.
        default_focus = float(np.linalg.norm(vec(cam["look_at"]) - vec(cam["position"])))
        sensor.update(type="thinlens", aperture_radius=aperture,
                      focus_distance=float(cam.get("focus_distance", default_focus)))
    sensor["film"] = {
        "type": "hdrfilm",
        "width": int(width or render.get("width", 256)),
        "height": int(height or render.get("height", 256)),
        "rfilter": {"type": "box"},
        "pixel_format": "rgb",
        "component_format": "float32",
    }
    sensor["sampler"] = {"type": sampler, "sample_count": int(spp), "seed": int(render.get("seed", 0))}
    return sensor


def convert_integrator(scene: dict) -> dict:
    """``path``, or ``volpath`` when a dielectric absorbs; same max_depth, RR from depth 5."""
    render = scene.get("render", {})
    if render.get("integrator", "path") != "path":
        raise ValueError("references are path traced: set render.integrator to 'path'")
    return {
        "type": "volpath" if uses_absorption(scene) else "path",
        "max_depth": int(render.get("max_depth", 8)),
        "rr_depth": int(render.get("rr_depth", RR_DEPTH)),
    }


def to_mitsuba(mi, scene: dict, time: float = 0.0, spp: int | None = None,
               width: int | None = None, height: int | None = None, assets: str = ".",
               sampler: str = "independent") -> dict:
    """The Mitsuba scene dictionary of a penumbra scene at instant ``time``.

    ``spp``, ``width`` and ``height`` override the scene's render settings; texture files are
    relative to ``assets`` (the scene file's folder); ``sampler`` is the Mitsuba sampler plugin.
    """
    if scene.get("version") != 1:
        raise ValueError("only penumbra scene format version 1 is supported")
    render = scene.get("render", {})
    out: dict[str, Any] = {
        "type": "scene",
        "integrator": convert_integrator(scene),
        "sensor": convert_sensor(mi, scene, spp or render.get("spp", 64), width, height, sampler),
    }
    materials = scene.get("materials", {})
    textures = TextureBaker(mi, assets)
    objects = scene.get("objects", [])
    for i, obj in enumerate(objects):
        if obj.get("type") == "instances":
            convert_instances(mi, i, obj, objects, materials, time, textures, out)
        else:
            out[f"object{i}"] = convert_object(mi, i, obj, materials, time, textures)
    for i, light in enumerate(scene.get("lights", [])):
        out[f"light{i}"] = convert_light(light)
    environment = convert_environment(mi, scene.get("environment"))
    if environment is not None:
        out["environment"] = environment
    return out


def load_json(path: str) -> dict:
    """Read a penumbra scene file; the files it names are resolved against its folder."""
    with open(path, encoding="utf-8") as f:
        scene = json.load(f)
    return resolve_mesh_files(scene, os.path.dirname(os.path.abspath(path)))


def render_average(mi, scene: dict, spp: int, instants: int = 64, seed: int = 0,
                   width: int | None = None, height: int | None = None, assets: str = ".") -> np.ndarray:
    """Render ``scene`` with ``spp`` samples per pixel in total, as the mean over the shutter
    instants (one instant without motion blur), and return an (h, w, 3) float64 array.

    Each instant gets spp / instants samples (at least 1) and its own sampler seed.
    """
    times = shutter_instants(scene, instants)
    per_instant = max(1, spp // len(times))
    total = None
    for k, t in enumerate(times):
        mscene = mi.load_dict(to_mitsuba(mi, scene, time=t, spp=per_instant, width=width, height=height,
                                         assets=assets))
        img = np.asarray(mi.render(mscene, spp=per_instant, seed=seed * len(times) + k), dtype=np.float64)
        total = img if total is None else total + img
    return total / len(times)


def main(argv: list[str]) -> int:
    """Command line: convert and render one scene (a quick preview, or a reference by hand)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", help="penumbra scene v1 JSON")
    ap.add_argument("-o", "--output", required=True, help="output EXR (linear RGB float)")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--instants", type=int, default=64, help="shutter instants for motion blur")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    args = ap.parse_args(argv)
    mi = import_mitsuba(args.variant)
    use_scene_folder(mi, args.scene)
    img = render_average(mi, load_json(args.scene), args.spp, args.instants, args.seed,
                         assets=os.path.dirname(os.path.abspath(args.scene)))
    mi.Bitmap(img.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
