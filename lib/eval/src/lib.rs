//! Evaluation of PIS outputs, and the stages that read containers: display metrics,
//! comparison of played frames with the ray-traced gold standard, differences between
//! containers, baselines and charts.
//!
//! One entry point per tool's work (each tool's binary parses arguments, calls it, prints
//! its report):
//!
//! | stage | call | report |
//! |---|---|---|
//! | look inside a file (`pis-inspect`) | [`inspect::summarize`], [`inspect::extract`] | [`inspect::Summary`] |
//! | re-encode a file (`pis-reencode`) | [`reencode::reencode`] | [`reencode::ReencodeReport`] |
//! | two files (`pis-diff A B`) | [`diff::files::diff`] | [`diff::files::DiffReport`] |
//! | a file against a set (`pis-diff FILE SET`) | [`diff::gold::gold`] | [`diff::gold::GoldReport`] |
//! | two sets (`pis-diff SET_A SET_B`) | [`diff::sets::compare_sets`] | [`diff::sets::SetsReport`] |
//! | play without a window (`pis-play --headless`) | [`headless::run_frames`], [`headless::run_compare`] | [`headless::PathReport`], [`headless::CompareReport`] |
//! | benchmarks (`pis-bench`) | [`bench::rd::run`], [`bench::speed::run`], [`bench::stability::run`], [`bench::all::run`] | their reports |
//!
//! The pack itself is [`pis_pack::pack()`]; texture inference measured alone (`pis-bench
//! infer`) is [`pis_pack::infer::infer`].
//!
//! Every accuracy figure PIS reports is measured on display values (see [`metrics`]):
//! linear radiance clamped to [0, 1] and sRGB-encoded, peak 1.

pub mod baselines;
pub mod bench;
pub mod budget;
pub mod chart;
pub mod compare;
pub mod diff;
pub mod flip;
pub mod headless;
pub mod heatmap;
pub mod inspect;
pub mod metrics;
pub mod reencode;
pub mod relight;
pub mod report;
