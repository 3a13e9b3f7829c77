"""One parameter point's layers (RAYSET.md 4, 5.3) from Cycles renders.

Segmentation is exact at edges: each object is rendered on its own with every other object
a holdout (Object > Visibility > Holdout). A holdout stops only camera rays, so the object's
camera samples follow the very paths of the full render (same seed), while the others still
shadow it and appear in its reflections. Its render's alpha is then Σw·m_o/Σw, the coverage,
and its colour passes Σw·m_o·v/Σw, which divided by the coverage are the layers: no
neighbour's colour enters an edge pixel.

- diffuse  = (DiffDir + DiffInd) · DiffCol, over coverage;
- specular = Combined − diffuse (emission, glossy, transmission: everything else), over coverage;
- fresnel  = GlossCol over coverage (reflective objects);
- distant  = GlossDir + GlossInd of a render where the object's reflector is invisible to
  glossy rays (Cycles' light passes are already divided by their colour pass: incident light);
- local    = A: GlossDir + GlossInd of a render where every camera ray on the object is
  reflected by a white glossy lobe of its roughness and the reflector's parts are the only
  light (emission 1, every other surface black), i.e. the fraction of reflected rays that
  meet the reflector again; RGB = incident − (1 − A)·distant, the incident light of the
  regular render less what arrives past the reflector (premultiplied by A, at least 0).
"""

import numpy as np

from . import coords, cycles

EPS = 1e-6


def rgb(p, name):
    return np.stack([p[name + ".R"], p[name + ".G"], p[name + ".B"]], axis=-1)


def over_coverage(value, coverage):
    """`value` divided by `coverage` where it is above 0, 0 elsewhere."""
    out = np.zeros_like(value)
    mask = coverage > EPS
    out[mask] = value[mask] / coverage[mask][:, None]
    return out


class Renderer:
    """Renders one point's passes into a scratch folder."""

    def __init__(self, scene, scratch, objects):
        self.scene, self.scratch, self.objects = scene, scratch, objects
        self.count = 0

    def render(self):
        """The passes of the scene as it stands."""
        self.count += 1
        return cycles.render(self.scene, f"{self.scratch}/render_{self.count}.exr")

    def full(self):
        """The full render's passes."""
        return self.render()

    def alone(self, target, saved):
        """The passes of `target` with every other object a holdout."""
        for o in self.objects:
            saved.set(o, "is_holdout", o is not target)
        return self.render()


def guides(p, camera_matrix):
    """The denoiser's guides (RAYSET.md 5.4) from a render's Denoising Data passes: the albedo,
    and the normal turned from Cycles' camera space into glTF's world."""
    normal = np.stack([p["Denoising Normal." + c] for c in "XYZ"], axis=-1)
    return {"albedo": rgb(p, "Denoising Albedo"), "normal": coords.cycles_normal_to_gltf(normal, camera_matrix)}


def object_layers(renderer, obj, role, parts, fraction_material):
    """The layers of `obj` (set layer name → array) at the point the scene stands at. `parts`
    are the objects of its reflector; `fraction_material` makes the local-fraction material
    of a roughness."""
    saved = cycles.Settings()
    try:
        p = renderer.alone(obj, saved)
        coverage = np.clip(p["Combined.A"], 0.0, 1.0)
        diffuse = (rgb(p, "DiffDir") + rgb(p, "DiffInd")) * rgb(p, "DiffCol")
        specular = np.maximum(rgb(p, "Combined") - diffuse, 0.0)
        out = {
            "coverage": coverage[..., None],
            "diffuse": over_coverage(diffuse, coverage),
            "specular": over_coverage(specular, coverage),
        }
        if role == "reflective":
            incident = rgb(p, "GlossDir") + rgb(p, "GlossInd")
            out["fresnel"] = over_coverage(rgb(p, "GlossCol"), coverage)
            distant = _distant(renderer, parts)
            alpha = _local_fraction(renderer, obj, parts, fraction_material)
            local = np.maximum(incident - (1.0 - alpha)[..., None] * distant, 0.0)
            mask = (coverage > EPS)[..., None]
            out["local"] = np.concatenate([local, alpha[..., None]], axis=-1) * mask
            out["distant"] = distant * mask
        return out
    finally:
        saved.restore()


def _distant(renderer, parts):
    inner = cycles.Settings()
    try:
        for o in parts:
            inner.set(o, "visible_glossy", False)
        p = renderer.render()
    finally:
        inner.restore()
    return rgb(p, "GlossDir") + rgb(p, "GlossInd")


def _local_fraction(renderer, obj, parts, fraction_material):
    scene = renderer.scene
    inner = cycles.Settings()
    try:
        for o in renderer.objects:
            inner.set(o, "pass_index", 1 if o in parts else 0)
        for light in (o for o in scene.objects if o.type == "LIGHT"):
            inner.set(light, "hide_render", True)
        inner.set(scene, "world", None)
        inner.set(scene.view_layers[0], "material_override", fraction_material(roughness(obj)))
        p = renderer.render()
    finally:
        inner.restore()
    return np.clip(p["GlossDir.R"] + p["GlossInd.R"], 0.0, 1.0)


def roughness(obj):
    """The roughness of the object's first Principled BSDF (its input's value; 0 without one)."""
    for slot in obj.material_slots:
        m = slot.material
        if m is None or not m.use_nodes:
            continue
        for node in m.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED":
                return float(node.inputs["Roughness"].default_value)
    return 0.0


def fraction_material_maker():
    """A function of roughness → the local-fraction material (made once per roughness)."""
    import bpy

    made = {}

    def make(r):
        key = round(r, 4)
        if key in made:
            return made[key]
        m = bpy.data.materials.new(f"PIS local fraction {key}")
        m.use_nodes = True
        nodes, links = m.node_tree.nodes, m.node_tree.links
        nodes.clear()
        out = nodes.new("ShaderNodeOutputMaterial")
        path = nodes.new("ShaderNodeLightPath")
        info = nodes.new("ShaderNodeObjectInfo")
        is_part = nodes.new("ShaderNodeMath")
        is_part.operation = "COMPARE"
        is_part.inputs[1].default_value = 1.0
        is_part.inputs[2].default_value = 0.5
        emission = nodes.new("ShaderNodeEmission")
        emission.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        glossy = nodes.new("ShaderNodeBsdfGlossy")
        glossy.distribution = "GGX"
        glossy.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        glossy.inputs["Roughness"].default_value = r
        mix = nodes.new("ShaderNodeMixShader")
        links.new(info.outputs["Object Index"], is_part.inputs[0])
        links.new(is_part.outputs[0], emission.inputs["Strength"])
        links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
        links.new(emission.outputs[0], mix.inputs[1])
        links.new(glossy.outputs[0], mix.inputs[2])
        links.new(mix.outputs[0], out.inputs["Surface"])
        made[key] = m
        return m

    return make
