//! Receiver stages, each a small unit with explicit buffers, in the order a receiver applies
//! them (docs/architecture.md, "Signal chain"): [`Blanking`] on the received record (the
//! receiver's), [`GainStc`] on the compressed signal before detection (the engine's chain,
//! skipped at its neutral setting, so the calibrated outputs stay exactly the matched
//! filter's power), the [`Detector`] (the integrators detect with it) and the [`Ftc`] on
//! detected power (the operator's display controls, `super::video`).
//!
//! Sensitivity time control lowers the gain by `10·k·log10(R_stc/R)` dB inside `R_stc`, the
//! classic R⁻ᵏ law against sea clutter (k = 3 for a point target's R⁻⁴ echo against an
//! area's R⁻³; Skolnik, *Radar Handbook*, 3rd ed., §2.9). The fast time constant is a
//! differentiator along range: it takes `α` times the local mean power over
//! `2·half_window + 1` cells off each cell, keeping leading edges and flattening extended
//! echoes such as rain (Skolnik §2.9; Briggs, *Target Detection by Marine Radar*, IEE,
//! 2004, on the fast time constant).

use num_complex::Complex32;

/// Zeroes the first `samples` samples of a record: the receiver is switched off while its own
/// pulse goes out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Blanking {
    /// Blanked samples (the transmitted pulse's length).
    pub samples: usize,
}

impl Blanking {
    /// Blanks `record` in place.
    pub fn apply(&self, record: &mut [Complex32]) {
        let n = self.samples.min(record.len());
        record[..n].fill(Complex32::new(0.0, 0.0));
    }
}

/// Sensitivity time control loss at range `range_m` for law `k` and reach `reach_m`, dB
/// (0 at and beyond `reach_m` and for k = 0; ranges under 1 m count as 1 m).
pub fn stc_loss_db(range_m: f64, law: f32, reach_m: f64) -> f32 {
    if law == 0.0 || range_m >= reach_m {
        return 0.0;
    }
    (10.0 * f64::from(law) * (reach_m / range_m.max(1.0)).log10()) as f32
}

/// Gain and sensitivity time control on the compressed signal, before the detector: bin j
/// (range `j·range_bin_m`) is scaled in amplitude by `10^((gain − STC(R))/20)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GainStc {
    /// Gain, dB (0: the calibrated signal).
    pub gain_db: f32,
    /// STC law k (0: off).
    pub stc_law: f32,
    /// Range inside which STC acts, m.
    pub stc_reach_m: f64,
    /// Range of one bin, m.
    pub range_bin_m: f64,
}

impl GainStc {
    /// Whether it leaves the signal as it is (0 dB gain, STC off).
    pub fn is_neutral(&self) -> bool {
        self.gain_db == 0.0 && self.stc_law == 0.0
    }

    /// The amplitude factor of bin `j`.
    pub fn factor(&self, j: usize) -> f32 {
        let stc = stc_loss_db(j as f64 * self.range_bin_m, self.stc_law, self.stc_reach_m);
        10f32.powf((self.gain_db - stc) / 20.0)
    }

    /// Applies it to a spoke's compressed bins in place.
    pub fn apply(&self, bins: &mut [Complex32]) {
        if self.is_neutral() {
            return;
        }
        let flat = 10f32.powf(self.gain_db / 20.0);
        for (j, y) in bins.iter_mut().enumerate() {
            let factor = if (j as f64) * self.range_bin_m < self.stc_reach_m {
                self.factor(j)
            } else {
                flat
            };
            *y *= factor;
        }
    }
}

/// The detector: what the video carries of each complex bin.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Detector {
    /// Linear power `|y|²` (a square-law detector; the calibrated record).
    #[default]
    LinearPower,
}

impl Detector {
    /// The detected value of one bin.
    #[inline]
    pub fn power(&self, y: Complex32) -> f32 {
        match self {
            Detector::LinearPower => y.norm_sqr(),
        }
    }

    /// Detects `bins` into `out` (the same length).
    pub fn apply(&self, bins: &[Complex32], out: &mut [f32]) {
        for (o, y) in out.iter_mut().zip(bins) {
            *o = self.power(*y);
        }
    }
}

/// The fast time constant on detected power: `max(p − α·mean, floor)` with the mean over the
/// `2·half_window + 1` cells around each cell along range (clipped at the record's ends).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ftc {
    /// The fraction α of the local mean taken off (0: off).
    pub fraction: f32,
    /// Half-width of the local mean, bins.
    pub half_window_bins: usize,
    /// Smallest value it leaves, linear power.
    pub floor_power: f32,
}

impl Ftc {
    /// Whether it leaves the video as it is (α = 0).
    pub fn is_neutral(&self) -> bool {
        self.fraction == 0.0
    }

    /// Applies it to the detected `power` of one spoke into `out` (the same length), with a
    /// running sum over the window (f64).
    pub fn apply(&self, power: &[f32], out: &mut [f32]) {
        let n = power.len();
        if n == 0 {
            return;
        }
        let h = self.half_window_bins;
        let mut sum: f64 = power[..(h + 1).min(n)].iter().map(|&p| f64::from(p)).sum();
        for j in 0..n {
            let lo = j.saturating_sub(h);
            let hi = (j + h).min(n - 1);
            let mean = (sum / (hi - lo + 1) as f64) as f32;
            out[j] = (power[j] - self.fraction * mean).max(self.floor_power);
            // Slide: add j+h+1, drop j−h.
            if j + h + 1 < n {
                sum += f64::from(power[j + h + 1]);
            }
            if j >= h {
                sum -= f64::from(power[j - h]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bins(n: usize) -> Vec<Complex32> {
        (0..n)
            .map(|j| Complex32::new((j as f32 * 0.37).sin() * 3.0, (j as f32 * 0.11).cos()))
            .collect()
    }

    #[test]
    fn blanking_zeroes_the_transmit_interval_only() {
        let mut r = bins(20);
        let keep = r.clone();
        Blanking { samples: 7 }.apply(&mut r);
        for (j, (a, b)) in r.iter().zip(&keep).enumerate() {
            let want = if j < 7 { Complex32::new(0.0, 0.0) } else { *b };
            assert_eq!(*a, want, "sample {j}");
        }
        // Longer than the record: all of it.
        let mut short = bins(3);
        Blanking { samples: 9 }.apply(&mut short);
        assert!(short.iter().all(|c| c.norm() == 0.0));
    }

    #[test]
    fn gain_and_stc_match_the_law_bin_by_bin() {
        let stage = GainStc {
            gain_db: 6.0,
            stc_law: 3.0,
            stc_reach_m: 1000.0,
            range_bin_m: 7.5,
        };
        let input = bins(200);
        let mut y = input.clone();
        stage.apply(&mut y);
        for j in 0..200 {
            // Naive reference: R⁻ᵏ inside the reach, in f64.
            let r = (j as f64 * 7.5).max(1.0);
            let stc = if r < 1000.0 && j as f64 * 7.5 < 1000.0 {
                30.0 * (1000.0 / r).log10()
            } else {
                0.0
            };
            let g = 10f64.powf((6.0 - stc) / 20.0);
            let want = Complex32::new(
                (f64::from(input[j].re) * g) as f32,
                (f64::from(input[j].im) * g) as f32,
            );
            assert!(
                (y[j] - want).norm() <= 1e-5 * want.norm().max(1e-30),
                "bin {j}: {} vs {want}",
                y[j]
            );
        }
        assert!((stc_loss_db(100.0, 3.0, 1000.0) - 30.0).abs() < 1e-4);
        assert_eq!(stc_loss_db(1000.0, 3.0, 1000.0), 0.0);
        let neutral = GainStc {
            gain_db: 0.0,
            stc_law: 0.0,
            ..stage
        };
        let mut same = input.clone();
        neutral.apply(&mut same);
        assert_eq!(same, input);
        assert!(neutral.is_neutral() && !stage.is_neutral());
    }

    #[test]
    fn detector_is_the_square_law() {
        let y = bins(33);
        let mut p = vec![0f32; 33];
        Detector::LinearPower.apply(&y, &mut p);
        for (o, c) in p.iter().zip(&y) {
            assert_eq!(*o, c.re * c.re + c.im * c.im);
        }
    }

    /// The FTC's step response, the differentiator's signature: on a step from p0 to P at
    /// bin s (half-window h, fraction α) the leading edge keeps `P − α·((h+1)·P + h·p0)/(2h+1)`,
    /// the plateau settles to `P·(1 − α)` once the window is inside it, and before the step
    /// the background keeps `p0·(1 − α)` until the window reaches the edge (Briggs, *Target
    /// Detection by Marine Radar*, 2004: the fast time constant passes leading edges and
    /// flattens extended echoes).
    #[test]
    fn ftc_step_response() {
        let (p0, p, s, h, alpha) = (1.0f32, 100.0f32, 40usize, 8usize, 0.9f32);
        let power: Vec<f32> = (0..100).map(|j| if j < s { p0 } else { p }).collect();
        let ftc = Ftc {
            fraction: alpha,
            half_window_bins: h,
            floor_power: 1e-3,
        };
        let mut out = vec![0f32; power.len()];
        ftc.apply(&power, &mut out);
        let n = (2 * h + 1) as f32;
        let edge = p - alpha * ((h as f32 + 1.0) * p + h as f32 * p0) / n;
        assert!(
            (out[s] - edge).abs() < 1e-3 * edge,
            "edge {} vs {edge}",
            out[s]
        );
        for j in s + h..power.len() - h {
            assert!(
                (out[j] - p * (1.0 - alpha)).abs() < 1e-3 * p,
                "plateau bin {j}: {}",
                out[j]
            );
        }
        for j in h..s - h {
            assert!(
                (out[j] - p0 * (1.0 - alpha)).abs() < 1e-5,
                "background bin {j}"
            );
        }
        // The edge stands out of the plateau by the differentiator's gain.
        assert!(out[s] > 4.0 * out[s + h]);
    }

    #[test]
    fn ftc_running_mean_matches_a_direct_mean() {
        for (n, h) in [(50, 8), (5, 8), (17, 0), (1, 3)] {
            let power: Vec<f32> = (0..n).map(|j| 1.0 + ((j * 37) % 23) as f32).collect();
            let ftc = Ftc {
                fraction: 0.6,
                half_window_bins: h,
                floor_power: 1e-3,
            };
            let mut out = vec![0f32; n];
            ftc.apply(&power, &mut out);
            for j in 0..n {
                let lo = j.saturating_sub(h);
                let hi = (j + h).min(n - 1);
                let mean: f64 = power[lo..=hi].iter().map(|&p| f64::from(p)).sum::<f64>()
                    / (hi - lo + 1) as f64;
                let want = (f64::from(power[j]) - 0.6 * mean).max(1e-3);
                assert!(
                    (f64::from(out[j]) - want).abs() <= 1e-5 * want,
                    "n {n}, h {h}, bin {j}: {} vs {want}",
                    out[j]
                );
            }
        }
        assert!(Ftc {
            fraction: 0.0,
            half_window_bins: 8,
            floor_power: 1e-3
        }
        .is_neutral());
    }
}
