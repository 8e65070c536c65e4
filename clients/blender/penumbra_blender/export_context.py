"""State shared by the exporters of one scene: the folder meshes are written to, the asset files
the scene names, and the warnings shown in Blender's report after the render."""
from __future__ import annotations

import os
import re
import shutil
from typing import Dict, List


def safe_name(name: str) -> str:
    """A file-name-safe form of a Blender datablock name (penumbra refuses `..` and absolute
    paths; other odd characters would only make the files awkward to look at)."""
    clean = re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "unnamed"
    return clean[:80]


class ExportContext:
    """`folder`: where mesh files are written (and, with `copy_assets`, copies of the images the
    scene names, so that the folder renders on its own with `penumbra render`)."""

    def __init__(self, folder: str, copy_assets: bool):
        self.folder = folder
        self.copy_assets = copy_assets
        self.files: Dict[str, str] = {}  # scene name -> local path (what the client uploads)
        self.warnings: List[str] = []
        self._by_source: Dict[str, str] = {}

    def warn(self, message: str) -> None:
        if message not in self.warnings:
            self.warnings.append(message)

    def unique(self, name: str) -> str:
        """A scene-relative name no other file has taken."""
        stem, ext = os.path.splitext(name)
        candidate, n = name, 1
        while candidate in self.files:
            n += 1
            candidate = f"{stem}_{n}{ext}"
        return candidate

    def new_file(self, name: str) -> (str, str):
        """Reserves `name` (made unique) for a file the exporter writes; (scene name, path)."""
        name = self.unique(name)
        path = os.path.join(self.folder, *name.split("/"))
        os.makedirs(os.path.dirname(path), exist_ok=True)
        self.files[name] = path
        return name, path

    def add_existing(self, source: str, name: str) -> str:
        """Names an existing file (an image) in the scene; the same file gets one name."""
        source = os.path.abspath(source)
        if source in self._by_source:
            return self._by_source[source]
        name = self.unique(name)
        path = source
        if self.copy_assets:
            path = os.path.join(self.folder, *name.split("/"))
            os.makedirs(os.path.dirname(path), exist_ok=True)
            shutil.copyfile(source, path)
        self.files[name] = path
        self._by_source[source] = name
        return name
