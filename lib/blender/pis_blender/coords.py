"""Blender's world (+Z up) and PIS's (glTF: +Y up, RAYSET.md 1), and the camera math that
pis-scene does (lib/scene/src/orbit.rs, light_path.rs), written again so that the add-on
places Blender's camera and lights where pis-pack will compute them.

Blender (x, y, z) is glTF (x, z, −y). Meshes are exported in glTF axes, so an object's
transform is C·M·C⁻¹; a camera or light keeps its own local axes (both look down local −Z),
so its transform is C·M.
"""

import math

import numpy as np

# glTF from Blender: (x, y, z) -> (x, z, -y).
C = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
C_INV = C.T


def point_to_gltf(p):
    return [float(p[0]), float(p[2]), -float(p[1])]


def point_to_blender(p):
    return [float(p[0]), -float(p[2]), float(p[1])]


def matrix(m):
    """A mathutils.Matrix (or nested rows) as a 4×4 numpy array."""
    return np.array([[float(m[r][c]) for c in range(4)] for r in range(4)])


def object_to_gltf(m):
    return C @ matrix(m) @ C_INV


def rigid(m):
    """`m` without scale: its rotation columns normalised (pis-scene's `rigid_part`)."""
    out = np.array(m, dtype=float)
    for c in range(3):
        out[:3, c] /= np.linalg.norm(out[:3, c])
    return out


def camera_to_gltf(m):
    return C @ rigid(matrix(m))


def column_major(m):
    """A 4×4 as RAYSET.md's 16 column-major numbers."""
    return [float(x) for x in np.asarray(m).T.reshape(16)]


def orbit_eye(target, radius, elevation_deg, azimuth_deg):
    """pis-scene's orbit_eye, glTF axes: azimuth 0 on the +Z side of `target`, positive towards +X."""
    el, az = math.radians(elevation_deg), math.radians(azimuth_deg)
    d = (math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az))
    return [target[k] + radius * d[k] for k in range(3)]


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """pis-scene's look_at: camera-to-world looking from `eye` at `target`, +Y up, glTF axes."""
    eye, target, up = (np.array(v, dtype=float) for v in (eye, target, up))
    forward = target - eye
    n = np.linalg.norm(forward)
    forward = forward / n if n > 0 else np.array([0.0, 0.0, -1.0])
    right = np.cross(forward, up)
    for axis in ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0)):
        if np.dot(right, right) >= 1e-12:
            break
        right = np.cross(forward, axis)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    m = np.identity(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, true_up, -forward, eye
    return m


def point_on_path(path, s):
    """pis-scene's point_on_path: normalised arc length `s` along the polyline `path`."""
    if not path:
        return [0.0, 0.0, 0.0]
    pts = [np.array(p, dtype=float) for p in path]
    lengths = [float(np.linalg.norm(b - a)) for a, b in zip(pts, pts[1:])]
    total = sum(lengths)
    if len(pts) == 1 or total <= 0.0:
        return list(pts[0])
    remaining = min(max(s, 0.0), 1.0) * total
    for a, b, length in zip(pts, pts[1:], lengths):
        if remaining <= length and length > 0.0:
            return list(a + (b - a) * (remaining / length))
        remaining -= length
    return list(pts[-1])


def projection(yfov, aspect, znear, zfar):
    """RAYSET.md 3.3's projection (clip depth in [0, 1]), column-major."""
    f = 1.0 / math.tan(yfov / 2.0)
    if zfar is None:
        cols = [[f / aspect, 0, 0, 0], [0, f, 0, 0], [0, 0, -1, -1], [0, 0, -znear, 0]]
    else:
        cols = [[f / aspect, 0, 0, 0], [0, f, 0, 0], [0, 0, zfar / (znear - zfar), -1], [0, 0, znear * zfar / (znear - zfar), 0]]
    return [float(x) for col in cols for x in col]


def yfov(camera_data, width, height):
    """The vertical field of view Cycles renders with, radians, from the sensor fit."""
    fit = camera_data.sensor_fit
    if fit == "AUTO":
        fit = "HORIZONTAL" if width >= height else "VERTICAL"
        size = camera_data.sensor_width
    else:
        size = camera_data.sensor_width if fit == "HORIZONTAL" else camera_data.sensor_height
    half = size / (2.0 * camera_data.lens)
    if fit == "HORIZONTAL":
        half *= height / width
    return 2.0 * math.atan(half)


def cycles_normal_to_gltf(n, camera_matrix):
    """Cycles' Denoising Normal pass (camera space with +Z forward: Blender's camera axes with
    Z turned) as glTF world normals; `n` is an array (..., 3)."""
    r = rigid(matrix(camera_matrix))[:3, :3]
    blender_camera = n * np.array([1.0, 1.0, -1.0], np.float32)
    return (blender_camera @ r.T @ C[:3, :3].T).astype(np.float32)
