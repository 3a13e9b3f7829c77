//! Relighting by spherical harmonics (Wong et al., seed 003): a texel's radiance as a function
//! of the direction ω of one light, `f(ω) = Σ_c Y_c(ω) x_c`, with the real spherical
//! harmonics Y_c up to band `l_max` ([`basis`]), fitted by least squares to the radiance the
//! set holds at its sampled directions ([`fit`]), and relit by superposition: lights of other
//! directions and colours add, and a sky projected into the same basis ([`sky`]) is one more
//! light.

pub mod basis;
pub mod fit;
pub mod lights;
pub mod sky;

pub use basis::{basis, coefficients, MAX_BAND};
pub use fit::{Cover, LightFit};
pub use lights::{azimuth_elevation, direction_at, sum_coefficients, DirectionalLight, Lights};
pub use sky::{
    load_sky, project_lat_long, reduce_lat_long, rotate_about_pole, sky_coefficients,
    SKY_PROJECTED_SIZE,
};
