//! Segmented layers (thesis 3.1, 5.7, 6.2): what exists per object role, how camera samples
//! accumulate into them, and the images of one parameter point.

use crate::integrator::CameraSample;
use glam::Vec3;
use pis_scene::lens_tree::MAX_TERMS;
use pis_scene::ObjectRole;

/// θc of the confidence image (thesis 6.3.3): 5 degrees.
pub const CONFIDENCE_THRESHOLD_RAD: f32 = 5.0 * std::f32::consts::PI / 180.0;

/// One per-object layer. Every layer except `Coverage` is divided by coverage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LayerKind {
    /// Filtered object mask (channel A).
    Coverage,
    /// Radiance from the first diffuse interaction (RGB).
    Diffuse,
    /// Everything else: emission, specular reflection, transmission (RGB).
    Specular,
    /// Reflective: Fresnel modulation F(n·v) of the specular lobe (RGB).
    Fresnel,
    /// Reflective: incident specular radiance from rays that hit the reflector again (the
    /// object or another part of it), alpha premultiplied (RGBA).
    Local,
    /// Reflective: incident specular radiance with the object transparent after the first
    /// bounce (RGB), defined wherever the object is covered.
    Distant,
    /// Refractive: reflection-first term R·F_R·G_R (RGB).
    Reflection,
    /// Refractive: reflection-first modulation F_R·G_R (RGB).
    ReflectionModulation,
    /// Refractive: confidence of the reflection-first exit rays (Y).
    ReflectionConfidence,
    /// Refractive: refraction-first term T·F_T·G_T (RGB).
    Refraction,
    /// Refractive: refraction-first modulation F_T·G_T (RGB).
    RefractionModulation,
    /// Refractive: confidence of the refraction-first exit rays (Y).
    RefractionConfidence,
    /// Refractive, tree model: the refraction-first term that took the lesser branch
    /// k = 1 or 2 times, its modulation and its confidence (as `Refraction…`).
    Internal(u8, TermPart),
}

/// The lens terms' value layers, in term order (RAYSET.md 5.3).
pub const TERM_VALUES: [LayerKind; MAX_TERMS] = [
    LayerKind::Reflection,
    LayerKind::Refraction,
    LayerKind::Internal(1, TermPart::Value),
    LayerKind::Internal(2, TermPart::Value),
];

/// Which image of a lens term a layer holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TermPart {
    /// The term's radiance × F·G (RGB).
    Value,
    /// F·G (RGB).
    Modulation,
    /// The confidence of its exit rays (Y).
    Confidence,
}

impl LayerKind {
    /// Name used in channel names (`object.<object>.<name>.<channel>`) and set.json.
    pub fn name(self) -> &'static str {
        match self {
            LayerKind::Coverage => "coverage",
            LayerKind::Diffuse => "diffuse",
            LayerKind::Specular => "specular",
            LayerKind::Fresnel => "fresnel",
            LayerKind::Local => "local",
            LayerKind::Distant => "distant",
            LayerKind::Reflection => "reflection",
            LayerKind::ReflectionModulation => "reflection_modulation",
            LayerKind::ReflectionConfidence => "reflection_confidence",
            LayerKind::Refraction => "refraction",
            LayerKind::RefractionModulation => "refraction_modulation",
            LayerKind::RefractionConfidence => "refraction_confidence",
            LayerKind::Internal(1, TermPart::Value) => "refraction_1",
            LayerKind::Internal(1, TermPart::Modulation) => "refraction_1_modulation",
            LayerKind::Internal(1, TermPart::Confidence) => "refraction_1_confidence",
            LayerKind::Internal(_, TermPart::Value) => "refraction_2",
            LayerKind::Internal(_, TermPart::Modulation) => "refraction_2_modulation",
            LayerKind::Internal(_, TermPart::Confidence) => "refraction_2_confidence",
        }
    }

    /// The layer of lens term `t` (as [`LayerKind::term`] numbers them) holding `part`.
    pub fn of_term(t: usize, part: TermPart) -> LayerKind {
        match (t, part) {
            (0, TermPart::Value) => LayerKind::Reflection,
            (0, TermPart::Modulation) => LayerKind::ReflectionModulation,
            (0, TermPart::Confidence) => LayerKind::ReflectionConfidence,
            (1, TermPart::Value) => LayerKind::Refraction,
            (1, TermPart::Modulation) => LayerKind::RefractionModulation,
            (1, TermPart::Confidence) => LayerKind::RefractionConfidence,
            (t, part) => LayerKind::Internal(t.clamp(2, MAX_TERMS - 1) as u8 - 1, part),
        }
    }

    /// The lens term (0 reflection-first, 1 refraction-first, 2 and 3 the tree's
    /// refraction-first terms that took the lesser branch once and twice) and the part of it
    /// the layer holds.
    pub fn term(self) -> Option<(usize, TermPart)> {
        match self {
            LayerKind::Reflection => Some((0, TermPart::Value)),
            LayerKind::ReflectionModulation => Some((0, TermPart::Modulation)),
            LayerKind::ReflectionConfidence => Some((0, TermPart::Confidence)),
            LayerKind::Refraction => Some((1, TermPart::Value)),
            LayerKind::RefractionModulation => Some((1, TermPart::Modulation)),
            LayerKind::RefractionConfidence => Some((1, TermPart::Confidence)),
            LayerKind::Internal(k, part) => Some((1 + k.clamp(1, 2) as usize, part)),
            _ => None,
        }
    }

    /// Channel names of the layer.
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            LayerKind::Coverage => &["A"],
            LayerKind::Local => &["R", "G", "B", "A"],
            LayerKind::ReflectionConfidence
            | LayerKind::RefractionConfidence
            | LayerKind::Internal(_, TermPart::Confidence) => &["Y"],
            _ => &["R", "G", "B"],
        }
    }

    /// The layer with name `name`.
    pub fn from_name(name: &str) -> Option<LayerKind> {
        ALL_LAYERS.iter().copied().find(|l| l.name() == name)
    }

    /// The layers an object of `role` has, in file order, in a set whose lens model has
    /// `lens_terms` terms (2 greedy, up to 4 tree): three layers a term.
    pub fn for_role(role: ObjectRole, lens_terms: usize) -> &'static [LayerKind] {
        use LayerKind::*;
        match role {
            ObjectRole::Diffuse => &[Coverage, Diffuse, Specular],
            ObjectRole::Reflective => &[Coverage, Diffuse, Specular, Fresnel, Local, Distant],
            ObjectRole::Refractive => &ALL_LAYERS[..3 + 3 * lens_terms.clamp(2, MAX_TERMS)],
        }
    }
}

const ALL_LAYERS: [LayerKind; 18] = {
    use LayerKind::*;
    [
        Coverage,
        Diffuse,
        Specular,
        Reflection,
        ReflectionModulation,
        ReflectionConfidence,
        Refraction,
        RefractionModulation,
        RefractionConfidence,
        Internal(1, TermPart::Value),
        Internal(1, TermPart::Modulation),
        Internal(1, TermPart::Confidence),
        Internal(2, TermPart::Value),
        Internal(2, TermPart::Modulation),
        Internal(2, TermPart::Confidence),
        Fresnel,
        Local,
        Distant,
    ]
};

/// A named, multi-channel f32 image, one plane per channel, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerImage {
    /// Full layer name: `combined` or `object.<object>.<layer>`.
    pub name: String,
    /// Channel suffixes ("R", "G", "B", "A", "Y").
    pub channels: Vec<String>,
    pub width: u32,
    pub height: u32,
    /// `planes[c][y * width + x]`.
    pub planes: Vec<Vec<f32>>,
}

impl LayerImage {
    /// A zero image.
    pub fn new(name: String, channels: &[&str], width: u32, height: u32) -> LayerImage {
        let n = width as usize * height as usize;
        LayerImage {
            name,
            channels: channels.iter().map(|c| c.to_string()).collect(),
            width,
            height,
            planes: vec![vec![0.0; n]; channels.len()],
        }
    }

    /// The plane of channel `c` ("R" ...).
    pub fn channel(&self, c: &str) -> Option<&[f32]> {
        self.channels.iter().position(|x| x == c).map(|i| self.planes[i].as_slice())
    }

    /// RGB at pixel (x, y) (missing channels read 0).
    pub fn rgb(&self, x: u32, y: u32) -> Vec3 {
        let i = (y * self.width + x) as usize;
        let g = |c| self.channel(c).map_or(0.0, |p| p[i]);
        Vec3::new(g("R"), g("G"), g("B"))
    }

    /// The single value of channel `c` at (x, y), 0 when absent.
    pub fn value(&self, c: &str, x: u32, y: u32) -> f32 {
        self.channel(c).map_or(0.0, |p| p[(y * self.width + x) as usize])
    }
}

/// All images of one parameter point.
#[derive(Clone, Debug, PartialEq)]
pub struct PointImages {
    pub width: u32,
    pub height: u32,
    /// `combined` first, then every object's layers in object and [`LayerKind::for_role`] order.
    pub layers: Vec<LayerImage>,
}

impl PointImages {
    /// The layer named `name` (`combined`, `object.vase.diffuse`).
    pub fn layer(&self, name: &str) -> Option<&LayerImage> {
        self.layers.iter().find(|l| l.name == name)
    }

    /// The layer `kind` of the object whose channel name is `object`.
    pub fn object_layer(&self, object: &str, kind: LayerKind) -> Option<&LayerImage> {
        self.layer(&object_layer_name(object, kind))
    }
}

/// `object.<object>.<layer>`.
pub fn object_layer_name(object: &str, kind: LayerKind) -> String {
    format!("object.{object}.{}", kind.name())
}

/// Per-pixel, per-object sums of camera samples.
#[derive(Clone, Debug, Default)]
pub struct ObjectAccum {
    pub object: u32,
    pub count: u32,
    pub diffuse: Vec3,
    pub specular: Vec3,
    pub fresnel: Vec3,
    pub local: Vec3,
    pub local_alpha: f32,
    pub distant: Vec3,
    /// Sums of term values and modulations: reflection-first, refraction-first, and the
    /// tree's refraction-first terms with one and two internal reflections.
    pub term_value: [Vec3; MAX_TERMS],
    pub term_modulation: [Vec3; MAX_TERMS],
    /// Exit directions per term (for the confidence image).
    pub exit_dirs: [Vec<Vec3>; MAX_TERMS],
}

/// Everything one pixel accumulates.
#[derive(Clone, Debug, Default)]
pub struct PixelAccum {
    pub samples: u32,
    pub combined: Vec3,
    pub objects: Vec<ObjectAccum>,
    /// Sums of the denoiser's guides (renders that denoise only).
    pub albedo: Vec3,
    pub normal: Vec3,
}

impl PixelAccum {
    /// Adds one camera sample (in sample order; the sums are order-dependent only within
    /// a pixel, which is always traversed in the same order).
    pub fn add(&mut self, s: &CameraSample) {
        self.samples += 1;
        self.combined += s.combined;
        self.albedo += s.guide.albedo;
        self.normal += s.guide.normal;
        let Some(o) = s.object else { return };
        let idx = match self.objects.iter().position(|a| a.object == o) {
            Some(i) => i,
            None => {
                self.objects.push(ObjectAccum { object: o, ..Default::default() });
                self.objects.len() - 1
            }
        };
        let a = &mut self.objects[idx];
        a.count += 1;
        a.diffuse += s.diffuse;
        a.specular += s.specular;
        if let Some(r) = &s.reflective {
            a.fresnel += r.fresnel;
            a.local += r.local * r.local_alpha;
            a.local_alpha += r.local_alpha;
            a.distant += r.distant;
        }
        if let Some(terms) = &s.lens {
            for (k, t) in terms.iter().enumerate() {
                a.term_value[k] += t.modulation * t.radiance;
                a.term_modulation[k] += t.modulation;
                if let Some((_, d)) = t.exit {
                    a.exit_dirs[k].push(d);
                }
            }
        }
    }
}

/// The denoiser's guide images of a point: `guide.albedo` and `guide.normal` (the mean of the
/// pixel's samples; RGB; the normal not renormalised, as the denoiser expects it filtered).
pub fn resolve_guides(pixels: &[PixelAccum], width: u32, height: u32) -> [LayerImage; 2] {
    let mut albedo = LayerImage::new("guide.albedo".into(), &["R", "G", "B"], width, height);
    let mut normal = LayerImage::new("guide.normal".into(), &["R", "G", "B"], width, height);
    for (i, px) in pixels.iter().enumerate() {
        let n = px.samples.max(1) as f32;
        for c in 0..3 {
            albedo.planes[c][i] = px.albedo[c] / n;
            normal.planes[c][i] = px.normal[c] / n;
        }
    }
    [albedo, normal]
}

/// Confidence 1 − min(θm², θc²)/θc² where θm is the largest angle between any two of `dirs`.
pub fn confidence(dirs: &[Vec3]) -> f32 {
    let mut min_dot = 1.0f32;
    for (i, a) in dirs.iter().enumerate() {
        for b in &dirs[i + 1..] {
            min_dot = min_dot.min(a.dot(*b));
        }
    }
    let theta = min_dot.clamp(-1.0, 1.0).acos();
    let tc2 = CONFIDENCE_THRESHOLD_RAD * CONFIDENCE_THRESHOLD_RAD;
    1.0 - (theta * theta).min(tc2) / tc2
}

/// Fills the images of one point from per-pixel accumulators (row-major).
/// `objects` gives each object's channel name and role, in scene order.
pub fn resolve(
    pixels: &[PixelAccum],
    width: u32,
    height: u32,
    objects: &[(String, ObjectRole)],
    lens_terms: usize,
) -> PointImages {
    let mut layers = vec![LayerImage::new("combined".into(), &["R", "G", "B"], width, height)];
    let mut first_layer = Vec::with_capacity(objects.len());
    for (name, role) in objects {
        first_layer.push(layers.len());
        for &k in LayerKind::for_role(*role, lens_terms) {
            layers.push(LayerImage::new(object_layer_name(name, k), k.channels(), width, height));
        }
    }
    let put = |img: &mut LayerImage, i: usize, v: Vec3| {
        for (c, x) in v.to_array().into_iter().enumerate().take(img.planes.len()) {
            img.planes[c][i] = x;
        }
    };
    for (i, px) in pixels.iter().enumerate() {
        let n = px.samples.max(1) as f32;
        put(&mut layers[0], i, px.combined / n);
        for a in &px.objects {
            let Some((_, role)) = objects.get(a.object as usize) else { continue };
            let base = first_layer[a.object as usize];
            let c = a.count.max(1) as f32;
            for (j, &k) in LayerKind::for_role(*role, lens_terms).iter().enumerate() {
                let img = &mut layers[base + j];
                match k {
                    LayerKind::Coverage => img.planes[0][i] = a.count as f32 / n,
                    LayerKind::Diffuse => put(img, i, a.diffuse / c),
                    LayerKind::Specular => put(img, i, a.specular / c),
                    LayerKind::Fresnel => put(img, i, a.fresnel / c),
                    LayerKind::Local => {
                        put(img, i, a.local / c);
                        img.planes[3][i] = a.local_alpha / c;
                    }
                    LayerKind::Distant => put(img, i, a.distant / c),
                    _ => match k.term() {
                        Some((t, TermPart::Value)) => put(img, i, a.term_value[t] / c),
                        Some((t, TermPart::Modulation)) => put(img, i, a.term_modulation[t] / c),
                        Some((t, TermPart::Confidence)) => {
                            img.planes[0][i] = confidence(&a.exit_dirs[t])
                        }
                        None => {}
                    },
                }
            }
        }
    }
    PointImages { width, height, layers }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn confidence_falls_to_zero_at_five_degrees() {
        let a = Vec3::Z;
        assert_eq!(confidence(&[a, a, a]), 1.0);
        let b = glam::Quat::from_rotation_x(2.5f32.to_radians()) * a;
        assert!((confidence(&[a, b]) - 0.75).abs() < 1e-3);
        let c = glam::Quat::from_rotation_x(6f32.to_radians()) * a;
        assert_eq!(confidence(&[a, b, c]), 0.0);
        assert_eq!(
            LayerKind::from_name("refraction_modulation"),
            Some(LayerKind::RefractionModulation)
        );
    }

    #[test]
    fn every_term_layer_is_named_by_its_term_and_part() {
        for &k in LayerKind::for_role(ObjectRole::Refractive, MAX_TERMS) {
            if let Some((t, part)) = k.term() {
                assert_eq!(LayerKind::of_term(t, part), k, "{}", k.name());
            }
        }
        assert_eq!(LayerKind::of_term(3, TermPart::Value).name(), "refraction_2");
    }
}
