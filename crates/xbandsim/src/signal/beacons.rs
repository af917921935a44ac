//! Signal source: racons and SARTs answering this radar ([`Beacons`]; docs/physics.md §14).
//! A transponder answers a pulse whose power at it, `Pt·G0·Gn(Δaz)·Gn_el(el)·λ²/(4πR)²`,
//! reaches its sensitivity — so it answers while the main beam (and, when near, the
//! sidelobes) sweeps it. Its answer reaches this receiver with `EIRP·G0·Gn(Δaz)·Gn_el(el)·
//! λ²/(4πR)²` (one-way Friis) and starts at the beacon's own range: a racon's Morse character
//! after its delay, over its length (a dot one unit, a dash three, ITU-R M.1677-1, as marks
//! outward from the beacon along its bearing); a SART's 12 slow sweeps, each crossing this
//! receiver's band once — a dot every 7.5 µs (0.6 NM) outward, each as long as the sweep
//! spends in the band (`B_rx/(300 MHz/7.5 µs)`, `B_rx` the sweep bandwidth or `1/T`). A mark of
//! amplitude a enters the record as impulses `a/N_T` on its samples: after this radar's pulse
//! and matched filter it peaks at `a²·N_T` (the energy a receiver matched to T takes from a
//! signal of at least its length; an upper bound for a chirped receiver). Each answer has a
//! carrier phase of its own, drawn from the render's seed: the transponder's oscillator is
//! not this radar's, so its answers do not add coherently over a dwell.

use super::{PulseAt, Source, SourceScratch, ThisRadar};
use crate::constants::SPEED_OF_LIGHT_M_PER_S;
use crate::model::artefacts::{Beacon, BeaconKind, SART_DOTS, SART_SWEEP_S};
use num_complex::Complex32;

/// A SART's slow sweep rate through its 9.2–9.5 GHz band, Hz/s.
pub const SART_SWEEP_RATE_HZ_PER_S: f64 = 300.0e6 / SART_SWEEP_S;

/// One mark of an answer in a record: samples `[first, end)` at amplitude `amplitude`
/// (noise-rms units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mark {
    /// First sample (may lie beyond the record).
    pub first: usize,
    /// One past the last sample.
    pub end: usize,
    /// Amplitude of the received signal, noise-rms units.
    pub amplitude: f32,
}

/// The scene's transponders as this radar sees them.
pub struct Beacons<'a> {
    beacons: &'a [Beacon],
    radar: ThisRadar<'a>,
}

impl<'a> Beacons<'a> {
    /// `beacons` as `radar` meets them.
    pub fn new(beacons: &'a [Beacon], radar: ThisRadar<'a>) -> Beacons<'a> {
        Beacons { beacons, radar }
    }

    /// Whether there is any beacon.
    pub fn is_empty(&self) -> bool {
        self.beacons.is_empty()
    }

    /// This radar's pulse, samples.
    pub fn pulse_len(&self) -> usize {
        self.radar.pulse_len
    }

    /// The marks of beacon `i`'s answer to a pulse with the antenna at `azimuth_rad` (none
    /// when the pulse does not trigger it), calling `each` with each.
    pub fn answer(&self, i: usize, azimuth_rad: f64, mut each: impl FnMut(Mark)) {
        let b = &self.beacons[i];
        let link = self.radar.link(b.position_m, azimuth_rad);
        if self.radar.peak_power_w * link.gain_times_spreading < b.sensitivity_w {
            return;
        }
        let range_m = link.range_m;
        let amplitude =
            (b.eirp_w * link.gain_times_spreading / self.radar.noise_power_w).sqrt() as f32;
        let fs = self.radar.sample_rate_hz;
        let arrival_s = 2.0 * range_m / SPEED_OF_LIGHT_M_PER_S;
        let mut mark = |t0: f64, t1: f64| {
            let first = (t0 * fs).round() as usize;
            let end = ((t1 * fs).round() as usize).max(first + 1);
            each(Mark {
                first,
                end,
                amplitude,
            });
        };
        match &b.kind {
            BeaconKind::Racon {
                marks,
                length_s,
                delay_s,
                ..
            } => {
                let start = arrival_s + delay_s;
                for (f0, f1) in marks {
                    mark(start + f0 * length_s, start + f1 * length_s);
                }
            }
            BeaconKind::Sart => {
                let dot_s = self.radar.bandwidth_hz / SART_SWEEP_RATE_HZ_PER_S;
                for k in 0..SART_DOTS {
                    let t0 = arrival_s + k as f64 * SART_SWEEP_S;
                    mark(t0, t0 + dot_s);
                }
            }
        }
    }

    /// The matched filter's peak power of a mark over the noise, `a²·N_T·min(D/N_T, 1)²` for a
    /// mark of D samples.
    pub fn peak_power(&self, m: &Mark) -> f64 {
        let fill = ((m.end - m.first) as f64 / self.radar.pulse_len as f64).min(1.0);
        f64::from(m.amplitude).powi(2) * self.radar.pulse_len as f64 * fill * fill
    }
}

impl Source for Beacons<'_> {
    fn add_to_pulse(
        &self,
        at: &PulseAt,
        _scratch: &mut SourceScratch,
        samples: &mut [Complex32],
    ) -> Option<usize> {
        let record = &mut samples[..self.radar.record_len];
        let mut earliest: Option<usize> = None;
        let scale = 1.0 / self.radar.pulse_len as f32;
        for i in 0..self.beacons.len() {
            self.answer(i, at.pulse.azimuth_rad, |m| {
                let end = m.end.min(record.len());
                if m.first >= end {
                    return;
                }
                // Its own oscillator: a phase unrelated to this pulse's, answer by answer.
                let phase = super::unrelated_phase_rad(
                    at.key.seed,
                    0xBEAC_0A57,
                    i,
                    &[at.key.frame, at.pulse.number],
                );
                let v = Complex32::from_polar(m.amplitude * scale, phase as f32);
                for s in &mut record[m.first..end] {
                    *s += v;
                }
                earliest = Some(earliest.map_or(m.first, |e| e.min(m.first)));
            });
        }
        earliest
    }
}
