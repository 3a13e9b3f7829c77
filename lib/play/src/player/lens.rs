//! Lens objects in the player's frame (thesis 6.4): per frame each one's vertex rays traced
//! through the object at its transform (on the workers), its tessellation refined where they
//! diverge (or the last frame's drawn again when nothing it depends on changed), its lens
//! model's terms' corner buffers built once per shell geometry, and the lens draws of the
//! frame's parameter samples.

use std::time::Instant;

use rayon::prelude::*;

use pis_compile::hybrid::{tessellate_timed, HybridView, Term};
use pis_compile::shell::Shell;
use pis_format::PisReader;

use super::lens_ahead::{LensAhead, LensRequest};
use super::objects::{content, LensState, TessellationKey};
use super::plan::Plan;
use super::resident::{GpuTexture, Textures};
use crate::error::PlayError;
use crate::frame::hybrid::{corner_buffer, term_corners, LensDraw};
use crate::gpu::Gpu;

/// A frame's lens work: per lens object and shell geometry, its terms' corner buffers
/// (and their corner counts); the time it took, its rays and triangles.
pub(super) struct LensWork {
    pub(super) sets: Vec<LensSet>,
    pub(super) ms: f64,
    pub(super) rays: u64,
    pub(super) triangles: u64,
    /// Tessellations found made ahead ([`LensAhead`]).
    pub(super) traced_ahead: u64,
}

/// What lens object `draw`'s tessellation in the frame of `plan` depends on.
pub(super) fn tessellation_key(
    plan: &Plan,
    draw: usize,
    size: (u32, u32),
    tau_px: f32,
) -> TessellationKey {
    (plan.worlds[draw], plan.eye, plan.clip_from_world, size, tau_px)
}

/// The tessellations the frames of `plans` (expected next) need that `states` (the lens
/// objects by draw index) have not made: one request per lens object and key, in order.
pub(super) fn lens_requests<'a>(
    plans: &[Plan],
    state_of: impl Fn(usize) -> Option<&'a LensState>,
    size: (u32, u32),
    tau_px: f32,
) -> Vec<LensRequest> {
    let mut wanted: Vec<LensRequest> = Vec::new();
    for plan in plans {
        for r in &plan.lenses {
            let key = tessellation_key(plan, r.draw, size, tau_px);
            let Some(state) = state_of(r.draw) else { continue };
            let made = state.tessellated.as_ref().is_some_and(|(k, _)| *k == key);
            if !made && !wanted.contains(&(r.draw, key)) {
                wanted.push((r.draw, key));
            }
        }
    }
    wanted
}

/// One lens object's terms for one shell geometry: the object's draw index, the shells, and
/// per term of its lens model the corner buffer with its corner count.
pub(super) type LensSet = (usize, Vec<Shell>, Vec<(wgpu::Buffer, u32)>);

/// Traces the vertex rays of every lens object `plan` draws through the object placed at
/// the frame's transform, refines its tessellation down to `tau_px`, and builds its lens
/// model's terms' corners once per object and shell geometry (`states`: the objects' lens states).
pub(super) fn lens_corners(
    gpu: &Gpu,
    (states, ahead): (&mut [(usize, LensState)], &mut LensAhead),
    plan: &Plan,
    size: (u32, u32),
    tau_px: f32,
) -> LensWork {
    let t = Instant::now();
    let mut work = LensWork { sets: Vec::new(), ms: 0.0, rays: 0, triangles: 0, traced_ahead: 0 };
    for r in &plan.lenses {
        let shells: Vec<Shell> = r.shells.iter().map(|(_, s, _)| s.clone()).collect();
        if work.sets.iter().any(|(d, s, _)| *d == r.draw && *s == shells) {
            continue;
        }
        let Some((_, state)) = states.iter_mut().find(|(d, _)| *d == r.draw) else { continue };
        let key = tessellation_key(plan, r.draw, size, tau_px);
        let tess = match &state.tessellated {
            Some((k, t)) if *k == key => t.clone(),
            _ => {
                let t = match ahead.take(r.draw, &key) {
                    Some(t) => {
                        work.traced_ahead += 1;
                        t
                    }
                    None => {
                        let settings = state.settings(tau_px);
                        let (lens, tracer) = state.at(plan.worlds[r.draw]);
                        let view = HybridView {
                            eye: plan.eye,
                            clip_from_world: plan.clip_from_world,
                            size,
                        };
                        let t = tessellate_timed(lens, &view, &settings, tracer.as_ref()).0;
                        work.rays += t.stats.rays;
                        t
                    }
                };
                let t = std::sync::Arc::new(t);
                state.tessellated = Some((key, t.clone()));
                t
            }
        };
        let corners: Vec<_> = Term::of(state.model)
            .par_iter()
            .map(|&term| term_corners(&tess, term, &shells))
            .collect();
        let buffers: Vec<(wgpu::Buffer, u32)> = corners
            .iter()
            .map(|corners| (corner_buffer(gpu, corners), corners.len() as u32))
            .collect();
        work.triangles += buffers.iter().map(|b| b.1 as u64 / 3).max().unwrap_or(0);
        work.sets.push((r.draw, shells, buffers));
    }
    work.ms = t.elapsed().as_secs_f64() * 1e3;
    work
}

/// The lens draws of `plan`: per lens term and parameter sample, the terms' corner buffers
/// of its shell geometry (`sets`, from [`lens_corners`]) with the shells' cube maps.
pub(super) fn lens_draws<'a>(
    reader: &PisReader,
    textures: &'a Textures,
    plan: &Plan,
    sets: &'a [LensSet],
) -> Result<Vec<LensDraw<'a>>, PlayError> {
    let mut lenses = Vec::new();
    for r in &plan.lenses {
        let shells: Vec<Shell> = r.shells.iter().map(|(_, s, _)| s.clone()).collect();
        let Some((_, _, buffers)) = sets.iter().find(|(d, s, _)| *d == r.draw && *s == shells)
        else {
            continue;
        };
        let mut cubes = Vec::with_capacity(r.shells.len());
        for (key, _, lookups) in &r.shells {
            let GpuTexture::Shell(cube) = textures.get(key) else {
                return Err(content(
                    reader,
                    format!("{key:?}: a surface texture drawn as a shell"),
                ));
            };
            cubes.push((cube, *lookups));
        }
        for (corners, count) in buffers {
            lenses.push(LensDraw {
                object: r.draw as u32,
                clip_from_world: plan.clip_from_world,
                weight: r.weight,
                corners,
                count: *count,
                shells: cubes.clone(),
            });
        }
    }
    Ok(lenses)
}
