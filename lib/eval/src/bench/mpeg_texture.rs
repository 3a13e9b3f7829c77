//! The MPEG-texture baseline (thesis 4.8): each object's inferred textures, layer by layer,
//! along the zig-zag path through the parameter space the layer depends on, encoded as one
//! video per object and layer with x265 — every video at one common rate factor, searched
//! to meet the byte budget — decoded and rendered through the hardware model like PIS's own
//! textures (MIP chain rebuilt by decimation), PSNR over the covered pixels. Samples whose
//! blocks carry different placements (different texture sizes) go into separate videos,
//! one per object, layer and placement.
//!
//! Texels go into the video gamma-compensated like PIS stores them (L^(1/2.2)), scaled by
//! the layer's largest texel so the 8-bit range covers it (4 bytes of scale per video are
//! counted); negative texels are clamped to 0.

use std::collections::BTreeMap;

use crate::baselines::path::zigzag;
use crate::baselines::video::{decode, encode_to_budget, Frames, Matched, VideoCodec};
use anyhow::{bail, Result};

use pis_pack::encode::{finest, mip_chain, LayerTextures};
use pis_pack::predict::{display_error, psnr};
use pis_pack::Inferred;

const GAMMA: f32 = 2.2;

struct LayerVideo {
    model: usize,
    layer: usize,
    keys: Vec<Vec<u32>>,
    scale: f32,
    frames: Frames,
}

fn videos(inf: &Inferred) -> Result<Vec<LayerVideo>> {
    let dims = &inf.set.scene.space.dims;
    let mut out = Vec::new();
    for (mi, m) in inf.models.iter().enumerate() {
        for (li, l) in m.layers.iter().enumerate() {
            if l.form.channels() != 3 {
                bail!(
                    "object {}: the video baseline codes RGB textures, and its layer {li} has {} channels (a translucent object's opacity)",
                    m.name,
                    l.form.channels()
                );
            }
            let counts: Vec<u32> =
                l.depends_on.dims().map(|d| dims[d].values.len() as u32).collect();
            let path: Vec<Vec<u32>> =
                zigzag(&counts).into_iter().filter(|k| l.textures.contains_key(k)).collect();
            let mut placements: Vec<usize> = path.iter().map(|k| l.placement_of[k]).collect();
            placements.sort_unstable();
            placements.dedup();
            for pid in placements {
                let layout = m.placements[pid].layout;
                let keys: Vec<Vec<u32>> =
                    path.iter().filter(|k| l.placement_of[*k] == pid).cloned().collect();
                let textures =
                    keys.iter().map(|k| l.textures.get(k)).collect::<Result<Vec<_>>>()?;
                let scale = textures
                    .iter()
                    .flat_map(|x| finest(layout, x, 3))
                    .fold(0.0f32, f32::max)
                    .max(1e-6);
                let mut rgb = Vec::new();
                for x in &textures {
                    rgb.extend(finest(layout, x, 3).iter().map(|&v| {
                        ((v.max(0.0) / scale).powf(1.0 / GAMMA) * 255.0).round().clamp(0.0, 255.0)
                            as u8
                    }));
                }
                let frames =
                    Frames { width: layout.width, height: layout.height, count: keys.len(), rgb };
                out.push(LayerVideo { model: mi, layer: li, frames, keys, scale });
            }
        }
    }
    Ok(out)
}

/// One encoded point.
pub struct TexturePoint {
    pub matched: Matched,
    /// Stream bytes plus the per-video scales.
    pub bytes: usize,
    pub psnr_db: f64,
    pub videos: usize,
}

/// Encodes every layer video at `budget` bytes in all, decodes, renders through A.
pub fn texture_point(inf: &Inferred, budget: usize) -> Result<TexturePoint> {
    let vids = videos(inf)?;
    let side = 4 * vids.len();
    let frames: Vec<Frames> = vids.iter().map(|v| v.frames.clone()).collect();
    let matched = encode_to_budget(&frames, VideoCodec::X265, budget.saturating_sub(side).max(1))?;
    let mut textures: Vec<Vec<LayerTextures>> =
        inf.models.iter().map(|m| m.layers.iter().map(|_| BTreeMap::new()).collect()).collect();
    for (v, stream) in vids.iter().zip(&matched.streams) {
        let m = &inf.models[v.model];
        let d = decode(stream, VideoCodec::X265, v.frames.width, v.frames.height, v.frames.count)?;
        let n = v.frames.width as usize * v.frames.height as usize * 3;
        for (i, k) in v.keys.iter().enumerate() {
            let lin: Vec<f32> = d.rgb[i * n..(i + 1) * n]
                .iter()
                .map(|&b| v.scale * (b as f32 / 255.0).powf(GAMMA))
                .collect();
            textures[v.model][v.layer].insert(k.clone(), mip_chain(m.layout(v.layer, k), lin, 3));
        }
    }
    let e = inf
        .models
        .iter()
        .zip(&textures)
        .map(|(m, t)| display_error(&inf.set, m, t.as_slice()))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let (s, n) = e.iter().fold((0.0, 0), |a, x| (a.0 + x.0, a.1 + x.1));
    Ok(TexturePoint {
        bytes: matched.bytes + side,
        matched,
        psnr_db: psnr(s, n),
        videos: vids.len(),
    })
}
