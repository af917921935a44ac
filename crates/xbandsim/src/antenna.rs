//! Stage: antenna. Normalised sinc² power patterns, peak gain from the beamwidths, and the
//! two-way voltage weight applied to each scattering contribution.
//!
//! One-way normalised power pattern per plane (docs/physics.md §3):
//!
//! `Gn(θ) = [sin(u)/u]²`, `u = 2.783·θ/θ3dB`, so that `Gn(±θ3dB/2) = ½` (−3 dB), the first null
//! is at `θ = π·θ3dB/2.783 ≈ 1.129·θ3dB` and the first sidelobe is −13.26 dB.
//!
//! Peak gain of a uniformly illuminated rectangular aperture whose half-power beamwidths are
//! `θaz`, `θel` (HPBW = 0.8859·λ/D; Balanis, *Antenna Theory*, 4th ed., §12.5):
//! `G0 = 4π·0.8859²/(θaz·θel)` (25.2 dBi for 3.9° × 25°).
//!
//! A scatterer seen at (Δaz, Δel) off boresight returns a voltage ∝ `G0·Gn(Δaz)·Gn(Δel)`
//! (transmit power gain × receive power gain under a square root = one-way power pattern);
//! its echo power is ∝ `G0²·Gn²`, as in the radar equation.

/// The `u` at which sinc²(u) = ½, so that `u = SINC_HALF_POWER_U · θ/(θ3dB/2)`; written as the
/// conventional `2.783·θ/θ3dB`.
pub const SINC_BEAMWIDTH_FACTOR: f64 = 2.783;

/// Beamwidth factor of a uniform aperture: HPBW = 0.8859 λ/D.
pub const UNIFORM_APERTURE_HPBW_FACTOR: f64 = 0.8859;

/// A separable sinc² antenna: azimuth and elevation 3-dB beamwidths, peak gain, tilt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Antenna {
    /// Azimuth 3-dB (half-power) beamwidth, rad.
    pub az_beamwidth_rad: f64,
    /// Elevation 3-dB beamwidth, rad.
    pub el_beamwidth_rad: f64,
    /// Peak one-way power gain G0 (linear).
    pub peak_gain_linear: f64,
    /// Elevation of the beam axis above horizontal, rad.
    pub tilt_rad: f64,
}

/// One-way normalised sinc² power pattern of one plane at `off_axis_rad` from boresight.
#[inline]
pub fn sinc2_pattern(off_axis_rad: f64, beamwidth_3db_rad: f64) -> f64 {
    let u = SINC_BEAMWIDTH_FACTOR * off_axis_rad / beamwidth_3db_rad;
    if u.abs() < 1e-8 {
        1.0
    } else {
        let s = crate::special::sin_fast(u) / u;
        s * s
    }
}

/// Peak gain of a uniform rectangular aperture with the given half-power beamwidths (linear).
pub fn uniform_aperture_gain(az_beamwidth_rad: f64, el_beamwidth_rad: f64) -> f64 {
    4.0 * std::f64::consts::PI * UNIFORM_APERTURE_HPBW_FACTOR * UNIFORM_APERTURE_HPBW_FACTOR
        / (az_beamwidth_rad * el_beamwidth_rad)
}

/// Wraps an angle difference into (−π, π].
#[inline]
pub fn wrap_angle_rad(angle_rad: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    let mut a = crate::special::rem_euclid_tau(angle_rad);
    if a > std::f64::consts::PI {
        a -= two_pi;
    }
    a
}

impl Antenna {
    /// One-way normalised azimuth power pattern at `delta_az_rad` off the beam axis.
    #[inline]
    pub fn azimuth_pattern(&self, delta_az_rad: f64) -> f64 {
        sinc2_pattern(wrap_angle_rad(delta_az_rad), self.az_beamwidth_rad)
    }

    /// `|u|` of the azimuth pattern at `delta_az_rad` off the beam axis: the pattern
    /// `[sin(u)/u]²` is at most `1/u²` there (its envelope), which needs no sine.
    #[inline]
    pub fn azimuth_pattern_abs_u(&self, delta_az_rad: f64) -> f64 {
        (SINC_BEAMWIDTH_FACTOR * wrap_angle_rad(delta_az_rad) / self.az_beamwidth_rad).abs()
    }

    /// The same antenna with its beam axis raised by `extra_tilt_rad` (the deck's roll and
    /// pitch).
    pub fn tilted_by(&self, extra_tilt_rad: f64) -> Antenna {
        Antenna {
            tilt_rad: self.tilt_rad + extra_tilt_rad,
            ..*self
        }
    }

    /// One-way normalised elevation power pattern at elevation `el_rad` (the beam axis is at
    /// the tilt angle).
    #[inline]
    pub fn elevation_pattern(&self, el_rad: f64) -> f64 {
        sinc2_pattern(el_rad - self.tilt_rad, self.el_beamwidth_rad)
    }

    /// Two-way voltage weight (0..1) of a path leaving the radar toward (`az_tx`, `el_tx`) and
    /// returning from (`az_rx`, `el_rx`), with the beam pointing at `beam_az_rad`:
    /// `sqrt(Gn_tx · Gn_rx)` in each plane (docs/physics.md §3).
    #[inline]
    pub fn two_way_voltage_weight(
        &self,
        beam_az_rad: f64,
        az_tx_rad: f64,
        el_tx_rad: f64,
        az_rx_rad: f64,
        el_rx_rad: f64,
    ) -> f64 {
        let az = (self.azimuth_pattern(az_tx_rad - beam_az_rad)
            * self.azimuth_pattern(az_rx_rad - beam_az_rad))
        .sqrt();
        let el = (self.elevation_pattern(el_tx_rad) * self.elevation_pattern(el_rx_rad)).sqrt();
        az * el
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_power_at_half_beamwidth() {
        let bw = 3.9f64.to_radians();
        let g = sinc2_pattern(bw / 2.0, bw);
        assert!(
            (10.0 * g.log10() + 3.0103).abs() < 0.01,
            "{}",
            10.0 * g.log10()
        );
    }

    #[test]
    fn wrap_keeps_range() {
        for a in [-7.0, -3.2, 0.0, 3.2, 7.0, 100.0] {
            let w = wrap_angle_rad(a);
            assert!(w > -std::f64::consts::PI - 1e-12 && w <= std::f64::consts::PI + 1e-12);
            assert!(
                ((a - w) / std::f64::consts::TAU).fract().abs() < 1e-9
                    || ((a - w) / std::f64::consts::TAU).fract().abs() > 1.0 - 1e-9
            );
        }
    }
}
