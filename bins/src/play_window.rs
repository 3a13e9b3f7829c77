//! pis-play's window mode (thesis 1.4, third step; 5.9): the player's frames in a window,
//! with panels to move through the parameter space, play a path, switch blending and camera,
//! compare with the ray-traced gold standard, and watch the frame rate.

pub mod app;
pub mod camera;
pub mod gold;
pub mod path;
pub mod screenshot;
pub mod space;
pub mod stats;
pub mod surface;
pub mod ui;
pub mod view;

pub use app::{run_window, RunReport, WindowOptions};
