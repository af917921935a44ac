//! Stage: propagation. Everything that happens to a wave between the antenna and a scatterer,
//! in one place (docs/physics.md §5–6):
//! - the 4/3-earth curvature: the radar horizon and the grazing angle on the sea;
//! - the atmosphere's uniform two-way attenuation;
//! - the sea surface as a reflector (multipath): [`sea_reflection`];
//! - rain attenuation along a path: [`rain_attenuation`].

pub mod rain_attenuation;
pub mod sea_reflection;

pub use rain_attenuation::{itu_p838_coefficients, specific_attenuation_db_per_km, RainAttenuator};
pub use sea_reflection::{
    fresnel_reflection, roughness_factor, sea_water_permittivity, SeaRoughness, SeaSurface,
};

/// Two-way power factor of a uniform specific attenuation `two_way_db_per_km` over a one-way
/// range `range_m`: `10^(−α·R/10)` with α in dB/km counted over the two-way trip already.
#[inline]
pub fn two_way_attenuation_power(two_way_db_per_km: f64, range_m: f64) -> f64 {
    10f64.powf(-two_way_db_per_km * range_m / 1000.0 / 10.0)
}

/// Effective earth radius of the 4/3-earth model, m (Skolnik, *Introduction to Radar
/// Systems*, 3rd ed., §8.2; mean earth radius 6371 km).
pub const EFFECTIVE_EARTH_RADIUS_M: f64 = 4.0 / 3.0 * 6_371_000.0;

/// Distance to the radar horizon from height `height_m` over a smooth 4/3 earth,
/// `√(2·a_e·h)` (4.12·√h km with h in m), m.
#[inline]
pub fn horizon_distance_m(height_m: f64) -> f64 {
    (2.0 * EFFECTIVE_EARTH_RADIUS_M * height_m.max(0.0)).sqrt()
}

/// Whether a point at `height_m` and `ground_range_m` is above the horizon of a radar at
/// `radar_height_m`: `d ≤ 4.12(√h_r + √h_t)` km.
#[inline]
pub fn above_horizon(radar_height_m: f64, ground_range_m: f64, height_m: f64) -> bool {
    ground_range_m <= horizon_distance_m(radar_height_m) + horizon_distance_m(height_m)
}

/// Sine of the grazing angle at the sea under a radar at height `radar_height_m` for a
/// slant range `range_m`: `h/R − R/(2a_e)` over the 4/3 earth (Skolnik, *Introduction to
/// Radar Systems*, 3rd ed., §8.2), `h/R` over a flat one. Zero or below: beyond the horizon.
#[inline]
pub fn sin_grazing(radar_height_m: f64, range_m: f64, earth_curvature: bool) -> f64 {
    if earth_curvature {
        radar_height_m / range_m - range_m / (2.0 * EFFECTIVE_EARTH_RADIUS_M)
    } else {
        radar_height_m / range_m
    }
}
