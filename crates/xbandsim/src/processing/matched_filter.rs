//! Matched filter by FFT, with the echo synthesis that feeds it.
//!
//! Reference `h = w·s/‖w·s‖` (docs/physics.md §7): white noise of variance N keeps variance N at
//! the output and a point echo `a·s(t−τ)` peaks at `|a|·Σw/√Σw²` in bin `τ·fs`.
//! Correlation `y[n] = Σ_m r[n+m]·h*[m]` is computed as `y = IFFT(R·H*)` (Richards,
//! *Fundamentals of Radar Signal Processing*, 2nd ed., §4.3), on an FFT length that holds the
//! record plus a pulse so nothing wraps into the output bins.
//!
//! Received record: `r = h_ir ⊛ s + n`, zeroed for `n < N_T` when the receiver is blanked
//! while transmitting. When no echo starts inside the blanked interval the echo part is
//! computed directly in the frequency domain, `Y = H_ir·(S·H*) + N·H*` (3 FFTs); otherwise
//! `r` is formed in time, blanked and transformed (4 FFTs). Plans and scratch are reused.

use crate::waveform::{LfmChirp, Window};
use num_complex::{Complex32, Complex64};
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// Smallest `2^a·3^b·5^c ≥ n` (fast sizes for rustfft).
pub fn fast_fft_len(n: usize) -> usize {
    let mut best = n.next_power_of_two();
    let mut p5 = 1usize;
    while p5 < best {
        let mut p35 = p5;
        while p35 < best {
            let mut p = p35;
            while p < n {
                p *= 2;
            }
            best = best.min(p);
            p35 *= 3;
        }
        p5 *= 5;
    }
    best
}

/// FFT plans and spectra for one waveform and record length (a clone shares the plans).
#[derive(Clone)]
pub struct PulseCompressor {
    fft_len: usize,
    pulse_len: usize,
    num_bins: usize,
    forward: Arc<dyn Fft<f32>>,
    inverse: Arc<dyn Fft<f32>>,
    /// `FFT(s)/n`: multiplies `FFT(h_ir)` to give the echo record after the inverse FFT.
    chirp_spectrum: Vec<Complex32>,
    /// `conj(FFT(h))/n`: the matched filter.
    filter_spectrum: Vec<Complex32>,
    /// `FFT(s)·conj(FFT(h))/n`: echo synthesis and matched filter in one.
    combined_spectrum: Vec<Complex32>,
    /// Peak gain of the filter on a unit echo, `Σw/√Σw²`.
    peak_gain: f64,
    /// The transmitted chirp's samples (for Doppler-shifted copies).
    chirp_samples: Vec<Complex64>,
}

/// The spectra of a Doppler-shifted echo `s(t)·exp(j2π·f_D·t)` (docs/physics.md §10): its
/// chirp spectrum `FFT(s_D)/n` (exact path) and `FFT(s_D)·conj(FFT(h))/n` (fused path).
#[derive(Debug, Clone)]
pub struct DopplerSpectra {
    /// `FFT(s_D)/n`.
    pub chirp: Vec<Complex32>,
    /// `FFT(s_D)·conj(FFT(h))/n`.
    pub combined: Vec<Complex32>,
}

impl std::fmt::Debug for PulseCompressor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PulseCompressor")
            .field("fft_len", &self.fft_len)
            .field("pulse_len", &self.pulse_len)
            .field("num_bins", &self.num_bins)
            .finish()
    }
}

/// Per-thread buffers for [`PulseCompressor::process`].
pub struct SpokeScratch {
    /// Impulse response / spectrum buffer (FFT length).
    pub buffer: Vec<Complex32>,
    /// Noise buffer (FFT length).
    pub noise: Vec<Complex32>,
    /// Impulse response of one moving object (FFT length), for
    /// [`PulseCompressor::add_moving_echo`].
    pub moving: Vec<Complex32>,
    /// Sum of the moving echoes' spectra (FFT length).
    moving_spectrum: Vec<Complex32>,
    fft_scratch: Vec<Complex32>,
    /// When set, [`PulseCompressor::process_with_moving`] forms the received record
    /// explicitly (the exact path) and keeps it in `received` (raw I/Q output).
    pub capture_received: bool,
    /// The last received record (`record_len` samples) when `capture_received` is set.
    pub received: Vec<Complex32>,
    /// The short-pulse channel's buffers (combined pulse mode; set by the engine).
    pub short: Option<Box<SpokeScratch>>,
    /// The signal sources' buffers (`crate::signal`).
    pub sources: crate::signal::SourceScratch,
}

impl SpokeScratch {
    /// Fills every buffer, the FFT's private scratch included, with `value`: results must not
    /// depend on what a scratch held before (tested with NaN).
    pub fn fill(&mut self, value: Complex32) {
        self.buffer.fill(value);
        self.noise.fill(value);
        self.moving.fill(value);
        self.moving_spectrum.fill(value);
        self.fft_scratch.fill(value);
        self.received.fill(value);
        self.sources.fill(value);
        if let Some(short) = &mut self.short {
            short.fill(value);
        }
    }
}

impl PulseCompressor {
    /// Plans for `chirp` with `window`, producing `num_bins` output range bins.
    pub fn new(chirp: &LfmChirp, window: Window, num_bins: usize) -> PulseCompressor {
        let s = chirp.samples();
        let pulse_len = s.len();
        let fft_len = fast_fft_len(num_bins + 2 * pulse_len);
        let mut planner = FftPlanner::<f32>::new();
        let forward = planner.plan_fft_forward(fft_len);
        let inverse = planner.plan_fft_inverse(fft_len);
        let w = window.coefficients(pulse_len);
        let norm: f64 = s
            .iter()
            .zip(&w)
            .map(|(x, wi)| (x * wi).norm_sqr())
            .sum::<f64>()
            .sqrt();
        let sum_w: f64 = w.iter().sum();
        let sum_w2: f64 = w.iter().map(|x| x * x).sum();
        let to32 = |c: Complex64| Complex32::new(c.re as f32, c.im as f32);
        let inv_n = 1.0 / fft_len as f64;
        let mut s_buf: Vec<Complex64> = vec![Complex64::new(0.0, 0.0); fft_len];
        s_buf[..pulse_len].copy_from_slice(&s);
        let mut h_buf: Vec<Complex64> = vec![Complex64::new(0.0, 0.0); fft_len];
        for i in 0..pulse_len {
            h_buf[i] = s[i] * (w[i] / norm);
        }
        // Spectra in f64 for accuracy, stored as f32.
        let mut planner64 = FftPlanner::<f64>::new();
        let fwd64 = planner64.plan_fft_forward(fft_len);
        fwd64.process(&mut s_buf);
        fwd64.process(&mut h_buf);
        let chirp_spectrum: Vec<Complex32> = s_buf.iter().map(|x| to32(x * inv_n)).collect();
        let filter_spectrum: Vec<Complex32> =
            h_buf.iter().map(|x| to32(x.conj() * inv_n)).collect();
        let combined_spectrum: Vec<Complex32> = s_buf
            .iter()
            .zip(&h_buf)
            .map(|(a, b)| to32(a * b.conj() * inv_n))
            .collect();
        PulseCompressor {
            fft_len,
            pulse_len,
            num_bins,
            forward,
            inverse,
            chirp_spectrum,
            filter_spectrum,
            combined_spectrum,
            peak_gain: sum_w / sum_w2.sqrt(),
            chirp_samples: s,
        }
    }

    /// The spectra of the chirp shifted by `doppler_hz` within the pulse, sampled at
    /// `sample_rate_hz`: `s_D[n] = s[n]·exp(j2π·f_D·n/fs)`. The matched filter stays the
    /// unshifted chirp's, so the compressed peak moves by the LFM range–Doppler coupling.
    pub fn doppler_spectra(&self, doppler_hz: f64, sample_rate_hz: f64) -> DopplerSpectra {
        let n = self.fft_len;
        let mut buf = vec![Complex64::new(0.0, 0.0); n];
        for (i, (b, x)) in buf.iter_mut().zip(&self.chirp_samples).enumerate() {
            let phase = std::f64::consts::TAU * doppler_hz * i as f64 / sample_rate_hz;
            *b = x * Complex64::from_polar(1.0, phase);
        }
        FftPlanner::<f64>::new()
            .plan_fft_forward(n)
            .process(&mut buf);
        let inv_n = 1.0 / n as f64;
        let chirp: Vec<Complex32> = buf
            .iter()
            .map(|x| {
                let y = x * inv_n;
                Complex32::new(y.re as f32, y.im as f32)
            })
            .collect();
        // filter_spectrum = conj(FFT h)/n, so FFT(s_D)·conj(FFT h)/n = FFT(s_D)·filter.
        let combined = buf
            .iter()
            .zip(&self.filter_spectrum)
            .map(|(x, h)| {
                let y = x * Complex64::new(h.re as f64, h.im as f64);
                Complex32::new(y.re as f32, y.im as f32)
            })
            .collect();
        DopplerSpectra { chirp, combined }
    }

    /// Clears the sum of moving echoes before a pulse's first [`Self::add_moving_echo`].
    pub fn clear_moving(&self, scratch: &mut SpokeScratch) {
        scratch.moving_spectrum.fill(Complex32::new(0.0, 0.0));
    }

    /// Adds the echo of one moving object to the pulse: its impulse response in
    /// `scratch.moving` (FFT length, zero beyond the record; overwritten) is transformed,
    /// delayed by `delay_samples` (a phase ramp `exp(−j2π·k·δ/n)` over signed frequency
    /// bins k: exact for a band-limited echo), multiplied by `factor` (the carrier phase
    /// advance) and by its Doppler-shifted chirp spectrum — `spectra.combined` for the fused
    /// path, `spectra.chirp` when the pulse takes the exact path (`fused == false`, see
    /// [`Self::process_with_moving`]).
    pub fn add_moving_echo(
        &self,
        scratch: &mut SpokeScratch,
        spectra: &DopplerSpectra,
        factor: Complex64,
        delay_samples: f64,
        fused: bool,
    ) {
        let SpokeScratch {
            moving,
            moving_spectrum,
            fft_scratch,
            ..
        } = scratch;
        self.forward.process_with_scratch(moving, fft_scratch);
        let n = self.fft_len;
        let spectrum = if fused {
            &spectra.combined
        } else {
            &spectra.chirp
        };
        let step = Complex64::from_polar(1.0, -std::f64::consts::TAU * delay_samples / n as f64);
        // Non-negative frequencies k = 0 .. ceil(n/2), then negative ones k − n.
        let half = n.div_ceil(2);
        let mut ramp = factor;
        for k in 0..half {
            let m = ramp * Complex64::new(spectrum[k].re as f64, spectrum[k].im as f64);
            moving_spectrum[k] += moving[k] * Complex32::new(m.re as f32, m.im as f32);
            ramp *= step;
        }
        let mut ramp = factor
            * Complex64::from_polar(
                1.0,
                std::f64::consts::TAU * delay_samples * (n - half) as f64 / n as f64,
            );
        for k in half..n {
            let m = ramp * Complex64::new(spectrum[k].re as f64, spectrum[k].im as f64);
            moving_spectrum[k] += moving[k] * Complex32::new(m.re as f32, m.im as f32);
            ramp *= step;
        }
    }

    /// FFT length used.
    pub fn fft_len(&self) -> usize {
        self.fft_len
    }

    /// Samples in the pulse, `N_T`.
    pub fn pulse_len(&self) -> usize {
        self.pulse_len
    }

    /// Output range bins.
    pub fn num_bins(&self) -> usize {
        self.num_bins
    }

    /// Samples recorded per pulse: every sample any output bin depends on, `bins + N_T − 1`.
    pub fn record_len(&self) -> usize {
        self.num_bins + self.pulse_len - 1
    }

    /// Peak amplitude gain of the filter on a unit echo, `Σw/√Σw²`.
    pub fn peak_gain(&self) -> f64 {
        self.peak_gain
    }

    /// Fresh buffers for one worker.
    pub fn scratch(&self) -> SpokeScratch {
        let n = self
            .forward
            .get_inplace_scratch_len()
            .max(self.inverse.get_inplace_scratch_len());
        SpokeScratch {
            buffer: vec![Complex32::new(0.0, 0.0); self.fft_len],
            noise: vec![Complex32::new(0.0, 0.0); self.fft_len],
            moving: vec![Complex32::new(0.0, 0.0); self.fft_len],
            moving_spectrum: vec![Complex32::new(0.0, 0.0); self.fft_len],
            fft_scratch: vec![Complex32::new(0.0, 0.0); n],
            capture_received: false,
            received: Vec::new(),
            short: None,
            sources: Default::default(),
        }
    }

    /// Runs the receive chain on `scratch.buffer` (the impulse response, FFT length; samples
    /// at and beyond `record_len()` must be zero) and, if `with_noise`, on `scratch.noise`
    /// (noise samples for the first `record_len()` samples, zeros elsewhere). `blank` zeroes the
    /// record for `n < N_T`; `echo_in_blanking` says whether any echo sample is earlier than
    /// `N_T` (then the slower exact path is taken). On return `scratch.buffer[..num_bins]`
    /// holds the compressed output.
    pub fn process(
        &self,
        scratch: &mut SpokeScratch,
        with_noise: bool,
        blank: bool,
        echo_in_blanking: bool,
    ) {
        self.process_with_moving(scratch, with_noise, blank, echo_in_blanking, false);
    }

    /// As [`Self::process`], adding the moving echoes summed by [`Self::add_moving_echo`]
    /// when `with_moving` (added in the fused path's domain unless `blank && echo_in_blanking`
    /// or `scratch.capture_received`, which take the exact path; the caller adds the moving
    /// echoes with the matching spectra, see [`Self::takes_exact_path`]).
    pub fn process_with_moving(
        &self,
        scratch: &mut SpokeScratch,
        with_noise: bool,
        blank: bool,
        echo_in_blanking: bool,
        with_moving: bool,
    ) {
        let exact = self.takes_exact_path(scratch, blank, echo_in_blanking);
        let SpokeScratch {
            buffer,
            noise,
            moving_spectrum,
            fft_scratch,
            capture_received,
            received,
            ..
        } = scratch;
        if blank && with_noise {
            noise[..self.pulse_len.min(self.fft_len)].fill(Complex32::new(0.0, 0.0));
        }
        self.forward.process_with_scratch(buffer, fft_scratch);
        if exact {
            for (b, s) in buffer.iter_mut().zip(&self.chirp_spectrum) {
                *b *= s;
            }
            if with_moving {
                for (b, m) in buffer.iter_mut().zip(moving_spectrum.iter()) {
                    *b += m;
                }
            }
            self.inverse.process_with_scratch(buffer, fft_scratch);
            if blank {
                buffer[..self.pulse_len.min(self.fft_len)].fill(Complex32::new(0.0, 0.0));
            }
            if with_noise {
                for (b, n) in buffer.iter_mut().zip(noise.iter()) {
                    *b += n;
                }
            }
            if *capture_received {
                let record = self.record_len();
                received.clear();
                received.extend_from_slice(&buffer[..record]);
                // The record ends at record_len: the fused path never sees the circular
                // convolution's tail beyond it, and neither may the exact one.
                buffer[record..].fill(Complex32::new(0.0, 0.0));
            }
            self.forward.process_with_scratch(buffer, fft_scratch);
            for (b, h) in buffer.iter_mut().zip(&self.filter_spectrum) {
                *b *= h;
            }
        } else {
            for (b, c) in buffer.iter_mut().zip(&self.combined_spectrum) {
                *b *= c;
            }
            if with_moving {
                for (b, m) in buffer.iter_mut().zip(moving_spectrum.iter()) {
                    *b += m;
                }
            }
            if with_noise {
                self.forward.process_with_scratch(noise, fft_scratch);
                for ((b, n), h) in buffer
                    .iter_mut()
                    .zip(noise.iter())
                    .zip(&self.filter_spectrum)
                {
                    *b += n * h;
                }
            }
        }
        self.inverse.process_with_scratch(buffer, fft_scratch);
    }

    /// Whether [`Self::process_with_moving`] forms the received record in time (the exact
    /// path): when blanking cuts an echo, or when the record is captured for raw I/Q.
    pub fn takes_exact_path(
        &self,
        scratch: &SpokeScratch,
        blank: bool,
        echo_in_blanking: bool,
    ) -> bool {
        (blank && echo_in_blanking) || scratch.capture_received
    }

    /// Matched filter alone on a received record (`record` FFT length, zero-padded), in place.
    pub fn compress_record(&self, record: &mut [Complex32], scratch: &mut SpokeScratch) {
        self.forward
            .process_with_scratch(record, &mut scratch.fft_scratch);
        for (b, h) in record.iter_mut().zip(&self.filter_spectrum) {
            *b *= h;
        }
        self.inverse
            .process_with_scratch(record, &mut scratch.fft_scratch);
    }

    /// Echo synthesis alone: impulse response (FFT length) → received record `h_ir ⊛ s`, in place.
    pub fn synthesize_record(
        &self,
        impulse_response: &mut [Complex32],
        scratch: &mut SpokeScratch,
    ) {
        self.forward
            .process_with_scratch(impulse_response, &mut scratch.fft_scratch);
        for (b, s) in impulse_response.iter_mut().zip(&self.chirp_spectrum) {
            *b *= s;
        }
        self.inverse
            .process_with_scratch(impulse_response, &mut scratch.fft_scratch);
    }
}

/// Direct (naive) matched filter `y[n] = Σ_m r[n+m]·h*[m]` with `h = w·s/‖w·s‖`, for
/// `n < num_bins`: the reference the FFT path is tested against.
pub fn direct_correlation(
    record: &[Complex64],
    chirp: &LfmChirp,
    window: Window,
    num_bins: usize,
) -> Vec<Complex64> {
    let s = chirp.samples();
    let w = window.coefficients(s.len());
    let norm: f64 = s
        .iter()
        .zip(&w)
        .map(|(x, wi)| (x * wi).norm_sqr())
        .sum::<f64>()
        .sqrt();
    let h: Vec<Complex64> = s.iter().zip(&w).map(|(x, wi)| x * (wi / norm)).collect();
    (0..num_bins)
        .map(|n| {
            h.iter()
                .enumerate()
                .filter_map(|(m, hm)| record.get(n + m).map(|r| r * hm.conj()))
                .sum()
        })
        .collect()
}
