"""Render a penumbra scene (format v1, JSON) with Blender Cycles (CPU), for the run-time-against-
error benchmark (tools/bench_accuracy.py, docs/accuracy.md).

Run inside Blender (Debian's ``blender`` 3.4, no numpy there: pure Python)::

    blender -b --factory-startup --python-exit-code 1 --python tools/penumbra_to_cycles.py -- \\
        scene.json -o out.exr [--spp 64] [--seed 0] [--sphere-mesh 512] [--check]

It builds the same scene for the features Cycles expresses exactly and refuses the rest, naming
the JSON pointer at fault (exit code 2, message on stderr, nothing rendered). :func:`refusals`
is plain Python, so the benchmark asks it without starting Blender.

Mapping (each checked against penumbra and Mitsuba on the accuracy scenes, docs/accuracy.md):

* ``diffuse``   -> Diffuse BSDF, roughness 0 (Lambert).
* ``conductor`` -> Glossy BSDF, GGX (Sharp at roughness 0), colour = the constant reflectance.
  Blender's roughness squares into the GGX alpha as penumbra's does, so r carries over as r.
  Cycles' Glossy BSDF has no Fresnel term: a constant reflectance, as penumbra's conductor.
* ``dielectric`` -> Glass BSDF, Sharp, white, same IOR. Rough glass is refused unless
  ``--rough-glass``: Cycles 3.x's Glass BSDF (svm closure setup) weighs a GGX reflection and a
  GGX refraction lobe by the Fresnel factor at the *shading* normal, where Walter et al. 2007 (and
  penumbra, Mitsuba) take the Fresnel factor of each sampled microfacet; it is exact only when
  smooth. Measured on glass_rough at 48x48, 512 spp: a cube of IOR 1.33, roughness 0.5 is 14 %
  brighter in Cycles than in Mitsuba (IOR 1.5: 2 %). Cycles 4.0 changed the node to the
  microfacet Fresnel. ``absorption`` sigma_a ->
  a Volume Absorption node in the material's volume output with density = max(sigma_a) and
  colour = 1 - sigma_a / density: Cycles absorbs with (1 - colour) * density per unit length
  (Beer-Lambert, exact for a homogeneous volume, which the material is marked as).
* ``emission`` -> an Emission shader added to the BSDF, strength 1: a Cycles mesh emitter of
  strength 1 shows its colour as radiance (unlike lamps, whose strength is watts). Penumbra
  emits from the front only; Cycles from both sides, so the strength is multiplied by
  (1 - Backfacing).
* quads -> a one-polygon mesh origin, origin+u, origin+u+v, origin+v (front = u x v);
  inline meshes as they are (counter-clockwise front), per-vertex normals as custom split
  normals (smooth), none -> flat. Transforms become the object's matrix.
* spheres: Cycles has no analytic sphere. Refused unless ``--sphere-mesh N``: a UV sphere of N
  segments and N/2 rings with the sphere's exact normals at its vertices, smooth shaded (NOT
  exact: its facets lie inside the true sphere by up to r(1 - cos(pi/N)), and the interpolated
  normals are not the sphere's between vertices; the benchmark says so).
* environment ``radiance`` -> World Background of that colour, strength 1.
* camera: look_at matrix, vertical fov (sensor fit Vertical), thin lens with aperture radius
  a: Cycles' aperture radius is focal_length / (2 f-stop), so f-stop = focal_length / (2 a).
* render: max_depth d (path segments, Mitsuba's convention) -> Cycles max_bounces d - 2 (Cycles
  counts bounces after the first hit: 0 = direct light only), all per-type limits the same;
  -1 -> 1024. Seed -> Cycles seed.

Everything Cycles does to trade bias for speed is off: adaptive sampling, denoising, clamping
(direct and indirect 0 = off), Filter Glossy (blur_glossy 0), light threshold 0, path guiding,
shadow-terminator offsets 0; caustics on. Pixel filter: Box of width 1 pixel (Cycles'
``pixel_filter_type`` BOX: each sample lands uniformly in its pixel with weight 1, penumbra's
and Mitsuba's box filter). Cycles samples with its own quasi-random sequence (its default
pattern) and its own Russian roulette (penumbra's rr_depth has no Cycles equivalent); both are
unbiased.

* mesh files (PLY, OBJ; relative to the scene's folder) are read here as penumbra reads them
  (:func:`read_ply`, :func:`read_obj`: polygons fan-triangulated, vertex normals when the PLY
  has nx, ny, nz or every OBJ corner names a normal, else flat) and built as inline meshes:
  Blender 3.4's PLY importer drops normals and its OBJ importer may merge or smooth otherwise.
* point light of intensity I (W/sr) -> a Point lamp of radius 0, power 4 pi max(I) W, colour
  I / max(I) (Cycles: intensity = power / 4 pi, docs/blender.md). Directional light of
  irradiance E travelling along d -> a Sun of angle 0, strength max(E), colour E / max(E), its
  -Z along d.

Refused: plastic (Cycles has no layered diffuse + dielectric coat equal to penumbra's), textures
and normal maps, environment maps, instances, motion blur, max_depth 1, integrators other than
``path``, a zero normal in a mesh.

Output: a linear float32 RGB EXR. Printed on stdout:
``cycles: render S s, process P s`` where S is ``bpy.ops.render.render`` (Cycles' scene sync,
BVH build and sampling: comparable to penumbra's build + render) and P the whole Blender process
from its start to the written EXR (start-up, conversion, render, write).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

#: Default reflectance of each material type when ``color`` is absent (docs/scene-format.md).
DEFAULT_COLOR = {"diffuse": [0.5, 0.5, 0.5], "conductor": [1.0, 1.0, 1.0]}

#: Cycles bounces for penumbra's unlimited depth (-1).
UNLIMITED_BOUNCES = 1024


class Refused(ValueError):
    """A part of the scene Cycles cannot render exactly; ``pointer`` is its JSON pointer."""

    def __init__(self, pointer: str, why: str):
        super().__init__(f"{pointer}: {why}")
        self.pointer = pointer


def _nonzero(values) -> bool:
    if isinstance(values, (int, float)):
        return values != 0
    return any(float(x) != 0 for x in values)


def refusals(scene: dict, sphere_mesh: int = 0, rough_glass: bool = False) -> list[Refused]:
    """Every reason why ``scene`` does not translate exactly (empty: it does). Plain Python.
    ``sphere_mesh`` > 0 and ``rough_glass`` accept the two approximations (module docstring)."""
    out: list[Refused] = []
    if scene.get("version") != 1:
        out.append(Refused("/version", "only scene format version 1"))
    render = scene.get("render", {})
    if render.get("integrator", "path") != "path":
        out.append(Refused("/render/integrator", "only 'path' has a Cycles equivalent"))
    if render.get("max_depth", 8) == 1:
        out.append(Refused("/render/max_depth", "1 (emitters only): Cycles always adds direct light"))
    for i, light in enumerate(scene.get("lights", [])):
        if light.get("type") not in ("point", "directional"):
            out.append(Refused(f"/lights/{i}/type", f"{light.get('type')!r} is not translated"))
    env = scene.get("environment") or {}
    for key in env:
        if key != "radiance":
            out.append(Refused(f"/environment/{key}", "only a constant environment radiance"))
    for name, mat in scene.get("materials", {}).items():
        base = f"/materials/{name}"
        kind = mat.get("type")
        if kind not in ("diffuse", "conductor", "dielectric"):
            out.append(Refused(f"{base}/type", f"{kind!r} has no exact Cycles equivalent"))
        if kind == "dielectric" and not rough_glass and not isinstance(mat.get("roughness", 0), dict) \
                and float(mat.get("roughness", 0)) > 0:
            out.append(Refused(f"{base}/roughness", "Cycles 3.x's rough Glass BSDF is not Walter et al.'s "
                                                     "model (--rough-glass renders it anyway)"))
        for key, value in mat.items():
            if isinstance(value, dict) or key == "normal_map":
                out.append(Refused(f"{base}/{key}", "textures and normal maps are not translated"))
    for i, obj in enumerate(scene.get("objects", [])):
        base = f"/objects/{i}"
        kind = obj.get("type")
        if kind == "sphere" and sphere_mesh <= 0:
            out.append(Refused(f"{base}/type", "Cycles has no analytic sphere (--sphere-mesh N "
                                               "tessellates it, not exactly)"))
        elif kind == "sphere" and not uniform_scale(object_matrix(obj.get("transform"))):
            out.append(Refused(f"{base}/transform", "a sphere's transform must scale uniformly"))
        elif kind == "mesh" and "file" in obj:
            if os.path.splitext(obj["file"])[1].lower() not in (".ply", ".obj"):
                out.append(Refused(f"{base}/file", "only .ply and .obj files"))
        elif kind == "mesh" and obj.get("normals") and any(
                obj["normals"][k:k + 3] == [0, 0, 0] for k in range(0, len(obj["normals"]), 3)):
            out.append(Refused(f"{base}/normals", "a zero normal (penumbra's fallback is not translated)"))
        elif kind not in ("sphere", "quad", "mesh"):
            out.append(Refused(f"{base}/type", f"{kind!r} is not translated"))
        for key in ("velocity", "acceleration"):
            if key in obj and _nonzero(obj[key]):
                out.append(Refused(f"{base}/{key}", "motion blur is not translated"))
        if isinstance(obj.get("emission"), dict):
            out.append(Refused(f"{base}/emission", "textured emission is not translated"))
    return out


# --------------------------------------------------------------------------------------------
# Geometry helpers (pure Python, row-major 4x4 lists)
# --------------------------------------------------------------------------------------------

def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def rotation(axis, degrees: float):
    """4x4 right-handed rotation by ``degrees`` about ``axis`` (Rodrigues)."""
    n = math.sqrt(sum(x * x for x in axis))
    x, y, z = (c / n for c in axis)
    t = math.radians(degrees)
    c, s, C = math.cos(t), math.sin(t), 1 - math.cos(t)
    return [[c + x * x * C, x * y * C - z * s, x * z * C + y * s, 0],
            [y * x * C + z * s, c + y * y * C, y * z * C - x * s, 0],
            [z * x * C - y * s, z * y * C + x * s, c + z * z * C, 0],
            [0, 0, 0, 1]]


def object_matrix(transform: dict | None):
    """penumbra's object-to-world matrix: ``matrix`` (row-major), or T * R * S."""
    m = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
    if not transform:
        return m
    if "matrix" in transform:
        v = transform["matrix"]
        return [[float(v[4 * i + j]) for j in range(4)] for i in range(4)]
    if "scale" in transform:
        s = transform["scale"]
        s = [s, s, s] if isinstance(s, (int, float)) else s
        m = matmul([[s[0], 0, 0, 0], [0, s[1], 0, 0], [0, 0, s[2], 0], [0, 0, 0, 1]], m)
    if "rotate" in transform:
        m = matmul(rotation(transform["rotate"]["axis"], transform["rotate"]["degrees"]), m)
    if "translate" in transform:
        t = transform["translate"]
        m = matmul([[1, 0, 0, t[0]], [0, 1, 0, t[1]], [0, 0, 1, t[2]], [0, 0, 0, 1]], m)
    return m


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalize(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a]


def look_at(position, target, up):
    """Blender camera matrix: the camera looks along its -Z with +Y up."""
    back = normalize(sub(position, target))
    right = normalize(cross(up, back))
    true_up = cross(back, right)
    return [[right[0], true_up[0], back[0], position[0]],
            [right[1], true_up[1], back[1], position[1]],
            [right[2], true_up[2], back[2], position[2]],
            [0, 0, 0, 1]]


def uv_sphere(center, radius: float, segments: int):
    """A UV sphere of ``segments`` meridians and ``segments // 2`` rings around ``center``:
    flat lists (positions, polygons, normals), the normals exact (the sphere's own at each
    vertex), polygons counter-clockwise seen from outside (front outwards, as penumbra's
    sphere). Its flat facets lie inside the sphere by at most radius * (1 - cos(pi / segments))."""
    rings = max(2, segments // 2)
    dirs = [[0.0, 0.0, 1.0]]
    for i in range(1, rings):
        theta = math.pi * i / rings
        for j in range(segments):
            phi = 2.0 * math.pi * j / segments
            dirs.append([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)])
    dirs.append([0.0, 0.0, -1.0])
    bottom = len(dirs) - 1

    def at(i, j):  # ring i in 1 .. rings-1
        return 1 + (i - 1) * segments + j % segments

    polys = []
    for j in range(segments):
        polys.append([0, at(1, j), at(1, j + 1)])
        for i in range(1, rings - 1):
            polys.append([at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
        polys.append([at(rings - 1, j), bottom, at(rings - 1, j + 1)])
    positions = [center[k] + radius * d[k] for d in dirs for k in range(3)]
    return positions, polys, [x for d in dirs for x in d]


def uniform_scale(matrix) -> bool:
    """Whether the linear part of a 4x4 matrix is a rotation times one scale (a sphere stays one)."""
    cols = [[matrix[r][c] for r in range(3)] for c in range(3)]
    dots = [[sum(a * b for a, b in zip(cols[i], cols[j])) for j in range(3)] for i in range(3)]
    s2 = dots[0][0]
    return all(abs(dots[i][j] - (s2 if i == j else 0.0)) <= 1e-6 * s2 for i in range(3) for j in range(3))


# --------------------------------------------------------------------------------------------
# Mesh files, read as penumbra's readers read them (renderer/io/, docs/mesh-files.md)
# --------------------------------------------------------------------------------------------

_PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
              "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
              "float": "f", "float32": "f", "double": "d", "float64": "d"}


def _fan(polygon):
    """Fan triangulation from the first corner, as penumbra's FaceSink."""
    return [[polygon[0], polygon[k], polygon[k + 1]] for k in range(1, len(polygon) - 1)]


def read_ply(path: str):
    """(positions, triangles, normals or None) of a PLY file (ASCII or binary), flat lists."""
    import struct

    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header")
    body = data[data.index(b"\n", end) + 1:]
    fmt, elements = "ascii", []
    for line in data[:end].decode("ascii", "replace").splitlines():
        w = line.split()
        if w[:1] == ["format"]:
            fmt = w[1]
        elif w[:1] == ["element"]:
            elements.append((w[1], int(w[2]), []))
        elif w[:1] == ["property"]:
            elements[-1][2].append(("list", w[2], w[3], w[4]) if w[1] == "list" else ("scalar", w[1], w[2]))
    order = "<" if fmt == "binary_little_endian" else ">"
    tokens = body.split() if fmt == "ascii" else None
    pos = 0
    positions, normals, faces = [], [], []

    def scalar(kind):
        nonlocal pos
        if tokens is not None:
            pos += 1
            return float(tokens[pos - 1]) if _PLY_TYPES[kind] in "fd" else int(tokens[pos - 1])
        code = order + _PLY_TYPES[kind]
        value = struct.unpack_from(code, body, pos)[0]
        pos += struct.calcsize(code)
        return value

    for name, count, props in elements:
        names = [p[-1] for p in props]
        for _ in range(count):
            values = {}
            for prop in props:
                if prop[0] == "list":
                    n = scalar(prop[1])
                    values[prop[3]] = [scalar(prop[2]) for _ in range(n)]
                else:
                    values[prop[2]] = scalar(prop[1])
            if name == "vertex":
                positions += [values["x"], values["y"], values["z"]]
                if {"nx", "ny", "nz"} <= set(names):
                    normals += [values["nx"], values["ny"], values["nz"]]
            elif name == "face":
                corners = values.get("vertex_indices", values.get("vertex_index"))
                for tri in _fan(corners):
                    faces += tri
    return positions, faces, normals or None


def read_obj(path: str):
    """(positions, triangles, normals or None) of an OBJ file: v, vn and f statements; vertex
    normals only when every corner names one (then one vertex per distinct position/normal
    pair, as penumbra's reader splits them)."""
    v, vn, polys = [], [], []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "v":
                v.append([float(x) for x in w[1:4]])
            elif w[0] == "vn":
                vn.append([float(x) for x in w[1:4]])
            elif w[0] == "f":
                corners = []
                for c in w[1:]:
                    parts = c.split("/")
                    vi = int(parts[0])
                    ni = int(parts[2]) if len(parts) == 3 and parts[2] else None
                    corners.append((vi - 1 if vi > 0 else len(v) + vi,
                                    None if ni is None else (ni - 1 if ni > 0 else len(vn) + ni)))
                polys.append(corners)
    with_normals = bool(polys) and all(n is not None for p in polys for _, n in p)
    index, positions, normals, faces = {}, [], [], []
    for p in polys:
        ids = []
        for vi, ni in p:
            key = (vi, ni) if with_normals else (vi, None)
            if key not in index:
                index[key] = len(index)
                positions += v[vi]
                if with_normals:
                    normals += vn[ni]
            ids.append(index[key])
        for tri in _fan(ids):
            faces += tri
    return positions, faces, normals or None


def read_mesh_file(path: str):
    return read_ply(path) if path.lower().endswith(".ply") else read_obj(path)


# --------------------------------------------------------------------------------------------
# Blender side
# --------------------------------------------------------------------------------------------

def build_material(bpy, name: str, mat: dict, emission):
    """The Cycles material of a penumbra material (plus an object's emission, if any)."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    kind = mat["type"]
    roughness = float(mat.get("roughness", 0.0))
    if kind == "diffuse":
        bsdf = nodes.new("ShaderNodeBsdfDiffuse")
        bsdf.inputs["Roughness"].default_value = 0.0
        bsdf.inputs["Color"].default_value = [*map(float, mat.get("color", DEFAULT_COLOR["diffuse"])), 1.0]
    elif kind == "conductor":
        bsdf = nodes.new("ShaderNodeBsdfGlossy")
        bsdf.distribution = "GGX" if roughness > 0 else "SHARP"
        bsdf.inputs["Roughness"].default_value = roughness
        bsdf.inputs["Color"].default_value = [*map(float, mat.get("color", DEFAULT_COLOR["conductor"])), 1.0]
    else:
        bsdf = nodes.new("ShaderNodeBsdfGlass")
        bsdf.distribution = "GGX" if roughness > 0 else "SHARP"
        bsdf.inputs["Roughness"].default_value = roughness
        bsdf.inputs["IOR"].default_value = float(mat.get("ior", 1.5))
        bsdf.inputs["Color"].default_value = [1.0, 1.0, 1.0, 1.0]
        sigma = [float(x) for x in mat.get("absorption", [0, 0, 0])]
        if max(sigma) > 0:
            density = max(sigma)
            vol = nodes.new("ShaderNodeVolumeAbsorption")
            vol.inputs["Density"].default_value = density
            vol.inputs["Color"].default_value = [*(1.0 - s / density for s in sigma), 1.0]
            links.new(vol.outputs[0], out.inputs["Volume"])
            m.cycles.homogeneous_volume = True  # no ray marching: exact exp(-sigma d)
    shader = bsdf.outputs[0]
    if emission is not None and _nonzero(emission):
        emit = nodes.new("ShaderNodeEmission")
        emit.inputs["Color"].default_value = [*map(float, emission), 1.0]
        geometry = nodes.new("ShaderNodeNewGeometry")
        front = nodes.new("ShaderNodeMath")
        front.operation = "SUBTRACT"
        front.inputs[0].default_value = 1.0
        links.new(geometry.outputs["Backfacing"], front.inputs[1])
        links.new(front.outputs[0], emit.inputs["Strength"])
        add = nodes.new("ShaderNodeAddShader")
        links.new(shader, add.inputs[0])
        links.new(emit.outputs[0], add.inputs[1])
        shader = add.outputs[0]
    links.new(shader, out.inputs["Surface"])
    return m


def add_mesh_object(bpy, name: str, positions, faces, normals, matrix, material):
    """A mesh object; ``positions``/``normals`` flat lists of floats, ``faces`` flat triangles
    or a list of polygons (lists of indices)."""
    mesh = bpy.data.meshes.new(name)
    if faces and isinstance(faces[0], list):
        polys = faces
    else:
        polys = [faces[k:k + 3] for k in range(0, len(faces), 3)]
    verts = [positions[k:k + 3] for k in range(0, len(positions), 3)]
    mesh.from_pydata(verts, [], polys)
    mesh.materials.append(material)
    if normals:
        mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
        mesh.use_auto_smooth = True  # Cycles reads custom split normals only with auto smooth
        mesh.normals_split_custom_set_from_vertices(
            [normalize(normals[k:k + 3]) for k in range(0, len(normals), 3)])
    mesh.validate(clean_customdata=False)
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    obj.matrix_world = _matrix(matrix)
    _no_bias(obj)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _matrix(rows):
    from mathutils import Matrix
    return Matrix([[float(x) for x in row] for row in rows])


def _no_bias(obj):
    """Cycles' shadow-terminator offsets move shadow rays off smooth-shaded surfaces (the
    geometry offset defaults to 0.1): both off."""
    obj.cycles.shadow_terminator_offset = 0.0
    obj.cycles.shadow_terminator_geometry_offset = 0.0


def add_lights(bpy, lights: list):
    """Point lights (radius 0) and suns (angle 0) of the same intensity / irradiance."""
    for i, light in enumerate(lights):
        if light["type"] == "point":
            value = [float(x) for x in light["intensity"]]
            data = bpy.data.lights.new(f"light{i}", "POINT")
            data.shadow_soft_size = 0.0
            data.energy = 4.0 * math.pi * max(value)  # Cycles: W/sr = W / 4 pi
            matrix = [[1, 0, 0, light["position"][0]], [0, 1, 0, light["position"][1]],
                      [0, 0, 1, light["position"][2]], [0, 0, 0, 1]]
        else:
            value = [float(x) for x in light["irradiance"]]
            data = bpy.data.lights.new(f"light{i}", "SUN")
            data.angle = 0.0
            data.energy = max(value)  # W/m^2 on a surface facing the sun
            d = normalize([float(x) for x in light["direction"]])
            z = [-d[0], -d[1], -d[2]]  # the sun shines along its -Z
            helper = [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0]
            x = normalize(cross(helper, z))
            y = cross(z, x)
            matrix = [[x[0], y[0], z[0], 0], [x[1], y[1], z[1], 0], [x[2], y[2], z[2], 0], [0, 0, 0, 1]]
        peak = max(value)
        data.color = [c / peak for c in value] if peak > 0 else [0.0, 0.0, 0.0]
        data.cycles.cast_shadow = True
        obj = bpy.data.objects.new(f"light{i}", data)
        obj.matrix_world = _matrix(matrix)
        bpy.context.scene.collection.objects.link(obj)


def build_scene(bpy, scene_json: dict, spp: int, seed: int, sphere_mesh: int, folder: str = "."):
    """Empty the factory scene and build ``scene_json`` into it."""
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    scene = bpy.context.scene
    render = scene_json.get("render", {})
    materials = scene_json.get("materials", {})
    cache: dict = {}
    for i, obj in enumerate(scene_json.get("objects", [])):
        emission = obj.get("emission")
        key = (obj["material"], json.dumps(emission))
        if key not in cache:
            cache[key] = build_material(bpy, f"m{len(cache)}_{obj['material']}", materials[obj["material"]],
                                        emission)
        material = cache[key]
        matrix = object_matrix(obj.get("transform"))
        kind = obj["type"]
        if kind == "quad":
            o, u, v = ([float(x) for x in obj[k]] for k in ("origin", "u", "v"))
            corners = [o, [o[j] + u[j] for j in range(3)], [o[j] + u[j] + v[j] for j in range(3)],
                       [o[j] + v[j] for j in range(3)]]
            add_mesh_object(bpy, f"object{i}", [c for p in corners for c in p], [[0, 1, 2, 3]], None,
                            matrix, material)
        elif kind == "mesh" and "file" in obj:
            positions, faces, normals = read_mesh_file(os.path.join(folder, obj["file"]))
            add_mesh_object(bpy, f"object{i}", positions, faces, normals, matrix, material)
        elif kind == "mesh":
            add_mesh_object(bpy, f"object{i}", [float(x) for x in obj["positions"]],
                            [int(x) for x in obj["indices"]],
                            [float(x) for x in obj["normals"]] if obj.get("normals") else None,
                            matrix, material)
        else:  # sphere, tessellated on request (refusals() guards the rest)
            positions, faces, normals = uv_sphere([float(x) for x in obj["center"]], float(obj["radius"]),
                                                  sphere_mesh)
            add_mesh_object(bpy, f"object{i}", positions, faces, normals, matrix, material)

    add_lights(bpy, scene_json.get("lights", []))

    # camera
    cam_json = scene_json["camera"]
    cam_data = bpy.data.cameras.new("camera")
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(float(cam_json.get("fov", 40.0)))
    cam_data.clip_start = 1e-4
    cam_data.clip_end = 1e6
    aperture = float(cam_json.get("aperture_radius", 0.0))
    if aperture > 0:
        position, target = cam_json["position"], cam_json["look_at"]
        default_focus = math.sqrt(sum((float(a) - float(b)) ** 2 for a, b in zip(position, target)))
        cam_data.dof.use_dof = True
        cam_data.dof.focus_distance = float(cam_json.get("focus_distance", default_focus))
        # Cycles: aperture radius = focal length (m) / (2 f-stop); blades 0 = a disk
        cam_data.dof.aperture_fstop = (cam_data.lens * 1e-3) / (2.0 * aperture)
        cam_data.dof.aperture_blades = 0
        cam_data.dof.aperture_ratio = 1.0
    camera = bpy.data.objects.new("camera", cam_data)
    camera.matrix_world = _matrix(look_at([float(x) for x in cam_json["position"]],
                                          [float(x) for x in cam_json["look_at"]],
                                          [float(x) for x in cam_json.get("up", [0, 1, 0])]))
    scene.collection.objects.link(camera)
    scene.camera = camera

    # world
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    radiance = (scene_json.get("environment") or {}).get("radiance", [0, 0, 0])
    background.inputs["Color"].default_value = [*map(float, radiance), 1.0]
    background.inputs["Strength"].default_value = 1.0
    scene.world = world

    # render settings
    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x = int(render.get("width", 256))
    r.resolution_y = int(render.get("height", 256))
    r.resolution_percentage = 100
    r.use_compositing = False
    r.use_sequencer = False
    r.film_transparent = False
    r.use_motion_blur = False
    r.use_persistent_data = False
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_mode = "RGB"
    r.image_settings.color_depth = "32"
    r.image_settings.exr_codec = "ZIP"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    c = scene.cycles
    c.device = "CPU"
    c.feature_set = "SUPPORTED"
    c.samples = int(spp)
    c.seed = int(seed)
    c.use_animated_seed = False
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.light_sampling_threshold = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.time_limit = 0.0
    c.use_fast_gi = False
    if hasattr(c, "direct_light_sampling_type"):
        c.direct_light_sampling_type = "MULTIPLE_IMPORTANCE_SAMPLING"
    for attr in ("use_guiding", "auto_scrambling_distance"):
        if hasattr(c, attr):
            setattr(c, attr, False)
    if hasattr(c, "scrambling_distance"):
        c.scrambling_distance = 1.0
    depth = int(render.get("max_depth", 8))
    bounces = UNLIMITED_BOUNCES if depth < 0 else depth - 2
    c.max_bounces = bounces
    c.diffuse_bounces = bounces
    c.glossy_bounces = bounces
    c.transmission_bounces = bounces
    c.volume_bounces = bounces
    c.transparent_max_bounces = bounces
    c.min_light_bounces = 0
    c.min_transparent_bounces = 0
    world.cycles.sample_as_light = True  # MIS on the environment (unbiased)
    scene.view_layers[0].use_pass_combined = True


def struct_error():
    import struct
    return struct.error


def process_seconds() -> float:
    """Seconds since this process started (/proc: start time in clock ticks after boot)."""
    with open("/proc/self/stat") as f:
        start_ticks = float(f.read().rsplit(")", 1)[1].split()[19])
    with open("/proc/uptime") as f:
        uptime = float(f.read().split()[0])
    return uptime - start_ticks / os.sysconf("SC_CLK_TCK")


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(prog="penumbra_to_cycles.py",
                                 description="Render a penumbra scene with Blender Cycles.")
    ap.add_argument("scene", help="penumbra scene v1 JSON")
    ap.add_argument("-o", "--output", help="output EXR (linear float RGB)")
    ap.add_argument("--spp", type=int, help="samples per pixel (default: the scene's)")
    ap.add_argument("--seed", type=int, help="Cycles seed (default: the scene's render.seed)")
    ap.add_argument("--sphere-mesh", type=int, default=0,
                    help="tessellate spheres as UV spheres of N segments (not exact; default: refuse)")
    ap.add_argument("--rough-glass", action="store_true",
                    help="render rough dielectrics with Cycles' own (different) rough glass model")
    ap.add_argument("--check", action="store_true", help="only say whether the scene translates")
    args = ap.parse_args(argv)
    try:
        with open(args.scene, encoding="utf-8") as f:
            scene_json = json.load(f)
    except (OSError, ValueError) as e:
        print(f"penumbra_to_cycles: {args.scene}: {e}", file=sys.stderr)
        return 2
    try:
        problems = refusals(scene_json, args.sphere_mesh, args.rough_glass)
    except (AttributeError, KeyError, TypeError, ValueError, IndexError) as e:
        # not a valid penumbra scene (penumbra validate names the field); no traceback
        print(f"penumbra_to_cycles: {args.scene}: not a valid scene ({type(e).__name__}: {e})", file=sys.stderr)
        return 2
    for p in problems:
        print(f"penumbra_to_cycles: {args.scene}: refused: {p}", file=sys.stderr)
    if problems:
        return 2
    if args.check:
        print("penumbra_to_cycles: translates")
        return 0
    if not args.output:
        print("penumbra_to_cycles: -o/--output is required", file=sys.stderr)
        return 2
    import bpy

    render = scene_json.get("render", {})
    try:
        build_scene(bpy, scene_json, args.spp or int(render.get("spp", 64)),
                    args.seed if args.seed is not None else int(render.get("seed", 0)), args.sphere_mesh,
                    os.path.dirname(os.path.abspath(args.scene)))
    except (KeyError, TypeError, ValueError, IndexError, OSError, struct_error()) as e:
        print(f"penumbra_to_cycles: {args.scene}: not a valid scene ({type(e).__name__}: {e}); "
              "`penumbra validate` names the field", file=sys.stderr)
        return 2
    bpy.context.scene.render.filepath = os.path.abspath(args.output)
    start = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    seconds = time.perf_counter() - start
    bpy.data.images["Render Result"].save_render(os.path.abspath(args.output))
    print(f"cycles: render {seconds:.4f} s, process {process_seconds():.4f} s", flush=True)
    return 0


def _blender_args() -> list[str]:
    """Arguments after Blender's ``--`` (all of them when run by plain Python)."""
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]


if __name__ == "__main__":
    code = main(_blender_args())
    sys.stdout.flush()
    sys.stderr.flush()
    # Blender keeps running after a --python script unless told otherwise; os._exit ends it
    # with our code (also for refusals) without its shutdown noise.
    os._exit(code)
