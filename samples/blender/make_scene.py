"""Builds samples/blender's scene in Blender and saves it as a .blend with its PIS settings:
a textured floor, a mirror ball, a glass ball and a textured box, lit by a sphere light that
takes 2 places on a path, seen from 4 views on an orbit (2 × 4 points).

    python3 samples/blender/make_scene.py OUT.blend [--resolution 160x120] [--spp 64] [--turning]

With --turning the camera stands still and the box turns and slides over 3 animation frames;
with --corner two mirror walls meeting at a right angle, parts of one reflector, stand behind.

Needs Blender's `bpy` module (python3 -m pip install bpy==4.5.4). The textures are written
as PNG files beside OUT.blend.
"""

import argparse
import math
import os
import sys

import bpy
import numpy as np


def image(path, size, texel):
    """A PNG of `size`² texels, colour texel(u, v) in sRGB 0..1, saved and loaded."""
    v, u = np.mgrid[0:size, 0:size] / size
    rgb = texel(u, v)
    img = bpy.data.images.new(os.path.basename(path), size, size, alpha=False)
    pixels = np.concatenate([rgb, np.ones((size, size, 1))], axis=-1)
    img.pixels.foreach_set(pixels.astype(np.float32).ravel())
    img.filepath_raw = path
    img.file_format = "PNG"
    img.save()
    return img


def material(name, color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5, transmission=0.0, ior=1.5, texture=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Transmission Weight"].default_value = transmission
    bsdf.inputs["IOR"].default_value = ior
    if texture is not None:
        node = m.node_tree.nodes.new("ShaderNodeTexImage")
        node.image = texture
        m.node_tree.links.new(node.outputs["Color"], bsdf.inputs["Base Color"])
    return m


def add(obj, mat):
    obj.data.materials.append(mat)
    return obj


def build(out, resolution, spp, turning, corner):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    folder = os.path.dirname(os.path.abspath(out))
    checker = image(
        os.path.join(folder, "floor.png"), 256,
        lambda u, v: np.where(((np.floor(u * 8) + np.floor(v * 8)) % 2)[..., None] > 0, [0.85, 0.82, 0.75], [0.15, 0.25, 0.45]),
    )
    stripes = image(
        os.path.join(folder, "box.png"), 128,
        lambda u, v: np.where((np.floor(u * 6) % 2)[..., None] > 0, [0.8, 0.3, 0.1], [0.95, 0.85, 0.3]),
    )
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    floor = add(bpy.context.object, material("Floor", texture=checker, roughness=0.7))
    floor.name = "Floor"
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-0.7, 0.3, 0.5), segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    add(bpy.context.object, material("Mirror", color=(0.9, 0.9, 0.9), metallic=1.0, roughness=0.0)).name = "MirrorBall"
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, location=(0.7, -0.4, 0.45), segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    add(bpy.context.object, material("Glass", color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0)).name = "GlassBall"
    bpy.ops.mesh.primitive_cube_add(size=0.7, location=(0.3, 1.0, 0.35), rotation=(0.0, 0.0, math.radians(25)))
    box = add(bpy.context.object, material("Box", texture=stripes, roughness=0.6))
    box.name = "Box"

    bpy.ops.object.light_add(type="POINT", location=(1.5, -1.5, 3.0))
    lamp = bpy.context.object
    lamp.name = "Lamp"
    lamp.data.energy = 400.0
    lamp.data.shadow_soft_size = 0.2
    bpy.ops.curve.primitive_bezier_curve_add()
    path = bpy.context.object
    path.name = "LampPath"
    path.data.splines.clear()
    spline = path.data.splines.new("POLY")
    spline.points.add(1)
    spline.points[0].co = (1.5, -1.5, 3.0, 1.0)
    spline.points[1].co = (-1.5, -1.0, 3.0, 1.0)
    path.hide_render = True

    bpy.ops.object.camera_add()
    cam = bpy.context.object
    cam.data.lens = 35.0
    cam.data.clip_start = 0.05
    cam.data.clip_end = 100.0
    scene = bpy.context.scene
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y = resolution
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.05, 0.06, 0.08, 1.0)
    scene.world = world

    s = scene.pis
    s.spp = spp
    if corner:
        # Two mirror walls meeting at a right angle behind the balls, one reflector: each
        # sees the other (RAYSET.md's local layer).
        for name, loc, rot in (("MirrorLeft", (-1.2, 1.6, 0.6), (math.radians(90), 0, math.radians(45))),
                               ("MirrorRight", (0.4, 2.0, 0.6), (math.radians(90), 0, math.radians(-45)))):
            bpy.ops.mesh.primitive_plane_add(size=1.2, location=loc, rotation=rot)
            wall = add(bpy.context.object, material(name, color=(0.9, 0.9, 0.9), metallic=1.0, roughness=0.0))
            wall.name = name
            wall.pis_reflector = "Corner"
    if turning:
        # The box turns a quarter about Z from frame 1 to 25 and slides 0.4 along X; the
        # camera stays where it was placed; the space is 3 frames.
        cam.location, cam.rotation_euler = (0.0, -4.5, 2.4), (math.radians(62), 0.0, 0.0)
        for frame, angle, x in ((1, 25.0, 0.3), (25, 115.0, 0.7)):
            box.rotation_euler.z, box.location.x = math.radians(angle), x
            box.keyframe_insert("rotation_euler", index=2, frame=frame)
            box.keyframe_insert("location", index=0, frame=frame)
        scene.frame_start, scene.frame_end = 1, 25
        s.frames_on, s.frames_range, s.frames_samples, s.frames_kind = True, (1.0, 25.0), 3, "OBJECT_MOTION"
    else:
        s.light_path_on, s.light_path_light, s.light_path_curve, s.light_path_samples = True, lamp, path, 2
        s.orbit_on, s.orbit_target, s.orbit_radius = True, (0.0, 0.2, 0.4), 4.5
        s.orbit_elevation_deg, s.orbit_azimuth_deg, s.orbit_samples = 28.0, (-20.0, 20.0), 4
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out))


def main():
    import pis_blender

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out")
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--turning", action="store_true", help="a fixed camera and the box turning over 3 animation frames instead")
    parser.add_argument("--corner", action="store_true", help="add two mirror walls meeting at a right angle, one reflector")
    args = parser.parse_args()
    pis_blender.register()
    build(args.out, tuple(int(x) for x in args.resolution.split("x")), args.spp, args.turning, args.corner)


if __name__ == "__main__":
    main()
    # bpy can hang in its exit handlers; the file is saved, so leave at once.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)
