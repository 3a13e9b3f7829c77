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

/// No object plays more than this many times the file's target below its own solved
/// figure: the target holds the file over every object's pixels together, where a small
/// object's error weighs little, so an object that falls further has its allocation weight
/// raised and the search runs again.
pub const OBJECT_WITHIN_FACTOR: f64 = 3.0;
/// Searches one pack makes at most: the first, and again after raising weights.
pub const OBJECT_ROUNDS: usize = 3;
/// An object that plays at or above this PSNR (dB) is held as it is, whatever its solved
/// figure: its error is below what 8-bit display values show.
const FINE_DB: f64 = 50.0;
/// How far inside the object limit a raised weight aims (a factor on the coding error).
const OBJECT_AIM: f64 = 0.7;
/// The most one round raises a weight by.
const MOST_RAISE: f64 = 1e4;

/// The objects (by index) that play more than `limit_db` below their own solved figure,
/// from `objects`' (decoded, solved) PSNR, each with the factor to raise its allocation
/// weight by: under equal-slope allocation an object's coding error falls as its weight
/// rises, so the factor is its coding error over what the limit allows.
pub fn raised_weights(objects: &[(f64, f64)], limit_db: f64) -> Vec<(usize, f64)> {
    objects
        .iter()
        .enumerate()
        .filter(|(_, (decoded, solved))| solved - decoded > limit_db && *decoded < FINE_DB)
        .map(|(o, &(decoded, solved))| {
            let coding = mse(decoded) - mse(solved);
            let allowed = mse(solved) * (10f64.powf(limit_db / 10.0) - 1.0) * OBJECT_AIM;
            (o, (coding / allowed).clamp(1.0, MOST_RAISE))
        })
        .collect()
}

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
/// A bracket whose files differ by less than this share of the smaller file that meets the
/// goal ends the search: the allocation's rate–distortion points are discrete, and between
/// two neighbours the played PSNR steps without a file in between worth the trials.
const BYTES_GAP: f64 = 0.02;

/// How much smaller than the smallest file that meets the goal the largest that misses it
/// is, as a share of the former.
fn bytes_gap(trials: &[Trial], goal: Goal) -> f64 {
    let met = trials.iter().filter(|t| meets(t.psnr_db, goal.goal_db)).map(|t| t.bytes).min();
    let missed = trials.iter().filter(|t| !meets(t.psnr_db, goal.goal_db)).map(|t| t.bytes).max();
    match (met, missed) {
        (Some(m), Some(x)) if m > 0 => m.saturating_sub(x) as f64 / m as f64,
        _ => 1.0,
    }
}

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

/// A pack's played-quality search as the report tells it: the last search, the objects
/// whose allocation weight was raised to hold them near their solved figure, and how many
/// searches were made.
#[derive(Clone, Debug, PartialEq)]
pub struct Played {
    pub found: Found,
    pub held: Vec<String>,
    pub searches: usize,
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
    // The highest coding PSNR that missed the goal, and the lowest that met it.
    let (mut lo, mut hi): (Option<f64>, Option<f64>) = (None, None);
    // The first guess: coding error as it stands, added to the solved error.
    let first = (aim_mse > solved_mse).then(|| -10.0 * (aim_mse - solved_mse).log10());
    let mut c = first.unwrap_or(top).clamp(LOWEST_CODING_DB, top);
    let mut trials: Vec<Trial> = Vec::new();
    while trials.len() < MAX_TRIALS {
        let t = trial(c)?;
        trials.push(t);
        if meets(t.psnr_db, goal.goal_db) {
            hi = Some(c);
            if t.psnr_db - goal.goal_db < CLOSE_DB {
                break;
            }
        } else {
            lo = Some(c);
            if c >= top {
                break;
            }
        }
        if let (Some(l), Some(h)) = (lo, hi) {
            if h - l < NARROWEST_DB || bytes_gap(&trials, goal) < BYTES_GAP {
                break;
            }
        }
        let step = modelled(&t, solved_mse, aim_mse).unwrap_or(c - 3.0);
        let (floor, ceiling) = (lo.unwrap_or(LOWEST_CODING_DB), hi.unwrap_or(top));
        c = if step > floor && step < ceiling {
            step
        } else if hi.is_none() && step >= ceiling {
            top
        } else {
            0.5 * (floor + ceiling)
        };
        if trials.iter().any(|t| (t.coding_db - c).abs() < NARROWEST_DB / 2.0) {
            break;
        }
    }
    // The fewest bytes among the trials that meet the goal, else the highest PSNR.
    let index = 0..trials.len();
    let kept = index
        .clone()
        .filter(|&i| meets(trials[i].psnr_db, goal.goal_db))
        .min_by_key(|&i| trials[i].bytes)
        .or_else(|| index.max_by(|&a, &b| trials[a].psnr_db.total_cmp(&trials[b].psnr_db)))
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
    fn a_staircase_ends_once_the_bracket_holds_neighbouring_files() {
        // discrete rate–distortion points: a file per dB of coding PSNR, 1 % apart in bytes
        let stairs = |c: f64| -> Result<Trial, ()> {
            let psnr_db = (c.floor() - 10.0).min(30.0);
            Ok(Trial { coding_db: c, bytes: 10_000 + (c.floor() * 100.0) as usize, psnr_db })
        };
        let found = search(goal(25.5, 30.0), stairs).unwrap();
        // the smallest file that meets 25.5 dB is 26 dB, 13 600 bytes: the one kept is
        // within 2 % of it
        assert!(found.reached && found.trial().bytes as f64 <= 13_600.0 * 1.02, "{found:?}");
        assert!(found.trials.len() < MAX_TRIALS, "{} trials: {found:?}", found.trials.len());
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
    fn objects_far_below_their_solved_figure_get_their_weight_raised() {
        // (decoded, solved): within 3 dB; 6 dB below; 10 dB below but above the fine
        // level; 20 dB below
        let objects = [(30.0, 32.0), (24.0, 30.0), (55.0, 65.0), (20.0, 40.0)];
        let raised = raised_weights(&objects, 3.0);
        assert_eq!(raised.iter().map(|r| r.0).collect::<Vec<_>>(), vec![1, 3]);
        // 6 dB below a 3 dB limit: coding error 3 × the solved error against 0.995 × 0.7
        let (_, f) = raised[0];
        let want = (mse(24.0) - mse(30.0)) / (mse(30.0) * (10f64.powf(0.3) - 1.0) * OBJECT_AIM);
        assert!((f - want).abs() < 1e-9 && f > 4.0, "{f}");
        assert!(raised[1].1 > f);
        assert!(raised_weights(&[(29.0, 30.0)], 3.0).is_empty());
    }

    #[test]
    fn a_trials_error_ends_the_search() {
        let failing = |_c: f64| -> Result<Trial, &str> { Err("no") };
        assert_eq!(search(goal(29.0, 30.0), failing), Err("no"));
    }
}
