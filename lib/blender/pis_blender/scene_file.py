"""The scene pis-pack reads beside the set: the glTF (Blender's exporter) and a scene.toml
(docs/SCENE.md) that gives the same cameras, lights (radiometric units, with their radius),
world light, object roles and parameter space that Cycles rendered.

Lights are written into scene.toml, not the glTF: the exporter's default converts watts to
photometric units (683 lm/W) and it drops a point light's radius. Cycles' point or spot light of
power P watts has radiant intensity P/(4π) W/sr, a sun of strength S irradiance S W/m²: PIS's
`intensity` (radiance = colour × intensity) in the same units.
"""

import json
import math
import os

from . import coords


class ExportError(Exception):
    """A scene the add-on cannot export as it stands, saying what to change."""


def export_gltf(path, with_animation, with_camera):
    import bpy

    bpy.ops.export_scene.gltf(
        filepath=path,
        export_format="GLTF_SEPARATE",
        use_renderable=True,
        export_cameras=with_camera,
        export_lights=False,
        export_apply=True,
        export_yup=True,
        export_extras=False,
        export_animations=with_animation,
        export_animation_mode="SCENE",
        export_anim_slide_to_zero=True,
        export_frame_range=True,
        export_force_sampling=True,
    )


def gltf_objects(path):
    """The names of the glTF's objects in pis-scene's order: nodes with a mesh reachable from
    the default scene, by node index (lib/scene/src/gltf_load.rs)."""
    with open(path) as f:
        doc = json.load(f)
    nodes = doc.get("nodes", [])
    scene = doc.get("scenes", [{}])[doc.get("scene", 0)]
    reached, stack = set(), list(scene.get("nodes", []))
    while stack:
        n = stack.pop()
        reached.add(n)
        stack.extend(nodes[n].get("children", []))
    names = [nodes[n].get("name", f"node{n}") for n in sorted(reached) if "mesh" in nodes[n]]
    animations = [a.get("name", f"animation{i}") for i, a in enumerate(doc.get("animations", []))]
    return names, animations


def channel_names(names):
    """RAYSET.md 3.2's channel names, as pis-trace makes them."""
    out = []
    for i, name in enumerate(names):
        s = "".join(c if (c.isascii() and c.isalnum()) or c in "_-" else "_" for c in name)
        s = s or f"object{i}"
        if s in out:
            s = f"{s}_{i}"
        out.append(s)
    return out


def role(obj):
    """The object's role: its setting, or inferred from its Principled BSDF as pis-scene does
    from the glTF's material (transmission > 0: refractive; metallic ≥ 0.5 and roughness ≤ 0.3,
    or roughness < 0.1: reflective)."""
    if obj.pis_role != "AUTO":
        return obj.pis_role.lower()
    best = "diffuse"
    for slot in obj.material_slots:
        node = _principled(slot.material)
        if node is None:
            continue
        transmission, metallic, roughness = (
            float(node.inputs[name].default_value) for name in ("Transmission Weight", "Metallic", "Roughness")
        )
        if transmission > 0:
            return "refractive"
        if (metallic >= 0.5 and roughness <= 0.3) or roughness < 0.1:
            best = "reflective"
    return best


def _principled(material):
    if material is None or not material.use_nodes:
        return None
    return next((n for n in material.node_tree.nodes if n.type == "BSDF_PRINCIPLED"), None)


def light_entry(obj):
    """A light as scene.toml's `[[light]]` table and RAYSET.md 3.3's per-point entry."""
    data, m = obj.data, coords.matrix(obj.matrix_world)
    position = coords.point_to_gltf(m[:3, 3])
    d = m[:3, :3] @ [0.0, 0.0, -1.0]
    direction = coords.point_to_gltf(d / max(float((d @ d) ** 0.5), 1e-30))
    color = [float(c) for c in data.color]
    if data.type in ("POINT", "SPOT"):
        intensity = data.energy / (4.0 * math.pi)
    elif data.type == "SUN":
        intensity = float(data.energy)
    else:
        raise ExportError(f"light {obj.name}: {data.type.lower()} lights are not supported (use point, spot or sun)")
    radius = float(data.shadow_soft_size) if data.type == "POINT" else 0.0
    kind = {"POINT": "sphere" if radius > 0 else "point", "SPOT": "spot", "SUN": "directional"}[data.type]
    table = {"name": obj.name, "kind": kind, "color": color, "intensity": intensity}
    if kind != "directional":
        table["position"] = position
    if kind in ("spot", "directional"):
        table["direction"] = direction
    if kind == "sphere":
        table["radius"] = radius
    if kind == "spot":
        outer = math.degrees(data.spot_size) / 2.0
        table["outer_cone_deg"] = outer
        table["inner_cone_deg"] = outer * (1.0 - data.spot_blend)
    point = {
        "name": obj.name,
        "kind": "point" if kind == "sphere" else kind,
        "position": position,
        "direction": direction,
        "radiance": [c * intensity for c in color],
        "radius": radius,
    }
    return table, point


def world_light(scene):
    """The world as `[environment]`: a uniform Background colour × strength, or None for black."""
    world = scene.world
    if world is None:
        return None
    if not world.use_nodes:
        color = [float(c) for c in world.color]
    else:
        out = next((n for n in world.node_tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
        link = out.inputs["Surface"].links[0] if out is not None and out.inputs["Surface"].is_linked else None
        if link is None:
            return None
        bg = link.from_node
        if bg.type != "BACKGROUND" or bg.inputs["Color"].is_linked or bg.inputs["Strength"].is_linked:
            raise ExportError(
                f"world {world.name}: its shader is not a uniform Background colour; PIS's "
                "[environment] from Blender takes a Background node with an unlinked colour and strength"
            )
        strength = float(bg.inputs["Strength"].default_value)
        color = [float(c) * strength for c in bg.inputs["Color"].default_value[:3]]
    return None if max(color) <= 0 else {"color": color}


def camera_table(scene, orbit_on, animated):
    cam = scene.camera
    data = cam.data
    if data.type != "PERSP":
        raise ExportError(f"camera {cam.name}: only perspective cameras are supported")
    if data.shift_x != 0 or data.shift_y != 0:
        raise ExportError(f"camera {cam.name}: lens shift is not supported (set Shift X and Y to 0)")
    w, h = scene.render.resolution_x, scene.render.resolution_y
    table = {
        "yfov_deg": math.degrees(coords.yfov(data, w, h)),
        "znear": float(data.clip_start),
        "zfar": float(data.clip_end),
    }
    if animated and not orbit_on:
        table["node"] = cam.name
    elif not orbit_on:
        m = coords.camera_to_gltf(cam.matrix_world)
        eye = m[:3, 3]
        table["eye"] = [float(x) for x in eye]
        table["target"] = [float(x) for x in eye - m[:3, 2]]
        table["up"] = [float(x) for x in m[:3, 1]]
    return table


def write_toml(path, scene_name, gltf_name, resolution, spp, camera, objects, lights, environment, dims):
    lines = [
        "# Written by the PIS Blender add-on (lib/blender): the scene Cycles rendered, for pis-pack.",
        f"name = {_value(scene_name)}",
        f"gltf = {_value(gltf_name)}",
        f"resolution = {_value(list(resolution))}",
        f"spp = {spp}",
        "",
        "[camera]",
    ]
    lines += [f"{k} = {_value(v)}" for k, v in camera.items()]
    for name, table in objects:
        lines += ["", f"[object.{_value(name)}]"] + [f"{k} = {_value(v)}" for k, v in table.items()]
    for table in lights:
        lines += ["", "[[light]]"] + [f"{k} = {_value(v)}" for k, v in table.items()]
    if environment:
        lines += ["", "[environment]"] + [f"{k} = {_value(v)}" for k, v in environment.items()]
    for d in dims:
        lines += ["", "[[dimension]]"] + [f"{k} = {_value(v)}" for k, v in d.table.items()]
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, path)


def _value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ExportError(f"a value is not finite: {v}")
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return _value(float(v))
