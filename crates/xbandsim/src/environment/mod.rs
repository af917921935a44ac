//! Stage: environment. The sea surface as a reflector (multipath) and propagation losses.
//! Later: sea clutter, rain, earth curvature.

pub mod sea;

pub use sea::{fresnel_reflection, roughness_factor, sea_water_permittivity, SeaSurface};

/// Two-way power factor of a uniform specific attenuation `two_way_db_per_km` over a one-way
/// range `range_m`: `10^(−α·R/10)` with α in dB/km counted over the two-way trip already.
#[inline]
pub fn two_way_attenuation_power(two_way_db_per_km: f64, range_m: f64) -> f64 {
    10f64.powf(-two_way_db_per_km * range_m / 1000.0 / 10.0)
}
