#!/usr/bin/env python3
"""Write the accuracy reference scenes (penumbra scene format v1) into this folder.

    python3 tests/accuracy/scenes/make_scenes.py      (numpy; run from anywhere)

The scenes are committed, so neither the accuracy test nor a user needs to run this; re-run it
only to change a scene, then remake the references (tools/make_references.py). Each scene is
small (<= 128 x 128, max_depth <= 8) so that penumbra renders it at 16-64 spp in seconds.
Together they cover every feature of the format and combinations of them:

==================  ==============================================================================
cornell             diffuse Cornell box, ceiling quad light, two box meshes placed by transforms
glass_smooth        smooth glass spheres, one with Beer-Lambert absorption; quad light, environment
glass_rough         rough glass sphere and rotated rough glass cube mesh, both absorbing
furnace             rough glass and rough plastic spheres in a white environment (energy balance)
conductors          smooth and rough (GGX) conductors of constant reflectance; mirror quad
plastics            smooth and rough plastics of several ior; plastic floor
dof                 thin-lens depth of field, 96 x 64 (non-square: checks the vertical fov)
motion_blur         velocity and acceleration on spheres, an emitter and a transformed mesh
all_lights          point + directional + quad + sphere + mesh emitters + environment together
mesh_100k           a 102,400-triangle torus knot with vertex normals, rough conductor
mesh_files          mesh files: a binary PLY blob with vertex normals and uvs (smooth), an OBJ prism
                    of quads and hexagons without normals (flat), both placed by transforms
kitchen_sink        depth of field + motion blur + absorbing rough glass + every light kind
environment_map     glossy and rough-glass spheres under an HDR sky with a small bright sun
                    (sky_sun.hdr, made by tools/make_sky.py), scaled and rotated
textured_diffuse    colour textures: bilinear checker floor (repeat), nearest wood wall (clamp),
                    textured spheres (linear, scaled), a checker-textured emitter
textured_roughness  rough conductors with roughness maps (nearest), textured conductor colour,
                    textured plastic base, rough glass with a roughness map
normal_map          normal maps on a diffuse floor, a rough plastic wall, a conductor and a
                    textured diffuse sphere (quad and sphere tangent frames)
many_lights         a 16 m hall lit by 48 ceiling panels and 16 coloured lamp spheres of different
                    powers, with diffuse, plastic and conductor objects: where each point is lit
                    mostly by the few lights near it (penumbra's light tree; Mitsuba chooses
                    emitters uniformly)
instances           a smooth-shaded, checker-textured lumpy mesh and copies of it placed by an
                    ``instances`` object (rotated, non-uniformly scaled and sheared, mirrored),
                    and a cube copied by a second one; Mitsuba: ``shapegroup`` + ``instance``
==================  ==============================================================================

The textured scenes read the images in ``textures/`` (tools/make_textures.py writes them).
"""
from __future__ import annotations

import json
import math
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
TOOLS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(HERE))), "tools")


# --------------------------------------------------------------------------------------------
# Building blocks
# --------------------------------------------------------------------------------------------

def render(width: int, height: int, max_depth: int = 8, spp: int = 64) -> dict:
    """The ``render`` block; references are path traced."""
    return {"width": width, "height": height, "spp": spp, "max_depth": max_depth,
            "integrator": "path", "seed": 0}


def camera(position, look_at, fov: float, **extra) -> dict:
    """A camera with +y up."""
    return {"position": list(position), "look_at": list(look_at), "up": [0, 1, 0], "fov": fov, **extra}


def quad(origin, u, v, material: str, **extra) -> dict:
    """A parallelogram origin + s*u + t*v; its front (and emission) faces along u x v."""
    return {"type": "quad", "origin": list(origin), "u": list(u), "v": list(v), "material": material, **extra}


def sphere(center, radius: float, material: str, **extra) -> dict:
    """A sphere; emission leaves its outside."""
    return {"type": "sphere", "center": list(center), "radius": radius, "material": material, **extra}


def mesh(positions: np.ndarray, indices: np.ndarray, material: str, normals: np.ndarray | None = None,
         digits: int = 6, **extra) -> dict:
    """An inline triangle mesh; numbers are rounded to ``digits`` decimals to keep files small."""
    obj = {"type": "mesh", "positions": rounded(positions, digits),
           "indices": [int(i) for i in np.asarray(indices).ravel()], "material": material}
    if normals is not None:
        obj["normals"] = rounded(normals, 4)
    obj.update(extra)
    return obj


def rounded(a: np.ndarray, digits: int) -> list:
    """A flat list of floats rounded to ``digits`` decimals (integers where exact)."""
    out = []
    for x in np.round(np.asarray(a, dtype=np.float64).ravel(), digits):
        out.append(int(x) if x == int(x) else float(x))
    return out


def transform(scale=None, axis=None, degrees=None, translate=None) -> dict:
    """A ``transform`` block: scale, then rotate, then translate."""
    t = {}
    if scale is not None:
        t["scale"] = list(scale)
    if axis is not None:
        t["rotate"] = {"axis": list(axis), "degrees": degrees}
    if translate is not None:
        t["translate"] = list(translate)
    return t


def cube_mesh() -> tuple[np.ndarray, np.ndarray]:
    """The unit cube [-0.5, 0.5]^3: 8 shared vertices, 12 triangles wound counter-clockwise
    seen from outside (so the front is the outside)."""
    positions = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, c, d in quads:
        tris += [(a, b, c), (a, c, d)]
    return positions, orient_outward(positions, np.array(tris))


def orient_outward(positions: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Flip triangles of a convex, origin-centred mesh whose normal points inward."""
    out = tris.copy()
    p = positions[tris]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    inward = np.einsum("ij,ij->i", n, p.mean(axis=1)) < 0
    out[inward] = out[inward][:, [0, 2, 1]]
    return out


def vertex_normals(positions: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals of a triangle mesh."""
    p = positions[tris]
    face_n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    n = np.zeros_like(positions)
    for k in range(3):
        np.add.at(n, tris[:, k], face_n)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def torus_knot(segments: int = 400, sides: int = 128, p: int = 2, q: int = 3,
               tube: float = 0.16, bumps: float = 0.12):
    """A closed (p, q) torus-knot tube with a bumpy radius: 2 * segments * sides triangles,
    counter-clockwise seen from outside, with area-weighted vertex normals."""
    phi = np.linspace(0, 2 * math.pi, segments, endpoint=False)

    def curve(t):
        r = 1.0 + 0.45 * np.cos(q * t)
        return np.stack([r * np.cos(p * t), -0.45 * np.sin(q * t), r * np.sin(p * t)], axis=-1)

    c = curve(phi)
    h = 1e-4
    tangent = curve(phi + h) - curve(phi - h)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    binormal = np.cross(tangent, c)
    binormal /= np.linalg.norm(binormal, axis=1, keepdims=True)
    normal = np.cross(binormal, tangent)

    theta = np.linspace(0, 2 * math.pi, sides, endpoint=False)
    radius = tube * (1 + bumps * np.sin(7 * theta)[None, :] * np.sin(5 * phi)[:, None])
    ring = (np.cos(theta)[None, :, None] * normal[:, None, :] + np.sin(theta)[None, :, None] * binormal[:, None, :])
    positions = (c[:, None, :] + radius[:, :, None] * ring).reshape(-1, 3)

    i = np.arange(segments)[:, None]
    j = np.arange(sides)[None, :]
    a = i * sides + j
    b = ((i + 1) % segments) * sides + j
    c2 = ((i + 1) % segments) * sides + (j + 1) % sides
    d = i * sides + (j + 1) % sides
    tris = np.concatenate([np.stack([a, b, c2], -1).reshape(-1, 3), np.stack([a, c2, d], -1).reshape(-1, 3)])
    # Orient outward: the face normal must point away from the curve point of its ring.
    pts = positions[tris]
    fn = np.cross(pts[:, 1] - pts[:, 0], pts[:, 2] - pts[:, 0])
    centre = np.repeat(c, sides, axis=0)[tris[:, 0]]
    if np.mean(np.einsum("ij,ij->i", fn, pts.mean(axis=1) - centre)) < 0:
        tris = tris[:, [0, 2, 1]]
    return positions, tris, vertex_normals(positions, tris)


def cornell_walls(white: str = "white", red: str = "red", green: str = "green") -> list:
    """The five walls of a 2 x 2 x 2 box, open towards +z; all fronts face inside."""
    return [
        quad([-1, 0, -1], [0, 0, 2], [2, 0, 0], white),   # floor, front +y
        quad([-1, 2, -1], [2, 0, 0], [0, 0, 2], white),   # ceiling, front -y
        quad([-1, 0, -1], [2, 0, 0], [0, 2, 0], white),   # back wall, front +z
        quad([-1, 0, -1], [0, 2, 0], [0, 0, 2], red),     # left wall, front +x
        quad([1, 0, -1], [0, 0, 2], [0, 2, 0], green),    # right wall, front -x
    ]


# --------------------------------------------------------------------------------------------
# The scenes
# --------------------------------------------------------------------------------------------

def cornell() -> dict:
    cube_p, cube_i = cube_mesh()
    return {
        "version": 1, "render": render(96, 96),
        "camera": camera([0, 1, 3.6], [0, 1, 0], 40),
        "materials": {"white": {"type": "diffuse", "color": [0.73, 0.73, 0.73]},
                      "red": {"type": "diffuse", "color": [0.63, 0.065, 0.05]},
                      "green": {"type": "diffuse", "color": [0.14, 0.45, 0.091]}},
        "objects": cornell_walls() + [
            quad([-0.25, 1.98, -0.25], [0.5, 0, 0], [0, 0, 0.5], "white", emission=[17, 12, 4]),
            mesh(cube_p, cube_i, "white", transform=transform([0.6, 1.2, 0.6], [0, 1, 0], 20, [-0.35, 0.6, -0.3])),
            mesh(cube_p, cube_i, "white", transform=transform([0.6, 0.6, 0.6], [0, 1, 0], -18, [0.35, 0.3, 0.3])),
        ],
    }


def floor_scene(objects: list, materials: dict, width=64, height=64, max_depth=8, env=0.3,
                cam_pos=(0, 1.2, 4.0), look=(0, 0.5, 0), fov=35, **cam_extra) -> dict:
    """A lit stage: large diffuse floor, back wall, an overhead quad light and a grey sky."""
    materials = {"floor": {"type": "diffuse", "color": [0.6, 0.6, 0.6]},
                 "wall": {"type": "diffuse", "color": [0.35, 0.45, 0.6]}, **materials}
    stage = [
        quad([-4, 0, -4], [0, 0, 8], [8, 0, 0], "floor"),
        quad([-4, 0, -1.5], [8, 0, 0], [0, 4, 0], "wall"),
        quad([-0.6, 2.6, -0.2], [1.2, 0, 0], [0, 0, 0.8], "floor", emission=[6, 6, 6]),
    ]
    return {"version": 1, "render": render(width, height, max_depth),
            "camera": camera(cam_pos, look, fov, **cam_extra),
            "environment": {"radiance": [env, env, env]},
            "materials": materials, "objects": stage + objects}


def glass_smooth() -> dict:
    return floor_scene(
        [sphere([-0.6, 0.5, 0], 0.5, "glass"), sphere([0.6, 0.5, 0.1], 0.5, "tinted")],
        {"glass": {"type": "dielectric", "ior": 1.5, "roughness": 0.0},
         "tinted": {"type": "dielectric", "ior": 1.5, "roughness": 0.0, "absorption": [0.2, 1.0, 2.0]}})


def glass_rough() -> dict:
    cube_p, cube_i = cube_mesh()
    return floor_scene(
        [sphere([-0.6, 0.5, 0], 0.5, "frosted"),
         mesh(cube_p, cube_i, "frosted_tint", transform=transform([0.8, 0.8, 0.8], [1, 2, 0.5], 35, [0.65, 0.55, 0.1]))],
        {"frosted": {"type": "dielectric", "ior": 1.5, "roughness": 0.3, "absorption": [1.5, 0.6, 0.1]},
         "frosted_tint": {"type": "dielectric", "ior": 1.33, "roughness": 0.5, "absorption": [0.1, 0.8, 1.2]}})


def furnace() -> dict:
    return {
        "version": 1, "render": render(64, 64),
        "camera": camera([0, 0, 4], [0, 0, 0], 35),
        "environment": {"radiance": [1, 1, 1]},
        "materials": {"frosted": {"type": "dielectric", "ior": 1.5, "roughness": 0.6},
                      "coat": {"type": "plastic", "color": [0.9, 0.9, 0.9], "ior": 1.5, "roughness": 0.5}},
        "objects": [sphere([-0.55, 0, 0], 0.5, "frosted"), sphere([0.55, 0, 0], 0.5, "coat")],
    }


def conductors() -> dict:
    return floor_scene(
        [sphere([-1.2, 0.4, 0], 0.4, "chrome"), sphere([-0.4, 0.4, 0], 0.4, "gold"),
         sphere([0.4, 0.4, 0], 0.4, "copper"), sphere([1.2, 0.4, 0], 0.4, "steel"),
         quad([-1.6, 0.05, -1.0], [3.2, 0, 0], [0, 1.6, -0.3], "mirror")],
        {"chrome": {"type": "conductor", "color": [0.9, 0.9, 0.9], "roughness": 0.0},
         "gold": {"type": "conductor", "color": [1.0, 0.78, 0.34], "roughness": 0.2},
         "copper": {"type": "conductor", "color": [0.95, 0.64, 0.54], "roughness": 0.45},
         "steel": {"type": "conductor", "color": [0.56, 0.57, 0.58], "roughness": 0.8},
         "mirror": {"type": "conductor", "color": [0.8, 0.85, 0.9], "roughness": 0.1}},
        max_depth=6, cam_pos=(0, 1.1, 5.4), look=(0, 0.5, 0), fov=38)


def plastics() -> dict:
    return floor_scene(
        [sphere([-0.9, 0.4, 0], 0.4, "smooth"), sphere([0.0, 0.4, 0], 0.4, "satin"),
         sphere([0.9, 0.4, 0], 0.4, "matte")],
        {"smooth": {"type": "plastic", "color": [0.1, 0.2, 0.6], "ior": 1.5, "roughness": 0.0},
         "satin": {"type": "plastic", "color": [0.7, 0.15, 0.1], "ior": 1.5, "roughness": 0.3},
         "matte": {"type": "plastic", "color": [0.2, 0.6, 0.2], "ior": 1.33, "roughness": 0.7},
         "floor": {"type": "plastic", "color": [0.6, 0.6, 0.55], "ior": 1.6, "roughness": 0.15}},
        max_depth=6)


def texture(path: str, **options) -> dict:
    """A texture reference (docs/scene-format.md, "Textures"); images live in textures/."""
    return {"texture": f"textures/{path}", **options}


def textured_diffuse() -> dict:
    scene = floor_scene(
        [sphere([-0.7, 0.45, 0.2], 0.45, "wood"), sphere([0.65, 0.4, 0.3], 0.4, "tiles"),
         quad([0.9, 0.2, -1.45], [1.2, 0, 0], [0, 1.2, 0], "black", emission=texture("checker.png", scale=3))],
        {"floor": {"type": "diffuse", "color": texture("checker.png")},
         "wall": {"type": "diffuse", "color": texture("wood.png", wrap="clamp", filter="nearest")},
         "wood": {"type": "diffuse", "color": texture("wood.png")},
         "tiles": {"type": "diffuse",
                   "color": texture("checker.png", colorspace="linear", scale=[0.9, 0.8, 0.6])},
         "black": {"type": "diffuse", "color": [0, 0, 0]}},
        width=80, height=80, max_depth=6)
    return scene


def textured_roughness() -> dict:
    return floor_scene(
        [sphere([-1.2, 0.4, 0], 0.4, "brushed"), sphere([-0.4, 0.4, 0], 0.4, "inlay"),
         sphere([0.4, 0.4, 0], 0.4, "tiles"), sphere([1.2, 0.4, 0], 0.4, "frosted")],
        {"floor": {"type": "conductor", "color": [0.8, 0.8, 0.8],
                   "roughness": texture("rough.png", filter="nearest")},
         "brushed": {"type": "conductor", "color": [0.95, 0.64, 0.54],
                     "roughness": texture("rough.png", channel=0, scale=0.8, filter="nearest")},
         "inlay": {"type": "conductor", "color": texture("wood.png"), "roughness": 0.3},
         "tiles": {"type": "plastic", "color": texture("checker.png"), "ior": 1.5, "roughness": 0.25},
         "frosted": {"type": "dielectric", "ior": 1.5,
                     "roughness": texture("rough.png", filter="nearest", wrap="clamp")}},
        width=80, height=80, max_depth=6, cam_pos=(0, 1.1, 5.4), look=(0, 0.5, 0), fov=38)


def normal_map() -> dict:
    return floor_scene(
        [sphere([-0.7, 0.45, 0.2], 0.45, "bumpy_metal"), sphere([0.65, 0.4, 0.3], 0.4, "bumpy_wood")],
        {"floor": {"type": "diffuse", "color": [0.6, 0.6, 0.6], "normal_map": "textures/normal.png"},
         "wall": {"type": "plastic", "color": [0.35, 0.45, 0.6], "ior": 1.5, "roughness": 0.2,
                  "normal_map": texture("normal.png", wrap="clamp")},
         "bumpy_metal": {"type": "conductor", "color": [0.9, 0.9, 0.9], "roughness": 0.25,
                         "normal_map": "textures/normal.png"},
         "bumpy_wood": {"type": "diffuse", "color": texture("wood.png"),
                        "normal_map": texture("normal.png", filter="nearest")}},
        width=80, height=80, max_depth=6)


def dof() -> dict:
    spheres = [sphere([-1.2 + 0.6 * k, 0.3, 1.2 - 0.7 * k], 0.3, ["a", "b", "c"][k % 3]) for k in range(5)]
    return floor_scene(
        spheres,
        {"a": {"type": "diffuse", "color": [0.8, 0.3, 0.2]},
         "b": {"type": "plastic", "color": [0.2, 0.4, 0.8], "ior": 1.5, "roughness": 0.2},
         "c": {"type": "conductor", "color": [0.9, 0.8, 0.5], "roughness": 0.25}},
        width=96, height=64, max_depth=6, cam_pos=(0, 1.0, 4.5), look=(0, 0.4, 0), fov=30,
        aperture_radius=0.12, focus_distance=4.0)


def motion_blur() -> dict:
    cube_p, cube_i = cube_mesh()
    return floor_scene(
        [sphere([-1.1, 0.35, 0.2], 0.35, "red", velocity=[0.6, 0, 0]),
         sphere([0.0, 1.1, 0.0], 0.3, "blue", velocity=[0.3, 0.4, 0], acceleration=[0, -2.0, 0]),
         sphere([1.0, 1.4, -0.5], 0.15, "lamp", emission=[8, 6, 3], velocity=[0, -0.5, 0], acceleration=[0.4, 0, 0]),
         mesh(cube_p, cube_i, "gold", transform=transform([0.5, 0.5, 0.5], [0, 1, 0], 30, [0.9, 0.25, 0.4]),
              velocity=[-0.3, 0, 0.3], acceleration=[0, 0.5, 0])],
        {"red": {"type": "diffuse", "color": [0.8, 0.2, 0.15]},
         "blue": {"type": "plastic", "color": [0.1, 0.2, 0.7], "ior": 1.5, "roughness": 0.1},
         "lamp": {"type": "diffuse", "color": [0.5, 0.5, 0.5]},
         "gold": {"type": "conductor", "color": [1.0, 0.78, 0.34], "roughness": 0.3}},
        max_depth=6, shutter=[0, 1])


def all_lights() -> dict:
    tri = np.array([[-0.3, 1.8, -1.2], [0.3, 1.8, -1.2], [0.0, 2.2, -1.2]])  # faces +z (towards camera)
    scene = floor_scene(
        [sphere([-0.7, 0.4, 0], 0.4, "white"), sphere([0.7, 0.4, 0], 0.4, "coat"),
         sphere([0.0, 1.2, -0.4], 0.12, "white", emission=[10, 10, 6]),
         mesh(tri, [0, 1, 2], "white", emission=[2, 4, 8])],
        {"white": {"type": "diffuse", "color": [0.8, 0.8, 0.8]},
         "coat": {"type": "plastic", "color": [0.6, 0.5, 0.1], "ior": 1.5, "roughness": 0.25}},
        env=0.15, max_depth=5)
    scene["objects"][2]["emission"] = [3, 3, 3]  # dimmer overhead quad: the other lights show
    scene["lights"] = [
        {"type": "point", "position": [1.2, 1.6, 1.0], "intensity": [4, 2, 1]},
        {"type": "directional", "direction": [-0.5, -1.0, -0.3], "irradiance": [0.6, 0.8, 1.2]},
    ]
    return scene


def mesh_100k() -> dict:
    positions, tris, normals = torus_knot()
    assert len(tris) >= 100_000
    return floor_scene(
        [mesh(positions, tris, "gold", normals=normals, digits=5,
              transform=transform([0.55, 0.55, 0.55], [1, 0, 0], 15, [0, 0.72, 0]))],
        {"gold": {"type": "conductor", "color": [1.0, 0.78, 0.34], "roughness": 0.35}},
        width=96, height=96, max_depth=6, cam_pos=(0, 1.6, 3.6), look=(0, 0.6, 0), fov=35)


def icosphere(subdivisions: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit sphere from a subdivided icosahedron: (positions, triangles), counter-clockwise seen
    from outside."""
    t = (1 + math.sqrt(5)) / 2
    p = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    positions = [np.array(v, dtype=np.float64) / np.linalg.norm(v) for v in p]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
            (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
            (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        midpoint: dict[tuple[int, int], int] = {}

        def mid(a: int, b: int) -> int:
            key = (min(a, b), max(a, b))
            if key not in midpoint:
                m = positions[a] + positions[b]
                positions.append(m / np.linalg.norm(m))
                midpoint[key] = len(positions) - 1
            return midpoint[key]

        tris = [t2 for a, b, c in tris
                for t2 in ((a, mid(a, b), mid(c, a)), (b, mid(b, c), mid(a, b)), (c, mid(c, a), mid(b, c)),
                           (mid(a, b), mid(b, c), mid(c, a)))]
    return np.array(positions), orient_outward(np.array(positions), np.array(tris))


def write_ply_binary(path: str, positions, normals, uvs, tris) -> None:
    """A binary little-endian PLY: float x, y, z, nx, ny, nz, u, v per vertex; triangles."""
    vertex = np.zeros(len(positions), dtype=[(n, "<f4") for n in ("x", "y", "z", "nx", "ny", "nz", "u", "v")])
    for k, n in enumerate(("x", "y", "z")):
        vertex[n] = positions[:, k]
        vertex["n" + n] = normals[:, k]
    vertex["u"], vertex["v"] = uvs[:, 0], uvs[:, 1]
    face = np.zeros(len(tris), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    face["n"], face["i"] = 3, tris
    header = (f"ply\nformat binary_little_endian 1.0\ncomment tests/accuracy/scenes/make_scenes.py\n"
              f"element vertex {len(positions)}\n" +
              "".join(f"property float {n}\n" for n in ("x", "y", "z", "nx", "ny", "nz", "u", "v")) +
              f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(vertex.tobytes())
        f.write(face.tobytes())


def blob_mesh():
    """A smooth lumpy sphere, 5120 triangles, with area-weighted vertex normals and spherical uvs."""
    unit, tris = icosphere(4)
    x, y, z = unit[:, 0], unit[:, 1], unit[:, 2]
    radius = 1 + 0.12 * np.sin(3 * x + 1) * np.cos(2 * y) + 0.08 * np.sin(4 * z)
    positions = unit * radius[:, None]
    uvs = np.stack([np.arctan2(z, x) / (2 * math.pi) + 0.5, np.arccos(np.clip(y, -1, 1)) / math.pi], axis=1)
    return positions, tris, vertex_normals(positions, tris), uvs


def prism_obj() -> str:
    """A hexagonal prism as OBJ text: two hexagons and six quads, counter-clockwise seen from
    outside, no normals (shaded flat)."""
    ring = [(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)]
    lines = ["# tests/accuracy/scenes/make_scenes.py: hexagonal prism, polygons, no normals"]
    lines += [f"v {c:.6f} {-0.5:.6f} {s_:.6f}" for c, s_ in ring] + [f"v {c:.6f} {0.5:.6f} {s_:.6f}" for c, s_ in ring]
    lines.append("f " + " ".join(str(k + 1) for k in range(6)))            # bottom, seen from below
    lines.append("f " + " ".join(str(12 - k) for k in range(6)))           # top, seen from above
    for k in range(6):
        a, b = k + 1, (k + 1) % 6 + 1
        lines.append(f"f {a} {a + 6} {b + 6} {b}")
    return "\n".join(lines) + "\n"


def mesh_files() -> dict:
    positions, tris, normals, uvs = blob_mesh()
    write_ply_binary(os.path.join(HERE, "mesh_files_blob.ply"), positions, normals, uvs, tris)
    with open(os.path.join(HERE, "mesh_files_prism.obj"), "w", encoding="utf-8") as f:
        f.write(prism_obj())
    return floor_scene(
        [{"type": "mesh", "file": "mesh_files_blob.ply", "material": "coat",
          "transform": transform([0.45, 0.45, 0.45], [0, 1, 0], 25, [-0.55, 0.56, 0])},
         {"type": "mesh", "file": "mesh_files_prism.obj", "material": "metal",
          "transform": transform([0.32, 0.5, 0.32], [1, 0, 1], 20, [0.6, 0.4, 0.15])}],
        {"coat": {"type": "plastic", "color": [0.7, 0.25, 0.1], "ior": 1.5, "roughness": 0.3},
         "metal": {"type": "conductor", "color": [0.9, 0.8, 0.55], "roughness": 0.25}},
        width=96, height=72, max_depth=6, cam_pos=(0, 1.2, 3.6), look=(0, 0.45, 0), fov=35)


def kitchen_sink() -> dict:
    cube_p, cube_i = cube_mesh()
    scene = floor_scene(
        [sphere([-0.9, 0.45, 0.6], 0.45, "frosted", velocity=[0.3, 0, 0], acceleration=[0, 0.4, 0]),
         sphere([0.2, 0.4, -0.3], 0.4, "coat"),
         mesh(cube_p, cube_i, "brushed", transform=transform([0.6, 0.6, 0.6], [0, 1, 0], 40, [1.1, 0.3, 0.2]),
              velocity=[0, 0.3, 0]),
         sphere([0.9, 1.5, -0.8], 0.1, "coat", emission=[20, 14, 8], velocity=[-0.4, 0, 0])],
        {"frosted": {"type": "dielectric", "ior": 1.45, "roughness": 0.2, "absorption": [0.2, 0.9, 1.6]},
         "coat": {"type": "plastic", "color": [0.15, 0.5, 0.3], "ior": 1.5, "roughness": 0.1},
         "brushed": {"type": "conductor", "color": [0.9, 0.9, 0.95], "roughness": 0.3}},
        width=80, height=60, max_depth=8, env=0.2, cam_pos=(0.3, 1.1, 4.2), look=(0, 0.45, 0), fov=32,
        aperture_radius=0.06, focus_distance=3.9, shutter=[0, 1])
    scene["lights"] = [
        {"type": "point", "position": [-1.5, 2.0, 1.5], "intensity": [3, 3, 3]},
        {"type": "directional", "direction": [0.4, -1.0, -0.6], "irradiance": [0.5, 0.45, 0.4]},
    ]
    return scene


def environment_map() -> dict:
    """Glossy (rough gold, rough plastic) and glass (nearly clear and frosted) spheres on a
    diffuse floor under sky_sun.hdr: a small sun (1.5 degrees, ~10^4 times the sky) that delivers
    most of the light. The map is rotated (the sun behind the camera's left shoulder) and scaled,
    so both fields reach the reference through the converter.

    The glass is rough (0.1 and 0.3), not smooth: the floor in a smooth sphere's shadow and
    caustic is lit by the sun only through paths that hit it by BSDF sampling alone, in both
    renderers, and that heavy-tailed estimate is beyond what the z-test can judge at 256 spp.
    Rough interfaces get next-event estimation, and smooth glass under a map is covered by the
    renderer's tests."""
    import sys
    sys.path.insert(0, TOOLS)
    import make_sky  # noqa: E402  (tools/make_sky.py, standard library only)
    make_sky.write_hdr(os.path.join(HERE, "sky_sun.hdr"), make_sky.make_sky(512, 256, 35.0, 150.0, 1.5, 12.0))
    return {
        "version": 1, "render": render(64, 64),
        "camera": camera([0, 1.1, 5.0], [0, 0.4, 0], 38),
        "environment": {"map": "sky_sun.hdr", "scale": 0.25, "rotate": {"axis": [0, 1, 0], "degrees": -50}},
        "materials": {"floor": {"type": "diffuse", "color": [0.5, 0.5, 0.5]},
                      "glass": {"type": "dielectric", "ior": 1.5, "roughness": 0.1},
                      "frosted": {"type": "dielectric", "ior": 1.5, "roughness": 0.3},
                      "gold": {"type": "conductor", "color": [1.0, 0.78, 0.34], "roughness": 0.25},
                      "coat": {"type": "plastic", "color": [0.1, 0.25, 0.6], "ior": 1.5, "roughness": 0.15}},
        "objects": [quad([-4, 0, -4], [0, 0, 8], [8, 0, 0], "floor"),
                    sphere([-1.2, 0.4, 0], 0.4, "glass"), sphere([-0.4, 0.4, 0], 0.4, "gold"),
                    sphere([0.4, 0.4, 0], 0.4, "frosted"), sphere([1.2, 0.4, 0], 0.4, "coat")],
    }


def instances() -> dict:
    """Copies of two meshes by ``instances`` objects. The blob has vertex normals, so the copies'
    shading normals (inverse transpose under shear and non-uniform scale) reach the image, and a
    checker texture on its uvs, so the copies' uvs do; one copy is mirrored (negative determinant: its front side turns inside out, which opaque,
    two-sided materials do not see, so Mitsuba's instance, which keeps it, agrees)."""
    unit, tris = icosphere(3)
    x, y, z = unit[:, 0], unit[:, 1], unit[:, 2]
    positions = unit * (1 + 0.15 * np.sin(3 * x + 1) * np.cos(2 * y) + 0.1 * np.sin(4 * z))[:, None]
    # Spherical uvs, so the checker texture shows that copies keep the mesh's uv.
    uvs = np.stack([np.arctan2(z, x) / (2 * math.pi) + 0.5, np.arccos(np.clip(y, -1, 1)) / math.pi], axis=1)
    cube_p, cube_i = cube_mesh()
    shear = [[1.1, 0.5, 0, -1.31], [0, 0.8, 0, 0.044], [0, 0, 0.9, 0.125], [0, 0, 0, 1]]
    mirror = [[-0.9, 0, 0, 1.2], [0, 0.9, 0, 0.03], [0, 0, 0.9, 0.1], [0, 0, 0, 1]]
    return floor_scene(
        [mesh(positions, tris, "coat", normals=vertex_normals(positions, tris), digits=5,
              transform=transform([0.3, 0.3, 0.3], [0, 1, 0], 30, [0, 0.32, 0.25]), uvs=rounded(uvs, 5)),
         {"type": "instances", "mesh": 3, "transforms": [
             {"translate": [-0.6, 0.0, -0.55]},
             {"rotate": {"axis": [1, 1, 0], "degrees": 50}, "translate": [0.457, 0.293, -0.684]},
             {"matrix": [v for row in shear for v in row]},
             {"matrix": [v for row in mirror for v in row]}]},
         mesh(cube_p, cube_i, "metal", transform=transform([0.25, 0.25, 0.25], [0, 1, 0], 20, [-0.3, 0.125, 0.9])),
         {"type": "instances", "mesh": 5, "transforms": [
             {"rotate": {"axis": [0, 1, 0], "degrees": 25}, "translate": [0.14, 0, -0.02]},
             {"scale": [1, 2.2, 1], "translate": [1.05, 0, -0.1]}]}],
        {"coat": {"type": "plastic", "color": texture("checker.png", scale=[0.9, 0.45, 0.2]), "ior": 1.5,
                  "roughness": 0.3},
         "metal": {"type": "conductor", "color": [0.85, 0.85, 0.9], "roughness": 0.3}},
        width=96, height=72, max_depth=6, cam_pos=(0, 1.3, 3.8), look=(0, 0.45, 0), fov=38)


def many_lights() -> dict:
    """A hall 4 m wide, 3 m high and 16 m deep along -z: 2 x 24 small ceiling panels 5 cm below
    the ceiling (clear of it by far more than Mitsuba's ray offset), 16 lamp spheres along the
    walls in four colours and three powers, a few objects on the floor."""
    objects = [
        quad([-2, 0, 1], [0, 0, -16], [4, 0, 0], "floor"),     # floor, front +y
        quad([-2, 3, 1], [4, 0, 0], [0, 0, -16], "white"),     # ceiling, front -y
        quad([-2, 0, -15], [4, 0, 0], [0, 3, 0], "white"),     # end wall, front +z
        quad([-2, 0, 1], [0, 3, 0], [0, 0, -16], "red"),       # left wall, front +x
        quad([2, 0, 1], [0, 0, -16], [0, 3, 0], "blue"),       # right wall, front -x
    ]
    for row in range(24):
        z = 0.5 - 0.65 * row
        for x in (-1.0, 0.7):
            # front -y: u x v = (0, 0, 0.12) x (0.3, 0, 0) points down
            objects.append(quad([x, 2.95, z - 0.12], [0, 0, 0.12], [0.3, 0, 0], "white", emission=[30, 28, 24]))
    colours = [[40, 12, 4], [6, 30, 10], [8, 14, 44], [30, 30, 30]]
    for k in range(16):
        z = 0.2 - 0.95 * k
        x = -1.75 if k % 2 == 0 else 1.75
        scale = (0.5, 1.0, 2.0)[k % 3]
        objects.append(sphere([x, 1.4, z], 0.06, "white", emission=[c * scale for c in colours[k % 4]]))
    objects += [
        sphere([-0.6, 0.5, -2.0], 0.5, "coat"),
        sphere([0.7, 0.4, -4.5], 0.4, "gold"),
        sphere([-0.5, 0.6, -8.0], 0.6, "white"),
        sphere([0.6, 0.35, -11.0], 0.35, "coat"),
    ]
    return {"version": 1, "render": render(128, 96, max_depth=6),
            "camera": camera([0, 1.5, 0.8], [0, 1.1, -8], 55),
            "materials": {"white": {"type": "diffuse", "color": [0.75, 0.75, 0.75]},
                          "floor": {"type": "diffuse", "color": [0.5, 0.45, 0.4]},
                          "red": {"type": "diffuse", "color": [0.6, 0.15, 0.1]},
                          "blue": {"type": "diffuse", "color": [0.15, 0.25, 0.6]},
                          "coat": {"type": "plastic", "color": [0.1, 0.5, 0.2], "ior": 1.5, "roughness": 0.2},
                          "gold": {"type": "conductor", "color": [1.0, 0.78, 0.34], "roughness": 0.25}},
            "objects": objects}


SCENES = {f.__name__: f for f in (cornell, glass_smooth, glass_rough, furnace, conductors, plastics,
                                  dof, motion_blur, all_lights, mesh_100k, mesh_files, kitchen_sink,
                                  environment_map, textured_diffuse, textured_roughness, normal_map,
                                  instances, many_lights)}


def write(name: str, scene: dict) -> str:
    """Write one scene; big meshes keep their arrays on one line."""
    path = os.path.join(HERE, f"{name}.json")
    with open(path, "w", encoding="utf-8") as f:
        if name == "mesh_100k":
            json.dump(scene, f, separators=(",", ":"))
        else:
            json.dump(scene, f, indent=1)
        f.write("\n")
    return path


def main() -> None:
    import sys
    names = sys.argv[1:] or list(SCENES)  # e.g. ``make_scenes.py instances``: only that one
    for name in names:
        make = SCENES[name]
        path = write(name, make())
        print(f"{path}: {os.path.getsize(path) / 1e3:.0f} kB")


if __name__ == "__main__":
    main()
