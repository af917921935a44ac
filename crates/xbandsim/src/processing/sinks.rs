//! Stage: integrators and sinks — a dwell's pulses in, a spoke's row out (docs/architecture.md,
//! "Signal chain"; docs/physics.md §10). Each [`DwellSink`] sees every pulse's compressed
//! output (and, if it asks, the received record) and writes its product's share of the
//! spoke ([`SpokeRows`]):
//!
//! - [`PowerIntegrator`]: non-coherent integration, the mean `|y|²` over the dwell;
//! - [`CoherentIntegrator`]: `|Σy|²/M`, the power of the coherent sum over the dwell's M pulses;
//! - [`NearestPulse`]: the power of the one pulse nearest the spoke's azimuth;
//! - [`CpiCollector`]: the first `M` pulses' windowed Doppler spectrum per range bin, the
//!   spoke's slab of the range-Doppler cube;
//! - [`PulsePair`]: the lag-one pulse-pair mean radial velocity of every cell;
//! - [`IqRecorder`]: every pulse's received record (raw I/Q).
//!
//! The integrators write the spoke's power in dB over noise, floored at [`POLAR_FLOOR_DB`].

use crate::model::Integration;
use crate::receiver::stages::Detector;
use crate::schedule::{Dwell, Pulse};
use num_complex::Complex32;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// The integrators' detector: linear power, `|y|²`.
const DETECTOR: Detector = Detector::LinearPower;

/// Smallest power written to the polar output, dB over noise (for noise-free runs).
pub const POLAR_FLOOR_DB: f32 = -120.0;

/// One spoke's rows of the radial-velocity product: velocity (m/s), estimated, power (dB).
pub type VelocityRows<'a> = (&'a mut [f32], &'a mut [bool], &'a mut [f32]);

/// One spoke's share of every product of a revolution.
pub struct SpokeRows<'a> {
    /// The polar record's row: power in dB over noise, one value per range bin.
    pub polar_db: &'a mut [f32],
    /// The spoke's slab of the range-Doppler cube (Doppler bins × range bins), if made.
    pub doppler_db: Option<&'a mut [f32]>,
    /// The spoke's radial-velocity rows, if made.
    pub velocity: Option<VelocityRows<'a>>,
    /// The received records of the dwell's pulses (pulses × record), if captured.
    pub iq: Option<&'a mut [Complex32]>,
}

/// One pulse's outputs as the sinks see them.
pub struct PulseOutput<'a> {
    /// Its place in the dwell.
    pub index: usize,
    /// The pulse.
    pub pulse: &'a Pulse,
    /// Matched-filter output, one value per range bin (noise-rms units).
    pub compressed: &'a [Complex32],
    /// The received record (only when some sink [`DwellSink::wants_received`]).
    pub received: &'a [Complex32],
}

/// A consumer of a dwell's pulses that writes a spoke's row.
pub trait DwellSink: Send {
    /// Whether it needs each pulse's received record (the matched filter then forms it in
    /// time, its exact path).
    fn wants_received(&self) -> bool {
        false
    }

    /// A new dwell starts (the spoke's beam centre at `spoke_azimuth_rad`).
    fn begin(&mut self, dwell: &Dwell, spoke_azimuth_rad: f64, rows: &mut SpokeRows);

    /// One pulse's outputs.
    fn add_pulse(&mut self, out: &PulseOutput, rows: &mut SpokeRows);

    /// The dwell is over: write the row.
    fn finish(&mut self, dwell: &Dwell, rows: &mut SpokeRows);
}

/// Non-coherent integration: the mean power of the dwell's pulses (exactly the pulse's power
/// for a one-pulse dwell), in dB.
#[derive(Debug, Default)]
pub struct PowerIntegrator {
    /// Whether the mean is taken inside the dB conversion, `10·log10(Σ·(1/M))` (spoke mode's
    /// record), rather than as `Σ/M` before it (pulse mode's). The two are the same to half
    /// an ulp, and equal when M is a power of two; each mode keeps its bytes.
    scale_in_db: bool,
}

impl PowerIntegrator {
    /// The pulse-mode integrator (`Σ/M`, then dB).
    pub fn new() -> PowerIntegrator {
        PowerIntegrator { scale_in_db: false }
    }

    /// The spoke-mode integrator (`10·log10(Σ·(1/M))`).
    pub fn scaled_in_db() -> PowerIntegrator {
        PowerIntegrator { scale_in_db: true }
    }
}

impl DwellSink for PowerIntegrator {
    fn begin(&mut self, _dwell: &Dwell, _az: f64, rows: &mut SpokeRows) {
        rows.polar_db.fill(0.0);
    }

    fn add_pulse(&mut self, out: &PulseOutput, rows: &mut SpokeRows) {
        for (o, y) in rows.polar_db.iter_mut().zip(out.compressed) {
            *o += DETECTOR.power(*y);
        }
    }

    fn finish(&mut self, dwell: &Dwell, rows: &mut SpokeRows) {
        let count = dwell.pulses.len() as f32;
        if self.scale_in_db {
            crate::special::power_db_in_place(rows.polar_db, 1.0 / count, POLAR_FLOOR_DB);
            return;
        }
        rows.polar_db.iter_mut().for_each(|o| *o /= count);
        crate::special::power_db_in_place(rows.polar_db, 1.0, POLAR_FLOOR_DB);
    }
}

/// Coherent integration: `|Σ y_m|²/M` over the dwell's M pulses, in dB (noise stays at 0 dB;
/// a steady echo gains M).
#[derive(Debug, Default)]
pub struct CoherentIntegrator {
    sum: Vec<Complex32>,
}

impl DwellSink for CoherentIntegrator {
    fn begin(&mut self, _dwell: &Dwell, _az: f64, rows: &mut SpokeRows) {
        rows.polar_db.fill(0.0);
        self.sum.clear();
        self.sum
            .resize(rows.polar_db.len(), Complex32::new(0.0, 0.0));
    }

    fn add_pulse(&mut self, out: &PulseOutput, _rows: &mut SpokeRows) {
        for (o, v) in self.sum.iter_mut().zip(out.compressed) {
            *o += v;
        }
    }

    fn finish(&mut self, dwell: &Dwell, rows: &mut SpokeRows) {
        let count = dwell.pulses.len() as f32;
        for (o, v) in rows.polar_db.iter_mut().zip(&self.sum) {
            *o = DETECTOR.power(*v) / count;
        }
        crate::special::power_db_in_place(rows.polar_db, 1.0, POLAR_FLOOR_DB);
    }
}

/// No integration: the power of the dwell's pulse nearest the spoke's azimuth, in dB.
#[derive(Debug, Default)]
pub struct NearestPulse {
    nearest: usize,
}

impl DwellSink for NearestPulse {
    fn begin(&mut self, dwell: &Dwell, spoke_azimuth_rad: f64, rows: &mut SpokeRows) {
        rows.polar_db.fill(0.0);
        let off = |p: &Pulse| {
            ((p.azimuth_rad - spoke_azimuth_rad + std::f64::consts::PI)
                .rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI)
                .abs()
        };
        self.nearest = dwell
            .pulses
            .iter()
            .enumerate()
            .min_by(|(_, a), (_, b)| off(a).total_cmp(&off(b)))
            .map_or(0, |(i, _)| i);
    }

    fn add_pulse(&mut self, out: &PulseOutput, rows: &mut SpokeRows) {
        if out.index == self.nearest {
            for (o, v) in rows.polar_db.iter_mut().zip(out.compressed) {
                *o = DETECTOR.power(*v);
            }
        }
    }

    fn finish(&mut self, _dwell: &Dwell, rows: &mut SpokeRows) {
        crate::special::power_db_in_place(rows.polar_db, 1.0, POLAR_FLOOR_DB);
    }
}

/// The integrator `[processing] integration` names (pulse mode).
pub fn integrator(integration: Integration) -> Box<dyn DwellSink> {
    match integration {
        Integration::Noncoherent => Box::new(PowerIntegrator::new()),
        Integration::Coherent => Box::new(CoherentIntegrator::default()),
        Integration::None => Box::new(NearestPulse::default()),
    }
}

/// The Doppler FFT of pulse mode, planned once.
#[derive(Clone)]
pub struct DopplerPlan {
    fft: Arc<dyn Fft<f32>>,
    window: Vec<f32>,
    window_power: f32,
}

impl DopplerPlan {
    /// The FFT over `pulses` pulses with `window`.
    pub fn new(pulses: usize, window: crate::waveform::Window) -> DopplerPlan {
        let w: Vec<f32> = window
            .coefficients(pulses)
            .iter()
            .map(|&x| x as f32)
            .collect();
        let window_power = w.iter().map(|x| x * x).sum();
        DopplerPlan {
            fft: FftPlanner::<f32>::new().plan_fft_forward(pulses),
            window: w,
            window_power,
        }
    }

    /// Pulses of the coherent processing interval.
    pub fn pulses(&self) -> usize {
        self.window.len()
    }
}

/// The range-Doppler cube's collector: the first M pulses' outputs of each dwell, then the
/// spoke's slab (M Doppler bins × range bins, dB over the noise): per range bin the windowed
/// FFT over the pulses, `|Y|²/Σw²` (noise stays at 0 dB), zero Doppler in the middle row
/// `floor(M/2)` and bin d at `(d − floor(M/2))·PRF/M`.
pub struct CpiCollector {
    plan: DopplerPlan,
    bins: usize,
    cpi: Vec<Complex32>,
    column: Vec<Complex32>,
    fft_scratch: Vec<Complex32>,
}

impl CpiCollector {
    /// A collector of `bins` range bins with `plan`.
    pub fn new(plan: &DopplerPlan, bins: usize) -> CpiCollector {
        let m = plan.pulses();
        CpiCollector {
            bins,
            cpi: vec![Complex32::new(0.0, 0.0); m * bins],
            column: vec![Complex32::new(0.0, 0.0); m],
            fft_scratch: vec![Complex32::new(0.0, 0.0); plan.fft.get_inplace_scratch_len()],
            plan: plan.clone(),
        }
    }
}

impl DwellSink for CpiCollector {
    fn begin(&mut self, _dwell: &Dwell, _az: f64, _rows: &mut SpokeRows) {}

    fn add_pulse(&mut self, out: &PulseOutput, _rows: &mut SpokeRows) {
        let (m, bins) = (out.index, self.bins);
        if m < self.plan.pulses() {
            self.cpi[m * bins..(m + 1) * bins].copy_from_slice(&out.compressed[..bins]);
        }
    }

    fn finish(&mut self, _dwell: &Dwell, rows: &mut SpokeRows) {
        let Some(slab) = rows.doppler_db.as_deref_mut() else {
            return;
        };
        let (pulses, bins) = (self.plan.pulses(), self.bins);
        let centre = pulses / 2;
        let inv_power = 1.0 / self.plan.window_power;
        for j in 0..bins {
            for (m, c) in self.column.iter_mut().enumerate() {
                *c = self.cpi[m * bins + j] * self.plan.window[m];
            }
            self.plan
                .fft
                .process_with_scratch(&mut self.column, &mut self.fft_scratch);
            for (k, c) in self.column.iter().enumerate() {
                let d = (k + centre) % pulses;
                slab[d * bins + j] =
                    (10.0 * (c.norm_sqr() * inv_power).log10()).max(POLAR_FLOOR_DB);
            }
        }
    }
}

/// Pulse-pair radial velocity: over a dwell `R1 = Σ y_m·conj(y_{m−1})` and `R0 = Σ|y_m|²`;
/// the mean Doppler `arg(R1)/(2π·PRI)` over the dwell's pulse spacing, `v = −λ·f/2`, and the
/// mean power over the cell's own channel's noise.
pub struct PulsePair {
    wavelength_m: f64,
    /// Combined pulse mode: bins below `join_bin` carry the short pulse's higher noise
    /// floor, `short_noise_db` over the long pulse's.
    join_bin: usize,
    short_noise_db: f32,
    previous: Vec<Complex32>,
    lag_one: Vec<Complex32>,
    power: Vec<f32>,
}

impl PulsePair {
    /// An estimator over `bins` range bins at `wavelength_m`; `join_bin` and
    /// `short_noise_db` as [`crate::model::Radar::short_pulse_noise_db`] gives them (0, 0
    /// for a single pulse).
    pub fn new(bins: usize, wavelength_m: f64, join_bin: usize, short_noise_db: f32) -> Self {
        PulsePair {
            wavelength_m,
            join_bin,
            short_noise_db,
            previous: vec![Complex32::new(0.0, 0.0); bins],
            lag_one: vec![Complex32::new(0.0, 0.0); bins],
            power: vec![0.0; bins],
        }
    }
}

impl DwellSink for PulsePair {
    fn begin(&mut self, _dwell: &Dwell, _az: f64, _rows: &mut SpokeRows) {
        self.lag_one.fill(Complex32::new(0.0, 0.0));
        self.power.fill(0.0);
    }

    fn add_pulse(&mut self, out: &PulseOutput, _rows: &mut SpokeRows) {
        let y = &out.compressed[..self.power.len()];
        for (p, v) in self.power.iter_mut().zip(y) {
            *p += v.norm_sqr();
        }
        if out.index > 0 {
            for ((r, v), u) in self.lag_one.iter_mut().zip(y).zip(&self.previous) {
                *r += v * u.conj();
            }
        }
        self.previous.copy_from_slice(y);
    }

    fn finish(&mut self, dwell: &Dwell, rows: &mut SpokeRows) {
        let Some((v_row, e_row, p_row)) = rows.velocity.as_mut() else {
            return;
        };
        let n = dwell.pulses.len();
        let count = n as f32;
        let pri_s = (dwell.pulses[n - 1].time_s - dwell.pulses[0].time_s) / (n - 1).max(1) as f64;
        let to_velocity = -self.wavelength_m / (2.0 * std::f64::consts::TAU * pri_s);
        for j in 0..self.power.len() {
            let r1 = self.lag_one[j];
            e_row[j] = r1 != Complex32::new(0.0, 0.0);
            v_row[j] = if e_row[j] {
                (to_velocity * r1.arg() as f64) as f32
            } else {
                0.0
            };
            let local_noise_db = if j < self.join_bin {
                self.short_noise_db
            } else {
                0.0
            };
            p_row[j] =
                (10.0 * (self.power[j] / count).log10() - local_noise_db).max(POLAR_FLOOR_DB);
        }
    }
}

/// Raw I/Q: every pulse's received record into the spoke's capture rows.
#[derive(Debug)]
pub struct IqRecorder {
    record: usize,
}

impl IqRecorder {
    /// A recorder of records of `record` samples.
    pub fn new(record: usize) -> IqRecorder {
        IqRecorder { record }
    }
}

impl DwellSink for IqRecorder {
    fn wants_received(&self) -> bool {
        true
    }

    fn begin(&mut self, _dwell: &Dwell, _az: f64, _rows: &mut SpokeRows) {}

    fn add_pulse(&mut self, out: &PulseOutput, rows: &mut SpokeRows) {
        if let Some(slab) = rows.iq.as_deref_mut() {
            let (m, r) = (out.index, self.record);
            slab[m * r..(m + 1) * r].copy_from_slice(&out.received[..r]);
        }
    }

    fn finish(&mut self, _dwell: &Dwell, _rows: &mut SpokeRows) {}
}

#[cfg(test)]
mod tests {
    //! Every sink against a naive reference in f64 over the same pulses.
    use super::*;
    use crate::waveform::Window;
    use num_complex::Complex64;

    const BINS: usize = 24;

    /// A dwell of `m` pulses, pulse i at azimuth `az0 + i·step` and time `i·pri`, with
    /// deterministic outputs (a Doppler line in bins 3 and 10, other bins varied).
    fn dwell(m: usize, az0: f64, step: f64) -> (Dwell, Vec<Vec<Complex32>>) {
        let pri = 1e-3;
        let pulses = (0..m)
            .map(|i| Pulse {
                number: i as u64,
                time_s: i as f64 * pri,
                azimuth_rad: (az0 + i as f64 * step).rem_euclid(std::f64::consts::TAU),
            })
            .collect();
        let outputs = (0..m)
            .map(|i| {
                (0..BINS)
                    .map(|j| {
                        let phase = 0.7 * i as f32 * (j % 5) as f32 + 0.1 * j as f32;
                        let amp = 1.0 + ((i * 7 + j * 3) % 11) as f32 / 4.0;
                        Complex32::from_polar(amp, phase)
                    })
                    .collect()
            })
            .collect();
        (Dwell { spoke: 0, pulses }, outputs)
    }

    /// The rows a sink wrote: polar, cube, velocity (value, estimated, power), I/Q.
    type Written = (
        Vec<f32>,
        Vec<f32>,
        (Vec<f32>, Vec<bool>, Vec<f32>),
        Vec<Complex32>,
    );

    /// Runs `sink` over the dwell and returns the rows it wrote.
    fn run(
        sink: &mut dyn DwellSink,
        dwell: &Dwell,
        outputs: &[Vec<Complex32>],
        spoke_az: f64,
        doppler_len: usize,
    ) -> Written {
        let m = dwell.pulses.len();
        let mut polar = vec![f32::NAN; BINS];
        let mut cube = vec![f32::NAN; doppler_len * BINS];
        let (mut v, mut e, mut p) = (
            vec![f32::NAN; BINS],
            vec![false; BINS],
            vec![f32::NAN; BINS],
        );
        let mut iq = vec![Complex32::new(f32::NAN, 0.0); m * BINS];
        {
            let mut rows = SpokeRows {
                polar_db: &mut polar,
                doppler_db: Some(&mut cube),
                velocity: Some((&mut v, &mut e, &mut p)),
                iq: Some(&mut iq),
            };
            sink.begin(dwell, spoke_az, &mut rows);
            for (i, (pulse, y)) in dwell.pulses.iter().zip(outputs).enumerate() {
                // The received record: the output conjugated, so it differs from it.
                let received: Vec<Complex32> = y.iter().map(|c| c.conj()).collect();
                let out = PulseOutput {
                    index: i,
                    pulse,
                    compressed: y,
                    received: &received,
                };
                sink.add_pulse(&out, &mut rows);
            }
            sink.finish(dwell, &mut rows);
        }
        (polar, cube, (v, e, p), iq)
    }

    fn c64(c: Complex32) -> Complex64 {
        Complex64::new(f64::from(c.re), f64::from(c.im))
    }

    fn db(x: f64) -> f64 {
        (10.0 * x.log10()).max(f64::from(POLAR_FLOOR_DB))
    }

    #[test]
    fn integrators_match_their_sums() {
        for m in [1, 3, 8] {
            let (d, ys) = dwell(m, 0.3, 0.002);
            let (power, ..) = run(&mut PowerIntegrator::new(), &d, &ys, 0.3, 0);
            let (scaled, ..) = run(&mut PowerIntegrator::scaled_in_db(), &d, &ys, 0.3, 0);
            let (coherent, ..) = run(&mut CoherentIntegrator::default(), &d, &ys, 0.3, 0);
            for j in 0..BINS {
                let mean: f64 = ys.iter().map(|y| c64(y[j]).norm_sqr()).sum::<f64>() / m as f64;
                let sum: Complex64 = ys.iter().map(|y| c64(y[j])).sum();
                assert!(
                    (f64::from(power[j]) - db(mean)).abs() < 1e-4,
                    "m {m}, bin {j}"
                );
                assert!(
                    (f64::from(scaled[j]) - db(mean)).abs() < 1e-4,
                    "m {m}, bin {j}"
                );
                let want = db(sum.norm_sqr() / m as f64);
                assert!(
                    (f64::from(coherent[j]) - want).abs() < 1e-3,
                    "m {m}, bin {j}"
                );
            }
        }
    }

    #[test]
    fn nearest_pulse_is_the_one_nearest_the_spoke_across_north() {
        // Pulses from 359.5° on through north: the spoke at 0° is nearest pulse 2 (at 0.1°).
        let step = 0.3f64.to_radians();
        let (d, ys) = dwell(5, 359.5f64.to_radians(), step);
        let (row, ..) = run(&mut NearestPulse::default(), &d, &ys, 0.0, 0);
        let nearest = (0..5)
            .min_by(|&a, &b| {
                let off = |i: usize| {
                    let x = (359.5 + 0.3 * i as f64) % 360.0;
                    x.min(360.0 - x)
                };
                off(a).total_cmp(&off(b))
            })
            .unwrap();
        assert_eq!(nearest, 2);
        for j in 0..BINS {
            let want = db(c64(ys[nearest][j]).norm_sqr());
            assert!((f64::from(row[j]) - want).abs() < 1e-4, "bin {j}");
        }
    }

    #[test]
    fn cpi_collector_is_the_windowed_dft() {
        let m = 8;
        let plan = DopplerPlan::new(m, Window::Hamming);
        let w = Window::Hamming.coefficients(m);
        let w_power: f64 = w.iter().map(|x| x * x).sum();
        // Two more pulses than the CPI: only the first m count.
        let (d, ys) = dwell(m + 2, 0.0, 0.001);
        let (_, cube, ..) = run(&mut CpiCollector::new(&plan, BINS), &d, &ys, 0.0, m);
        for j in 0..BINS {
            for k in 0..m {
                let y: Complex64 = (0..m)
                    .map(|i| {
                        c64(ys[i][j])
                            * w[i]
                            * Complex64::from_polar(
                                1.0,
                                -std::f64::consts::TAU * (k * i) as f64 / m as f64,
                            )
                    })
                    .sum();
                let row = (k + m / 2) % m;
                let want = db(y.norm_sqr() / w_power);
                let got = f64::from(cube[row * BINS + j]);
                assert!(
                    (got - want).abs() < 2e-3,
                    "bin {j}, Doppler {k}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn pulse_pair_is_the_lag_one_estimate() {
        let (d, ys) = dwell(6, 0.0, 0.001);
        let lambda = 0.0316;
        let mut pp = PulsePair::new(BINS, lambda, 5, 7.0);
        let (_, _, (v, e, p), _) = run(&mut pp, &d, &ys, 0.0, 0);
        let pri = 1e-3;
        for j in 0..BINS {
            let r1: Complex64 = (1..6)
                .map(|i| c64(ys[i][j]) * c64(ys[i - 1][j]).conj())
                .sum();
            let r0: f64 = ys.iter().map(|y| c64(y[j]).norm_sqr()).sum::<f64>() / 6.0;
            let want_v = -lambda * r1.arg() / (4.0 * std::f64::consts::PI * pri);
            assert!(e[j]);
            assert!(
                (f64::from(v[j]) - want_v).abs() < 1e-4 * want_v.abs().max(1.0),
                "bin {j}"
            );
            let noise = if j < 5 { 7.0 } else { 0.0 };
            assert!((f64::from(p[j]) - (db(r0) - noise)).abs() < 1e-4, "bin {j}");
        }
        // Nothing received: no estimate, the floor.
        let zeros = vec![vec![Complex32::new(0.0, 0.0); BINS]; 6];
        let (_, _, (v, e, p), _) = run(&mut pp, &d, &zeros, 0.0, 0);
        assert!(e.iter().all(|&x| !x) && v.iter().all(|&x| x == 0.0));
        assert!(p.iter().all(|&x| x == POLAR_FLOOR_DB));
    }

    #[test]
    fn iq_recorder_keeps_every_received_record() {
        let (d, ys) = dwell(4, 0.0, 0.001);
        let mut rec = IqRecorder::new(BINS);
        assert!(rec.wants_received());
        let (.., iq) = run(&mut rec, &d, &ys, 0.0, 0);
        for (i, y) in ys.iter().enumerate() {
            for j in 0..BINS {
                assert_eq!(iq[i * BINS + j], y[j].conj());
            }
        }
    }
}
