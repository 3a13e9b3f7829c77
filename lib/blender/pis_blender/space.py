"""The parameter space the add-on's settings describe (docs/SCENE.md `[[dimension]]`): a light
moving along a path, the camera on an orbit, and the camera and objects at animation frames,
slowest first. Each dimension knows its scene.toml table, its RAYSET.md `space` entry and how
to put Blender's scene at one of its samples.
"""

import numpy as np

from . import coords


class SpaceError(Exception):
    """A parameter space the settings cannot describe, with the setting to change."""


def sample_values(a, b, n, periodic):
    """pis-scene's sample_values: `n` samples from a to b (a periodic range stops one step
    short), in f32 arithmetic as pis-scene computes them, so both name the same values."""
    f = np.float32
    a, b = f(a), f(b)
    if n == 1:
        return [float(a)]
    steps = f(n if periodic else n - 1)
    return [float(a + (b - a) * f(i) / steps) for i in range(n)]


class Dimension:
    def __init__(self, name, kind, driver, unit, values, periodic, table, place):
        self.name, self.kind, self.driver, self.unit = name, kind, driver, unit
        self.values, self.periodic, self.table, self.place = values, periodic, table, place

    def meta(self):
        """The set.json `space` entry (RAYSET.md 3.1)."""
        return {
            "name": self.name,
            "kind": self.kind,
            "driver": self.driver,
            "periodic": self.periodic,
            "unit": self.unit,
            "values": [float(v) for v in self.values],
        }


def dimensions(scene):
    """The dimensions `scene.pis` turns on, slowest first (light, frames, view)."""
    s = scene.pis
    dims = []
    if s.light_path_on:
        dims.append(_light_path(s))
    if s.frames_on:
        dims.append(_frames(scene, s))
    if s.orbit_on:
        dims.append(_orbit(s))
    names = [d.name for d in dims]
    if len(set(names)) != len(names):
        raise SpaceError(f"dimension names repeat: {names}")
    return dims


def _count(samples, what):
    if samples < 1:
        raise SpaceError(f"{what}: samples must be at least 1")
    return samples


def _range(a, b, n, what):
    if n > 1 and not b > a:
        raise SpaceError(f"{what}: the range must increase ({a} to {b})")


def _orbit(s):
    n = _count(s.orbit_samples, "orbit")
    a, b = s.orbit_azimuth_deg
    _range(a, b, n, "orbit azimuth")
    if s.orbit_radius <= 0:
        raise SpaceError("orbit: the radius must be above 0")
    target = coords.point_to_gltf(s.orbit_target)
    table = {
        "name": s.orbit_name,
        "driver": "orbit",
        "samples": n,
        "target": target,
        "radius": s.orbit_radius,
        "elevation_deg": s.orbit_elevation_deg,
        "azimuth_deg": [a, b],
        "periodic": s.orbit_periodic,
    }

    def place(scene, value):
        eye = coords.orbit_eye(target, s.orbit_radius, s.orbit_elevation_deg, value)
        import mathutils

        m = coords.C_INV @ coords.look_at(eye, target)
        scene.camera.matrix_world = mathutils.Matrix([list(row) for row in m])

    values = sample_values(a, b, n, s.orbit_periodic)
    return Dimension(s.orbit_name, "view", "orbit", "deg", values, s.orbit_periodic, table, place)


def light_path_points(s):
    """The path's polyline, world space, glTF axes: the first spline of the curve object
    (its points in order; a Bézier spline's control points)."""
    curve = s.light_path_curve
    if curve is None or curve.type != "CURVE" or not curve.data.splines:
        raise SpaceError("light path: choose a curve object for the path")
    spline = curve.data.splines[0]
    points = spline.bezier_points if spline.type == "BEZIER" else spline.points
    world = curve.matrix_world
    return [coords.point_to_gltf(world @ p.co.to_3d()) for p in points]


def _light_path(s):
    light = s.light_path_light
    if light is None or light.type != "LIGHT":
        raise SpaceError("light path: choose the light that moves")
    n = _count(s.light_path_samples, "light path")
    a, b = s.light_path_range
    _range(a, b, n, "light path range")
    path = light_path_points(s)
    table = {
        "name": s.light_path_name,
        "driver": "light_path",
        "samples": n,
        "light": light.name,
        "path": path,
        "range": [a, b],
    }

    def place(scene, value):
        p = coords.point_to_blender(coords.point_on_path(path, value))
        light.matrix_world.translation = p

    values = sample_values(a, b, n, False)
    return Dimension(s.light_path_name, "light", "light_path", "", values, False, table, place)


def _frames(scene, s):
    n = _count(s.frames_samples, "frames")
    first, last = s.frames_range
    _range(first, last, n, "frames")
    fps = scene.render.fps / scene.render.fps_base
    start = scene.frame_start
    # The glTF exporter writes frame f at time (f − frame_start) / fps (it slides the
    # animation to 0); pis-scene samples those times.
    a, b = (first - start) / fps, (last - start) / fps
    table = {
        "name": s.frames_name,
        "driver": "animation",
        "animation": None,  # the exported glTF's animation, named once it is written
        "kind": s.frames_kind.lower(),
        "samples": n,
        "time": [a, b],
    }

    def place(scene_, value):
        frame = start + value * fps
        whole = int(frame // 1)
        scene_.frame_set(whole, subframe=frame - whole)

    values = sample_values(a, b, n, False)
    return Dimension(s.frames_name, s.frames_kind.lower(), "animation", "s", values, False, table, place)


def points(dims):
    """Every point as its sample indices, the last dimension fastest (RAYSET.md 3.3)."""
    out = [[]]
    for d in dims:
        out = [p + [i] for p in out for i in range(len(d.values))]
    return out


def place(scene, dims, point):
    """Puts Blender's scene at `point`: the frame first, then the camera and the lights."""
    order = sorted(range(len(dims)), key=lambda k: dims[k].driver != "animation")
    for k in order:
        dims[k].place(scene, dims[k].values[point[k]])
