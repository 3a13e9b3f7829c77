"""Renders the scene's parameter space with Cycles into a ray-traced set (RAYSET.md) with the
glTF and scene.toml pis-pack reads beside it.

SET_DIR/ holds scene.toml, scene.gltf (+ .bin, textures), point_NNNNN.exr and set.json,
written last: a folder without set.json is an unfinished export. Every file is written under a
temporary name and renamed into place.
"""

import json
import os
import shutil
import subprocess
import tempfile
import time

import bpy

from . import coords, cycles, exr, layers, scene_file, space

GEOMETRY = ("MESH", "CURVE", "SURFACE", "META", "FONT")


def export_set(scene, out_dir, progress=lambda line, done: print(line), keep_halves=False, points=None):
    """Writes the set of `scene` (its `scene.pis` settings) into `out_dir`; returns a report.
    `progress(line, done)` hears of every point rendered, `done` the share of points so far;
    `keep_halves` leaves a denoised set's halves in `out_dir/.halves`; `points` renders only
    the first that many points (in linear order, each with the seed it has in the whole set)."""
    s = scene.pis
    if scene.camera is None:
        raise scene_file.ExportError("the scene has no camera")
    dims = space.dimensions(scene)
    os.makedirs(out_dir, exist_ok=True)
    # The points are about to be rewritten: until set.json is written again, the folder is
    # an unfinished set.
    stale = os.path.join(out_dir, "set.json")
    if os.path.exists(stale):
        os.remove(stale)
    start = time.time()
    saved = cycles.Settings()
    scratch = tempfile.mkdtemp(prefix="pis-blender-")
    try:
        frame = scene.frame_current
        gltf = os.path.join(out_dir, "scene.gltf")
        scene_file.export_gltf(gltf, with_animation=s.frames_on, with_camera=s.frames_on)
        names, animations = scene_file.gltf_objects(gltf)
        objects = _objects(scene, names)
        for d in dims:
            if d.driver == "animation":
                if not animations:
                    raise scene_file.ExportError("animation frames: the glTF exporter wrote no animation")
                d.table["animation"] = animations[0]
        roles = [scene_file.role(o) for o in objects]
        lights = [o for o in scene.objects if o.type == "LIGHT" and not o.hide_render]
        _write_scene_toml(scene, out_dir, objects, roles, lights, dims)
        cycles.configure(scene, saved, s.spp, s.filter_sigma_px, 0, s.caustics)
        for light in lights:
            if hasattr(light.data, "use_soft_falloff"):
                saved.set(light.data, "use_soft_falloff", False)
        job = _Job(scene, scratch, dims, objects, roles, lights, points)
        program, notes = _denoiser(s)
        if program:
            report = _render_halves(job, out_dir, saved, program, progress, keep_halves)
        else:
            report = _render_points(job, _Pass(out_dir, s.seed, s.spp, False, "scene.toml"), progress)
        report["notes"] = notes
        scene.frame_set(frame)
    finally:
        saved.restore()
        shutil.rmtree(scratch, ignore_errors=True)
    report["seconds"] = round(time.time() - start, 2)
    return report


def _objects(scene, names):
    objects = []
    for name in names:
        obj = scene.objects.get(name)
        if obj is None:
            raise scene_file.ExportError(f"the glTF exporter wrote object {name!r}, which the scene lacks")
        objects.append(obj)
    return objects


def _reflector(obj):
    return obj.pis_reflector or obj.name


def _parts(obj, objects):
    """The objects of `obj`'s reflector (scene.toml `reflector`), itself included."""
    return [o for o in objects if _reflector(o) == _reflector(obj)]


def _write_scene_toml(scene, out_dir, objects, roles, lights, dims):
    animated = any(d.driver == "animation" for d in dims)
    orbit = any(d.driver == "orbit" for d in dims)
    camera = scene_file.camera_table(scene, orbit, animated)
    tables = []
    for o, role in zip(objects, roles):
        t = {"role": role}
        if o.pis_reflector:
            t["reflector"] = o.pis_reflector
        tables.append((o.name, t))
    light_tables = [scene_file.light_entry(light)[0] for light in lights]
    environment = scene_file.world_light(scene)
    res = (scene.render.resolution_x, scene.render.resolution_y)
    scene_file.write_toml(
        os.path.join(out_dir, "scene.toml"), scene.name, "scene.gltf", res, scene.pis.spp,
        camera, tables, light_tables, environment, dims,
    )


def _layer_names(role):
    base = ["coverage", "diffuse", "specular"]
    return base + ["fresnel", "local", "distant"] if role == "reflective" else base


CHANNELS = {1: ["A"], 3: ["R", "G", "B"], 4: ["R", "G", "B", "A"]}


class _Job:
    """What every render of the export shares."""

    def __init__(self, scene, scratch, dims, objects, roles, lights, limit=None):
        self.scene, self.scratch, self.dims = scene, scratch, dims
        self.objects, self.roles, self.lights = objects, roles, lights
        # Render only the first `limit` points (None: every point).
        self.limit = limit


class _Pass:
    """One set written by the export: its folder, seed series, samples, whether its points
    carry the denoiser's guides, and its set.json's `scene_file`."""

    def __init__(self, out_dir, seed, spp, guides, scene_file):
        self.out_dir, self.seed, self.spp = out_dir, seed, spp
        self.guides, self.scene_file = guides, scene_file


def _render_halves(job, out_dir, saved, program, progress, keep_halves):
    """The set denoised: two halves at half the samples each, from the seed series 2·seed
    and 2·seed + 1, with guides, joined by `pis-trace denoise` (RAYSET.md 8)."""
    scene = job.scene
    if scene.pis.spp < 2:
        raise scene_file.ExportError("denoising renders two halves of the samples: give at least 2 samples")
    half = scene.pis.spp // 2
    saved.set(scene.cycles, "samples", half)
    halves = os.path.join(out_dir, ".halves")
    reports, dirs = [], []
    for k, name in enumerate(("even", "odd")):
        d = os.path.join(halves, name)
        os.makedirs(d, exist_ok=True)
        say = lambda line, done, k=k, name=name: progress(f"{name} half, {line}", (k + done) / 2)  # noqa: E731
        reports.append(_render_points(job, _Pass(d, 2 * scene.pis.seed + k, half, True, "../../scene.toml"), say))
        dirs.append(d)
    joined = _join(program, dirs, out_dir)
    if not keep_halves:
        shutil.rmtree(halves, ignore_errors=True)
    return reports[0] | {
        "set": out_dir,
        "spp": joined["spp"],
        "renders": sum(r["renders"] for r in reports),
        "denoised": {k: joined[k] for k in ("denoiser", "denoised_layers", "kept_raw")},
    }


def _denoiser(s):
    """The pis-trace that joins the halves, or None for a raw set; and what to tell the user."""
    if s.denoise == "OFF":
        return None, []
    if s.denoise == "AUTO" and s.spp < 2:
        return None, ["not denoised: one sample per pixel makes no halves"]
    program = bpy.path.abspath(s.pis_trace) if s.pis_trace else shutil.which("pis-trace")
    if program and os.access(program, os.X_OK):
        return program, []
    where = f"{s.pis_trace!r} is not a program" if s.pis_trace else "pis-trace is not on the PATH"
    if s.denoise == "AUTO":
        return None, [f"not denoised: {where} (name it with --pis-trace, or PIS set > pis-trace)"]
    raise scene_file.ExportError(
        f"denoising joins the halves with pis-trace, and {where}: name it (--pis-trace, or PIS set > pis-trace) or turn denoising off"
    )


def _join(program, dirs, out_dir):
    run = subprocess.run([program, "denoise", *dirs, "-o", out_dir, "--json"], capture_output=True, text=True)
    if run.returncode != 0:
        why = run.stderr.strip().splitlines()[-1:] or ["no message"]
        raise scene_file.ExportError(
            f"pis-trace denoise failed (exit {run.returncode}): {why[0]}; the halves are kept in {os.path.dirname(dirs[0])}"
        )
    return json.loads(run.stdout)


def _render_points(job, out, progress):
    scene, dims, objects = job.scene, job.dims, job.objects
    w, h = scene.render.resolution_x, scene.render.resolution_y
    channels = scene_file.channel_names([o.name for o in objects])
    geometry = [o for o in scene.objects if o.type in GEOMETRY and not o.hide_render]
    fraction = layers.fraction_material_maker()
    renderer = layers.Renderer(scene, job.scratch, geometry)
    every = space.points(dims)
    points = every[: job.limit]
    metas = []
    for index, point in enumerate(points):
        t0 = time.time()
        space.place(scene, dims, point)
        scene.cycles.seed = out.seed * len(every) + index
        bpy.context.view_layer.update()
        images = _point_images(renderer, job, channels, fraction, out.guides)
        image = f"point_{index:05d}.exr"
        tmp = os.path.join(out.out_dir, f".{image}.tmp{os.getpid()}")
        exr.write(tmp, images, w, h)
        os.replace(tmp, os.path.join(out.out_dir, image))
        metas.append(_point_meta(scene, index, point, dims, image, objects, channels, job.lights))
        progress(f"point {index + 1}/{len(points)}: {renderer.count} renders so far, {time.time() - t0:.1f} s", (index + 1) / len(points))
    _write_set_json(scene, out, dims, objects, job.roles, channels, metas)
    return {
        "set": out.out_dir,
        "points": len(points),
        "spp": out.spp,
        "renders": renderer.count,
        "objects": [{"name": o.name, "role": r} for o, r in zip(objects, job.roles)],
    }


def _point_images(renderer, job, channels, fraction, with_guides):
    """The point's EXR channels (RAYSET.md 5.1) as the scene stands: the full render's
    combined image (and the denoiser's guides), then every object's layers."""
    full = renderer.full()
    images = {f"combined.{name}": layers.rgb(full, "Combined")[..., c] for c, name in enumerate("RGB")}
    if with_guides:
        for name, value in layers.guides(full, job.scene.camera.matrix_world).items():
            for c, ch in enumerate("RGB"):
                images[f"guide.{name}.{ch}"] = value[..., c]
    for obj, role, ch in zip(job.objects, job.roles, channels):
        out = layers.object_layers(renderer, obj, role, _parts(obj, job.objects), fraction)
        for layer, value in out.items():
            for c, name in enumerate(CHANNELS[value.shape[-1]]):
                images[f"object.{ch}.{layer}.{name}"] = value[..., c]
    return images


def _write_set_json(scene, out, dims, objects, roles, channels, points):
    """set.json (RAYSET.md 3), written last and atomically: the set is complete."""
    sigma = scene.pis.filter_sigma_px
    meta = {
        "format": "pis-rayset",
        "version": 1,
        "scene": scene.name,
        "resolution": [scene.render.resolution_x, scene.render.resolution_y],
        "spp": out.spp,
        "filter": {"sigma_px": sigma, "radius_px": cycles.filter_radius(sigma)},
        "renderer": {"name": "Blender Cycles", "version": bpy.app.version_string},
        "scene_file": out.scene_file,
        "space": [d.meta() for d in dims] or [_still()],
        "objects": [
            {"name": o.name, "channel_name": ch, "role": role, "layers": _layer_names(role), "records": False}
            | ({"reflector": o.pis_reflector} if o.pis_reflector else {})
            for o, ch, role in zip(objects, channels, roles)
        ],
        "points": points,
    }
    tmp = os.path.join(out.out_dir, f".set.json.tmp{os.getpid()}")
    with open(tmp, "w") as f:
        json.dump(meta, f, indent=1)
    os.replace(tmp, os.path.join(out.out_dir, "set.json"))


def _still():
    return {"name": "point", "kind": "other", "driver": "still", "periodic": False, "unit": "", "values": [0.0]}


def _point_meta(scene, index, point, dims, image, objects, channels, lights):
    cam = scene.camera
    w, h = scene.render.resolution_x, scene.render.resolution_y
    m = coords.camera_to_gltf(cam.matrix_world)
    yfov = coords.yfov(cam.data, w, h)
    znear, zfar = float(cam.data.clip_start), float(cam.data.clip_end)
    return {
        "index": index,
        "samples": point if dims else [0],
        "values": [float(d.values[i]) for d, i in zip(dims, point)] if dims else [0.0],
        "image": image,
        "rays": None,
        "camera": {
            "world_from_camera": coords.column_major(m),
            "camera_from_world": coords.column_major(coords.np.linalg.inv(m)),
            "projection": coords.projection(yfov, w / h, znear, zfar),
            "yfov": yfov,
            "znear": znear,
            "zfar": zfar,
        },
        "lights": [scene_file.light_entry(light)[1] for light in lights],
        "objects": [
            {"name": ch, "world_from_object": coords.column_major(coords.object_to_gltf(o.matrix_world))}
            for o, ch in zip(objects, channels)
        ],
    }
