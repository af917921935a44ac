//! Receiver stages, each a small unit with explicit buffers, in the order a receiver applies
//! them (docs/architecture.md, "Signal chain"): [`Blanking`] on the received record (the
//! receiver's), [`GainStc`] on the compressed signal before detection (the engine's chain,
//! skipped at its neutral setting, so the calibrated outputs stay exactly the matched
//! filter's power), the [`Detector`] (the integrators detect with it) and the [`Ftc`] on
//! log video (the video chain, `super::video_chain`).
//!
//! Sensitivity time control lowers the gain by `10·k·log10(R_stc/R)` dB inside `R_stc`, the
//! classic R⁻ᵏ law against sea clutter (k = 3 for a point target's R⁻⁴ echo against an
//! area's R⁻³; Skolnik, *Radar Handbook*, 3rd ed., §2.9). The fast time constant is a
//! first-order differentiator along range, keeping leading edges and flattening extended
//! echoes such as rain (Briggs, *Target Detection by Marine Radar*, IEE, 2004, on the fast
//! time constant).

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

/// The fast time constant (rain clutter control): a first-order differentiator on a sweep's
/// log video along range, `y_n = a·(y_{n−1} + v_n − v_{n−1})` with `a = τ/(τ + Δt)` for time
/// constant τ and sample time Δt (from `y_{−1} = v_{−1} = 0`), negative output clipped to 0.
/// A step of height h leaves `h·aⁿ⁺¹` at its sample n: extended echoes such as rain fade
/// within a few τ, their leading edges and short echoes pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ftc {
    /// `τ/(τ + Δt)`.
    pub a: f32,
}

impl Ftc {
    /// The differentiator of time constant `tau_s` on samples `sample_s` apart.
    pub fn new(tau_s: f64, sample_s: f64) -> Ftc {
        Ftc {
            a: (tau_s / (tau_s + sample_s)) as f32,
        }
    }

    /// Applies it to one sweep's log video, in place.
    pub fn apply(&self, video_db: &mut [f32]) {
        let (mut prev_in, mut prev_out) = (0f32, 0f32);
        for v in video_db.iter_mut() {
            let x = *v;
            let y = self.a * (prev_out + x - prev_in);
            prev_in = x;
            prev_out = y;
            *v = y.max(0.0);
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

    /// The FTC's step response is `h·aⁿ⁺¹` (`a = τ/(τ + Δt)`, the first-order high-pass's
    /// sampled step response, `≈ exp(−t/τ)`); a pulse's trailing edge goes negative and is
    /// clipped to 0; a flat record stays 0 after its first samples fade.
    #[test]
    fn ftc_step_response() {
        let ftc = Ftc::new(0.5e-6, 0.05e-6);
        assert!((ftc.a - 0.5 / 0.55).abs() < 1e-7);
        let mut v: Vec<f32> = (0..60).map(|n| if n < 10 { 0.0 } else { 20.0 }).collect();
        ftc.apply(&mut v);
        for (n, y) in v.iter().enumerate() {
            let want = if n < 10 {
                0.0
            } else {
                20.0 * ftc.a.powi((n - 10) as i32 + 1)
            };
            assert!((y - want).abs() < 1e-4, "sample {n}: {y} vs {want}");
        }
        // exp(−t/τ): after 10 samples (τ) the step is down to about e⁻¹.
        assert!((v[19] / 20.0 - (-1.0f32).exp()).abs() < 0.02, "{}", v[19]);
        let mut pulse = vec![0f32; 20];
        pulse[5] = 30.0;
        ftc.apply(&mut pulse);
        assert!((pulse[5] - 30.0 * ftc.a).abs() < 1e-4);
        assert!(pulse[6..].iter().all(|&y| y == 0.0));
    }
}
