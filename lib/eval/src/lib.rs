//! Evaluation of PIS outputs: display metrics, comparison of played frames with the
//! ray-traced gold standard, differences between containers, baselines and charts.
//!
//! Every accuracy figure PIS reports is measured on display values (see [`metrics`]):
//! linear radiance clamped to [0, 1] and sRGB-encoded, peak 1.

pub mod baselines;
pub mod chart;
pub mod compare;
pub mod diff;
pub mod flip;
pub mod heatmap;
pub mod metrics;
pub mod report;
