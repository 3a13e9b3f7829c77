"""Uncompressed scan-line OpenEXR files: what the add-on reads from Cycles and writes as a
set's point images (RAYSET.md 5.1 lets a converter write NONE compression).

Only single-part scan-line files with NONE compression are read: the add-on renders its
passes that way. Pixels come back as float32 numpy arrays, row 0 at the top.
"""

import struct

import numpy as np

MAGIC = b"\x76\x2f\x31\x01"
_TYPES = {1: np.float16, 2: np.float32}
_FLOAT = 2
_TILED, _LONG_NAMES, _DEEP, _MULTIPART = 0x200, 0x400, 0x800, 0x1000


class ExrError(Exception):
    """A file this reader cannot read, with the reason."""


def read(path):
    """The channels of the EXR at `path`, as {name: float32 array of shape (height, width)}."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != MAGIC:
        raise ExrError(f"{path}: not an OpenEXR file")
    flags = struct.unpack_from("<I", data, 4)[0]
    if flags & 0xFF != 2 or flags & (_TILED | _DEEP | _MULTIPART):
        raise ExrError(f"{path}: tiled, deep or multi-part EXR (flags {flags:#x}) is not read")
    header, pos = _header(data, 8, path)
    if header.get("compression", 0) != 0:
        raise ExrError(f"{path}: compressed EXR (method {header['compression']}); render with codec NONE")
    x0, y0, x1, y1 = header["dataWindow"]
    width, height = x1 - x0 + 1, y1 - y0 + 1
    channels = header["channels"]
    pos += 8 * height  # the offset table: one scan line a block, in order
    out = {name: np.empty((height, width), np.float32) for name, _ in channels}
    for _ in range(height):
        y, size = struct.unpack_from("<ii", data, pos)
        pos += 8
        row = y - y0
        if not 0 <= row < height or pos + size > len(data):
            raise ExrError(f"{path}: scan line {y} out of range or truncated")
        for name, kind in channels:
            dtype = _TYPES[kind]
            count = width * np.dtype(dtype).itemsize
            out[name][row] = np.frombuffer(data, dtype, width, pos)
            pos += count
    return out


def _header(data, pos, path):
    header = {}
    while data[pos] != 0:
        name, pos = _cstring(data, pos)
        kind, pos = _cstring(data, pos)
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        value = data[pos : pos + size]
        pos += size
        if name == "channels":
            header[name] = _channels(value, path)
        elif name == "compression":
            header[name] = value[0]
        elif name == "dataWindow":
            header[name] = struct.unpack("<iiii", value)
    return header, pos + 1


def _channels(value, path):
    channels, pos = [], 0
    while value[pos] != 0:
        name, pos = _cstring(value, pos)
        kind, _, xs, ys = struct.unpack_from("<iB3xii", value, pos)
        pos += 16
        if kind not in _TYPES or (xs, ys) != (1, 1):
            raise ExrError(f"{path}: channel {name}: type {kind} sampling {xs}x{ys} is not read")
        channels.append((name, kind))
    return channels


def _cstring(data, pos):
    end = data.index(b"\0", pos)
    return data[pos:end].decode("utf-8"), end + 1


def write(path, channels, width, height):
    """Writes `channels` ({name: float array (height, width)}) as FLOAT channels, NONE
    compression, increasing lines: the file is complete only once this returns."""
    names = sorted(channels)
    chlist = b"".join(name.encode() + b"\0" + struct.pack("<iB3xii", _FLOAT, 0, 1, 1) for name in names) + b"\0"
    attrs = [
        ("channels", "chlist", chlist),
        ("compression", "compression", b"\0"),
        ("dataWindow", "box2i", struct.pack("<iiii", 0, 0, width - 1, height - 1)),
        ("displayWindow", "box2i", struct.pack("<iiii", 0, 0, width - 1, height - 1)),
        ("lineOrder", "lineOrder", b"\0"),
        ("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        ("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        ("screenWindowWidth", "float", struct.pack("<f", 1.0)),
    ]
    long_names = any(len(n) > 31 for n in names)
    header = MAGIC + struct.pack("<I", 2 | (_LONG_NAMES if long_names else 0))
    header += b"".join(n.encode() + b"\0" + t.encode() + b"\0" + struct.pack("<i", len(v)) + v for n, t, v in attrs)
    header += b"\0"
    planes = [np.ascontiguousarray(channels[n], np.float32).reshape(height, width) for n in names]
    line_size = 4 * width * len(names)
    first = len(header) + 8 * height
    offsets = struct.pack(f"<{height}Q", *(first + y * (8 + line_size) for y in range(height)))
    with open(path, "wb") as f:
        f.write(header + offsets)
        for y in range(height):
            f.write(struct.pack("<ii", y, line_size))
            f.write(b"".join(p[y].astype("<f4").tobytes() for p in planes))
