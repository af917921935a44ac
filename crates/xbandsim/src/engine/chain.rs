//! Stage: engine, the signal chain of one revolution (docs/architecture.md, "Signal chain").
//! One loop for every schedule, spoke mode (one pulse per dwell, no movers) and pulse mode
//! alike: for each dwell (in parallel), the sinks begin; for each of its pulses the sources
//! add their signal to the record ([`crate::signal`]: fixed echoes, sea and rain clutter,
//! weak moving echoes), the strong moving echoes enter the matched filter's spectrum, the
//! receiver blanks and adds its noise, the matched filter compresses (with the short-pulse
//! channel of combined pulse mode over the near bins), gain and STC act on the compressed
//! bins ([`crate::receiver::stages::GainStc`], skipped when neutral), and every sink takes
//! the pulse ([`crate::processing::sinks`]); then the sinks write the spoke's rows.

use super::{Simulation, POLAR_FLOOR_DB};
use crate::model::Integration;
use crate::model::Transmitter;
use crate::processing::sinks::{
    integrator, CpiCollector, DopplerPlan, DwellSink, IqRecorder, PowerIntegrator, PulseOutput,
    PulsePair, SpokeRows,
};
use crate::processing::{DopplerSpectra, SpokeScratch};
use crate::rng::{uniform_phase_rad, FrameKey, Stream};
use crate::schedule::{Dwell, Schedule};
use crate::signal::beacons::Beacons;
use crate::signal::clutter::SeaAndRainClutter;
use crate::signal::interference::Interference;
use crate::signal::targets::{FixedEchoes, MovingEchoes};
use crate::signal::{earlier, PulseAt, Source};
use num_complex::Complex32;
use rayon::prelude::*;

/// The signal sources of one revolution.
pub(crate) struct RevolutionSources<'a> {
    pub(crate) fixed: FixedEchoes<'a>,
    /// Indirect echoes via the own ship's structure, added past the blind sectors' loss
    /// (None without them).
    pub(crate) indirect: Option<FixedEchoes<'a>>,
    pub(crate) clutter: Option<SeaAndRainClutter<'a>>,
    pub(crate) moving: MovingEchoes<'a>,
    /// Each mover's Doppler-shifted chirp spectra (the matched filter's, for the strong
    /// movers).
    pub(crate) spectra: &'a [DopplerSpectra],
    /// Other radars' pulses (`[[artefacts.interferer]]`).
    pub(crate) interference: Interference<'a>,
    /// Racons' and SARTs' answers.
    pub(crate) beacons: Beacons<'a>,
}

impl RevolutionSources<'_> {
    fn begin_dwell(&self, dwell: &Dwell, key: FrameKey, scratch: &mut SpokeScratch) {
        self.fixed.begin_dwell(dwell, key, &mut scratch.sources);
        if let Some(c) = &self.clutter {
            c.begin_dwell(dwell, key, &mut scratch.sources);
        }
        self.moving.begin_dwell(dwell, key, &mut scratch.sources);
    }
}

/// The sinks a revolution feeds, made once per worker.
pub(crate) struct SinkPlan<'a> {
    /// The integrator: spoke mode's power integrator (None) or pulse mode's
    /// `[processing] integration`.
    pub(crate) integration: Option<Integration>,
    pub(crate) bins: usize,
    pub(crate) doppler: Option<&'a DopplerPlan>,
    /// Pulse pair: wavelength (m), join bin, the short pulse's noise over the long's (dB).
    pub(crate) pulse_pair: Option<(f64, usize, f32)>,
    /// Raw I/Q of records of this many samples.
    pub(crate) iq_record: Option<usize>,
}

impl SinkPlan<'_> {
    fn make(&self) -> Vec<Box<dyn DwellSink>> {
        let mut sinks = vec![match self.integration {
            Some(i) => integrator(i),
            None => Box::new(PowerIntegrator::scaled_in_db()),
        }];
        if let Some(plan) = self.doppler {
            sinks.push(Box::new(CpiCollector::new(plan, self.bins)));
        }
        if let Some((wavelength_m, join, short_db)) = self.pulse_pair {
            sinks.push(Box::new(PulsePair::new(
                self.bins,
                wavelength_m,
                join,
                short_db,
            )));
        }
        if let Some(record) = self.iq_record {
            sinks.push(Box::new(IqRecorder::new(record)));
        }
        sinks
    }
}

impl Simulation {
    /// Compressed output of pulse `at` into `scratch.buffer[..bins]` (amplitude in noise-rms
    /// units): the sources' record, the receiver's blanking and noise, the matched filter
    /// (and the short-pulse channel), gain and STC.
    pub(crate) fn receive_pulse(
        &self,
        sources: &RevolutionSources,
        at: &PulseAt,
        scratch: &mut SpokeScratch,
    ) {
        let record = self.compressor.record_len();
        scratch.buffer.fill(Complex32::new(0.0, 0.0));
        let samples = &mut scratch.buffer[..record];
        let work = &mut scratch.sources;
        let mut earliest = sources.fixed.add_to_pulse(at, work, samples);
        if let Some(c) = &sources.clutter {
            earliest = earlier(earliest, c.add_to_pulse(at, work, samples));
        }
        let (moving_earliest, any_strong) = sources.moving.add_weak(at, work, samples);
        earliest = earlier(earliest, moving_earliest);
        // Indirect echoes into their own buffer (the moving echoes' one, free until the strong
        // movers below): they join the record past the blind sectors' loss.
        let indirect_earliest = sources.indirect.as_ref().and_then(|indirect| {
            let buffer = &mut scratch.moving[..record];
            buffer.fill(Complex32::new(0.0, 0.0));
            indirect.add_to_pulse(at, work, buffer)
        });
        earliest = earlier(earliest, indirect_earliest);
        let interfered = !sources.interference.is_empty() || !sources.beacons.is_empty();
        if earliest.is_none() && !interfered && self.is_silent() && !scratch.capture_received {
            // Nothing in and no noise: the matched filter's output is zero (the buffer is).
            return;
        }
        // A magnetron's pulse starts at a random phase: every echo of the pulse turns with it
        // (the noise does not).
        let start = self.start_phase(at);
        if let Some(p) = start {
            let p = Complex32::new(p.re as f32, p.im as f32);
            for s in &mut scratch.buffer[..record] {
                *s *= p;
            }
        }
        // The own ship's structure in the beam: this radar's echoes through a blind sector
        // lose its two-way loss (the noise, the receiver's own, does not; other transmitters
        // cross it once, in their sources).
        let blocked = self.blind_factor(at.pulse.azimuth_rad);
        if let Some(f) = blocked {
            for s in &mut scratch.buffer[..record] {
                *s *= f as f32;
            }
        }
        // The echoes that come from the structure rather than through it: this pulse's start
        // phase, no blind loss.
        if indirect_earliest.is_some() {
            let p = start.map_or(Complex32::new(1.0, 0.0), |p| {
                Complex32::new(p.re as f32, p.im as f32)
            });
            for (s, v) in scratch.buffer[..record]
                .iter_mut()
                .zip(&scratch.moving[..record])
            {
                *s += v * p;
            }
        }
        // Other radars' pulses and the beacons' answers: their own phases, after this
        // transmitter's.
        if interfered {
            let samples = &mut scratch.buffer[..record];
            earliest = earlier(
                earliest,
                sources
                    .interference
                    .add_to_pulse(at, &mut scratch.sources, samples),
            );
            earliest = earlier(
                earliest,
                sources
                    .beacons
                    .add_to_pulse(at, &mut scratch.sources, samples),
            );
        }
        let rx = &self.receiver;
        let in_blanking = rx.echo_in_blanking(earliest);
        let fused = !self
            .compressor
            .takes_exact_path(scratch, rx.blanking(), in_blanking);
        // Combined pulse mode: the short pulse's channel gets the same impulse response; its
        // strong movers are added below with their carrier phase (docs/physics.md §11).
        self.begin_short(scratch);
        if any_strong {
            self.compressor.clear_moving(scratch);
            for (m, spectra) in sources.moving.movers().iter().zip(sources.spectra) {
                let Some(mut a) = sources.moving.strong(m, at) else {
                    continue;
                };
                if let Some(p) = start {
                    a.phase *= p;
                }
                if let Some(f) = blocked {
                    a.phase *= f;
                }
                // The whole buffer: it goes through an FFT.
                scratch.moving.fill(Complex32::new(0.0, 0.0));
                sources
                    .moving
                    .accumulate(m, a.beam_az_rad, &mut scratch.moving);
                self.add_to_short(
                    scratch.short.as_deref_mut(),
                    &scratch.moving,
                    Complex32::new(a.phase.re as f32, a.phase.im as f32),
                );
                self.compressor
                    .add_moving_echo(scratch, spectra, a.phase, a.delay_samples, fused);
            }
        }
        if rx.noise() {
            rx.fill_noise(at.key, at.pulse.number, &mut scratch.noise[..record]);
            scratch.noise[record..].fill(Complex32::new(0.0, 0.0));
        }
        self.compressor.process_with_moving(
            scratch,
            rx.noise(),
            rx.blanking(),
            in_blanking,
            any_strong,
        );
        self.finish_short(scratch, at, earliest);
        self.gain_stc
            .apply(&mut scratch.buffer[..self.compressor.num_bins()]);
    }

    /// Every dwell of `schedule` through the chain into `rows` (one entry per spoke, in spoke
    /// order), the sinks of `sinks` made once per worker; `skip[k]` leaves spoke k at
    /// [`POLAR_FLOOR_DB`]. `dwell_done` is called after every dwell (from the workers).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn run_dwells(
        &self,
        sources: &RevolutionSources,
        schedule: &Schedule,
        key: FrameKey,
        sinks: &SinkPlan,
        rows: Vec<SpokeRows>,
        skip: Option<&[bool]>,
        dwell_done: &(dyn Fn() + Sync),
    ) {
        let scan = *self.scene.radar().scan();
        let bins = self.compressor.num_bins();
        // Schedule::new and the scans guarantee one dwell per spoke.
        let mut dwell_of_spoke = vec![0usize; schedule.spokes()];
        for (i, d) in schedule.dwells().iter().enumerate() {
            dwell_of_spoke[d.spoke] = i;
        }
        rows.into_par_iter().enumerate().for_each_init(
            || (self.scratch(), sinks.make()),
            |(scratch, sinks), (k, mut rows)| {
                let dwell = &schedule.dwells()[dwell_of_spoke[k]];
                if skip.is_some_and(|s| !s.get(k).copied().unwrap_or(false)) {
                    rows.polar_db.fill(POLAR_FLOOR_DB);
                    dwell_done();
                    return;
                }
                let spoke_az = scan.spoke_azimuth_rad(k);
                for s in sinks.iter_mut() {
                    s.begin(dwell, spoke_az, &mut rows);
                }
                scratch.capture_received = sinks.iter().any(|s| s.wants_received());
                sources.begin_dwell(dwell, key, scratch);
                for (m, pulse) in dwell.pulses.iter().enumerate() {
                    let at = PulseAt {
                        pulse,
                        spoke: k,
                        index: m,
                        key,
                    };
                    self.receive_pulse(sources, &at, scratch);
                    let out = PulseOutput {
                        index: m,
                        pulse,
                        compressed: &scratch.buffer[..bins],
                        received: &scratch.received,
                    };
                    for s in sinks.iter_mut() {
                        s.add_pulse(&out, &mut rows);
                    }
                }
                for s in sinks.iter_mut() {
                    s.finish(dwell, &mut rows);
                }
                dwell_done();
            },
        );
    }

    /// The amplitude factor `10^{−L/20}` of the blind sectors' two-way loss L at antenna
    /// azimuth `azimuth_rad` (None outside every sector).
    fn blind_factor(&self, azimuth_rad: f64) -> Option<f64> {
        let sectors = &self.scene.artefacts().blind_sectors;
        if sectors.is_empty() {
            return None;
        }
        let heading = self.scene.own_ship().map_or(0.0, |s| s.heading_rad());
        let loss_db = crate::model::artefacts::blind_loss_db(sectors, azimuth_rad, heading);
        (loss_db > 0.0).then(|| 10f64.powf(-loss_db / 20.0))
    }

    /// A magnetron pulse's random start phase factor `exp(jφ)`, φ uniform in (0, 2π) from the
    /// pulse's `TransmitPhase` stream; None for a solid-state set (coherent pulses).
    fn start_phase(&self, at: &PulseAt) -> Option<num_complex::Complex64> {
        (self.scene.radar().transmitter() == Transmitter::Magnetron).then(|| {
            let mut rng = at.key.pulse(at.pulse.number, Stream::TransmitPhase).rng();
            num_complex::Complex64::from_polar(1.0, uniform_phase_rad(&mut rng))
        })
    }

    /// Combined pulse mode: hands the pulse's impulse response (`scratch.buffer`, before any
    /// compression) to the short-pulse channel.
    fn begin_short(&self, scratch: &mut SpokeScratch) {
        let Some(ch) = &self.short else { return };
        let record = ch.compressor.record_len();
        // A scratch from PulseCompressor::scratch gets the channel's buffers on first use.
        let short = scratch
            .short
            .get_or_insert_with(|| Box::new(ch.compressor.scratch()));
        short.buffer[..record].copy_from_slice(&scratch.buffer[..record]);
        short.buffer[record..].fill(Complex32::new(0.0, 0.0));
    }

    /// Combined pulse mode: adds `factor × echo` (an impulse response, at least the short
    /// record long) to the short-pulse channel's input.
    fn add_to_short(
        &self,
        short: Option<&mut SpokeScratch>,
        echo: &[Complex32],
        factor: Complex32,
    ) {
        let (Some(ch), Some(short)) = (&self.short, short) else {
            return;
        };
        let record = ch.compressor.record_len();
        for (b, x) in short.buffer[..record].iter_mut().zip(&echo[..record]) {
            *b += x * factor;
        }
    }

    /// Combined pulse mode: compresses the short pulse's record (its own noise stream and
    /// blanking) and writes its bins, scaled to the long pulse's calibration, over the
    /// first [`crate::model::Radar::join_bin`] bins of the long output in `scratch.buffer`.
    fn finish_short(&self, scratch: &mut SpokeScratch, at: &PulseAt, earliest: Option<usize>) {
        let Some(ch) = &self.short else { return };
        // begin_short gave the scratch its short-pulse buffers.
        let Some(short) = scratch.short.as_deref_mut() else {
            return;
        };
        let record = ch.compressor.record_len();
        let rx = &ch.receiver;
        if rx.noise() {
            rx.fill_noise(at.key, at.pulse.number, &mut short.noise[..record]);
            short.noise[record..].fill(Complex32::new(0.0, 0.0));
        }
        ch.compressor.process(
            short,
            rx.noise(),
            rx.blanking(),
            rx.echo_in_blanking(earliest),
        );
        let join = ch.compressor.num_bins();
        for (o, y) in scratch.buffer[..join].iter_mut().zip(&short.buffer[..join]) {
            *o = y * ch.scale;
        }
    }
}
