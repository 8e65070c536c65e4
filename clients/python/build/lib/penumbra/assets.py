"""The files a scene names, found and hashed so that a job's manifest can list them and only the
ones the server lacks are uploaded (the content-addressed store of `PUT /v1/assets/{sha256}`).

Where a scene names files (docs/scene-format.md): an object's "file" (PLY, OBJ, glTF), any
{"texture": path} (colours, roughness, emission, ...), a material's "normal_map", the
environment's "map". A .gltf file names its own buffers and images by URI, relative to its
folder; those are listed too. Paths are relative to the scene's folder and must stay inside it,
as the server requires.
"""
from __future__ import annotations

import hashlib
import json
import os
import posixpath
from typing import Any, Dict, Iterator, Mapping, Union
from urllib.parse import unquote

from .errors import PenumbraError

AssetSource = Union[str, os.PathLike, bytes]

_PATH_KEYS = ("file", "map", "normal_map", "texture")


def sha256_of(source: AssetSource) -> str:
    """"sha256:<64 hex digits>" of a file (read in 1 MiB pieces) or of bytes."""
    h = hashlib.sha256()
    if isinstance(source, (bytes, bytearray, memoryview)):
        h.update(source)
    else:
        with open(source, "rb") as f:
            for piece in iter(lambda: f.read(1 << 20), b""):
                h.update(piece)
    return "sha256:" + h.hexdigest()


def _names_in(value: Any) -> Iterator[str]:
    if isinstance(value, dict):
        for key, item in value.items():
            if key in _PATH_KEYS and isinstance(item, str):
                yield item
            else:
                yield from _names_in(item)
    elif isinstance(value, list):
        for item in value:
            yield from _names_in(item)


def _check_name(name: str) -> str:
    clean = posixpath.normpath(name)
    if (name.startswith("/") or "\\" in name or clean == ".." or clean.startswith("../")
            or "\0" in name):
        raise PenumbraError(f"{name!r}: scene paths must be relative and stay in the scene's folder")
    return clean


def _gltf_uris(path: str) -> Iterator[str]:
    """The files a .gltf names (buffers and images by relative URI; data: URIs are inline)."""
    try:
        with open(path, "rb") as f:
            doc = json.loads(f.read().decode("utf-8"))
    except (OSError, ValueError) as e:
        raise PenumbraError(f"{path}: cannot read it as glTF JSON: {e}") from None
    for key in ("buffers", "images"):
        for item in doc.get(key, []) or []:
            uri = item.get("uri") if isinstance(item, dict) else None
            if isinstance(uri, str) and not uri.startswith("data:"):
                yield unquote(uri)


def scene_files(scene: Mapping[str, Any], base_dir: Union[str, os.PathLike]) -> Dict[str, str]:
    """Every file the scene names: {name as the scene writes it: local path}. A missing file is an
    error naming it."""
    base = os.fspath(base_dir)
    found: Dict[str, str] = {}
    pending = [_check_name(n) for n in _names_in(scene)]
    while pending:
        name = pending.pop()
        if name in found:
            continue
        path = os.path.join(base, *name.split("/"))
        if not os.path.isfile(path):
            raise PenumbraError(f"the scene names {name!r}, which is not a file in {base}")
        found[name] = path
        if name.lower().endswith(".gltf"):
            folder = posixpath.dirname(name)
            pending.extend(_check_name(posixpath.join(folder, uri)) for uri in _gltf_uris(path))
    return found


def manifest(files: Mapping[str, AssetSource]) -> Dict[str, str]:
    """{name: "sha256:..."} for the job's "assets" field."""
    return {name: sha256_of(source) for name, source in files.items()}
