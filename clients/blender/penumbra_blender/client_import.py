"""Finds the penumbra Python client (clients/python/penumbra) without copying its code.

Order, first found wins:
1. the copy bundled in the add-on zip as the subpackage `penumbra_blender.penumbra`
   (scripts/package-blender-addon.sh puts it there), so an installed zip is self-contained;
2. `import penumbra` from Blender's Python path (a `pip install ./clients/python` into the
   Python Blender runs: Debian's Blender uses the system Python 3.11);
3. the repository's clients/python beside this folder, when the add-on runs from a checkout
   (the tests do this).
The client is standard library only, which is what Blender's Python guarantees.
"""
from __future__ import annotations

import importlib
import os
import sys


def load_client():
    """The `penumbra` client module, or raises ImportError saying where it looked."""
    tried = []
    try:
        return importlib.import_module(__package__ + ".penumbra")
    except ImportError as e:
        tried.append(f"bundled {__package__}.penumbra ({e})")
    try:
        module = importlib.import_module("penumbra")
        if hasattr(module, "Client"):
            return module
        tried.append(f"'penumbra' on sys.path is not the client ({module.__file__})")
    except ImportError as e:
        tried.append(f"'import penumbra' ({e})")
    checkout = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", "..", "python"))
    if os.path.isfile(os.path.join(checkout, "penumbra", "client.py")):
        sys.path.insert(0, checkout)
        sys.modules.pop("penumbra", None)
        return importlib.import_module("penumbra")
    tried.append(f"the repository's {checkout}")
    raise ImportError("penumbra client not found; tried " + "; ".join(tried))
