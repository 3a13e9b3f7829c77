"""The add-on's settings: the parameter space on the scene (`scene.pis`), each object's role
and reflector (`object.pis_role`, `object.pis_reflector`)."""

import bpy
from bpy.props import (
    BoolProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)


def _is_light(_self, obj):
    return obj.type == "LIGHT"


def _is_curve(_self, obj):
    return obj.type == "CURVE"


class PisSettings(bpy.types.PropertyGroup):
    output_dir: StringProperty(name="Set folder", subtype="DIR_PATH", default="//pis-set")
    spp: IntProperty(name="Samples", description="Cycles samples per pixel, every pixel", default=64, min=1)
    filter_sigma_px: FloatProperty(
        name="Filter σ", description="The Gaussian pixel filter's σ in pixels (Cycles width 4σ)", default=0.5, min=0.05, max=4.0
    )
    seed: IntProperty(
        name="Seed", description="Cycles' seed of point i is seed × points + i: another seed, an independent render", default=0, min=0
    )
    denoise: EnumProperty(
        name="Denoise",
        description="Render each point as two halves from independent seeds, each at half the samples with the denoiser's guides, and join them with pis-trace denoise: the raw layers and, where the halves estimate it nearer the converged image, a denoised twin of each (RAYSET.md 5.4)",
        items=(
            ("AUTO", "Auto", "Denoise when pis-trace is found, else render the raw set and say so"),
            ("ON", "On", "Denoise; an error without pis-trace"),
            ("OFF", "Off", "The raw set, each point one render at all the samples"),
        ),
        default="AUTO",
    )
    pis_trace: StringProperty(
        name="pis-trace",
        description="The pis-trace program that joins and denoises the halves (empty: pis-trace on the PATH)",
        subtype="FILE_PATH",
        default="",
    )
    caustics: BoolProperty(
        name="Caustics",
        description="Let Cycles trace caustics (light through glass or off mirrors onto diffuse surfaces): PIS plays none, and at a few hundred samples they are fireflies",
        default=False,
    )

    orbit_on: BoolProperty(name="Camera orbit", description="The camera circles a target (a view dimension)")
    orbit_name: StringProperty(name="Name", default="view")
    orbit_target: FloatVectorProperty(name="Target", subtype="XYZ", size=3)
    orbit_radius: FloatProperty(name="Radius", default=5.0, min=0.0)
    orbit_elevation_deg: FloatProperty(name="Elevation °", default=20.0, min=-90.0, max=90.0)
    orbit_azimuth_deg: FloatVectorProperty(
        name="Azimuth °", size=2, default=(-10.0, 10.0), description="First and last azimuth: 0 puts the camera on the target's −Y side, positive turns it towards +X"
    )
    orbit_samples: IntProperty(name="Samples", default=4, min=1)
    orbit_periodic: BoolProperty(name="Periodic", description="A closed loop: the last sample stops one step short")

    light_path_on: BoolProperty(name="Light path", description="A light moves along a curve (a light dimension)")
    light_path_name: StringProperty(name="Name", default="light")
    light_path_light: PointerProperty(name="Light", type=bpy.types.Object, poll=_is_light)
    light_path_curve: PointerProperty(name="Path", type=bpy.types.Object, poll=_is_curve)
    light_path_samples: IntProperty(name="Samples", default=4, min=1)
    light_path_range: FloatVectorProperty(name="Range", size=2, default=(0.0, 1.0), min=0.0, max=1.0)

    frames_on: BoolProperty(name="Animation frames", description="The scene's animation sampled at frames")
    frames_name: StringProperty(name="Name", default="time")
    frames_range: FloatVectorProperty(name="Frames", size=2, default=(1.0, 24.0))
    frames_samples: IntProperty(name="Samples", default=4, min=1)
    frames_kind: EnumProperty(
        name="Kind",
        items=[(k, k.replace("_", " ").title(), "") for k in ("TIME", "OBJECT_MOTION", "LIGHT", "VIEW", "OTHER")],
        default="TIME",
    )


ROLE_ITEMS = [
    ("AUTO", "Auto", "From the material, as pis-scene infers it"),
    ("DIFFUSE", "Diffuse", "One view-independent texture"),
    ("REFLECTIVE", "Reflective", "Diffuse and reflective layers (Fresnel, local, distant)"),
    ("REFRACTIVE", "Refractive", "A lens object"),
]


def register():
    bpy.utils.register_class(PisSettings)
    bpy.types.Scene.pis = PointerProperty(type=PisSettings)
    bpy.types.Object.pis_role = EnumProperty(name="PIS role", items=ROLE_ITEMS, default="AUTO")
    bpy.types.Object.pis_reflector = StringProperty(
        name="Reflector", description="The reflector this object is a part of (empty: its own)"
    )


def unregister():
    del bpy.types.Object.pis_reflector
    del bpy.types.Object.pis_role
    del bpy.types.Scene.pis
    bpy.utils.unregister_class(PisSettings)
