//! The radiance seen along given rays, segmented like a camera sample: what texture
//! inference's "ray tracing directly into texture maps" baseline (thesis 3.3) needs. Each
//! ray is traced `samples` times (different fallback seeds) and averaged; rays are traced in
//! fixed chunks, each with its own path context, so the result does not depend on threads.

use glam::Vec3;
use pis_scene::{Frame, Scene};
use rayon::prelude::*;

use crate::integrator::{Integrator, PathContext};
use crate::sampling::hash_keys;
use crate::{TraceError, TraceSettings};

/// What one ray sees, averaged over its samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayRadiance {
    /// The object the first sample hit, if any.
    pub object: Option<u32>,
    pub combined: Vec3,
    /// Radiance from the first diffuse interaction.
    pub diffuse: Vec3,
    /// Everything else leaving the first hit (emission, specular, transmission).
    pub specular: Vec3,
}

/// Rays per parallel chunk.
const CHUNK: usize = 256;

/// Traces every ray `(origin, unit direction)` in the scene evaluated at `frame`.
pub fn trace_rays(
    scene: &Scene,
    frame: &Frame,
    settings: &TraceSettings,
    rays: &[(Vec3, Vec3)],
    samples: u32,
) -> Result<Vec<RayRadiance>, TraceError> {
    if samples == 0 {
        return Err(TraceError::InvalidInput("0 samples per ray".into()));
    }
    if frame.instances.len() != scene.objects.len() {
        return Err(TraceError::InvalidInput(format!(
            "frame places {} objects, the scene has {}",
            frame.instances.len(),
            scene.objects.len()
        )));
    }
    let integrator = Integrator::new(scene, frame, settings);
    let out = rays
        .par_chunks(CHUNK)
        .enumerate()
        .flat_map_iter(|(c, chunk)| {
            let mut ctx = PathContext::default();
            let integrator = &integrator;
            chunk
                .iter()
                .enumerate()
                .map(move |(k, &(origin, dir))| {
                    let mut acc = RayRadiance::default();
                    let seed = hash_keys(&[(c * CHUNK + k) as u64, 0x7261_7973]);
                    for s in 0..samples {
                        ctx.fallback_seed = hash_keys(&[seed, s as u64]);
                        let sample = integrator.camera_sample(origin, dir, false, &mut ctx);
                        if s == 0 {
                            acc.object = sample.object;
                        }
                        acc.combined += sample.combined;
                        acc.diffuse += sample.diffuse;
                        acc.specular += sample.specular;
                    }
                    let k = 1.0 / samples as f32;
                    RayRadiance {
                        combined: acc.combined * k,
                        diffuse: acc.diffuse * k,
                        specular: acc.specular * k,
                        ..acc
                    }
                })
                .collect::<Vec<_>>()
        })
        .collect();
    Ok(out)
}
