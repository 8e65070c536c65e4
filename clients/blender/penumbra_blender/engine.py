"""The render engine: F12 exports the scene, submits it (uploading only the files the server
lacks), follows the job (progress in the status bar, the progressive preview in the render
window), cancels it when the user stops the render, and loads the final multi-layer EXR
(`?layout=blender`) into Blender's render result."""
from __future__ import annotations

import os
import shutil
import tempfile
import threading
import time

import bpy

from . import preferences
from .camera_export import image_size
from .client_import import load_client
from .scene_export import export_scene, write_scene

PREVIEW_INTERVAL = 1.0  # seconds between preview downloads


class PenumbraRenderEngine(bpy.types.RenderEngine):
    bl_idname = "PENUMBRA"
    bl_label = "penumbra"
    bl_use_preview = False
    bl_use_shading_nodes_custom = False  # materials keep Blender's (Cycles') node editor
    bl_use_eevee_viewport = True  # Material Preview shading draws with EEVEE

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        if renderlayer.use_pass_z:
            self.register_pass(scene, renderlayer, "Depth", 1, "Z", "VALUE")
        if renderlayer.use_pass_normal:
            self.register_pass(scene, renderlayer, "Normal", 3, "XYZ", "VECTOR")

    def render(self, depsgraph):
        scene = depsgraph.scene
        try:
            penumbra = load_client()
        except ImportError as e:
            self.report({"ERROR"}, str(e))
            return
        view_layer = depsgraph.view_layer
        if view_layer.use_pass_z:
            self.add_pass("Depth", 1, "Z")
        if view_layer.use_pass_normal:
            self.add_pass("Normal", 3, "XYZ")
        folder = tempfile.mkdtemp(prefix="penumbra-blender-")
        try:
            self._render(penumbra, depsgraph, scene, folder)
        except penumbra.PenumbraError as e:
            self.report({"ERROR"}, f"penumbra: {_describe(e)}")
        except (OSError, ValueError) as e:
            self.report({"ERROR"}, f"penumbra: {e}")
        finally:
            shutil.rmtree(folder, ignore_errors=True)

    def _render(self, penumbra, depsgraph, scene, folder):
        url, token = preferences.server_settings()
        samples, integrator, seed, max_depth = preferences.render_settings(scene)
        self.update_stats("penumbra", "Exporting scene")
        doc, ctx = export_scene(depsgraph, folder, samples=samples, integrator=integrator,
                                seed=seed, max_depth=max_depth, copy_assets=False,
                                frame_set=self.frame_set)
        for warning in ctx.warnings:
            self.report({"WARNING"}, warning)
        keep = os.environ.get("PENUMBRA_KEEP_EXPORT")
        if keep:
            keep_export(doc, ctx.files, keep)
        client = penumbra.Client(url, token=token)
        self.update_stats("penumbra", f"Uploading to {client.url}")
        job = client.submit(doc, assets=ctx.files)
        job_id = job["id"]
        width, height = image_size(scene)
        result = self.begin_result(0, 0, width, height)
        try:
            record = self._follow(client, penumbra, job_id, result, folder)
            if record is None:  # cancelled by the user
                self.end_result(result, cancel=True)
                return
            if record.get("state") != "succeeded":
                raise penumbra.JobFailed(record)
            self.update_stats("penumbra", "Downloading result")
            data = client.result(job_id, format="exr", layout="blender", as_array=False)
            path = os.path.join(folder, "result.exr")
            with open(path, "wb") as f:
                f.write(data)
            result.load_from_file(path)
            self.end_result(result)
            self.update_progress(1.0)
        except BaseException:
            self.end_result(result, cancel=True)
            raise

    def _follow(self, client, penumbra, job_id, result, folder):
        """The job's final record, or None when the user cancelled (the job is cancelled on
        the server too). The event stream is followed on a thread so that this one can watch
        test_break and fetch previews."""
        latest = {}
        outcome = {}

        def wait():
            try:
                outcome["record"] = client.wait(job_id, progress=latest.update, check=False)
            except BaseException as e:  # handed to the render thread
                outcome["error"] = e

        waiter = threading.Thread(target=wait, daemon=True)
        waiter.start()
        next_preview = time.monotonic() + PREVIEW_INTERVAL
        preview_path = os.path.join(folder, "preview.png")
        while waiter.is_alive():
            waiter.join(0.1)
            if self.test_break():
                self.update_stats("penumbra", "Cancelling")
                try:
                    client.cancel(job_id)
                except penumbra.PenumbraError as e:
                    self.report({"WARNING"}, f"penumbra: cancelling job {job_id}: {_describe(e)}")
                return None
            state = latest.get("state", "queued")
            fraction = float(latest.get("progress") or 0.0)
            self.update_progress(min(max(fraction, 0.0), 1.0))
            eta = latest.get("eta_seconds")
            text = f"Job {job_id[:8]} {state} {100 * fraction:.0f}%"
            if state == "running" and isinstance(eta, (int, float)):
                text += f", {eta:.0f} s left"
            elif state == "queued" and latest.get("queue_position") is not None:
                text += f", position {latest['queue_position']} in the queue"
            self.update_stats("penumbra", text)
            if state == "running" and time.monotonic() >= next_preview:
                next_preview = time.monotonic() + PREVIEW_INTERVAL
                self._show_preview(client, penumbra, job_id, result, preview_path)
        if "error" in outcome:
            raise outcome["error"]
        return outcome["record"]

    def _show_preview(self, client, penumbra, job_id, result, path):
        # A PNG: the plain preview EXR carries the layers' channels too, which Blender would
        # read as a multi-layer file that RenderLayer.load_from_file refuses.
        try:
            data = client.result(job_id, format="png", preview=True, as_array=False)
        except penumbra.PenumbraError:
            return  # no pass finished yet (409), or the job just ended
        with open(path, "wb") as f:
            f.write(data)
        result.layers[0].load_from_file(path)
        self.update_result(result)


def keep_export(doc, files, folder) -> None:
    """$PENUMBRA_KEEP_EXPORT: a copy of exactly what is submitted (scene.json and its files) in
    a folder `penumbra render` renders on its own. A second export (the Export operator) may
    differ in the last bits of smooth normals, which Blender computes in parallel."""
    os.makedirs(folder, exist_ok=True)
    for name, source in files.items():
        target = os.path.join(folder, *name.split("/"))
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(source, target)
    write_scene(doc, folder)


def _describe(error) -> str:
    errors = getattr(error, "errors", None)
    text = str(error)
    if errors:
        text += ": " + "; ".join(f"{e.pointer}: {e.detail}" for e in errors[:5])
    return text


# EEVEE's panels for what the exporter reads (material and world node trees, the depth of field,
# the light's power); Cycles' own panels need Cycles' properties, and Blender's generic ones
# (those listing BLENDER_RENDER) show for any engine.
_EEVEE_PANELS = ("EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface",
                 "EEVEE_WORLD_PT_surface", "DATA_PT_EEVEE_light", "DATA_PT_camera_dof",
                 "DATA_PT_camera_dof_aperture")


def compatible_panels():
    """The panels of the properties editor to show for this engine."""
    panels = []
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if engines is not None and ("BLENDER_RENDER" in engines
                                    or panel.__name__ in _EEVEE_PANELS):
            panels.append(panel)
    return panels
