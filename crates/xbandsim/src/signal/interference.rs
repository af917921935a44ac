//! Signal source: other radars' pulses ([`Interference`]; docs/physics.md §14). Each
//! interferer fires unmodulated pulses of its width at its PRF while its antenna turns; a
//! pulse reaches this receiver `R/c` later at the one-way (Friis) power
//! `P_i·G_i·Gn_i(θ_i)·G_0·Gn(Δaz)·Gn_el(el)·λ²/(4πR)²` — its pattern toward this radar times
//! this antenna's pattern toward it — over the noise of a sample, `k·T0·F·fs`: amplitude a
//! (noise-rms units) over its n samples. It lands in this pulse's record (the echoes' impulse
//! response, which the receiver convolves with this radar's pulse of `N_T` samples and the
//! matched filter) at `(t_m + R/c − t_n)·fs`, as an impulse of `a·min(n, N_T)/N_T`: after the
//! matched filter it peaks at `a²·min(n, N_T)²/N_T`, the energy a receiver matched to an
//! unmodulated pulse takes from the overlap — exact for two magnetron sets of equal pulses,
//! an upper bound for a chirped receiver (which would spread it). Each pulse has a phase of
//! its own, drawn from the render's seed (another transmitter: no coherence with this radar's
//! pulses). Its PRF differs from this radar's, so
//! from sweep to sweep its pulses walk in range: the curved dotted spokes of interference,
//! which sweep-to-sweep correlation (the receiver's interference rejection) removes.

use super::{PulseAt, Source, SourceScratch, ThisRadar};
use crate::constants::SPEED_OF_LIGHT_M_PER_S;
use crate::model::artefacts::Interferer;
use num_complex::Complex32;

/// One interfering pulse in a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterferingPulse {
    /// First sample it covers (may be before the record: clipped when added).
    pub first_sample: i64,
    /// Samples it lasts.
    pub samples: usize,
    /// Its amplitude, noise-rms units.
    pub amplitude: f32,
    /// Its number in its radar's pulse train (keys its phase).
    pub number: i64,
}

/// The interferers of a scene as seen by this radar.
pub struct Interference<'a> {
    interferers: &'a [Interferer],
    radar: ThisRadar<'a>,
}

impl<'a> Interference<'a> {
    /// `interferers` as `radar` meets them.
    pub fn new(interferers: &'a [Interferer], radar: ThisRadar<'a>) -> Interference<'a> {
        Interference { interferers, radar }
    }

    /// Whether there is any interferer.
    pub fn is_empty(&self) -> bool {
        self.interferers.is_empty()
    }

    /// This radar's pulse, samples.
    pub fn pulse_len(&self) -> usize {
        self.radar.pulse_len
    }

    /// The matched filter's peak power of `p` over the noise, `a²·min(n, N_T)²/N_T`.
    pub fn peak_power(&self, p: &InterferingPulse) -> f64 {
        let overlap = p.samples.min(self.radar.pulse_len) as f64;
        f64::from(p.amplitude).powi(2) * overlap * overlap / self.radar.pulse_len as f64
    }

    /// The pulses of interferer `i` that land in the record of a pulse fired at `time_s` with
    /// the antenna at `azimuth_rad`, calling `each` with each.
    pub fn pulses_in_record(
        &self,
        i: usize,
        time_s: f64,
        azimuth_rad: f64,
        mut each: impl FnMut(InterferingPulse),
    ) {
        let it = &self.interferers[i];
        let link = self.radar.link(it.position_m, azimuth_rad);
        let range_m = link.range_m;
        let fs = self.radar.sample_rate_hz;
        let delay_s = range_m / SPEED_OF_LIGHT_M_PER_S;
        let width = ((it.pulse_width_s * fs).round() as usize).max(1);
        let record_s = self.radar.record_len as f64 / fs;
        let lo = ((time_s - delay_s - it.pulse_width_s) * it.prf_hz).ceil() as i64;
        let hi = ((time_s + record_s - delay_s) * it.prf_hz).floor() as i64;
        let back_bearing = link.bearing_rad + std::f64::consts::PI;
        for m in lo..=hi {
            let t_m = m as f64 / it.prf_hz;
            let power_w = it.peak_power_w
                * it.peak_gain_linear
                * it.pattern_toward(back_bearing, t_m)
                * link.gain_times_spreading;
            let amplitude = (power_w / self.radar.noise_power_w).sqrt() as f32;
            each(InterferingPulse {
                first_sample: ((t_m + delay_s - time_s) * fs).round() as i64,
                samples: width,
                amplitude,
                number: m,
            });
        }
    }

    /// The phase of pulse `m` of interferer `i` in the render of `seed`, rad.
    fn phase(seed: u64, i: usize, m: i64) -> f64 {
        super::unrelated_phase_rad(seed, 0x1A7E_5EED, i, &[m as u64])
    }
}

impl Source for Interference<'_> {
    fn add_to_pulse(
        &self,
        at: &PulseAt,
        _scratch: &mut SourceScratch,
        samples: &mut [Complex32],
    ) -> Option<usize> {
        let record = &mut samples[..self.radar.record_len];
        let mut earliest: Option<usize> = None;
        for i in 0..self.interferers.len() {
            self.pulses_in_record(i, at.pulse.time_s, at.pulse.azimuth_rad, |p| {
                if p.first_sample < 0 || p.first_sample as usize >= record.len() {
                    return;
                }
                let overlap =
                    p.samples.min(self.radar.pulse_len) as f32 / self.radar.pulse_len as f32;
                let phase = Self::phase(at.key.seed, i, p.number);
                let start = p.first_sample as usize;
                record[start] += Complex32::from_polar(p.amplitude * overlap, phase as f32);
                earliest = Some(earliest.map_or(start, |e| e.min(start)));
            });
        }
        earliest
    }
}
