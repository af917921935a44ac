//! Clutter map, stage: speckle. A cell's echo is complex Gaussian with the cell's power
//! (the beam-weighted mean times its texture): fresh every pulse in spoke mode
//! ([`ClutterMap::add_to_spoke`]), or over a pulse-mode dwell a sum of spectral lines with a
//! Gaussian Doppler spectrum ([`ClutterMap::add_dwell`], [`doppler_lines`]) so that pulses
//! are correlated as the spectrum says (docs/physics.md, "Sea clutter", §10).

use super::ClutterMap;
use crate::rng::{normal_pair, RngKey, Stream};
use num_complex::Complex32;
use rand_pcg::Pcg64Mcg;

/// A Gaussian Doppler spectrum: mean and standard deviation, Hz.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussianDoppler {
    /// Mean (centroid), Hz.
    pub mean_hz: f64,
    /// Standard deviation, Hz (0: a single line).
    pub spread_hz: f64,
}

/// Reusable buffers of [`ClutterMap::add_dwell`].
#[derive(Debug, Default)]
pub struct DwellClutterScratch {
    sea: Vec<f32>,
    rain: Vec<f32>,
    lines: Vec<(f64, f32)>,
    phasors: Vec<Complex32>,
    coefficients: Vec<Complex32>,
}

/// Most spectral lines per process.
pub const MAX_DOPPLER_LINES: usize = 48;

/// Appends the lines `(f_b, a_b)` that synthesise `spectrum` over a dwell of `duration_s`:
/// spacing `Δf = min(σ/2, 1/(2D))` (so the line set's period `1/Δf` is at least twice the
/// dwell and the spectrum is resolved), lines within ±3σ of the mean (at most
/// [`MAX_DOPPLER_LINES`], widening Δf), amplitudes `a_b ∝ exp(−(f_b − f̄)²/(4σ²))` with
/// `Σ a_b² = 1`. A zero spread gives one line at the mean.
pub fn doppler_lines(spectrum: GaussianDoppler, duration_s: f64, lines: &mut Vec<(f64, f32)>) {
    let sigma = spectrum.spread_hz;
    if sigma <= 0.0 {
        lines.push((spectrum.mean_hz, 1.0));
        return;
    }
    let mut df = (sigma / 2.0).min(0.5 / duration_s.max(1e-9));
    let half_max = (MAX_DOPPLER_LINES - 1) / 2;
    if (3.0 * sigma / df).ceil() as usize > half_max {
        df = 3.0 * sigma / half_max as f64;
    }
    let half = (3.0 * sigma / df).ceil() as i64;
    let start = lines.len();
    let mut total = 0.0;
    for b in -half..=half {
        let f = spectrum.mean_hz + b as f64 * df;
        let p = (-(b as f64 * df).powi(2) / (2.0 * sigma * sigma)).exp();
        total += p;
        lines.push((f, p as f32));
    }
    for l in &mut lines[start..] {
        l.1 = (l.1 as f64 / total).sqrt() as f32;
    }
}

impl ClutterMap {
    /// Spoke `k`'s beam-weighted texture-free sea and rain powers of its first `n_max`
    /// samples into `sea` and `rain` (rain left empty without rain), row by row (contiguous,
    /// vectorisable); what the buffers held before does not matter.
    fn beam_weighted(&self, k: usize, n_max: usize, sea: &mut Vec<f32>, rain: &mut Vec<f32>) {
        let has_rain = !self.surface.rain[k].is_empty();
        sea.clear();
        sea.resize(n_max, 0.0);
        rain.clear();
        rain.resize(if has_rain { n_max } else { 0 }, 0.0);
        for (t, &w) in self.surface.weights.iter().enumerate() {
            let j = self.neighbour(k, t);
            for (acc, &v) in sea.iter_mut().zip(&self.surface.sea[j][..n_max]) {
                *acc += w * v;
            }
            if has_rain {
                for (acc, &v) in rain.iter_mut().zip(&self.surface.rain[j][..n_max]) {
                    *acc += w * v;
                }
            }
        }
    }

    /// Adds the clutter echo of one pulse with the beam at spoke `k` to `impulse_response`
    /// (noise-rms units): complex Gaussian speckle with the cell's power, drawn from the
    /// pulse's `speckle` stream. `sea` and `rain` are the caller's buffers for the spoke's
    /// beam-weighted powers (what they held before does not matter).
    pub fn add_to_spoke(
        &self,
        k: usize,
        speckle: RngKey,
        sea: &mut Vec<f32>,
        rain: &mut Vec<f32>,
        impulse_response: &mut [Complex32],
    ) {
        debug_assert_eq!(speckle.stream, Stream::ClutterSpeckle);
        let mut rng: Pcg64Mcg = speckle.rng();
        let n_max = self.surface.samples.min(impulse_response.len());
        // Beam-weighted sea and rain power of this spoke, accumulated row by row (contiguous,
        // vectorisable) into the caller's two buffers.
        let has_rain = !self.surface.rain[k].is_empty();
        self.beam_weighted(k, n_max, sea, rain);
        let texture = (!self.texture[k].is_empty()).then(|| &self.texture[k][..n_max]);
        for n in 0..n_max {
            let mut p = texture.map_or(sea[n], |t| t[n] * sea[n]);
            if has_rain {
                p += rain[n];
            }
            if p <= 0.0 {
                continue;
            }
            let s = (p * 0.5).sqrt();
            let (re, im) = normal_pair(&mut rng);
            impulse_response[n] += Complex32::new(re * s, im * s);
        }
        // Land: its frozen echo, the same every pulse.
        for (x, e) in impulse_response[..n_max]
            .iter_mut()
            .zip(&self.surface.land_echo[k])
        {
            *x += e;
        }
    }

    /// Adds the Doppler-coloured clutter of one pulse-mode dwell of spoke `k` into `out`
    /// (pulse m's record at `out[m·stride ..][..samples]`, noise-rms units): for every cell a
    /// sea and a rain process, each complex Gaussian with the cell's power and a Gaussian
    /// Doppler spectrum (`sea`, `rain`), evaluated at the pulses' `times_s`. Each process is a
    /// sum of spectral lines `Σ_b a_b·ξ_b·exp(j2π·f_b·(t − t_0))` with independent complex
    /// Gaussian ξ_b ([`doppler_lines`]), so the marginal stays Gaussian (times the cell's
    /// texture, constant over the dwell: it evolves over seconds, frame to frame) and the
    /// correlation between pulses is the Gaussian spectrum's. The land's frozen echo turns
    /// at `land_doppler_hz` (the own ship's motion toward it, `2·V_own·û/λ`).
    #[allow(clippy::too_many_arguments)]
    pub fn add_dwell(
        &self,
        k: usize,
        times_s: &[f64],
        sea: GaussianDoppler,
        rain: GaussianDoppler,
        land_doppler_hz: f64,
        key: RngKey,
        scratch: &mut DwellClutterScratch,
        out: &mut [Complex32],
        stride: usize,
    ) {
        debug_assert_eq!(key.stream, Stream::ClutterDwell);
        let mut rng: Pcg64Mcg = key.rng();
        let n_max = self.surface.samples.min(stride);
        let pulses = times_s.len();
        let has_rain = !self.surface.rain[k].is_empty();
        let s = scratch;
        self.beam_weighted(k, n_max, &mut s.sea, &mut s.rain);
        let duration =
            times_s.last().copied().unwrap_or(0.0) - times_s.first().copied().unwrap_or(0.0);
        let t0 = times_s.first().copied().unwrap_or(0.0);
        // Lines and their phasors at every pulse, sea first then rain.
        s.lines.clear();
        doppler_lines(sea, duration, &mut s.lines);
        let sea_lines = s.lines.len();
        if has_rain {
            doppler_lines(rain, duration, &mut s.lines);
        }
        let lines = s.lines.len();
        s.phasors.clear();
        for &t in times_s {
            for &(f, _) in &s.lines {
                let ph = std::f64::consts::TAU * f * (t - t0);
                s.phasors
                    .push(Complex32::new(ph.cos() as f32, ph.sin() as f32));
            }
        }
        s.coefficients.resize(lines, Complex32::new(0.0, 0.0));
        let texture = (!self.texture[k].is_empty()).then(|| &self.texture[k][..n_max]);
        for n in 0..n_max {
            let p_sea = texture.map_or(s.sea[n], |t| t[n] * s.sea[n]);
            let p_rain = if has_rain { s.rain[n] } else { 0.0 };
            if p_sea <= 0.0 && p_rain <= 0.0 {
                continue;
            }
            for (b, c) in s.coefficients.iter_mut().enumerate() {
                let (p, a) = if b < sea_lines {
                    (p_sea, s.lines[b].1)
                } else {
                    (p_rain, s.lines[b].1)
                };
                let scale = (p.max(0.0) * 0.5).sqrt() * a;
                let (re, im) = normal_pair(&mut rng);
                *c = Complex32::new(re * scale, im * scale);
            }
            for m in 0..pulses {
                let row = &s.phasors[m * lines..(m + 1) * lines];
                let mut acc = Complex32::new(0.0, 0.0);
                for (c, ph) in s.coefficients.iter().zip(row) {
                    acc += c * ph;
                }
                out[m * stride + n] += acc;
            }
        }
        if !self.surface.land_echo[k].is_empty() {
            for (m, &t) in times_s.iter().enumerate() {
                let ph = std::f64::consts::TAU * land_doppler_hz * (t - t0);
                let turn = Complex32::new(ph.cos() as f32, ph.sin() as f32);
                for (x, e) in out[m * stride..m * stride + n_max]
                    .iter_mut()
                    .zip(&self.surface.land_echo[k])
                {
                    *x += e * turn;
                }
            }
        }
    }
}
