//! Physical constants and decibel conversions shared by every pipeline stage.
//!
//! Values are the exact SI-2019 definitions (BIPM, *The International System of Units*, 9th ed.)
//! and the IEEE standard reference temperature T0 = 290 K (IEEE Std 145 / Skolnik, *Radar
//! Handbook*, 3rd ed., ch. 2) used for receiver noise figures.

/// Speed of light in vacuum, m/s (exact).
pub const SPEED_OF_LIGHT_M_PER_S: f64 = 299_792_458.0;

/// Boltzmann constant, J/K (exact).
pub const BOLTZMANN_J_PER_K: f64 = 1.380_649e-23;

/// Standard noise reference temperature T0, K.
pub const REFERENCE_TEMPERATURE_K: f64 = 290.0;

/// Power ratio from decibels: 10^(dB/10).
#[inline]
pub fn db_to_linear(db: f64) -> f64 {
    10f64.powf(db / 10.0)
}

/// Decibels from a power ratio: 10·log10(x).
#[inline]
pub fn linear_to_db(linear: f64) -> f64 {
    10.0 * linear.log10()
}

/// Wavelength in metres for a carrier frequency in hertz.
#[inline]
pub fn wavelength_m(freq_hz: f64) -> f64 {
    SPEED_OF_LIGHT_M_PER_S / freq_hz
}
