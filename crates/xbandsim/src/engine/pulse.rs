//! Stage: engine, pulse mode (docs/physics.md §10). Every pulse of a revolution is fired at
//! its own time and azimuth. The scene is traced once per revolution with each object where
//! the beam crosses it (time t_b); for each pulse at time t a moving object's echo is advanced
//! from that trace by its range rate ṙ: delay `2ṙ·(t − t_b)/c` (a phase ramp over the
//! frequency bins, exact for a band-limited echo), carrier phase `exp(−j4π·Δr/λ)` with
//! `Δr = ṙ·Δt + ½·r̈·Δt²`, `r̈ = (|v|² − ṙ²)/R` (straight relative motion), `Δt = t − t_b`,
//! and bearing `β̇·(t − t_b)` (the antenna pattern weights it at its moved bearing),
//! and its chirp is Doppler-shifted within the pulse (`s(t)·exp(j2π·f_D·t)`, which gives the
//! LFM range–Doppler coupling). A dwell's pulses are integrated into its spoke
//! (noncoherent, coherent or none), its first `doppler_pulses` pulses give the spoke's
//! slab of the range-Doppler cube, and (when asked) its consecutive pulses' lag-one products
//! give each cell's pulse-pair radial velocity.

use super::{Outputs, Simulation, MIN_GROUP_AMPLITUDE, POLAR_FLOOR_DB};
use crate::constants::SPEED_OF_LIGHT_M_PER_S;
use crate::echo::EchoGroups;
use crate::environment::clutter_map::{ClutterMap, DwellClutterScratch, GaussianDoppler};
use crate::model::revolution::Revolution;
use crate::model::Integration;
use crate::processing::{DopplerSpectra, SpokeScratch};
use crate::products::{DopplerCube, RadialVelocity};
use crate::rng::{RngKey, Stream};
use glam::DVec3;
use num_complex::{Complex32, Complex64};
use rayon::prelude::*;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

use super::schedule::{Pulse, Schedule};

/// A moving object's echo in pulse mode: when it was traced and how fast its range changes.
#[derive(Debug, Clone)]
pub struct Mover {
    /// The object.
    pub object: u32,
    /// Time of its trace (the beam crossing), s.
    pub beam_time_s: f64,
    /// Range rate relative to the antenna, m/s.
    pub range_rate_mps: f64,
    /// Second derivative of its range for straight relative motion, `(|v|² − ṙ²)/R`, m/s².
    pub range_acceleration_mps2: f64,
    /// Rate of change of its bearing from the antenna, rad/s (clockwise positive).
    pub bearing_rate_rad_per_s: f64,
    /// Its Doppler shift `−2ṙ/λ`, Hz.
    pub doppler_hz: f64,
    /// Its Doppler-shifted chirp spectra.
    pub spectra: DopplerSpectra,
}

/// Below this error amplitude (noise-rms units after compression, −60 dB) a moving echo is
/// added with its carrier phase only, into the pulse's common impulse response: the error of
/// leaving out its sub-sample delay walk and intra-pulse Doppler is at most
/// `Σ peaks · G_mf · (π|δ| + 2π|f_D|·T)`, the sum over the object's weighted groups and
/// `G_mf = Σw/√Σw²` the matched filter's peak gain.
pub const MOVING_ECHO_FOLD_ERROR: f32 = 1e-3;

/// The Doppler FFT of pulse mode, planned once.
#[derive(Clone)]
pub(crate) struct DopplerPlan {
    pub(crate) fft: Arc<dyn Fft<f32>>,
    pub(crate) window: Vec<f32>,
    pub(crate) window_power: f32,
}

impl DopplerPlan {
    pub(crate) fn new(pulses: usize, window: crate::waveform::Window) -> DopplerPlan {
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
}

/// Per-worker buffers of pulse mode.
struct PulseScratch {
    spoke: SpokeScratch,
    clutter: Vec<Complex32>,
    clutter_scratch: DwellClutterScratch,
    times: Vec<f64>,
    coherent: Vec<Complex32>,
    cpi: Vec<Complex32>,
    doppler: Vec<Complex32>,
    doppler_fft: Vec<Complex32>,
    /// Pulse pair: the previous pulse's output, the lag-one sum R1 and the power sum.
    previous: Vec<Complex32>,
    lag_one: Vec<Complex32>,
    power: Vec<f32>,
}

/// One spoke's rows of the radial-velocity product.
type VelocityRows<'a> = (&'a mut [f32], &'a mut [bool], &'a mut [f32]);

impl Simulation {
    /// The Doppler spectra of sea clutter and rain seen by a beam at `azimuth_rad` from an
    /// antenna moving at `own_velocity` (ENU m/s): mean `−2·(V − V_own)·û/λ` with V the
    /// scatterers' drift downwind, spread `2σ_v/λ`.
    pub fn clutter_doppler(
        &self,
        azimuth_rad: f64,
        own_velocity: DVec3,
    ) -> (GaussianDoppler, GaussianDoppler) {
        let d = self.scene.environment().clutter_doppler();
        let lambda = self.scene.radar().wavelength_m();
        let look = DVec3::new(azimuth_rad.sin(), azimuth_rad.cos(), 0.0);
        let downwind = DVec3::new(d.downwind_rad.sin(), d.downwind_rad.cos(), 0.0);
        let line = |speed: f64, spread: f64| GaussianDoppler {
            mean_hz: -2.0 * (downwind * speed - own_velocity).dot(look) / lambda,
            spread_hz: 2.0 * spread / lambda,
        };
        (
            line(d.sea_velocity_mps, d.sea_spread_mps),
            line(d.rain_velocity_mps, d.rain_spread_mps),
        )
    }

    /// The moving echoes of a revolution: every object whose range rate relative to the
    /// antenna is not zero, with its Doppler-shifted chirp spectra.
    pub fn movers(&self, revolution: &Revolution) -> Vec<Mover> {
        let scene = revolution.scene();
        let radar = scene.radar();
        scene
            .objects()
            .iter()
            .zip(revolution.objects())
            .enumerate()
            .filter_map(|(i, (o, state))| {
                let rel = o.position_m() - radar.position_m();
                let range = rel.length();
                if range <= 0.0 {
                    return None;
                }
                let v = state.relative_velocity_mps();
                let rate = v.dot(rel / range);
                let ground2 = rel.x * rel.x + rel.y * rel.y;
                let bearing_rate = if ground2 > 0.0 {
                    (rel.y * v.x - rel.x * v.y) / ground2
                } else {
                    0.0
                };
                (rate != 0.0 || bearing_rate != 0.0).then(|| {
                    let doppler_hz = -2.0 * rate / radar.wavelength_m();
                    Mover {
                        object: i as u32,
                        beam_time_s: state.beam_time_s,
                        range_rate_mps: rate,
                        range_acceleration_mps2: (v.length_squared() - rate * rate) / range,
                        bearing_rate_rad_per_s: bearing_rate,
                        doppler_hz,
                        spectra: self
                            .compressor
                            .doppler_spectra(doppler_hz, radar.sample_rate_hz()),
                    }
                })
            })
            .collect()
    }

    /// Compressed output of one pulse with moving echoes advanced to the pulse's time and its
    /// dwell's clutter record `clutter_echo` (from [`ClutterMap::add_dwell`]), into
    /// `scratch.buffer[..bins]` (noise-rms units).
    #[allow(clippy::too_many_arguments)]
    pub fn compress_moving_pulse(
        &self,
        clutter_echo: Option<&[Complex32]>,
        groups: &EchoGroups,
        movers: &[Mover],
        pulse: &Pulse,
        seed: u64,
        frame: u64,
        scratch: &mut SpokeScratch,
    ) {
        let radar = self.scene.radar();
        let antenna = radar.antenna();
        let record = self.compressor.record_len();
        let fs = radar.sample_rate_hz();
        let pulse_s = self.compressor.pulse_len() as f64 / fs;
        let az = pulse.azimuth_rad;
        scratch.buffer.fill(Complex32::new(0.0, 0.0));
        let is_mover = |o: u32| movers.iter().any(|m| m.object == o);
        let mut earliest = groups.accumulate_where(
            antenna,
            az,
            MIN_GROUP_AMPLITUDE,
            &mut scratch.buffer[..record],
            |o| !is_mover(o),
        );
        if let Some(c) = clutter_echo {
            for (b, x) in scratch.buffer[..record].iter_mut().zip(c) {
                *b += x;
            }
        }
        // Each mover's delay walk, carrier phase and the beam's azimuth relative to its
        // moved bearing at this pulse.
        let period_s = radar.scan().period_s();
        let advance = |m: &Mover| {
            // Within half a revolution of its beam crossing: a revolution's record holds
            // each object once, where its labels put it (docs/physics.md §10).
            let dt = pulse.time_s - m.beam_time_s;
            let dt = dt - period_s * (dt / period_s).round();
            let dr = m.range_rate_mps * dt + 0.5 * m.range_acceleration_mps2 * dt * dt;
            let delay = 2.0 * dr / SPEED_OF_LIGHT_M_PER_S * fs;
            let phase = Complex64::from_polar(
                1.0,
                -2.0 * std::f64::consts::TAU * dr / radar.wavelength_m(),
            );
            (delay, phase, az - m.bearing_rate_rad_per_s * dt)
        };
        // A mover is "strong" when leaving out its delay walk and intra-pulse Doppler could
        // err by more than MOVING_ECHO_FOLD_ERROR after compression: the bound is the sum of
        // its weighted group peaks times the filter's peak gain times (π|δ| + 2π|f_D|·T).
        let peak_gain = self.compressor.peak_gain() as f32;
        let is_strong = |m: &Mover, delay: f64, bound: f32| {
            bound
                * peak_gain
                * (std::f64::consts::PI * delay.abs()
                    + std::f64::consts::TAU * m.doppler_hz.abs() * pulse_s) as f32
                >= MOVING_ECHO_FOLD_ERROR
        };
        // Pass 1: weak movers are folded in with their phase; strong ones only move the
        // earliest sample (their walk may bring them up to a sample earlier).
        let mut any_strong = false;
        for m in movers {
            let (delay, phase, beam_az) = advance(m);
            scratch.moving[..record].fill(Complex32::new(0.0, 0.0));
            let (Some(e), bound) = groups.accumulate_groups(
                groups.groups_of(m.object),
                antenna,
                beam_az,
                MIN_GROUP_AMPLITUDE,
                &mut scratch.moving[..record],
            ) else {
                continue;
            };
            if is_strong(m, delay, bound) {
                any_strong = true;
                let e = (e as f64 + delay.min(0.0)).floor().max(0.0) as usize;
                earliest = Some(earliest.map_or(e, |x| x.min(e)));
                continue;
            }
            let f = Complex32::new(phase.re as f32, phase.im as f32);
            for (b, x) in scratch.buffer[..record]
                .iter_mut()
                .zip(&scratch.moving[..record])
            {
                *b += x * f;
            }
            earliest = Some(earliest.map_or(e, |x| x.min(e)));
        }
        if earliest.is_none()
            && clutter_echo.is_none()
            && self.is_silent()
            && !scratch.capture_received
        {
            // Nothing in and no noise: the output is zero (the buffer is).
            return;
        }
        let rx = &self.receiver;
        let in_blanking = rx.echo_in_blanking(clutter_echo.is_some(), earliest);
        let fused = !self
            .compressor
            .takes_exact_path(scratch, rx.blanking(), in_blanking);
        // Combined pulse mode: the short pulse's channel gets the same impulse response; its
        // strong movers are added below with their carrier phase (docs/physics.md §11).
        self.begin_short(scratch);
        // Pass 2: strong movers through their own spectra (the same bound decides again).
        if any_strong {
            self.compressor.clear_moving(scratch);
            for m in movers {
                let (delay, phase, beam_az) = advance(m);
                let (e, bound) = EchoGroups::weighted_peak_bound(
                    groups.groups_of(m.object),
                    antenna,
                    beam_az,
                    MIN_GROUP_AMPLITUDE,
                );
                if e.is_none() || !is_strong(m, delay, bound) {
                    continue;
                }
                // The whole buffer: it goes through an FFT.
                scratch.moving.fill(Complex32::new(0.0, 0.0));
                groups.accumulate_groups(
                    groups.groups_of(m.object),
                    antenna,
                    beam_az,
                    MIN_GROUP_AMPLITUDE,
                    &mut scratch.moving[..record],
                );
                self.add_to_short(
                    scratch.short.as_deref_mut(),
                    &scratch.moving,
                    Complex32::new(phase.re as f32, phase.im as f32),
                );
                self.compressor
                    .add_moving_echo(scratch, &m.spectra, phase, delay, fused);
            }
        }
        if rx.noise() {
            rx.fill_noise(seed, frame, pulse.number, &mut scratch.noise[..record]);
            scratch.noise[record..].fill(Complex32::new(0.0, 0.0));
        }
        self.compressor.process_with_moving(
            scratch,
            rx.noise(),
            rx.blanking(),
            in_blanking,
            any_strong,
        );
        self.finish_short(
            scratch,
            seed,
            frame,
            pulse.number,
            clutter_echo.is_some(),
            earliest,
        );
    }

    /// Pulse mode: every dwell's pulses compressed with their moving echoes, integrated into
    /// the spoke as `[processing] integration` says, and (when `outputs` ask) the Doppler
    /// spectrum of each spoke's first `doppler_pulses` pulses and every cell's pulse-pair
    /// radial velocity (docs/physics.md §10). Returns the polar record, the cube and the
    /// velocities.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn synthesize_pulses(
        &self,
        groups: &EchoGroups,
        clutter: Option<&ClutterMap>,
        own_velocity: DVec3,
        movers: &[Mover],
        seed: u64,
        schedule: &Schedule,
        outputs: Outputs,
        iq: Option<&mut super::iq::IqCapture>,
        dwell_done: &(dyn Fn() + Sync),
    ) -> (Vec<f32>, Option<DopplerCube>, Option<RadialVelocity>) {
        let cube = outputs.doppler_cube;
        let radar = self.scene.radar();
        let spokes = radar.spokes();
        let bins = self.compressor.num_bins();
        let processing = self.scene.processing();
        let integration = processing.integration();
        let plan = self
            .doppler
            .as_ref()
            .filter(|_| cube)
            .map(|p| (p, p.window.len()));
        let cpi_len = plan.map_or(0, |(_, m)| m);
        let mut dwell_of_spoke = vec![0usize; spokes];
        for (i, d) in schedule.dwells().iter().enumerate() {
            dwell_of_spoke[d.spoke] = i;
        }
        let mut polar = vec![0f32; spokes * bins];
        let mut cube_values = vec![0f32; if cube { spokes * cpi_len * bins } else { 0 }];
        let mut slabs: Vec<Option<&mut [f32]>> = if cpi_len > 0 {
            cube_values.chunks_mut(cpi_len * bins).map(Some).collect()
        } else {
            (0..spokes).map(|_| None).collect()
        };
        let mut iq_slabs = iq.map_or_else(|| (0..spokes).map(|_| None).collect(), |c| c.slabs());
        let pairs = outputs.radial_velocity;
        let cells = if pairs { spokes * bins } else { 0 };
        let mut velocity = vec![0f32; cells];
        let mut estimated = vec![false; cells];
        let mut power = vec![0f32; cells];
        let mut velocity_rows: Vec<Option<VelocityRows>> = if pairs {
            velocity
                .chunks_mut(bins)
                .zip(estimated.chunks_mut(bins))
                .zip(power.chunks_mut(bins))
                .map(|((v, e), p)| Some((v, e, p)))
                .collect()
        } else {
            (0..spokes).map(|_| None).collect()
        };
        let pair_len = if pairs { bins } else { 0 };
        let wavelength_m = radar.wavelength_m();
        // Combined pulse mode: the short pulse's bins carry its higher noise floor in the
        // record's units; the colour threshold is over each channel's own noise.
        let (join_bin, short_noise_db) = radar
            .short_pulse_noise_db()
            .map_or((0, 0.0), |d| (radar.join_bin().min(bins), d as f32));
        polar
            .par_chunks_mut(bins)
            .zip(
                slabs
                    .par_iter_mut()
                    .zip(velocity_rows.par_iter_mut().zip(iq_slabs.par_iter_mut())),
            )
            .enumerate()
            .for_each_init(
                || PulseScratch {
                    spoke: self.scratch(),
                    clutter: Vec::new(),
                    clutter_scratch: DwellClutterScratch::default(),
                    times: Vec::new(),
                    coherent: vec![Complex32::new(0.0, 0.0); bins],
                    cpi: vec![Complex32::new(0.0, 0.0); cpi_len * bins],
                    doppler: vec![Complex32::new(0.0, 0.0); cpi_len],
                    doppler_fft: vec![
                        Complex32::new(0.0, 0.0);
                        plan.map_or(0, |(p, _)| p.fft.get_inplace_scratch_len())
                    ],
                    previous: vec![Complex32::new(0.0, 0.0); pair_len],
                    lag_one: vec![Complex32::new(0.0, 0.0); pair_len],
                    power: vec![0.0; pair_len],
                },
                |s, (k, (row, (slab, (velocity_row, iq_slab))))| {
                    let dwell = &schedule.dwells()[dwell_of_spoke[k]];
                    let spoke_az = radar.scan().spoke_azimuth_rad(k);
                    let nearest = dwell
                        .pulses
                        .iter()
                        .enumerate()
                        .min_by(|(_, a), (_, b)| {
                            let d = |p: &Pulse| {
                                ((p.azimuth_rad - spoke_az + std::f64::consts::PI)
                                    .rem_euclid(std::f64::consts::TAU)
                                    - std::f64::consts::PI)
                                    .abs()
                            };
                            d(a).total_cmp(&d(b))
                        })
                        .map_or(0, |(i, _)| i);
                    row.fill(0.0);
                    s.coherent.fill(Complex32::new(0.0, 0.0));
                    s.lag_one.fill(Complex32::new(0.0, 0.0));
                    s.power.fill(0.0);
                    let record = self.compressor.record_len();
                    if let Some(c) = clutter {
                        s.times.clear();
                        s.times.extend(dwell.pulses.iter().map(|p| p.time_s));
                        s.clutter.clear();
                        s.clutter
                            .resize(dwell.pulses.len() * record, Complex32::new(0.0, 0.0));
                        let (sea, rain) = self.clutter_doppler(spoke_az, own_velocity);
                        c.add_dwell(
                            k,
                            &s.times,
                            sea,
                            rain,
                            RngKey::new(seed, schedule.frame(), k as u64, Stream::ClutterDwell),
                            &mut s.clutter_scratch,
                            &mut s.clutter,
                            record,
                        );
                    }
                    s.spoke.capture_received = iq_slab.is_some();
                    for (m, pulse) in dwell.pulses.iter().enumerate() {
                        self.compress_moving_pulse(
                            clutter.map(|_| &s.clutter[m * record..(m + 1) * record]),
                            groups,
                            movers,
                            pulse,
                            seed,
                            schedule.frame(),
                            &mut s.spoke,
                        );
                        if let Some(slab) = iq_slab.as_deref_mut() {
                            slab[m * record..(m + 1) * record].copy_from_slice(&s.spoke.received);
                        }
                        let y = &s.spoke.buffer[..bins];
                        match integration {
                            Integration::Noncoherent => {
                                for (o, v) in row.iter_mut().zip(y) {
                                    *o += v.norm_sqr();
                                }
                            }
                            Integration::Coherent => {
                                for (o, v) in s.coherent.iter_mut().zip(y) {
                                    *o += v;
                                }
                            }
                            Integration::None => {
                                if m == nearest {
                                    for (o, v) in row.iter_mut().zip(y) {
                                        *o = v.norm_sqr();
                                    }
                                }
                            }
                        }
                        if m < cpi_len {
                            s.cpi[m * bins..(m + 1) * bins].copy_from_slice(y);
                        }
                        if pairs {
                            // Pulse pair: R1 += y_m·conj(y_{m−1}), R0 += |y_m|².
                            for (p, v) in s.power.iter_mut().zip(y) {
                                *p += v.norm_sqr();
                            }
                            if m > 0 {
                                for ((r, v), u) in s.lag_one.iter_mut().zip(y).zip(&s.previous) {
                                    *r += v * u.conj();
                                }
                            }
                            s.previous.copy_from_slice(y);
                        }
                    }
                    let count = dwell.pulses.len() as f32;
                    match integration {
                        Integration::Noncoherent => row.iter_mut().for_each(|o| *o /= count),
                        Integration::Coherent => {
                            for (o, v) in row.iter_mut().zip(&s.coherent) {
                                *o = v.norm_sqr() / count;
                            }
                        }
                        Integration::None => {}
                    }
                    crate::special::power_db_in_place(row, 1.0, POLAR_FLOOR_DB);
                    if let Some((v_row, e_row, p_row)) = velocity_row.as_mut() {
                        // Mean Doppler arg(R1)/(2π·PRI) over the dwell's pulse spacing (at
                        // least two pulses a spoke in pulse mode), v = −λ·f/2.
                        let n = dwell.pulses.len();
                        let pri_s = (dwell.pulses[n - 1].time_s - dwell.pulses[0].time_s)
                            / (n - 1).max(1) as f64;
                        let to_velocity = -wavelength_m / (2.0 * std::f64::consts::TAU * pri_s);
                        for j in 0..bins {
                            let r1 = s.lag_one[j];
                            e_row[j] = r1 != Complex32::new(0.0, 0.0);
                            v_row[j] = if e_row[j] {
                                (to_velocity * r1.arg() as f64) as f32
                            } else {
                                0.0
                            };
                            let local_noise_db = if j < join_bin { short_noise_db } else { 0.0 };
                            p_row[j] = (10.0 * (s.power[j] / count).log10() - local_noise_db)
                                .max(POLAR_FLOOR_DB);
                        }
                    }
                    if let (Some((p, m_len)), Some(slab)) = (plan, slab.as_deref_mut()) {
                        doppler_slab(
                            p,
                            m_len,
                            bins,
                            &mut s.cpi,
                            &mut s.doppler,
                            &mut s.doppler_fft,
                            slab,
                        );
                    }
                    dwell_done();
                },
            );
        let cube = (cpi_len > 0).then(|| DopplerCube {
            spokes,
            doppler_bins: cpi_len,
            range_bins: bins,
            doppler_bin_hz: radar.prf_hz() / cpi_len as f64,
            values_db: cube_values,
        });
        let radial_velocity = pairs.then(|| RadialVelocity {
            spokes,
            range_bins: bins,
            velocity_mps: velocity,
            estimated,
            power_db: power,
            unambiguous_mps: wavelength_m * radar.prf_hz() / 4.0,
        });
        (polar, cube, radial_velocity)
    }
}

/// The Doppler spectrum of one spoke's CPI (`cpi`: M pulses × bins, compressed outputs) into
/// `slab` (M Doppler bins × range bins, dB over the noise): per range bin the windowed FFT
/// over the pulses, `|Y|²/Σw²` (noise stays at 0 dB), zero Doppler in the middle row
/// `floor(M/2)` and bin d at `(d − floor(M/2))·PRF/M`.
fn doppler_slab(
    plan: &DopplerPlan,
    pulses: usize,
    bins: usize,
    cpi: &mut [Complex32],
    column: &mut [Complex32],
    fft_scratch: &mut [Complex32],
    slab: &mut [f32],
) {
    let centre = pulses / 2;
    let inv_power = 1.0 / plan.window_power;
    for j in 0..bins {
        for (m, c) in column.iter_mut().enumerate() {
            *c = cpi[m * bins + j] * plan.window[m];
        }
        plan.fft.process_with_scratch(column, fft_scratch);
        for (k, c) in column.iter().enumerate() {
            let d = (k + centre) % pulses;
            slab[d * bins + j] = (10.0 * (c.norm_sqr() * inv_power).log10()).max(POLAR_FLOOR_DB);
        }
    }
}
