"""Unit tests of the plain-Python half of tools/penumbra_to_cycles.py (no Blender needed):

    python3 -m unittest tools/penumbra_to_cycles_test.py

What the Blender half renders is checked against penumbra and Mitsuba by the benchmark
(docs/accuracy.md, "Blender Cycles").
"""
from __future__ import annotations

import json
import math
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import penumbra_to_cycles as p2c  # noqa: E402

SCENES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "accuracy", "scenes")


def load(name: str) -> dict:
    with open(os.path.join(SCENES, name + ".json"), encoding="utf-8") as f:
        return json.load(f)


def pointers(scene: dict, **kw) -> set[str]:
    return {r.pointer for r in p2c.refusals(scene, **kw)}


class Refusals(unittest.TestCase):
    def test_exact_scenes_translate(self):
        self.assertEqual(pointers(load("cornell")), set())
        self.assertEqual(pointers(load("mesh_100k")), set())

    def test_spheres_only_with_a_mesh(self):
        scene = load("conductors")
        self.assertEqual(pointers(scene), {f"/objects/{i}/type" for i in (3, 4, 5, 6)})
        self.assertEqual(pointers(scene, sphere_mesh=64), set())

    def test_rough_glass_only_on_request(self):
        scene = load("glass_rough")
        self.assertEqual(pointers(scene, sphere_mesh=64),
                         {"/materials/frosted/roughness", "/materials/frosted_tint/roughness"})
        self.assertEqual(pointers(scene, sphere_mesh=64, rough_glass=True), set())
        self.assertEqual(pointers(load("glass_smooth"), sphere_mesh=64), set())

    def test_untranslatable_parts_are_named(self):
        self.assertIn("/materials/coat/type", pointers(load("mesh_files")))
        self.assertIn("/materials/floor/color", pointers(load("textured_diffuse")))
        self.assertIn("/environment/map", pointers(load("environment_map"), sphere_mesh=64))
        scene = load("cornell")
        scene["objects"][6]["velocity"] = [0, 1, 0]
        scene["render"]["max_depth"] = 1
        scene["lights"] = [{"type": "spot"}]
        self.assertEqual(pointers(scene), {"/objects/6/velocity", "/render/max_depth", "/lights/0/type"})

    def test_sphere_needs_uniform_scale(self):
        scene = {"version": 1, "camera": {}, "materials": {"m": {"type": "diffuse"}},
                 "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m",
                              "transform": {"scale": [1, 2, 1]}}]}
        self.assertEqual(pointers(scene, sphere_mesh=64), {"/objects/0/transform"})
        scene["objects"][0]["transform"] = {"scale": 2, "rotate": {"axis": [1, 1, 0], "degrees": 30}}
        self.assertEqual(pointers(scene, sphere_mesh=64), set())


class Geometry(unittest.TestCase):
    def test_object_matrix_is_translate_rotate_scale(self):
        m = p2c.object_matrix({"scale": [2, 1, 1], "rotate": {"axis": [0, 1, 0], "degrees": 90},
                               "translate": [0, 0, 5]})
        x = [m[r][0] * 1 + m[r][3] for r in range(3)]  # the point (1, 0, 0)
        for got, want in zip(x, [0, 0, 3]):  # scaled to 2, turned onto -z, moved by +5 z
            self.assertAlmostEqual(got, want, places=12)

    def test_look_at_camera_looks_down_its_minus_z(self):
        m = p2c.look_at([0, 1, 3.6], [0, 1, 0], [0, 1, 0])
        back = [m[r][2] for r in range(3)]
        up = [m[r][1] for r in range(3)]
        self.assertEqual([round(c, 12) for c in back], [0, 0, 1])
        self.assertEqual([round(c, 12) for c in up], [0, 1, 0])

    def test_uv_sphere_faces_outwards_and_hugs_the_sphere(self):
        center, radius, n = [0.5, -1.0, 2.0], 0.7, 32
        positions, polys, normals = p2c.uv_sphere(center, radius, n)
        verts = [positions[k:k + 3] for k in range(0, len(positions), 3)]
        area = 0.0
        for poly in polys:
            pts = [verts[i] for i in poly]
            # Newell's normal: twice the vector area, along the counter-clockwise front
            nx = sum((a[1] - b[1]) * (a[2] + b[2]) for a, b in zip(pts, pts[1:] + pts[:1]))
            ny = sum((a[2] - b[2]) * (a[0] + b[0]) for a, b in zip(pts, pts[1:] + pts[:1]))
            nz = sum((a[0] - b[0]) * (a[1] + b[1]) for a, b in zip(pts, pts[1:] + pts[:1]))
            mid = [sum(p[k] for p in pts) / len(pts) - center[k] for k in range(3)]
            self.assertGreater(nx * mid[0] + ny * mid[1] + nz * mid[2], 0.0)
            area += 0.5 * math.sqrt(nx * nx + ny * ny + nz * nz)
        for v, nrm in zip(verts, [normals[k:k + 3] for k in range(0, len(normals), 3)]):
            for k in range(3):
                self.assertAlmostEqual(v[k], center[k] + radius * nrm[k], places=12)
        # inscribed facets: a little less than the sphere's area, converging as 1/n^2
        self.assertLess(area, 4 * math.pi * radius ** 2)
        self.assertGreater(area, 4 * math.pi * radius ** 2 * (1 - 4 * (math.pi / n) ** 2))


class MeshFiles(unittest.TestCase):
    def test_ply_with_normals(self):
        positions, faces, normals = p2c.read_ply(os.path.join(SCENES, "mesh_files_blob.ply"))
        self.assertEqual((len(positions) // 3, len(faces) // 3, len(normals) // 3), (2562, 5120, 2562))
        self.assertTrue(all(0 <= i < 2562 for i in faces))
        for k in range(0, len(normals), 3):
            self.assertAlmostEqual(math.sqrt(sum(x * x for x in normals[k:k + 3])), 1.0, places=5)

    def test_obj_polygons_fan_triangulated_flat(self):
        positions, faces, normals = p2c.read_obj(os.path.join(SCENES, "mesh_files_prism.obj"))
        # two hexagons (4 triangles each) and six quads (2 each)
        self.assertEqual((len(positions) // 3, len(faces) // 3, normals), (12, 20, None))
        self.assertEqual(faces[:3], [0, 1, 2])

    def test_same_mesh_in_ascii_ply_and_obj_with_normals(self):
        ply = ("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
               "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
               "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
               "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n")
        obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf -4//1 -3//1 -2//1 -1//1\n"
        with tempfile.TemporaryDirectory() as tmp:
            for name, text in (("a.ply", ply), ("a.obj", obj)):
                with open(os.path.join(tmp, name), "w", encoding="utf-8") as f:
                    f.write(text)
            a = p2c.read_ply(os.path.join(tmp, "a.ply"))
            b = p2c.read_obj(os.path.join(tmp, "a.obj"))
        self.assertEqual(a, b)
        self.assertEqual(a[1], [0, 1, 2, 0, 2, 3])

    def test_obj_corners_with_different_normals_are_split(self):
        obj = ("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 1\nvn 0 0 1\nvn 0 1 0\n"
               "f 1//1 2//1 3//1\nf 1//2 3//2 4//2\n")
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "a.obj")
            with open(path, "w", encoding="utf-8") as f:
                f.write(obj)
            positions, faces, normals = p2c.read_obj(path)
        # vertices 1 and 3 carry two normals each: 4 positions become 6 vertices
        self.assertEqual((len(positions) // 3, faces), (6, [0, 1, 2, 3, 4, 5]))
        self.assertEqual(normals[9:12], [0.0, 1.0, 0.0])


if __name__ == "__main__":
    unittest.main()
