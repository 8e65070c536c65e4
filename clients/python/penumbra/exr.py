"""Reads the OpenEXR files penumbra writes (scanline, uncompressed, ZIPS or ZIP; HALF, FLOAT or
UINT channels) into numpy arrays, with no library but numpy and zlib.

The layout follows the OpenEXR file-format document ("The OpenEXR File Layout"): magic and
version, attributes up to an empty name, a table of chunk offsets, then chunks of scanlines, each
holding every channel of a line in alphabetical order. ZIP data is zlib-deflated after two
reversible steps, which are undone here: a byte-delta predictor and a split of the bytes into
their even and odd positions.
"""
from __future__ import annotations

import struct
import zlib
from typing import Dict, List, Tuple

MAGIC = 20000630
_COMPRESSION_LINES = {0: 1, 2: 1, 3: 16}  # NONE, ZIPS, ZIP
_TYPES = {0: ("<u4", 4), 1: ("<f2", 2), 2: ("<f4", 4)}  # UINT, HALF, FLOAT


class ExrError(ValueError):
    """The bytes are not an EXR file this reader understands."""


def _read_header(data: bytes) -> Tuple[Dict[str, Tuple[str, bytes]], int]:
    if len(data) < 8 or struct.unpack_from("<i", data, 0)[0] != MAGIC:
        raise ExrError("not an OpenEXR file")
    version = struct.unpack_from("<I", data, 4)[0]
    if version & 0xFF != 2:
        raise ExrError(f"OpenEXR version {version & 0xFF}")
    if version & 0x200:
        raise ExrError("tiled EXR files are not read")
    if version & 0x1800:
        raise ExrError("multi-part or deep EXR files are not read")
    pos, attrs = 8, {}
    while True:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode("latin-1")
        pos = end + 1
        if not name:
            return attrs, pos
        end = data.index(b"\0", pos)
        kind = data[pos:end].decode("latin-1")
        pos = end + 1
        (size,) = struct.unpack_from("<i", data, pos)
        pos += 4
        if size < 0 or pos + size > len(data):
            raise ExrError(f"attribute {name!r} runs past the end of the file")
        attrs[name] = (kind, data[pos:pos + size])
        pos += size


def _channels(value: bytes) -> List[Tuple[str, int]]:
    out, pos = [], 0
    while pos < len(value) and value[pos] != 0:
        end = value.index(b"\0", pos)
        name = value[pos:end].decode("utf-8")
        pixel_type, _linear, xs, ys = struct.unpack_from("<iB3xii", value, end + 1)
        if pixel_type not in _TYPES:
            raise ExrError(f"channel {name!r} has pixel type {pixel_type}")
        if xs != 1 or ys != 1:
            raise ExrError(f"channel {name!r} is subsampled")
        out.append((name, pixel_type))
        pos = end + 1 + 16
    return out


def _unzip(chunk: bytes, expected: int) -> bytes:
    import numpy as np

    raw = zlib.decompress(chunk)
    if len(raw) != expected:
        raise ExrError("a ZIP chunk decompresses to the wrong size")
    d = np.frombuffer(raw, dtype=np.uint8).copy()
    # Undo the predictor, t[i] = t[i-1] + d[i] - 128 (mod 256): a running sum in uint8 wraps.
    d[1:] -= np.uint8(128)
    t = np.cumsum(d, dtype=np.uint8)
    # Undo the split: the first half of t holds the even bytes, the second half the odd ones.
    half = (len(t) + 1) // 2
    out = np.empty_like(t)
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return out.tobytes()


def read_exr(data: bytes) -> Dict[str, "numpy.ndarray"]:  # noqa: F821
    """Every channel of a scanline EXR as a float32 (or uint32) array of shape (height, width),
    keyed by channel name ("R", "albedo.R", "ViewLayer.Combined.R", ...)."""
    import numpy as np

    attrs, pos = _read_header(data)
    try:
        channels = _channels(attrs["channels"][1])
        compression = attrs["compression"][1][0]
        xmin, ymin, xmax, ymax = struct.unpack("<4i", attrs["dataWindow"][1])
    except (KeyError, IndexError, struct.error) as e:
        raise ExrError(f"missing or malformed header attribute: {e}") from None
    if compression not in _COMPRESSION_LINES:
        raise ExrError(f"compression {compression} is not read (penumbra writes ZIP)")
    width, height = xmax - xmin + 1, ymax - ymin + 1
    if width <= 0 or height <= 0 or width * height > 1 << 28:
        raise ExrError(f"data window {width} x {height}")
    lines = _COMPRESSION_LINES[compression]
    chunks = (height + lines - 1) // lines
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    channels.sort(key=lambda c: c[0])
    line_bytes = sum(width * _TYPES[t][1] for _, t in channels)
    planes = {name: np.empty((height, width), dtype=np.dtype(_TYPES[t][0]))
              for name, t in channels}
    for offset in offsets:
        if offset + 8 > len(data):
            raise ExrError("a chunk offset points past the end of the file")
        y, size = struct.unpack_from("<ii", data, offset)
        first = y - ymin
        count = min(lines, height - first)
        if first < 0 or count <= 0 or size < 0 or offset + 8 + size > len(data):
            raise ExrError(f"chunk at scanline {y} is malformed")
        body = data[offset + 8:offset + 8 + size]
        expected = count * line_bytes
        if compression != 0 and size < expected:
            body = _unzip(body, expected)
        if len(body) != expected:
            raise ExrError(f"chunk at scanline {y} has {len(body)} bytes, expected {expected}")
        at = 0
        for row in range(first, first + count):
            for name, t in channels:
                dtype, bytes_per = _TYPES[t]
                n = width * bytes_per
                planes[name][row] = np.frombuffer(body, dtype=np.dtype(dtype), count=width,
                                                  offset=at)
                at += n
    return {name: (p.astype(np.float32) if p.dtype.kind == "f" else p)
            for name, p in planes.items()}


def rgb(planes: Dict[str, "numpy.ndarray"], layer: str = "") -> "numpy.ndarray":  # noqa: F821
    """The (height, width, 3) float32 image of a layer's R, G, B channels ("" for the plain
    R, G, B; "albedo" for albedo.R ...); a layer of other channels (normal.X/Y/Z, depth.Z) comes
    back with its own channels in the order X, Y, Z or as (height, width, 1)."""
    import numpy as np

    prefix = layer + "." if layer else ""
    for names in (("R", "G", "B"), ("X", "Y", "Z"), ("Z",), ("V",), ("Y",)):
        keys = [prefix + n for n in names]
        if all(k in planes for k in keys):
            return np.stack([planes[k] for k in keys], axis=-1)
    raise KeyError(f"no channels of layer {layer!r}: {sorted(planes)}")
