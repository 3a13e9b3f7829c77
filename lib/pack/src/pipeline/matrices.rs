//! Where an object's render matrix A at a point comes from (thesis 3.4): the hardware model
//! (A computed in software as the player draws), or probe mode (3.4.3: A measured through
//! the player's textured pipeline with texel-identifier renderings on the GPU the pack runs
//! on, anisotropic filtering included). The same A serves the solves and the predicted PSNR.

use anyhow::Result;
use pis_compile::{
    render_matrix, scene_depth, DrawMesh, Filter, RenderMatrix, TexturedObject, Viewport,
};
use pis_play::{Gpu, PlayError, TexturedPipeline};

use crate::error::{Exit, Failure};

/// The render matrix source a pack uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MatrixSource {
    /// pis-compile's hardware model.
    #[default]
    Model,
    /// Measured through wgpu (probe mode).
    Probe,
}

impl MatrixSource {
    /// The name the provenance and the report use.
    pub fn name(self) -> &'static str {
        match self {
            MatrixSource::Model => "model",
            MatrixSource::Probe => "probe",
        }
    }
}

/// Builds render matrices; in probe mode it holds the one GPU device and pipeline of the
/// pack (all GPU work on the calling thread).
pub enum Matrices {
    Model,
    Probe { gpu: Box<Gpu>, pipeline: Box<TexturedPipeline>, renderings: u64, matrices: u64 },
}

/// Why `--filter` and `--matrix` do not go together, if they do not.
pub fn filter_needs_probe(filter: Filter, source: MatrixSource) -> Option<String> {
    match (filter, source) {
        (Filter::Anisotropic(_), MatrixSource::Model) => Some(
            "--filter anisotropic needs --matrix probe: the hardware model cannot describe anisotropic filtering (the adapter chooses its taps), so its render matrices are measured through the GPU".into(),
        ),
        _ => None,
    }
}

impl Matrices {
    /// The GPU adapter of probe mode, described.
    pub fn device(&self) -> Option<String> {
        match self {
            Matrices::Model => None,
            Matrices::Probe { gpu, .. } => Some(gpu.describe()),
        }
    }

    /// The source of `source`: probe mode opens the GPU adapter once (no adapter: exit 5,
    /// with the hint to install Mesa's lavapipe).
    pub fn open(source: MatrixSource, filter: Filter) -> Result<Matrices, Failure> {
        if let Some(why) = filter_needs_probe(filter, source) {
            return Err(Failure::new(Exit::Usage, anyhow::anyhow!(why)));
        }
        match source {
            MatrixSource::Model => Ok(Matrices::Model),
            MatrixSource::Probe => {
                let gpu = Gpu::new().map_err(|e| match e {
                    PlayError::NoAdapter(_) => {
                        Failure::new(Exit::NotSupported, anyhow::anyhow!("--matrix probe: {e}"))
                    }
                    e => Failure::new(Exit::Runtime, anyhow::anyhow!("--matrix probe: {e}")),
                })?;
                if gpu.texture_format != wgpu::TextureFormat::Rgba32Float {
                    let e = PlayError::ProbeNeedsFloat32(gpu.info.name.clone());
                    return Err(Failure::new(
                        Exit::NotSupported,
                        anyhow::anyhow!("--matrix probe: {e}"),
                    ));
                }
                let pipeline = TexturedPipeline::new(&gpu);
                Ok(Matrices::Probe {
                    gpu: Box::new(gpu),
                    pipeline: Box::new(pipeline),
                    renderings: 0,
                    matrices: 0,
                })
            }
        }
    }

    /// The render matrix of object `o` of `draw` (the scene's meshes at this point; `object`
    /// is `draw[o]` with its block texture), every other mesh occluding it.
    pub fn matrix(
        &mut self,
        viewport: Viewport,
        draw: &[DrawMesh],
        o: usize,
        object: &TexturedObject,
    ) -> Result<RenderMatrix> {
        match self {
            Matrices::Model => {
                let occluders = scene_depth(viewport, draw, Some(o))?;
                Ok(render_matrix(viewport, object, Some(&occluders))?)
            }
            Matrices::Probe { gpu, pipeline, renderings, matrices } => {
                let occluders: Vec<DrawMesh> =
                    draw.iter().enumerate().filter(|&(k, _)| k != o).map(|(_, m)| *m).collect();
                let p = pis_play::probe(gpu, pipeline, viewport, &occluders, object)?;
                *renderings += u64::from(p.renderings);
                *matrices += 1;
                Ok(p.matrix)
            }
        }
    }

    /// A line for the stage's progress: the source and, for probe mode, its renderings.
    pub fn describe(&self) -> String {
        match self {
            Matrices::Model => "hardware model".into(),
            Matrices::Probe { renderings, matrices, .. } => {
                format!("probe mode: {matrices} matrices measured with {renderings} renderings")
            }
        }
    }

    /// Probe renderings made so far (0 for the model).
    pub fn renderings(&self) -> u64 {
        match self {
            Matrices::Model => 0,
            Matrices::Probe { renderings, .. } => *renderings,
        }
    }
}
