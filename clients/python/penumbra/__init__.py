"""Python client of the penumbra render service.

    import penumbra
    client = penumbra.Client("http://127.0.0.1:8080", token="...")
    image = client.render("scene.json")          # submit (uploading the files it names), wait, fetch

Standard library only (it runs inside Blender's Python); numpy, when installed, turns EXR results
into float arrays.
"""
from .assets import manifest, scene_files, sha256_of
from .client import FINAL_STATES, Client
from .errors import (Busy, ConnectionFailed, FieldError, InvalidRequest, JobFailed, NotFound,
                     PenumbraError, ProblemError, Unauthorized)
from .exr import ExrError, read_exr

__all__ = ["Client", "FINAL_STATES", "PenumbraError", "ProblemError", "InvalidRequest",
           "Unauthorized", "NotFound", "Busy", "ConnectionFailed", "JobFailed", "FieldError",
           "scene_files", "manifest", "sha256_of", "read_exr", "ExrError"]
__version__ = "0.2.0"
