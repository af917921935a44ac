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
/// it) and its two-way integral (the clutter map's beam weights).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pattern {
    /// `Gn(θ) = [sin(u)/u]²`, `u = 2.783·θ/θ3dB` (a uniformly illuminated aperture).
    Sinc2 {
        /// Half-power (3-dB) beamwidth, rad.
        beamwidth_3db_rad: f64,
    },
    /// A tapered aperture's pattern over the whole circle ([`Tapered`]): Taylor's n̄ line
    /// source in front, a floor under its far sidelobes and a back lobe behind.
    Tapered(Tapered),
    /// A measured cut from a CSV file ([`PatternTable`]).
    Table(&'static PatternTable),
}

/// The tapered patterns made last, by their inputs' bits.
static TAPERS: crate::cache::KeptLast<[u64; 5], Tapered> = crate::cache::KeptLast::new(16, 1 << 16);

/// Most n̄ a Taylor pattern takes.
pub const MAX_TAYLOR_NBAR: usize = 12;

/// A slotted-waveguide array's azimuth pattern over 360°: in front (`|θ| < 90°`) Taylor's n̄
/// line source (Taylor 1955; Balanis, *Antenna Theory*, 4th ed., §7.6)
/// `F(u) = sinc(πu)·Π_{n<n̄} (1 − u²/u_n²)/(1 − u²/n²)`, `u_n = σ·√(A² + (n − ½)²)`,
/// `σ = n̄/√(A² + (n̄ − ½)²)`, `A = acosh(R)/π` for the sidelobe ratio R (voltage), with
/// `u = u₃·sin θ/sin(θ3dB/2)` so that `F² = ½` at the half-power angle; `Gn = max(F², floor)`
/// (the far sidelobes of a real array stop falling at the level its errors set); behind
/// (`|θ| ≥ 90°`) `Gn = back lobe`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tapered {
    /// Half-power beamwidth, rad.
    pub beamwidth_3db_rad: f64,
    /// n̄.
    pub nbar: usize,
    /// The `u_n` of n = 1 … n̄ − 1 (unused beyond).
    pub zeros: [f64; MAX_TAYLOR_NBAR],
    /// `u₃/sin(θ3dB/2)`: u per unit of sin θ.
    pub u_per_sine: f64,
    /// One-way floor of the far sidelobes (linear).
    pub floor: f64,
    /// One-way back-lobe level (linear).
    pub back_lobe: f64,
    /// `∫Gn²` over the circle, rad (numerical, at construction).
    pub two_way_integral_rad: f64,
    /// Angle of the first null, rad.
    pub first_null_rad: f64,
    /// `K` with `|F(u)| ≤ K/(π|u|)` for `|u| ≥ n̄` (the far sidelobes' sinc envelope times the
    /// product's limit, found over `n̄ … 64·n̄` with a margin).
    pub far_envelope: f64,
}

impl Tapered {
    /// The pattern of half-power beamwidth `beamwidth_3db_rad` with Taylor sidelobes
    /// `sidelobe_db` (< −13.3, e.g. −28) and `nbar`, far-sidelobe floor `floor_db` and back
    /// lobe `back_lobe_db` (one-way, dB under the peak). Its integral takes a few
    /// milliseconds: the last patterns made are kept ([`TAPERS`]), so that a dataset's scenes
    /// of one radar make it once.
    pub fn new(
        beamwidth_3db_rad: f64,
        sidelobe_db: f64,
        nbar: usize,
        floor_db: f64,
        back_lobe_db: f64,
    ) -> Tapered {
        let key = [
            beamwidth_3db_rad.to_bits(),
            sidelobe_db.to_bits(),
            nbar as u64,
            floor_db.to_bits(),
            back_lobe_db.to_bits(),
        ];
        TAPERS.get_or_make(
            key,
            || Tapered::make(beamwidth_3db_rad, sidelobe_db, nbar, floor_db, back_lobe_db),
            |_| std::mem::size_of::<Tapered>(),
        )
    }

    fn make(
        beamwidth_3db_rad: f64,
        sidelobe_db: f64,
        nbar: usize,
        floor_db: f64,
        back_lobe_db: f64,
    ) -> Tapered {
        let nbar = nbar.clamp(2, MAX_TAYLOR_NBAR);
        let r = 10f64.powf(-sidelobe_db / 20.0);
        let a = r.acosh() / std::f64::consts::PI;
        let nb = nbar as f64;
        let sigma = nb / (a * a + (nb - 0.5).powi(2)).sqrt();
        let mut zeros = [0.0; MAX_TAYLOR_NBAR];
        for (n, z) in zeros.iter_mut().enumerate().take(nbar).skip(1) {
            *z = sigma * (a * a + (n as f64 - 0.5).powi(2)).sqrt();
        }
        let mut t = Tapered {
            beamwidth_3db_rad,
            nbar,
            zeros,
            u_per_sine: 1.0,
            floor: 10f64.powf(floor_db / 10.0),
            back_lobe: 10f64.powf(back_lobe_db / 10.0),
            two_way_integral_rad: 0.0,
            first_null_rad: 0.0,
            far_envelope: 0.0,
        };
        // u₃: F² = ½, by bisection on the main lobe (F falls monotonically to its first zero,
        // u_1 or, for n̄ = 2 … , below n̄).
        let (mut lo, mut hi) = (0.0, t.zeros[1].max(1.0));
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if t.taylor_power(mid) > 0.5 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let u3 = 0.5 * (lo + hi);
        t.u_per_sine = u3 / (beamwidth_3db_rad / 2.0).sin();
        t.first_null_rad = (t.zeros[1] / t.u_per_sine).min(1.0).asin();
        let steps = 200_000;
        t.far_envelope = (0..=steps)
            .map(|i| {
                let u = nb + 63.0 * nb * i as f64 / steps as f64;
                t.taylor_power(u).sqrt() * std::f64::consts::PI * u
            })
            .fold(0.0, f64::max)
            * 1.02;
        // ∫Gn² over the circle: fine steps through the main lobe and near sidelobes, then the
        // rest of the front and the back.
        let n = 400_000;
        let h = std::f64::consts::TAU / n as f64;
        t.two_way_integral_rad = (0..n)
            .map(|i| {
                let th = -std::f64::consts::PI + (i as f64 + 0.5) * h;
                t.value(th).powi(2) * h
            })
            .sum();
        t
    }

    /// Taylor's power pattern `F²(u)`.
    fn taylor_power(&self, u: f64) -> f64 {
        let pu = std::f64::consts::PI * u;
        let mut f = if pu.abs() < 1e-9 { 1.0 } else { pu.sin() / pu };
        let u2 = u * u;
        for n in 1..self.nbar {
            let nn = (n * n) as f64;
            let zz = self.zeros[n] * self.zeros[n];
            let den = 1.0 - u2 / nn;
            if den.abs() < 1e-12 {
                // sinc's zero at u = n cancels this pole: the finite limit, taken a hair off.
                return self.taylor_power(u + 1e-7);
            }
            f *= (1.0 - u2 / zz) / den;
        }
        f * f
    }

    /// A lower bound of `1/√Gn(θ)`: 0 where `|u| < n̄`, else `min(π|u|/K, 1/√floor)`, and
    /// `1/√back_lobe` behind.
    pub fn inverse_voltage_envelope(&self, off_axis_rad: f64) -> f64 {
        let th = wrap_angle_rad(off_axis_rad);
        if th.abs() >= std::f64::consts::FRAC_PI_2 {
            return 1.0 / self.back_lobe.sqrt();
        }
        let u = (self.u_per_sine * th.sin()).abs();
        if u < self.nbar as f64 {
            return 0.0;
        }
        (std::f64::consts::PI * u / self.far_envelope).min(1.0 / self.floor.sqrt())
    }

    /// `Gn(θ)` at `off_axis_rad` (wrapped into (−π, π]).
    pub fn value(&self, off_axis_rad: f64) -> f64 {
        let th = wrap_angle_rad(off_axis_rad);
        if th.abs() >= std::f64::consts::FRAC_PI_2 {
            return self.back_lobe;
        }
        let u = self.u_per_sine * th.sin();
        self.taylor_power(u).max(self.floor)
    }
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
            Pattern::Tapered(ref t) => t.value(off_axis_rad),
            Pattern::Table(t) => t.value(off_axis_rad),
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
            Pattern::Tapered(ref t) => t.inverse_voltage_envelope(off_axis_rad),
            Pattern::Table(t) => t.inverse_voltage_envelope(off_axis_rad),
        }
    }

    /// The two-way integral `∫Gn²(θ)dθ` over the plane, rad: for sinc²
    /// `(2π/3)·θ3dB/2.783 = 0.753·θ3dB` (∫sinc⁴ = 2π/3).
    pub fn two_way_integral_rad(&self) -> f64 {
        match *self {
            Pattern::Sinc2 { beamwidth_3db_rad } => {
                (2.0 * std::f64::consts::PI / 3.0) * beamwidth_3db_rad / SINC_BEAMWIDTH_FACTOR
            }
            Pattern::Tapered(ref t) => t.two_way_integral_rad,
            Pattern::Table(t) => t.two_way_integral_rad(),
        }
    }

    /// Angle of the first null from the axis, rad: for sinc² `π·θ3dB/2.783`.
    pub fn first_null_rad(&self) -> f64 {
        match *self {
            Pattern::Sinc2 { beamwidth_3db_rad } => {
                std::f64::consts::PI * beamwidth_3db_rad / SINC_BEAMWIDTH_FACTOR
            }
            Pattern::Tapered(ref t) => t.first_null_rad,
            Pattern::Table(t) => t.first_null_rad(),
        }
    }
}

/// A separable antenna: azimuth and elevation 3-dB beamwidths (the elevation plane's
/// [`Pattern`] is the sinc² of its beamwidth; the azimuth plane's too, or a [`Tapered`]
/// pattern over the whole circle), peak gain, tilt.
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
    /// The azimuth plane's tapered pattern (None: the uniform aperture's sinc²).
    pub azimuth_taper: Option<Tapered>,
    /// The azimuth plane's measured cut (it takes precedence).
    pub azimuth_table: Option<&'static PatternTable>,
    /// The elevation plane's measured cut (None: sinc²).
    pub elevation_table: Option<&'static PatternTable>,
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

pub mod table;
pub use table::PatternTable;

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
        match (self.azimuth_table, self.azimuth_taper) {
            (Some(t), _) => Pattern::Table(t),
            (None, Some(t)) => Pattern::Tapered(t),
            (None, None) => Pattern::sinc2(self.az_beamwidth_rad),
        }
    }

    /// The elevation plane's pattern.
    #[inline]
    pub fn elevation(&self) -> Pattern {
        match self.elevation_table {
            Some(t) => Pattern::Table(t),
            None => Pattern::sinc2(self.el_beamwidth_rad),
        }
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

    /// The tapered pattern: −3 dB at half the beamwidth, its highest sidelobe at the design
    /// level (Taylor's n̄ pattern holds its first sidelobes at it), the floor and back lobe
    /// where they belong, its envelope a bound everywhere, its integral the brute-force one.
    #[test]
    fn tapered_pattern_against_its_design() {
        for (bw_deg, sll, nbar) in [(1.1, -28.0, 5), (3.9, -25.0, 4), (1.9, -30.0, 6)] {
            let bw = f64::to_radians(bw_deg);
            let t = Tapered::new(bw, sll, nbar, -40.0, -35.0);
            let db = |th: f64| 10.0 * t.value(th).log10();
            assert!(
                (db(bw / 2.0) + 3.0103).abs() < 1e-6,
                "{bw_deg}°: {}",
                db(bw / 2.0)
            );
            assert!(db(t.first_null_rad) <= -40.0 + 1e-9);
            let (mut peak_side, mut i) = (f64::MIN, 0);
            while i < 200_000 {
                let th = t.first_null_rad * 1.0001 + i as f64 * 1e-6;
                if th > 10.0 * bw {
                    break;
                }
                peak_side = peak_side.max(db(th));
                i += 1;
            }
            // Taylor's sidelobes are nearly equal to the design level, within a few tenths of
            // a dB for small n̄ (Hansen, *Phased Array Antennas*, 2nd ed., 2009, on the n̄
            // choice).
            assert!(
                (peak_side - sll).abs() < 0.4,
                "{bw_deg}°: sidelobes {peak_side:.2} dB"
            );
            assert!((db(2.5) + 35.0).abs() < 1e-9 && (db(-2.0) + 35.0).abs() < 1e-9);
            // The floor holds the far sidelobes up: their lowest is it, none is under it.
            let far_min = (0..10_000)
                .map(|i| db(0.5 + i as f64 * 1e-4))
                .fold(f64::MAX, f64::min);
            assert!(
                (far_min + 40.0).abs() < 1e-9,
                "far sidelobes down to {far_min}"
            );
            let p = Pattern::Tapered(t);
            for i in 0..200_000 {
                let th = -std::f64::consts::PI + (i as f64 + 0.5) * std::f64::consts::TAU / 2e5;
                let r = p.inverse_voltage_envelope(th);
                assert!(p.value(th) * r * r <= 1.0 + 1e-9, "{bw_deg}° at {th}");
            }
            let n = 1_000_000;
            let h = std::f64::consts::TAU / n as f64;
            let numeric: f64 = (0..n)
                .map(|i| {
                    p.value(-std::f64::consts::PI + (i as f64 + 0.5) * h)
                        .powi(2)
                        * h
                })
                .sum();
            assert!((numeric / p.two_way_integral_rad() - 1.0).abs() < 1e-3);
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
