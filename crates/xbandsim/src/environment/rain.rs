//! Rain: the rain field (uniform rate and cells) and its volume reflectivity. Its attenuation
//! along a path is propagation's (`crate::propagation::rain_attenuation`).
//!
//! Reflectivity factor (Marshall & Palmer, J. Meteor. 5, 1948): `Z = 200·R^1.6` mm⁶/m³ for a
//! rain rate R in mm/h; volume reflectivity (Doviak & Zrnić, *Doppler Radar and Weather
//! Observations*, 2nd ed., eq. 4.34) `η = π⁵·|K|²·Z/λ⁴` m²/m³ with Z in m³ (×1e-18) and
//! |K|² = 0.93 for water.

use glam::DVec2;

/// |K|² of liquid water at microwave frequencies.
pub const WATER_K_SQUARED: f64 = 0.93;

/// Volume reflectivity η (m²/m³) of rain of `rate_mm_per_h` at `wavelength_m`.
pub fn volume_reflectivity_m2_per_m3(rate_mm_per_h: f64, wavelength_m: f64) -> f64 {
    if rate_mm_per_h <= 0.0 {
        return 0.0;
    }
    let z_m3 = 200.0 * rate_mm_per_h.powf(1.6) * 1e-18;
    std::f64::consts::PI.powi(5) * WATER_K_SQUARED * z_m3 / wavelength_m.powi(4)
}

/// A vertical cylinder of rain from the sea to the rain top.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RainCell {
    /// Centre (east, north), m.
    pub centre_m: DVec2,
    /// Radius, m.
    pub radius_m: f64,
    /// Rain rate inside, mm/h.
    pub rate_mm_per_h: f64,
}

/// Rain in the scene: a uniform rate plus cells (rates add where they overlap).
#[derive(Debug, Clone, PartialEq)]
pub struct Rain {
    /// Uniform rain rate everywhere, mm/h.
    pub uniform_rate_mm_per_h: f64,
    /// Rain cells.
    pub cells: Vec<RainCell>,
    /// Height of the rain top above the sea, m.
    pub top_m: f64,
}

impl Rain {
    /// Rain rate at ground point (x, y), mm/h.
    pub fn rate_at(&self, p: DVec2) -> f64 {
        self.uniform_rate_mm_per_h
            + self
                .cells
                .iter()
                .filter(|c| (p - c.centre_m).length_squared() <= c.radius_m * c.radius_m)
                .map(|c| c.rate_mm_per_h)
                .sum::<f64>()
    }
}
