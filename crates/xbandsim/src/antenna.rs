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

/// A one-way normalised power pattern of one plane, `Gn(θ)` with `Gn(0) = 1`: its value, a
/// bound on it that needs no trigonometry (the engine skips echoes far in the sidelobes with
/// it) and its two-way integral (the clutter map's beam weights). The uniform aperture's
/// sinc² is the only pattern today; another pattern is another variant with these three.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pattern {
    /// `Gn(θ) = [sin(u)/u]²`, `u = 2.783·θ/θ3dB` (a uniformly illuminated aperture).
    Sinc2 {
        /// Half-power (3-dB) beamwidth, rad.
        beamwidth_3db_rad: f64,
    },
}

impl Pattern {
    /// The sinc² pattern of half-power beamwidth `beamwidth_3db_rad`.
    pub fn sinc2(beamwidth_3db_rad: f64) -> Pattern {
        Pattern::Sinc2 { beamwidth_3db_rad }
    }

    /// `Gn(θ)` at `off_axis_rad` from the beam axis (not wrapped).
    #[inline]
    pub fn value(&self, off_axis_rad: f64) -> f64 {
        match *self {
            Pattern::Sinc2 { beamwidth_3db_rad } => sinc2_pattern(off_axis_rad, beamwidth_3db_rad),
        }
    }

    /// A lower bound of `1/√Gn(θ)` at `off_axis_rad` — the reciprocal of an envelope of the
    /// one-way voltage pattern — that needs no trigonometry: for sinc², `|u|`, since
    /// `[sin(u)/u]² ≤ 1/u²`. Small near the axis (where it says nothing), large in the far
    /// sidelobes.
    #[inline]
    pub fn inverse_voltage_envelope(&self, off_axis_rad: f64) -> f64 {
        match *self {
            Pattern::Sinc2 { beamwidth_3db_rad } => {
                (SINC_BEAMWIDTH_FACTOR * off_axis_rad / beamwidth_3db_rad).abs()
            }
        }
    }

    /// The two-way integral `∫Gn²(θ)dθ` over the plane, rad: for sinc²
    /// `(2π/3)·θ3dB/2.783 = 0.753·θ3dB` (∫sinc⁴ = 2π/3).
    pub fn two_way_integral_rad(&self) -> f64 {
        match *self {
            Pattern::Sinc2 { beamwidth_3db_rad } => {
                (2.0 * std::f64::consts::PI / 3.0) * beamwidth_3db_rad / SINC_BEAMWIDTH_FACTOR
            }
        }
    }

    /// Angle of the first null from the axis, rad: for sinc² `π·θ3dB/2.783`.
    pub fn first_null_rad(&self) -> f64 {
        match *self {
            Pattern::Sinc2 { beamwidth_3db_rad } => {
                std::f64::consts::PI * beamwidth_3db_rad / SINC_BEAMWIDTH_FACTOR
            }
        }
    }
}

/// A separable antenna: azimuth and elevation 3-dB beamwidths (each plane's [`Pattern`] is
/// the sinc² of its beamwidth), peak gain, tilt.
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
    /// The azimuth plane's pattern.
    #[inline]
    pub fn azimuth(&self) -> Pattern {
        Pattern::sinc2(self.az_beamwidth_rad)
    }

    /// The elevation plane's pattern.
    #[inline]
    pub fn elevation(&self) -> Pattern {
        Pattern::sinc2(self.el_beamwidth_rad)
    }

    /// One-way normalised azimuth power pattern at `delta_az_rad` off the beam axis.
    #[inline]
    pub fn azimuth_pattern(&self, delta_az_rad: f64) -> f64 {
        self.azimuth().value(wrap_angle_rad(delta_az_rad))
    }

    /// The azimuth pattern's [`Pattern::inverse_voltage_envelope`] at `delta_az_rad` off the
    /// beam axis (wrapped).
    #[inline]
    pub fn azimuth_inverse_envelope(&self, delta_az_rad: f64) -> f64 {
        self.azimuth()
            .inverse_voltage_envelope(wrap_angle_rad(delta_az_rad))
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
        self.elevation().value(el_rad - self.tilt_rad)
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

    /// The pattern's bound holds everywhere (to the sine's rounding), and its two-way
    /// integral is the numerical one (midpoint rule over ±40 beamwidths, the tail beyond
    /// falls as θ⁻⁴: under 10⁻⁶ of the whole).
    #[test]
    fn pattern_bound_and_integral_against_brute_force() {
        for bw_deg in [1.2, 3.9, 25.0] {
            let p = Pattern::sinc2(f64::to_radians(bw_deg));
            let bw = f64::to_radians(bw_deg);
            for i in 0..20_000 {
                let t = (i as f64 - 10_000.0) / 10_000.0 * 40.0 * bw;
                let r = p.inverse_voltage_envelope(t);
                assert!(p.value(t) * r * r <= 1.0 + 1e-9, "{bw_deg}° at {t}");
            }
            let n = 400_000;
            let h = 80.0 * bw / n as f64;
            let numeric: f64 = (0..n)
                .map(|i| p.value(-40.0 * bw + (i as f64 + 0.5) * h).powi(2) * h)
                .sum();
            let closed = p.two_way_integral_rad();
            assert!(
                (numeric / closed - 1.0).abs() < 1e-5,
                "{bw_deg}°: {numeric} vs {closed}"
            );
            assert!(p.value(p.first_null_rad()) < 1e-12);
        }
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
