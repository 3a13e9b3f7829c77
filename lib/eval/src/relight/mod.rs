//! Relighting judged (seed 003): how well a set traced over light directions can be relit
//! at all ([`ceiling`]: its pixels fitted per band), and packed files played ([`held_out`]),
//! under the lights of a held-out set: other directions of the one light, two coloured
//! lights, or a sky.

mod ceiling;
mod held;
mod played;

use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::Serialize;

pub use ceiling::{ceiling, ceiling_of, placement_of};
pub use held::{light_dimension, HeldLights, Placement};
pub use played::{held_out, reference_step};

/// One band's figure, or the nearest sampled direction's (`band` `None`).
#[derive(Clone, Debug, Serialize)]
pub struct CeilingRow {
    pub band: Option<u32>,
    pub coefficients: usize,
    /// Whole image under the held-out set's lights, display PSNR (dB).
    pub held_out_db: f64,
    /// Whole image at the set's own directions.
    pub samples_db: f64,
}

/// One file played at a held-out set's light directions.
#[derive(Clone, Debug, Serialize)]
pub struct HeldOutRow {
    pub file: String,
    pub bytes: u64,
    /// Whether the file relights (its layers span the light directions), else it shows the
    /// sampled light nearest each direction.
    pub relightable: bool,
    /// Whole image against the held-out set, display PSNR (dB); `None` where the file
    /// samples one light and the set is lit otherwise (two lights, a sky).
    pub psnr_db: Option<f64>,
    /// Per held-out point, display PSNR (dB).
    pub points_db: Vec<f64>,
    /// Where the held-out set's light moves continuously: the largest change between
    /// consecutive frames, as the PSNR of one against the other (dB; lower is a larger jump).
    pub largest_step_db: Option<f64>,
}

/// What `pis-bench relight` measured.
#[derive(Clone, Debug, Serialize)]
pub struct RelightReport {
    pub ceiling: Option<Vec<CeilingRow>>,
    pub played: Vec<HeldOutRow>,
    /// The held-out set's own largest step, where its light moves continuously.
    pub reference_step_db: Option<f64>,
}

/// `pis-bench relight`: with `fitted` (the set the files were packed from), the ceiling of
/// its per-pixel fit for each of `bands` and the placement of its light; each of `files`
/// played under `held`'s lights; and `held`'s own largest step where its light moves.
pub fn judge(
    files: &[PathBuf],
    held: &Path,
    fitted: Option<&Path>,
    bands: &[u32],
) -> Result<RelightReport> {
    let ceiling = fitted.map(|f| ceiling_of(f, held, bands)).transpose()?;
    let placement = fitted.map(placement_of).transpose()?.flatten();
    let played = held_out(files, held, placement.as_ref())?;
    let reference_step_db = reference_step(held)?;
    Ok(RelightReport { ceiling, played, reference_step_db })
}

/// The report as text.
pub fn render(r: &RelightReport) -> String {
    let mut out = String::new();
    if let Some(rows) = &r.ceiling {
        out.push_str(
            "the set's pixels fitted per band, under the held-out set's lights (at its own):\n",
        );
        for row in rows {
            match row.band {
                Some(b) => out.push_str(&format!(
                    "  band {b} ({:>2} coefficients)  {:6.2} dB  ({:.2} dB)\n",
                    row.coefficients, row.held_out_db, row.samples_db
                )),
                None => out.push_str(&format!(
                    "  nearest sampled directions     {:6.2} dB\n",
                    row.held_out_db
                )),
            }
        }
    }
    out.push_str("played under the held-out set's lights:\n");
    for row in &r.played {
        let how = if row.relightable { "relit" } else { "nearest sample" };
        let db = match row.psnr_db {
            Some(db) => format!("{db:.2} dB"),
            None => "cannot show these lights (it samples one light)".into(),
        };
        out.push_str(&format!("  {}  {} bytes, {how}: {db}\n", row.file, row.bytes));
    }
    if let Some(reference) = r.reference_step_db {
        out.push_str(&format!(
            "largest change from one light step to the next (PSNR of a frame against the \
             previous; lower is a larger jump):\n  traced  {reference:.2} dB\n"
        ));
        for row in &r.played {
            if let Some(db) = row.largest_step_db {
                out.push_str(&format!("  {}  {db:.2} dB\n", row.file));
            }
        }
    }
    out
}
