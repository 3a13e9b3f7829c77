//! An object's shading constants (SPEC.md 6.4: f0, ior, absorption) from its material, by
//! the formulas the tracer shades with ([`pis_trace::material::ShadingMaterial`]).
//!
//! An object with several materials is described by the one covering the largest surface
//! area of its mesh (object space; the first of equal ones). A texture counts as the mean of
//! its texels ([`pis_scene::material::mean_material`]: base colour × its texture's mean,
//! metallic × the metallic-roughness texture's mean B): the constants are per object, not
//! per surface point.

use glam::Vec3;
use pis_format::Shading;
use pis_scene::material::mean_material;
use pis_scene::{Material, Scene};
use pis_trace::material::ShadingMaterial;

/// The shading constants of object `o` of `scene`: those of its largest material
/// ([`dominant_material`]); [`Material::default`] where a primitive names no material, as
/// the tracer shades it.
pub fn object_shading(scene: &Scene, o: usize) -> Shading {
    let default = Material::default();
    let material =
        dominant_material(scene, o).and_then(|m| scene.materials.get(m)).unwrap_or(&default);
    material_shading(scene, material)
}

/// The shading constants of `material`:
///
/// - f0 = f0_dielectric · (1 − metallic) · specular + base · metallic, linear RGB clamped to
///   [0, 1], with the tracer's f0_dielectric (((ior − 1)/(ior + 1))² × specular colour), and
///   base and metallic of the material with its textures' means. The tracer's opaque
///   Fresnel is specular · (1 − metallic) · Schlick(f0_dielectric) + metallic · Schlick(base);
///   Schlick's approximation is affine in F0, so Schlick(f0) reproduces it exactly when the
///   specular factor is 1 (as it is without KHR_materials_specular), and otherwise differs
///   only towards grazing angles.
/// - ior: KHR_materials_ior (1.5 where absent or below 1).
/// - absorption: KHR_materials_volume's Beer–Lambert coefficients, −ln(attenuation colour) /
///   attenuation distance; 0 without a finite attenuation distance.
pub fn material_shading(scene: &Scene, material: &Material) -> Shading {
    let flat = mean_material(material, &scene.textures);
    let s = ShadingMaterial::at(scene, &flat, glam::Vec2::ZERO);
    let f0 = s.f0_dielectric * ((1.0 - s.metallic) * s.specular) + s.base * s.metallic;
    Shading {
        f0: f0.to_array().map(|v| if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 }),
        ior: s.ior,
        absorption: s.sigma_a.to_array().map(|v| if v > 0.0 { v.min(f32::MAX) } else { 0.0 }),
    }
}

/// The material covering the largest surface area of object `o`'s primitives (object
/// space; the first of equal areas); `None` for an object without primitives.
pub fn dominant_material(scene: &Scene, o: usize) -> Option<usize> {
    let mut area: Vec<(usize, f64)> = Vec::new();
    for p in &scene.objects[o].primitives {
        let a: f64 = p
            .indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]]
                    .map(|i| p.positions.get(i as usize).copied().unwrap_or(Vec3::ZERO));
                0.5 * (b - a).cross(c - a).length() as f64
            })
            .sum();
        match area.iter_mut().find(|(m, _)| *m == p.material) {
            Some(e) => e.1 += a,
            None => area.push((p.material, a)),
        }
    }
    area.into_iter()
        .fold(None, |best: Option<(usize, f64)>, (m, a)| match best {
            Some((_, b)) if b >= a => best,
            _ => Some((m, a)),
        })
        .map(|(m, _)| m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;
    use pis_scene::{ObjectRole, Primitive, SceneObject, TextureImage, TextureRef};

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        a.iter().zip(&b).all(|(a, b)| (a - b).abs() < 1e-6)
    }

    /// A triangle of area `scale² / 2` with material `material`.
    fn triangle(scale: f32, material: usize) -> Primitive {
        Primitive {
            positions: vec![Vec3::ZERO, Vec3::X * scale, Vec3::Y * scale],
            normals: vec![Vec3::Z; 3],
            uvs: vec![Vec2::ZERO; 3],
            indices: vec![0, 1, 2],
            material,
            ..Primitive::default()
        }
    }

    fn scene(materials: Vec<Material>, primitives: Vec<Primitive>) -> Scene {
        Scene {
            materials,
            objects: vec![SceneObject {
                name: "o".into(),
                role: ObjectRole::Reflective,
                reflector: None,
                primitives,
            }],
            ..Scene::default()
        }
    }

    #[test]
    fn a_glossy_dielectric_has_the_f0_of_its_ior() {
        let m = Material { metallic: 0.0, ior: 2.0, ..Material::default() };
        let s = material_shading(&Scene::default(), &m);
        let r0 = (1.0f32 / 3.0).powi(2);
        assert!(close(s.f0, [r0; 3]), "{:?}", s.f0);
        assert_eq!((s.ior, s.absorption), (2.0, [0.0; 3]));
    }

    #[test]
    fn f0_mixes_the_dielectric_and_the_base_colour_by_metallic() {
        let m = Material {
            base_color: [0.8, 0.5, 0.2, 1.0],
            metallic: 0.25,
            specular: 0.5,
            specular_color: [1.0, 0.5, 1.0],
            ..Material::default()
        };
        let s = material_shading(&Scene::default(), &m);
        let want =
            [0, 1, 2].map(|c| 0.04 * m.specular_color[c] * 0.75 * 0.5 + m.base_color[c] * 0.25);
        assert!(close(s.f0, want), "{:?} vs {want:?}", s.f0);
    }

    #[test]
    fn f0_reproduces_the_tracers_fresnel_with_a_unit_specular_factor() {
        let m = Material {
            base_color: [0.9, 0.6, 0.3, 1.0],
            metallic: 0.4,
            ior: 1.7,
            ..Material::default()
        };
        let s = material_shading(&Scene::default(), &m);
        let traced = ShadingMaterial::at(&Scene::default(), &m, Vec2::ZERO);
        for cos in [1.0f32, 0.7, 0.3, 0.05] {
            let want = traced.fresnel(cos);
            let got = pis_trace::material::schlick(Vec3::from(s.f0), cos);
            assert!((want - got).abs().max_element() < 1e-6, "cos {cos}: {got} vs {want}");
        }
    }

    #[test]
    fn absorption_is_beer_lambert_of_the_attenuation() {
        let m = Material {
            transmission: 1.0,
            metallic: 0.0,
            attenuation_color: [0.5, 1.0, 0.25],
            attenuation_distance: 2.0,
            ..Material::default()
        };
        let s = material_shading(&Scene::default(), &m);
        let want = [0.5f32, 1.0, 0.25].map(|c| -c.ln() / 2.0);
        assert!(close(s.absorption, want), "{:?} vs {want:?}", s.absorption);
    }

    #[test]
    fn a_base_colour_texture_counts_as_its_mean() {
        let mut sc = Scene::default();
        sc.textures.push(TextureImage {
            width: 2,
            height: 1,
            texels: vec![[1.0, 0.0, 0.5, 1.0], [0.0, 0.0, 0.5, 1.0]],
        });
        let m = Material {
            base_color: [0.8, 1.0, 1.0, 1.0],
            base_color_texture: Some(TextureRef::new(0)),
            metallic: 1.0,
            ..Material::default()
        };
        let s = material_shading(&sc, &m);
        assert!(close(s.f0, [0.4, 0.0, 0.5]), "{:?}", s.f0);
    }

    #[test]
    fn a_metallic_roughness_texture_counts_as_its_mean_metallic() {
        // metallicFactor 1 with a map half dielectric, half metal: metallic ½, not 1.
        let mut sc = Scene::default();
        sc.textures.push(TextureImage {
            width: 2,
            height: 1,
            texels: vec![[0.0, 1.0, 0.0, 1.0], [0.0, 1.0, 1.0, 1.0]],
        });
        let m = Material {
            base_color: [0.8, 0.8, 0.8, 1.0],
            metallic: 1.0,
            metallic_roughness_texture: Some(TextureRef::new(0)),
            ..Material::default()
        };
        let s = material_shading(&sc, &m);
        assert!(close(s.f0, [0.04 * 0.5 + 0.8 * 0.5; 3]), "{:?}", s.f0);
    }

    #[test]
    fn the_material_covering_the_largest_area_describes_the_object() {
        let glass = Material { transmission: 1.0, metallic: 0.0, ior: 1.33, ..Material::default() };
        let steel =
            Material { metallic: 1.0, base_color: [0.6, 0.6, 0.6, 1.0], ..Material::default() };
        // Material 0 in two small triangles (area 2 · 0.5), material 1 in one of area 2.
        let sc =
            scene(vec![glass, steel], vec![triangle(1.0, 0), triangle(2.0, 1), triangle(1.0, 0)]);
        assert_eq!(dominant_material(&sc, 0), Some(1));
        assert!(close(object_shading(&sc, 0).f0, [0.6; 3]));
        // Equal areas: the first.
        let sc = scene(
            vec![Material::default(), Material::default()],
            vec![triangle(1.0, 1), triangle(1.0, 0)],
        );
        assert_eq!(dominant_material(&sc, 0), Some(1));
        // No primitives, or a material index out of range: the default material.
        let sc = scene(vec![], vec![]);
        assert_eq!(dominant_material(&sc, 0), None);
        assert_eq!(object_shading(&sc, 0), material_shading(&sc, &Material::default()));
    }
}
