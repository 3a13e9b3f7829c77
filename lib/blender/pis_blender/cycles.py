"""Cycles set up to render what a set records (RAYSET.md 4 and 8): every sample counted
(no adaptive sampling, no clamping, no denoising, no glossy filter), a transparent film (rays
that hit nothing leave black, as pis-trace's background), the Gaussian filter recorded as σ
and R, and the passes the layers are made from, written as a 32-bit uncompressed EXR.
"""

import contextlib
import os
import sys

from . import exr

PASSES = (
    "diffuse_direct",
    "diffuse_indirect",
    "diffuse_color",
    "glossy_direct",
    "glossy_indirect",
    "glossy_color",
)


def filter_width(sigma_px):
    """Cycles' Gaussian filter of width W weighs exp(−2·(6x/(3W))²) over |x| ≤ 3W/2 (the
    table is made three widths wide): σ = W/4 and R = 1.5·W, per axis."""
    return 4.0 * sigma_px


def filter_radius(sigma_px):
    return 1.5 * filter_width(sigma_px)


class Settings:
    """Attributes set for the export and put back afterwards (the user's file is left as it was)."""

    def __init__(self):
        self._saved = []

    def set(self, owner, name, value):
        self._saved.append((owner, name, getattr(owner, name)))
        setattr(owner, name, value)

    def restore(self):
        for owner, name, value in reversed(self._saved):
            setattr(owner, name, value)
        self._saved.clear()


def configure(scene, saved, spp, sigma_px, seed, caustics=False):
    c, r = scene.cycles, scene.render
    for owner, name, value in (
        (r, "engine", "CYCLES"),
        (c, "device", "CPU"),
        (c, "samples", spp),
        (c, "use_adaptive_sampling", False),
        (c, "use_denoising", False),
        (c, "sample_clamp_direct", 0.0),
        (c, "sample_clamp_indirect", 0.0),
        (c, "blur_glossy", 0.0),
        (c, "caustics_reflective", caustics),
        (c, "caustics_refractive", caustics),
        (c, "seed", seed),
        (c, "use_animated_seed", False),
        (c, "pixel_filter_type", "GAUSSIAN"),
        (c, "filter_width", filter_width(sigma_px)),
        (c, "film_exposure", 1.0),
        (c, "film_transparent_glass", False),
        (r, "film_transparent", True),
        (r, "resolution_percentage", 100),
        (r, "pixel_aspect_x", 1.0),
        (r, "pixel_aspect_y", 1.0),
        (r, "use_border", False),
        (r, "use_compositing", False),
        (r, "use_sequencer", False),
        (r.image_settings, "file_format", "OPEN_EXR_MULTILAYER"),
        (r.image_settings, "color_depth", "32"),
        (r.image_settings, "exr_codec", "NONE"),
    ):
        saved.set(owner, name, value)
    layer = scene.view_layers[0]
    for p in PASSES:
        saved.set(layer, "use_pass_" + p, True)
    saved.set(layer, "use_pass_combined", True)
    # The denoiser's guides (Denoising Albedo and Normal); Cycles' own denoiser stays off.
    saved.set(layer.cycles, "denoising_store_passes", True)


def render(scene, path):
    """Renders the scene as it stands into `path` and returns its passes by name
    (`Combined.A`, `DiffDir.R`, ...) as float32 arrays, row 0 at the top."""
    import bpy

    scene.render.filepath = path
    with _quiet():
        bpy.ops.render.render(write_still=True, scene=scene.name)
    channels = exr.read(path)
    os.remove(path)
    prefix = scene.view_layers[0].name + "."
    return {k[len(prefix) :]: v for k, v in channels.items() if k.startswith(prefix)}


@contextlib.contextmanager
def _quiet():
    """Cycles' progress lines (written by C code to file descriptor 1) go to /dev/null."""
    sys.stdout.flush()
    kept = os.dup(1)
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        yield
    finally:
        os.dup2(kept, 1)
        os.close(kept)
        os.close(null)
