"""The Python client against a real `penumbra serve` ($PENUMBRA_BINARY), started per test class
on an ephemeral port with a token and its own data directory. Standard library unittest; the EXR
array tests need numpy and are skipped without it."""
from __future__ import annotations

import io
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import zlib
from contextlib import redirect_stderr

import penumbra
from penumbra.__main__ import main as cli_main

BINARY = os.environ.get("PENUMBRA_BINARY", "penumbra")
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
TOKEN = "client-test-token"

try:
    import numpy as np
except ImportError:  # pragma: no cover - the CI venv has numpy
    np = None


def sky_scene(width=8, height=6, spp=4, radiance=(0.25, 0.5, 0.75)):
    """A camera that sees only a uniform environment: every pixel is exactly `radiance`."""
    return {"version": 1, "render": {"width": width, "height": height, "spp": spp, "seed": 3},
            "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30},
            "environment": {"radiance": list(radiance)}, "materials": {}, "objects": []}


def slow_scene():
    scene = sky_scene(256, 256, 4096)
    scene["materials"] = {"m": {"type": "diffuse", "color": [0.5, 0.5, 0.5]}}
    scene["objects"] = [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]
    return scene


def ply_bytes():
    """A binary PLY of one triangle facing +z, with uvs."""
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
              "property float y\nproperty float z\nproperty float u\nproperty float v\n"
              "element face 1\nproperty list uchar int vertex_indices\nend_header\n").encode()
    verts = [(-1, -1, 0, 0, 1), (1, -1, 0, 1, 1), (0, 1, 0, 0.5, 0)]
    body = b"".join(struct.pack("<5f", *v) for v in verts) + struct.pack("<B3i", 3, 0, 1, 2)
    return header + body


def png_bytes(rgb=(200, 100, 50)):
    """A 2x2 RGB PNG, written with zlib (no imaging library needed)."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = b"".join(b"\0" + bytes(rgb) * 2 for _ in range(2))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


class Server:
    def __init__(self, extra=()):
        self.dir = tempfile.mkdtemp(prefix="penumbra-client-test-")
        self.proc = subprocess.Popen(
            [BINARY, "serve", "--port", "0", "--data-dir", os.path.join(self.dir, "data"),
             "--token", TOKEN, *extra],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        line = self.proc.stdout.readline()
        match = re.search(r"listening on (http://\S+)", line)
        if not match:
            self.stop()
            raise RuntimeError(f"penumbra serve did not start: {line!r}")
        self.url = match.group(1)
        threading.Thread(target=self.proc.stdout.read, daemon=True).start()

    def stop(self):
        self.proc.terminate()
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        shutil.rmtree(self.dir, ignore_errors=True)


class ServerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server = Server()
        cls.client = penumbra.Client(cls.server.url, token=TOKEN, timeout=30)

    @classmethod
    def tearDownClass(cls):
        cls.server.stop()


class JobsTest(ServerTest):
    def test_submit_wait_result_png_and_bytes(self):
        job = self.client.submit(sky_scene())
        self.assertIn(job["state"], ("queued", "running", "succeeded"))
        final = self.client.wait(job, progress=False, timeout=60)
        self.assertEqual(final["state"], "succeeded")
        png = self.client.result(job, format="png")
        self.assertEqual(png[:8], b"\x89PNG\r\n\x1a\n")
        exr = self.client.result(job, format="exr", as_array=False)
        self.assertEqual(exr[:4], b"\x76\x2f\x31\x01")

    @unittest.skipIf(np is None, "numpy is not installed")
    def test_exr_result_is_the_exact_radiance_as_an_array(self):
        image = self.client.render(sky_scene(radiance=(0.25, 0.5, 0.75)), progress=False)
        self.assertEqual(image.shape, (6, 8, 3))
        self.assertEqual(image.dtype, np.float32)
        np.testing.assert_allclose(image[..., 0], 0.25, rtol=1e-6)
        np.testing.assert_allclose(image[..., 1], 0.5, rtol=1e-6)
        np.testing.assert_allclose(image[..., 2], 0.75, rtol=1e-6)

    @unittest.skipIf(np is None, "numpy is not installed")
    def test_exr_reader_decodes_a_varied_image_like_the_server_png(self):
        # A lit sphere: many distinct values across ZIP's 16-line blocks; against the PNG of the
        # same job (8-bit sRGB of the clamped values) to within the PNG's rounding.
        scene = sky_scene(40, 37, 8)  # 37 lines: a last, partial 16-line block
        scene["materials"] = {"m": {"type": "diffuse", "color": [0.8, 0.3, 0.1]}}
        scene["objects"] = [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]
        # Under the sky alone the sphere is flat (the path integrator's cosine samples of a
        # constant environment carry no noise); a point light shades it.
        scene["lights"] = [{"type": "point", "position": [2, 3, 3], "intensity": [6, 6, 6]}]
        job = self.client.submit(scene)
        self.client.wait(job, progress=False)
        linear = self.client.result(job)
        png = self.client.result(job, format="png")
        srgb = decode_png_rgb(png).astype(np.float64) / 255.0
        c = np.clip(linear.astype(np.float64), 0, 1)
        encoded = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
        self.assertEqual(encoded.shape, srgb.shape)
        self.assertGreater(len(np.unique(linear)), 100)
        self.assertLess(np.max(np.abs(encoded - srgb)), 1.01 / 255 + 1e-9)

    def test_invalid_scene_raises_with_field_pointers(self):
        scene = sky_scene()
        scene["render"]["width"] = -4
        with self.assertRaises(penumbra.InvalidRequest) as caught:
            self.client.submit(scene)
        self.assertEqual(caught.exception.status, 422)
        self.assertIn("/render/width", [e.pointer for e in caught.exception.errors])
        self.assertIn("/render/width", str(caught.exception))

    def test_wrong_token_and_unknown_job(self):
        with self.assertRaises(penumbra.Unauthorized):
            penumbra.Client(self.server.url, token="wrong").job("0" * 24)
        with self.assertRaises(penumbra.NotFound):
            self.client.job("0" * 24)
        with self.assertRaises(penumbra.NotFound):
            self.client.wait("0" * 24, progress=False, timeout=10)

    def test_cancel_and_list(self):
        job = self.client.submit(slow_scene())
        ids = [j["id"] for j in self.client.list(limit=1)]  # one per page: paging followed
        self.assertIn(job["id"], ids)
        self.client.cancel(job)
        with self.assertRaises(penumbra.JobFailed) as caught:
            self.client.wait(job, progress=False, timeout=60)
        self.assertEqual(caught.exception.job["state"], "cancelled")
        record = self.client.wait(job, progress=False, check=False)
        self.assertEqual(record["state"], "cancelled")

    def test_preview_of_a_running_job(self):
        job = self.client.submit(slow_scene())
        try:
            deadline = time.monotonic() + 60
            while True:
                try:
                    png = self.client.result(job, format="png", preview=True)
                    break
                except penumbra.ProblemError as e:  # 409 until the first pass is done
                    self.assertEqual(e.status, 409)
                    self.assertLess(time.monotonic(), deadline, "no preview in 60 s")
                    time.sleep(0.1)
            self.assertTrue(png.startswith(b"\x89PNG"))
            self.assertEqual(self.client.job(job)["state"], "running")  # a preview, not the result
        finally:
            self.client.cancel(job)

    def test_animation_frames_one_by_one_and_as_files(self):
        """An animation job: result(frame=N) per frame, download_frames extracts the archive,
        each file byte for byte the frame's result; bad frames raise naming the parameter."""
        scene = sky_scene(6, 4, 2)
        scene["materials"] = {"m": {"type": "diffuse", "color": [0.5, 0.5, 0.5]}}
        scene["objects"] = [{"type": "sphere", "center": [-1, 0, 0], "radius": 0.5,
                             "material": "m", "velocity": [6, 0, 0]}]
        scene["animation"] = {"frames": [2, 5], "fps": 24, "shutter": 0.5}
        job = self.client.submit(scene)
        final = self.client.wait(job, progress=False, timeout=60)
        self.assertEqual(final["frames"], {"first": 2, "last": 5, "done": 4})
        frames = {f: self.client.result(job, format="exr", frame=f, as_array=False)
                  for f in range(2, 6)}
        self.assertEqual(len(set(frames.values())), 4, "the sphere moves: every frame differs")
        with tempfile.TemporaryDirectory() as out:
            paths = self.client.download_frames(job, os.path.join(out, "frames"))
            self.assertEqual([os.path.basename(p) for p in paths],
                             [f"frame_000{f}.exr" for f in range(2, 6)])
            for f, path in zip(range(2, 6), paths):
                with open(path, "rb") as fh:
                    self.assertEqual(fh.read(), frames[f], f"frame {f}")
            pngs = self.client.download_frames(job, os.path.join(out, "png"), format="png")
            self.assertEqual(len(pngs), 4)
            for f, path in zip(range(2, 6), pngs):
                with open(path, "rb") as fh:
                    self.assertEqual(fh.read(), self.client.result(job, format="png", frame=f))
            buf = io.BytesIO()
            size = self.client.frames_archive(job, buf)
            self.assertEqual(size, len(buf.getvalue()))
            self.assertEqual(size % 512, 0)
        for bad, status in ((1, 404), (6, 404)):
            with self.assertRaises(penumbra.ProblemError) as caught:
                self.client.result(job, frame=bad)
            self.assertEqual(caught.exception.status, status)
            self.assertEqual(caught.exception.problem["errors"][0]["parameter"], "frame")
        still = self.client.submit(sky_scene())
        self.client.wait(still, progress=False, timeout=60)
        with self.assertRaises(penumbra.ProblemError) as caught:
            self.client.result(still, frame=1)
        self.assertEqual(caught.exception.status, 422)
        with self.assertRaises(penumbra.ProblemError) as caught:
            self.client.download_frames(still, tempfile.gettempdir())
        self.assertEqual(caught.exception.status, 404)

    def test_progress_callback_sees_the_final_state(self):
        seen = []
        self.client.wait(self.client.submit(sky_scene()), progress=seen.append)
        self.assertTrue(seen)
        self.assertEqual(seen[-1]["state"], "succeeded")

    def test_unreachable_server(self):
        with self.assertRaises(penumbra.ConnectionFailed):
            penumbra.Client("http://127.0.0.1:9", timeout=2).job("0" * 24)

    def test_command_line_renders_to_a_file(self):
        folder = tempfile.mkdtemp()
        try:
            path = os.path.join(folder, "scene.json")
            with open(path, "w") as f:
                json.dump(sky_scene(), f)
            out = os.path.join(folder, "out.png")
            with redirect_stderr(io.StringIO()):
                code = cli_main(["--url", self.server.url, "--token", TOKEN, "render", path,
                                 "-o", out])
            self.assertEqual(code, 0)
            with open(out, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        finally:
            shutil.rmtree(folder)


class JobOptionsTest(ServerTest):
    """Priorities (higher first), a .glb sent as it is, and a denoised result's noisy layer."""

    def test_priority_orders_the_queue(self):
        blocker = self.client.submit(slow_scene())
        low = self.client.submit(sky_scene(), priority=-5)
        high = self.client.submit(sky_scene(), priority=7)
        queued = [j["id"] for j in self.client.list(state="queued")]
        self.assertLess(queued.index(high["id"]), queued.index(low["id"]), queued)
        self.assertEqual(self.client.job(high)["priority"], 7)
        self.client.cancel(blocker)
        for job in (low, high):
            self.assertEqual(self.client.wait(job, progress=False)["state"], "succeeded")

    def test_glb_is_rendered_with_query_parameters(self):
        glb = os.path.join(REPO, "scenes", "gltf_showcase.glb")
        job = self.client.submit(glb, params={"width": 32, "height": 18, "spp": 2}, priority=1)
        record = self.client.wait(job, progress=False)
        self.assertEqual(record["render"], {"width": 32, "height": 18, "spp": 2})
        self.assertEqual(record["priority"], 1)
        self.assertEqual(self.client.result(job, format="png")[:8], b"\x89PNG\r\n\x1a\n")


class AssetsTest(ServerTest):
    """Scenes that name files: the client finds them, uploads only what the server lacks."""

    def write_scene(self, folder):
        os.makedirs(os.path.join(folder, "tex"), exist_ok=True)
        with open(os.path.join(folder, "tri.ply"), "wb") as f:
            f.write(ply_bytes())
        with open(os.path.join(folder, "tex", "wood.png"), "wb") as f:
            f.write(png_bytes())
        scene = sky_scene(16, 12, 2)
        scene["materials"] = {"wood": {"type": "diffuse", "color": {"texture": "tex/wood.png"}}}
        scene["objects"] = [{"type": "mesh", "file": "tri.ply", "material": "wood"}]
        path = os.path.join(folder, "scene.json")
        with open(path, "w") as f:
            json.dump(scene, f)
        return path

    def test_scene_files_are_found_with_gltf_buffers(self):
        folder = tempfile.mkdtemp()
        try:
            self.write_scene(folder)
            os.makedirs(os.path.join(folder, "m"))
            with open(os.path.join(folder, "m", "a.gltf"), "w") as f:
                json.dump({"asset": {"version": "2.0"},
                           "buffers": [{"uri": "a%20b.bin", "byteLength": 1},
                                       {"uri": "data:application/octet-stream;base64,AA==",
                                        "byteLength": 1}]}, f)
            with open(os.path.join(folder, "m", "a b.bin"), "wb") as f:
                f.write(b"\0")
            scene = {"objects": [{"type": "gltf", "file": "m/a.gltf"},
                                 {"type": "mesh", "file": "tri.ply"}],
                     "materials": {"x": {"color": {"texture": "tex/wood.png"}}}}
            files = penumbra.scene_files(scene, folder)
            self.assertEqual(sorted(files), ["m/a b.bin", "m/a.gltf", "tex/wood.png", "tri.ply"])
            with self.assertRaises(penumbra.PenumbraError):
                penumbra.scene_files({"environment": {"map": "../sky.exr"}}, folder)
            with self.assertRaises(penumbra.PenumbraError):
                penumbra.scene_files({"environment": {"map": "missing.exr"}}, folder)
        finally:
            shutil.rmtree(folder)

    def test_second_submit_of_the_same_scene_uploads_nothing(self):
        folder = tempfile.mkdtemp()
        try:
            path = self.write_scene(folder)
            client = penumbra.Client(self.server.url, token=TOKEN)
            first = client.submit(path)
            self.assertEqual(client.bytes_uploaded, len(ply_bytes()) + len(png_bytes()))
            self.assertEqual(client.wait(first, progress=False)["state"], "succeeded")
            second = client.submit(path)
            self.assertEqual(client.bytes_uploaded, len(ply_bytes()) + len(png_bytes()))
            self.assertEqual(client.wait(second, progress=False)["state"], "succeeded")
            # The pixels, not the files: each PNG's metadata names its own job.
            self.assertEqual(png_idat(client.result(first, format="png")),
                             png_idat(client.result(second, format="png")))
        finally:
            shutil.rmtree(folder)


def png_idat(data):
    """The concatenated IDAT chunks of a PNG: its compressed pixels, without the text chunks."""
    pos, idat = 8, b""
    while pos < len(data):
        (length,) = struct.unpack_from(">I", data, pos)
        if data[pos + 4:pos + 8] == b"IDAT":
            idat += data[pos + 8:pos + 8 + length]
        pos += 12 + length
    return idat


def decode_png_rgb(data):
    """8-bit RGB PNG (no interlace) to a (h, w, 3) uint8 array: enough for the server's PNGs."""
    pos, chunks = 8, {}
    idat = b""
    while pos < len(data):
        (length,) = struct.unpack_from(">I", data, pos)
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IDAT":
            idat += body
        else:
            chunks[kind] = body
        pos += 12 + length
    w, h, depth, color = struct.unpack(">IIBB", chunks[b"IHDR"][:10])
    assert depth == 8 and color in (2, 6), (depth, color)
    bpp = 3 if color == 2 else 4
    raw = zlib.decompress(idat)
    stride = w * bpp
    out = np.zeros((h, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, dtype=np.int32)
        for x in range(stride):
            a = cur[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 0:
                p = 0
            elif f == 1:
                p = a
            elif f == 2:
                p = b
            elif f == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[x] = (line[x] + p) & 0xFF
        out[y] = cur
        prev = cur
    return out.reshape(h, w, bpp)[..., :3].astype(np.uint8)


if __name__ == "__main__":
    unittest.main()
