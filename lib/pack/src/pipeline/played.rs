//! A played-quality target: the fewest level-image bytes whose predicted played PSNR reaches
//! a goal, the default of pis-pack (within [`super::DEFAULT_WITHIN_DB`] of the textures as
//! solved), as a video encoder's constant quality is its default rather than a bitrate.
//!
//! The allocation aims at a PSNR of the coded textures; what the screen shows is the solved
//! textures' own error plus what coding adds, drawn through the render matrices. So the
//! search runs over the allocation's coding PSNR c: each trial allocates, encodes and
//! predicts the file, and the next c comes from a model of the played error fitted to the
//! last trial, E(c) = E_s + k · 10^(−c/10) (E_s the solved error: coding error adds to it,
//! scaled by how the render matrices spread texels over pixels), kept inside the bracket of
//! trials that met and missed the goal, by bisection where the model steps out of it. The
//! file kept is the trial that meets the goal with the fewest bytes.

/// Most trials (allocations encoded and predicted) one search makes.
pub const MAX_TRIALS: usize = 8;
/// A trial within this many dB above the goal ends the search: fewer bytes would miss it.
pub const CLOSE_DB: f64 = 0.05;
/// The search aims this far above the goal, so that the model's next step lands on the
/// side that meets it.
const AIM_ABOVE_DB: f64 = 0.02;
/// The lowest coding PSNR tried (dB): below it every allocation is its floor.
const LOWEST_CODING_DB: f64 = 1.0;
/// A bracket this narrow (dB of coding PSNR) ends the search.
const NARROWEST_DB: f64 = 0.01;

/// What the search aims at: the predicted played PSNR to reach, the file's solved PSNR
/// (the most coding can leave), and the highest coding PSNR the codec reaches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Goal {
    pub goal_db: f64,
    pub solved_db: f64,
    pub reachable_coding_db: f64,
}

/// One trial: the coding PSNR allocated for, the level-image bytes it took and the
/// predicted played PSNR.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Trial {
    pub coding_db: f64,
    pub bytes: usize,
    pub psnr_db: f64,
}

/// What a search found: every trial in order, and which one is kept (the fewest bytes
/// among those that meet the goal, else the highest PSNR), with whether it meets it.
#[derive(Clone, Debug, PartialEq)]
pub struct Found {
    pub goal: Goal,
    pub trials: Vec<Trial>,
    pub kept: usize,
    pub reached: bool,
}

impl Found {
    /// The trial kept.
    pub fn trial(&self) -> Trial {
        self.trials[self.kept]
    }
}

/// Whether a predicted PSNR meets the goal (to display rounding).
fn meets(psnr_db: f64, goal_db: f64) -> bool {
    psnr_db >= goal_db - 1e-3
}

/// Mean squared error at peak 1 of a PSNR.
fn mse(db: f64) -> f64 {
    10f64.powf(-db / 10.0)
}

/// The coding PSNR the error model fitted to `t` says reaches `aim_mse`, with `solved_mse`
/// the solved textures' error; `None` where `t`'s coding added no error to fit.
fn modelled(t: &Trial, solved_mse: f64, aim_mse: f64) -> Option<f64> {
    let added = mse(t.psnr_db) - solved_mse;
    let wanted = aim_mse - solved_mse;
    (added > 0.0 && wanted > 0.0).then(|| {
        let k = added / mse(t.coding_db);
        -10.0 * (wanted / k).log10()
    })
}

/// Searches the coding PSNR for the fewest bytes that meet `goal`, `trial(c)` encoding and
/// predicting the file allocated for coding PSNR c (the caller holds each trial's file,
/// in call order, to keep [`Found::kept`]).
pub fn search<E>(goal: Goal, mut trial: impl FnMut(f64) -> Result<Trial, E>) -> Result<Found, E> {
    let solved_mse = mse(goal.solved_db);
    let aim_mse = mse(goal.goal_db + AIM_ABOVE_DB);
    let top = goal.reachable_coding_db.max(LOWEST_CODING_DB);
    // Trials at or below `lo` missed the goal, at or above `hi` met it.
    let (mut lo, mut hi) = (LOWEST_CODING_DB, top);
    let (mut missed_lo, mut met_hi) = (false, false);
    // The first guess: coding error as it stands, added to the solved error.
    let first = (aim_mse > solved_mse).then(|| -10.0 * (aim_mse - solved_mse).log10());
    let mut c = first.unwrap_or(top).clamp(LOWEST_CODING_DB, top);
    let mut trials: Vec<Trial> = Vec::new();
    while trials.len() < MAX_TRIALS {
        let t = trial(c)?;
        trials.push(t);
        if meets(t.psnr_db, goal.goal_db) {
            (hi, met_hi) = (c, true);
            if t.psnr_db - goal.goal_db < CLOSE_DB {
                break;
            }
        } else {
            (lo, missed_lo) = (c, true);
            if c >= top {
                break;
            }
        }
        if hi - lo < NARROWEST_DB && met_hi && missed_lo {
            break;
        }
        let step = modelled(&t, solved_mse, aim_mse).unwrap_or(c - 3.0);
        let (floor, ceiling) =
            (if missed_lo { lo } else { LOWEST_CODING_DB }, if met_hi { hi } else { top });
        c = if step > floor && step < ceiling {
            step
        } else if !met_hi && step >= ceiling {
            top
        } else {
            0.5 * (floor + ceiling)
        };
        if trials.iter().any(|t| (t.coding_db - c).abs() < NARROWEST_DB / 2.0) {
            break;
        }
    }
    let met = |t: &&Trial| meets(t.psnr_db, goal.goal_db);
    let kept = match trials.iter().filter(met).min_by_key(|t| t.bytes) {
        Some(best) => trials.iter().position(|t| t == best),
        None => (0..trials.len()).max_by(|&a, &b| trials[a].psnr_db.total_cmp(&trials[b].psnr_db)),
    }
    .expect("a search makes at least one trial");
    let reached = meets(trials[kept].psnr_db, goal.goal_db);
    Ok(Found { goal, trials, kept, reached })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file whose played error is the solved error plus `k` times the coding error, and
    /// whose bytes grow by 100 per dB of coding PSNR.
    fn file(solved_db: f64, k: f64) -> impl Fn(f64) -> Result<Trial, ()> {
        move |c| {
            let psnr_db = -10.0 * (mse(solved_db) + k * mse(c)).log10();
            Ok(Trial { coding_db: c, bytes: (c * 100.0) as usize, psnr_db })
        }
    }

    fn goal(goal_db: f64, solved_db: f64) -> Goal {
        Goal { goal_db, solved_db, reachable_coding_db: 60.0 }
    }

    #[test]
    fn the_search_lands_just_above_the_goal_in_few_trials() {
        for k in [0.05, 1.0, 30.0] {
            let found = search(goal(29.0, 30.0), file(30.0, k)).unwrap();
            let t = found.trial();
            assert!(found.reached, "k {k}: {found:?}");
            assert!(t.psnr_db >= 29.0 - 1e-3 && t.psnr_db < 29.0 + CLOSE_DB, "k {k}: {found:?}");
            assert!(found.trials.len() <= 3, "k {k}: {} trials", found.trials.len());
        }
    }

    #[test]
    fn the_kept_file_is_the_smallest_that_meets_the_goal() {
        // a played error that does not follow the model: steps of 1 dB
        let stepped = |c: f64| -> Result<Trial, ()> {
            let psnr_db = (c.floor() - 10.0).min(30.0);
            Ok(Trial { coding_db: c, bytes: (c * 100.0) as usize, psnr_db })
        };
        let found = search(goal(25.0, 30.0), stepped).unwrap();
        let t = found.trial();
        assert!(found.reached && t.psnr_db >= 25.0 - 1e-3, "{found:?}");
        for other in found.trials.iter().filter(|o| o.psnr_db >= 25.0 - 1e-3) {
            assert!(other.bytes >= t.bytes, "{found:?}");
        }
        assert!(found.trials.len() <= MAX_TRIALS);
    }

    #[test]
    fn a_goal_out_of_reach_keeps_the_richest_file_and_says_so() {
        // the codec reaches 32 dB of coding PSNR: 29.6 dB played at most
        let g = Goal { goal_db: 29.9, solved_db: 30.0, reachable_coding_db: 32.0 };
        let found = search(g, file(30.0, 1.0)).unwrap();
        assert!(!found.reached, "{found:?}");
        assert_eq!(found.trial().coding_db, 32.0, "{found:?}");
    }

    #[test]
    fn a_goal_above_the_solved_figure_is_searched_at_the_codecs_best() {
        let found = search(goal(31.0, 30.0), file(30.0, 1.0)).unwrap();
        assert!(!found.reached && found.trial().coding_db == 60.0, "{found:?}");
        assert_eq!(found.trials.len(), 1);
    }

    #[test]
    fn a_trials_error_ends_the_search() {
        let failing = |_c: f64| -> Result<Trial, &str> { Err("no") };
        assert_eq!(search(goal(29.0, 30.0), failing), Err("no"));
    }
}
