//! The logic of pis-play's window without the window: the free cameras that leave the
//! sampled views (orbit and fly), the parameter space's sliders and paths, the view the
//! panels choose, and the frame-rate statistics. The window itself (winit, egui) lives in
//! the pis-play binary.

pub mod camera;
pub mod path;
pub mod space;
pub mod stats;
pub mod view;
