//! Stage: waveform. Baseband linear-FM chirp and the amplitude windows used on the
//! matched-filter reference.
//!
//! Chirp (docs/physics.md §4; Richards, *Fundamentals of Radar Signal Processing*, 2nd ed., §4.6):
//! `s(t) = exp(jπ(B/T)(t − T/2)²)`, `0 ≤ t < T`, sampled at `t_n = n/fs`, `n = 0..N_T`,
//! `N_T = round(T·fs)`. Its instantaneous frequency sweeps −B/2 … +B/2; |s| = 1.
//!
//! Windows (Harris, "On the use of windows…", Proc. IEEE 66(1), 1978; Taylor weighting as in
//! Carrara, Goodman & Majewski, *Spotlight Synthetic Aperture Radar*, 1995, App. D):
//! Hamming `w[n] = 0.54 − 0.46·cos(2πn/(N−1))`; Taylor with n̄ and peak sidelobe level SLL:
//! `A = acosh(10^(−SLL/20))/π`, `σ² = n̄²/(A² + (n̄−½)²)`,
//! `F_m = (−1)^{m+1} Π_{n=1}^{n̄−1}[1 − m²/(σ²(A²+(n−½)²))] / (2 Π_{n≠m}[1 − m²/n²])`,
//! `w(x) = 1 + 2 Σ_{m=1}^{n̄−1} F_m cos(2πm·x)`, `x = (n − (N−1)/2)/N`.
//! SNR loss of a window on the reference only: `(Σw)²/(N·Σw²)` (docs/physics.md §7).

use num_complex::Complex64;
use std::f64::consts::PI;

/// Amplitude window applied to the matched-filter reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Window {
    /// No weighting (rectangular): PSLR −13.3 dB, no SNR loss.
    None,
    /// Hamming weighting: PSLR about −42 dB, SNR loss about 1.34 dB.
    Hamming,
    /// Taylor weighting with `nbar` terms and peak sidelobe level `sidelobe_db` (negative).
    Taylor { nbar: usize, sidelobe_db: f64 },
}

impl Window {
    /// The default Taylor window, n̄ = 4, −35 dB.
    pub const TAYLOR_DEFAULT: Window = Window::Taylor {
        nbar: 4,
        sidelobe_db: -35.0,
    };

    /// Window coefficients for `n` samples.
    pub fn coefficients(&self, n: usize) -> Vec<f64> {
        match *self {
            Window::None => vec![1.0; n],
            Window::Hamming => {
                if n == 1 {
                    return vec![1.0];
                }
                (0..n)
                    .map(|i| 0.54 - 0.46 * (2.0 * PI * i as f64 / (n as f64 - 1.0)).cos())
                    .collect()
            }
            Window::Taylor { nbar, sidelobe_db } => taylor_coefficients(n, nbar, sidelobe_db),
        }
    }

    /// SNR loss of this window used on the reference only, `(Σw)²/(N·Σw²)` (≤ 1, linear).
    pub fn snr_loss_linear(&self, n: usize) -> f64 {
        let w = self.coefficients(n);
        let sum: f64 = w.iter().sum();
        let sum_sq: f64 = w.iter().map(|x| x * x).sum();
        sum * sum / (n as f64 * sum_sq)
    }

    /// Lower-case name as used in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            Window::None => "none",
            Window::Hamming => "hamming",
            Window::Taylor { .. } => "taylor",
        }
    }
}

fn taylor_coefficients(n: usize, nbar: usize, sidelobe_db: f64) -> Vec<f64> {
    let r = 10f64.powf(-sidelobe_db.abs() / 20.0);
    let a = (1.0 / r).acosh() / PI;
    let nb = nbar as f64;
    let sigma2 = nb * nb / (a * a + (nb - 0.5) * (nb - 0.5));
    let fm: Vec<f64> = (1..nbar)
        .map(|m| {
            let mf = m as f64;
            let mut num = 1.0;
            for i in 1..nbar {
                let fi = i as f64;
                num *= 1.0 - mf * mf / (sigma2 * (a * a + (fi - 0.5) * (fi - 0.5)));
            }
            let mut den = 1.0;
            for i in 1..nbar {
                if i != m {
                    let fi = i as f64;
                    den *= 1.0 - mf * mf / (fi * fi);
                }
            }
            let sign = if m % 2 == 1 { 1.0 } else { -1.0 };
            sign * num / (2.0 * den)
        })
        .collect();
    let centre = (n as f64 - 1.0) / 2.0;
    let w: Vec<f64> = (0..n)
        .map(|i| {
            let x = (i as f64 - centre) / n as f64;
            1.0 + 2.0
                * fm.iter()
                    .enumerate()
                    .map(|(k, f)| f * (2.0 * PI * (k as f64 + 1.0) * x).cos())
                    .sum::<f64>()
        })
        .collect();
    let peak = w.iter().cloned().fold(f64::MIN, f64::max);
    w.into_iter().map(|x| x / peak).collect()
}

/// A baseband linear-FM pulse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LfmChirp {
    /// Swept bandwidth B, Hz.
    pub bandwidth_hz: f64,
    /// Pulse width T, s.
    pub pulse_width_s: f64,
    /// Complex sample rate fs, Hz.
    pub sample_rate_hz: f64,
}

impl LfmChirp {
    /// Number of samples in the pulse, `N_T = round(T·fs)` (at least 1).
    pub fn num_samples(&self) -> usize {
        ((self.pulse_width_s * self.sample_rate_hz).round() as usize).max(1)
    }

    /// Time-bandwidth product B·T (the pulse-compression gain).
    pub fn time_bandwidth_product(&self) -> f64 {
        self.bandwidth_hz * self.pulse_width_s
    }

    /// The pulse at continuous time `t_s` (zero outside `0 ≤ t < T`).
    #[inline]
    pub fn value_at(&self, t_s: f64) -> Complex64 {
        if !(0.0..self.pulse_width_s).contains(&t_s) {
            return Complex64::new(0.0, 0.0);
        }
        let tc = t_s - self.pulse_width_s / 2.0;
        let phase = PI * self.bandwidth_hz / self.pulse_width_s * tc * tc;
        Complex64::from_polar(1.0, phase)
    }

    /// The sampled pulse `s[n] = s(n/fs)`, `n = 0..N_T`.
    pub fn samples(&self) -> Vec<Complex64> {
        (0..self.num_samples())
            .map(|i| self.value_at(i as f64 / self.sample_rate_hz))
            .collect()
    }

    /// Instantaneous frequency at time `t_s`, Hz: `(B/T)(t − T/2)`.
    pub fn instantaneous_frequency_hz(&self, t_s: f64) -> f64 {
        self.bandwidth_hz / self.pulse_width_s * (t_s - self.pulse_width_s / 2.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hamming_snr_loss_is_1_34_db() {
        let loss_db = -10.0 * Window::Hamming.snr_loss_linear(1000).log10();
        assert!((loss_db - 1.34).abs() < 0.02, "{loss_db}");
    }

    #[test]
    fn taylor_is_symmetric_and_tapered() {
        let w = Window::TAYLOR_DEFAULT.coefficients(101);
        assert!((w[0] - w[100]).abs() < 1e-12);
        assert!(w[0] < w[50]);
        assert!((w[50] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn chirp_sweeps_band() {
        let c = LfmChirp {
            bandwidth_hz: 50e6,
            pulse_width_s: 1e-6,
            sample_rate_hz: 100e6,
        };
        assert_eq!(c.num_samples(), 100);
        assert!((c.instantaneous_frequency_hz(0.0) + 25e6).abs() < 1.0);
        assert!(c.samples().iter().all(|s| (s.norm() - 1.0).abs() < 1e-12));
    }
}
