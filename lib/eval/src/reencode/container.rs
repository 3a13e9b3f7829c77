//! The output container: the input's, its blocks' level images and the layers' gammas
//! replaced, and the provenance of the re-encoding.

use anyhow::anyhow;
use pis_codec::allocate;
use pis_format::checks::{decoded_sizes, required_codestream_bytes};
use pis_format::*;
use pis_pack::storage::BlockPyramid;
use pis_pack::{Exit, Failure, MaxMse};

use super::ReencodeRequest;

/// The input's container `c` with the new blocks (`space`, `staggers`), gammas and level
/// images (`pyramids`, in the order of the objects, layers and blocks); everything else
/// copied.
pub fn assemble<S>(
    c: &Container<S>,
    req: &ReencodeRequest,
    space: &ParameterSpace,
    staggers: &[Vec<u32>],
    gammas: &[Vec<f32>],
    pyramids: Vec<BlockPyramid>,
) -> Result<Container, Failure> {
    let runtime = |e: anyhow::Error| Failure::new(Exit::Runtime, e);
    let mut out: Container = c
        .try_map(&mut |_| Ok::<_, Error>(Codestream { codec: req.codec, bytes: vec![] }))
        .map_err(Failure::from)?;
    out.space = space.clone();
    let mut next = pyramids.into_iter();
    for ((o, gammas), st) in out.objects.iter_mut().zip(gammas).zip(staggers) {
        o.stagger = st.clone();
        for (l, &g) in o.layers.iter_mut().zip(gammas) {
            l.gamma = g;
            if req.block.is_some() {
                // Every new block keeps the layer's one placement (checked by the regrouping).
                let template = l
                    .blocks
                    .first()
                    .cloned()
                    .ok_or_else(|| runtime(anyhow!("a layer without blocks")))?;
                let count = pis_format::blocks::BlockGrid::new(space, l.depends_on, st)
                    .block_count() as usize;
                l.blocks = vec![Block { levels: Vec::new(), ..template }; count];
            }
            for b in &mut l.blocks {
                let p =
                    next.next().ok_or_else(|| runtime(anyhow!("fewer pyramids than blocks")))?;
                b.levels = p
                    .levels
                    .into_iter()
                    .map(|(counts, _, streams)| Level {
                        counts,
                        images: streams
                            .into_iter()
                            .map(|bytes| Codestream { codec: req.codec, bytes })
                            .collect(),
                    })
                    .collect();
            }
        }
    }
    Ok(out)
}

/// What the output's level images decode to, per block: the bytes of one level image and
/// their number.
fn decoded(pyramids: &[BlockPyramid]) -> impl Iterator<Item = (u64, u64)> + '_ {
    pyramids.iter().map(|p| {
        let values = pis_codec::value_count(&p.planes).map_or(u64::MAX, |n| n as u64);
        let images = p.levels.iter().map(|l| l.0.iter().map(|&c| c as u64).product::<u64>());
        (values.saturating_mul(4), images.sum())
    })
}

/// The least codestream bytes the output's level images need (SPEC.md section 12 bounds
/// what they decode to by the codestream bytes they read: 8192 × C per level image,
/// 131072 × C for all); refused, before anything is encoded, where the byte budget of
/// `target` is smaller, since no allocation within it could make the file valid.
pub fn check_budget(
    pyramids: &[BlockPyramid],
    target: &allocate::Target,
    target_text: &str,
    raw: u64,
) -> Result<u64, Failure> {
    let need = required_codestream_bytes(decoded(pyramids));
    match *target {
        allocate::Target::Bytes(budget) if need > budget as u64 => Err(Failure::new(
            Exit::Usage,
            anyhow!(
                "the target ({target_text}) leaves the level images {budget} bytes of codestream, and the textures they decode to need at least {need}: a file's level images decode to at most 8192 times the bytes of its codestreams, and all of them together to at most 131072 times (SPEC.md section 12); a ratio of at most {:.0} or an exact codec stores them; nothing was written",
                (raw as f64 / need as f64).floor()
            ),
        )),
        _ => Ok(need),
    }
}

/// Refuses an encoded output that breaks section 12's limits (rules 6009 and 6010: codecs
/// may code large flat textures in fewer bytes than the limits need, whatever the budget),
/// before anything is written.
pub fn check_limits(out: &Container, need: u64) -> Result<(), Failure> {
    let bytes: u64 = out.level_images().map(|r| r.bytes.len() as u64).sum();
    match decoded_sizes(out, bytes) {
        None => Ok(()),
        Some(issue) => Err(Failure::new(
            Exit::Usage,
            anyhow!(
                "the re-encoded level images hold {bytes} bytes of codestream and the textures they decode to need at least {need} (a file's level images decode to at most 8192 times the bytes of its codestreams, and all of them together to at most 131072 times: SPEC.md section 12; {issue}); a lower ratio or an exact codec stores them; nothing was written"
            ),
        )),
    }
}

/// The codecs of the input's level images, by name, sorted.
pub fn codecs(c: &Container<StreamRef>) -> Vec<String> {
    let mut v: Vec<String> = c.level_images().map(|s| s.codec.name().to_string()).collect();
    v.sort();
    v.dedup();
    v
}

/// What a re-encoding applied, as its provenance records it.
pub struct Applied<'a> {
    pub gamma: f32,
    /// The allocation's target (`ratio 96`, `psnr 40 dB`, `exact`, ...).
    pub target: &'a str,
    pub max_mse: MaxMse,
}

/// The output's provenance: the input's settings but those the re-encoding changes, and
/// the re-encoding's own.
pub fn provenance<S>(
    c: &Container<S>,
    req: &ReencodeRequest,
    space: &ParameterSpace,
    applied: Applied,
    codecs_before: &[String],
    raw: u64,
) -> Provenance {
    let Applied { gamma, target: target_text, max_mse } = applied;
    let exact = !req.codec.is_lossy();
    let before = c.provenance.clone().unwrap_or_default();
    let mut settings: Vec<(String, String)> = before
        .settings
        .iter()
        .filter(|(k, _)| !(req.block.is_some() && k == "block"))
        .filter(|(k, _)| {
            !matches!(
                k.as_str(),
                "codec"
                    | "gamma"
                    | "target"
                    | "reencoded_from"
                    | "source_tool"
                    | "source_codec"
                    | pis_pack::PREDICTED_PSNR_SETTING
                    | pis_pack::HALF_FLOAT_PSNR_SETTING
                    | pis_pack::LEVEL16_PSNR_SETTING
            )
        })
        // An exact output carries the writer's constraint on, for the next lossy coding.
        .filter(|(k, _)| exact || k != "max_mse_ratio")
        .cloned()
        .collect();
    if req.block.is_some() {
        settings.push((
            "block".to_string(),
            space.dims.iter().map(|d| d.block_size.to_string()).collect::<Vec<_>>().join("x"),
        ));
    }
    settings.extend([
        ("codec".to_string(), req.codec.name().to_string()),
        ("gamma".to_string(), gamma.to_string()),
        ("target".to_string(), target_text.to_string()),
        ("reencoded_from".to_string(), req.input.display().to_string()),
        ("source_tool".to_string(), before.tool.clone()),
        ("source_codec".to_string(), codecs_before.join("+")),
    ]);
    if !exact {
        settings.push(("max_mse_ratio".to_string(), max_mse.name()));
    }
    Provenance {
        tool: format!("pis-reencode {}", env!("CARGO_PKG_VERSION")),
        source: if before.source.is_empty() {
            req.input.display().to_string()
        } else {
            before.source.clone()
        },
        raw_image_bytes: raw,
        settings,
    }
}
