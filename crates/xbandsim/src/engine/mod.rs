//! Stage: engine. [`Simulation`] = the model + its BVH + FFT plans + the receiver + a trace
//! cache. It runs a [`Schedule`]: for the scene state the schedule sees it takes the traced
//! contributions and their echo groups (from the [`TraceCache`]), then for every pulse weights
//! the groups by the antenna pattern at the pulse's azimuth, adds clutter and noise, blanks and
//! compresses, and integrates each dwell's pulses into one spoke of the record
//! (docs/physics.md, "Pipeline"; docs/architecture.md, "Engine"). Today's render is the
//! frozen-scan schedule: one pulse per spoke and one scene state per revolution, every object
//! where the beam crosses it ([`crate::model::Revolution`]).

mod iq;
mod pulse;
mod schedule;
mod trace_cache;

pub use iq::MAX_IQ_BYTES;
pub use pulse::{Mover, MOVING_ECHO_FOLD_ERROR};
pub use schedule::{Dwell, Pulse, Schedule};
pub use trace_cache::{TraceCache, Traced};

use crate::echo::{EchoGroups, FractionalDelayKernel};
use crate::environment::clutter_map::ClutterMap;
use crate::error::{Error, Problem, Result};
use crate::geometry::Bvh;
use crate::model::revolution::Revolution;
use crate::model::{ProcessingMode, Radar, Scene};
use crate::processing::PulseCompressor;
use crate::products::labels::{object_truth, ObjectTruth};
use crate::products::{Frame, FrameStats};
use crate::receiver::Receiver;
use crate::rng::{RngKey, Stream};
use crate::scattering::{build_scene_bvh, trace_scene, ScatterSet};
use num_complex::Complex32;
use rayon::prelude::*;
use std::sync::{Arc, OnceLock};
use std::time::Instant;

/// Groups weaker than this after the azimuth weight (noise-rms units, −80 dB) are skipped.
pub const MIN_GROUP_AMPLITUDE: f32 = 1e-4;

/// Smallest power written to the polar output, dB over noise (for noise-free runs).
pub const POLAR_FLOOR_DB: f32 = -120.0;

/// A scene ready to render.
#[derive(Clone)]
pub struct Simulation {
    scene: Arc<Scene>,
    /// The BVH of the scene as written, built on first use: a moving scene's revolutions
    /// build their own (so a dataset sample with moving targets builds one BVH, not two).
    bvh: Arc<OnceLock<Arc<Bvh>>>,
    compressor: PulseCompressor,
    receiver: Receiver,
    kernel: FractionalDelayKernel,
    cache: Arc<TraceCache>,
    doppler: Option<pulse::DopplerPlan>,
    short: Option<ShortChannel>,
    /// Sea and rain clutter on (off in [`Simulation::targets_only`]).
    clutter: bool,
    /// The spokes a spoke-mode revolution renders (all when None; [`Simulation::only_spokes`]).
    spokes_rendered: Option<Arc<[bool]>>,
}

/// The short pulse's receive channel in combined pulse mode (docs/physics.md §11): its own
/// matched filter over the bins inside the long pulse's eclipse, its own noise, and the
/// amplitude scale that gives its output the long pulse's calibration.
#[derive(Clone)]
struct ShortChannel {
    compressor: PulseCompressor,
    receiver: Receiver,
    /// `G_long/G_short`, the matched filters' peak gains `Σw/√Σw²`: a point echo's compressed
    /// peak is the same on either side of the join.
    scale: f32,
}

/// Optional products of a frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Outputs {
    /// The range-Doppler cube (pulse mode).
    pub doppler_cube: bool,
    /// The raw received I/Q of every pulse ([`crate::products::PulseIq`]).
    pub iq: bool,
    /// Every cell's pulse-pair radial velocity (pulse mode; `[display] doppler_colour`).
    pub radial_velocity: bool,
}

/// The raw signals of one pulse, in units of the noise rms voltage `√(k·T0·F·fs)`.
#[derive(Debug, Clone)]
pub struct RawSpoke {
    /// Echoes alone (no noise, no blanking), `record_len` samples from the start of transmission.
    pub echo_iq: Vec<Complex32>,
    /// What the receiver records: echoes + noise, zero while transmitting if blanked.
    pub received_iq: Vec<Complex32>,
    /// Matched-filter output, one value per range bin.
    pub compressed: Vec<Complex32>,
}

impl Simulation {
    /// Makes the FFT plans (the BVH of the scene as written is built on first use).
    pub fn new(scene: Scene) -> Simulation {
        let compressor = PulseCompressor::new(
            scene.radar().chirp(),
            scene.radar().window(),
            scene.radar().num_range_bins(),
        );
        let receiver = Receiver::new(
            scene.environment().noise(),
            scene.radar().receiver_blanking(),
            compressor.pulse_len(),
        );
        let processing = scene.processing();
        let doppler = (processing.mode() == ProcessingMode::Pulse).then(|| {
            pulse::DopplerPlan::new(processing.doppler_pulses(), processing.doppler_window())
        });
        let short = scene.radar().short_pulse().map(|p| {
            let bins = scene.radar().join_bin().min(compressor.num_bins());
            let c = PulseCompressor::new(&p.chirp, p.window, bins);
            ShortChannel {
                receiver: Receiver::new(
                    scene.environment().noise(),
                    scene.radar().receiver_blanking(),
                    c.pulse_len(),
                )
                .with_noise_stream(Stream::ShortPulseNoise),
                scale: (compressor.peak_gain() / c.peak_gain()) as f32,
                compressor: c,
            }
        });
        Simulation {
            scene: Arc::new(scene),
            bvh: Arc::new(OnceLock::new()),
            compressor,
            receiver,
            kernel: FractionalDelayKernel::new(),
            cache: Arc::new(TraceCache::default()),
            doppler,
            short,
            clutter: true,
            spokes_rendered: None,
        }
    }

    /// Whether neither receiver channel adds noise (an empty pulse then compresses to zero).
    fn is_silent(&self) -> bool {
        !self.receiver.noise() && self.short.as_ref().is_none_or(|c| !c.receiver.noise())
    }

    /// The same simulation without thermal noise and without sea and rain clutter: its frames
    /// hold the objects' echoes alone as the receiver records them (blanked, compressed,
    /// integrated; the same schedule, pulses and motion) — the target-only render from which
    /// the dataset draws its masks (docs/formats.md, "Dataset labels"). It shares this
    /// simulation's trace cache, so a frame rendered by both is traced once.
    pub fn targets_only(&self) -> Simulation {
        let mut s = self.clone();
        s.receiver = s.receiver.without_noise();
        if let Some(ch) = &mut s.short {
            ch.receiver = ch.receiver.without_noise();
        }
        s.clutter = false;
        s
    }

    /// The same simulation rendering only the spokes `k` with `wanted[k]` in spoke processing
    /// mode (spokes beyond the slice are not rendered): every other spoke of its frames holds
    /// [`POLAR_FLOOR_DB`], as if nothing were received there. Each spoke's record depends on
    /// its own dwell alone, so the rendered spokes are byte for byte those of the full frame.
    /// For a caller that reads only those spokes, such as the dataset's masks (drawn from the
    /// target-only render within each object's polar box). Pulse processing mode renders
    /// every spoke.
    pub fn only_spokes(&self, wanted: &[bool]) -> Simulation {
        let mut s = self.clone();
        s.spokes_rendered = Some(wanted.into());
        s
    }

    /// Fresh buffers for one worker: the pulse compressor's, with the short-pulse channel's
    /// in combined pulse mode.
    pub fn scratch(&self) -> crate::processing::SpokeScratch {
        let mut s = self.compressor.scratch();
        s.short = self
            .short
            .as_ref()
            .map(|c| Box::new(c.compressor.scratch()));
        s
    }

    /// Combined pulse mode: hands the pulse's impulse response (`scratch.buffer`, before any
    /// compression) to the short-pulse channel.
    fn begin_short(&self, scratch: &mut crate::processing::SpokeScratch) {
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
        short: Option<&mut crate::processing::SpokeScratch>,
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
    /// first [`Radar::join_bin`] bins of the long output in `scratch.buffer`.
    fn finish_short(
        &self,
        scratch: &mut crate::processing::SpokeScratch,
        seed: u64,
        frame: u64,
        pulse: u64,
        clutter: bool,
        earliest: Option<usize>,
    ) {
        let Some(ch) = &self.short else { return };
        // begin_short gave the scratch its short-pulse buffers.
        let Some(short) = scratch.short.as_deref_mut() else {
            return;
        };
        let record = ch.compressor.record_len();
        let rx = &ch.receiver;
        if rx.noise() {
            rx.fill_noise(seed, frame, pulse, &mut short.noise[..record]);
            short.noise[record..].fill(Complex32::new(0.0, 0.0));
        }
        ch.compressor.process(
            short,
            rx.noise(),
            rx.blanking(),
            rx.echo_in_blanking(clutter, earliest),
        );
        let join = ch.compressor.num_bins();
        for (o, y) in scratch.buffer[..join].iter_mut().zip(&short.buffer[..join]) {
            *o = y * ch.scale;
        }
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The BVH of the scene as written (every object at its t = 0 pose).
    pub fn bvh(&self) -> &Bvh {
        self.bvh_shared()
    }

    fn bvh_shared(&self) -> &Arc<Bvh> {
        self.bvh
            .get_or_init(|| Arc::new(build_scene_bvh(self.scene.objects())))
    }

    /// The receiver (noise, blanking).
    pub fn receiver(&self) -> &Receiver {
        &self.receiver
    }

    /// The pulse compressor.
    pub fn compressor(&self) -> &PulseCompressor {
        &self.compressor
    }

    /// Traces the scene as written once (every object at its t = 0 pose).
    pub fn trace(&self) -> ScatterSet {
        trace_scene(&self.scene, self.bvh())
    }

    /// Bins contributions into per-group impulse responses in noise-rms units.
    pub fn echo_groups(&self, set: &ScatterSet) -> EchoGroups {
        let radar = self.scene.radar();
        EchoGroups::build(
            &set.contributions,
            radar.antenna(),
            radar.sample_rate_hz(),
            self.compressor.record_len(),
            radar.noise_power_w().sqrt(),
            &self.kernel,
        )
    }

    /// As [`Simulation::echo_groups`], with object i's elevation pattern raised by
    /// `object_tilt_rad[i]` (the own ship's roll and pitch when the beam crosses it).
    pub fn echo_groups_tilted(&self, set: &ScatterSet, object_tilt_rad: &[f64]) -> EchoGroups {
        let radar = self.scene.radar();
        EchoGroups::build_tilted(
            &set.contributions,
            radar.antenna(),
            object_tilt_rad,
            radar.sample_rate_hz(),
            self.compressor.record_len(),
            radar.noise_power_w().sqrt(),
            &self.kernel,
        )
    }

    /// Adds one pulse's band-limited impulse response (targets weighted by the azimuth pattern
    /// for a beam at `beam_az_rad`, plus the clutter of spoke `spoke` with the pulse's speckle)
    /// into `scratch.buffer[..record]` (noise-rms units); returns the earliest target sample
    /// written.
    fn impulse_response(
        &self,
        clutter: Option<&ClutterMap>,
        groups: &EchoGroups,
        spoke: usize,
        beam_az_rad: f64,
        speckle: RngKey,
        scratch: &mut crate::processing::SpokeScratch,
    ) -> Option<usize> {
        let impulse_response = &mut scratch.buffer[..self.compressor.record_len()];
        let earliest = groups.accumulate(
            self.scene.radar().antenna(),
            beam_az_rad,
            MIN_GROUP_AMPLITUDE,
            impulse_response,
        );
        if let Some(c) = clutter {
            c.add_to_spoke(
                spoke,
                speckle,
                &mut scratch.clutter_sea,
                &mut scratch.clutter_rain,
                impulse_response,
            );
        }
        earliest
    }

    /// Compressed output of one spoke at `beam_az_rad` into `scratch.buffer[..bins]`
    /// (amplitude in noise-rms units): the pulse numbered `spoke` of a one-pulse-per-spoke
    /// scan.
    pub fn compress_spoke(
        &self,
        clutter: Option<&ClutterMap>,
        groups: &EchoGroups,
        beam_az_rad: f64,
        seed: u64,
        frame: u64,
        spoke: u64,
        scratch: &mut crate::processing::SpokeScratch,
    ) {
        let pulse = Pulse {
            number: spoke,
            time_s: 0.0,
            azimuth_rad: beam_az_rad,
        };
        self.compress_pulse(
            clutter,
            groups,
            spoke as usize,
            &pulse,
            seed,
            frame,
            scratch,
        );
    }

    /// Compressed output of one pulse into `scratch.buffer[..bins]` (amplitude in noise-rms
    /// units): targets at the pulse's azimuth, the clutter cells of spoke `spoke`, the pulse's
    /// own speckle and noise streams, blanking, matched filter.
    pub fn compress_pulse(
        &self,
        clutter: Option<&ClutterMap>,
        groups: &EchoGroups,
        spoke: usize,
        pulse: &Pulse,
        seed: u64,
        frame: u64,
        scratch: &mut crate::processing::SpokeScratch,
    ) {
        let record = self.compressor.record_len();
        scratch.buffer.fill(Complex32::new(0.0, 0.0));
        let earliest = self.impulse_response(
            clutter,
            groups,
            spoke,
            pulse.azimuth_rad,
            RngKey::new(seed, frame, pulse.number, Stream::ClutterSpeckle),
            scratch,
        );
        if earliest.is_none() && clutter.is_none() && self.is_silent() && !scratch.capture_received
        {
            // Nothing in and no noise: the matched filter's output is zero (the buffer is).
            return;
        }
        self.begin_short(scratch);
        let rx = &self.receiver;
        if rx.noise() {
            rx.fill_noise(seed, frame, pulse.number, &mut scratch.noise[..record]);
            scratch.noise[record..].fill(Complex32::new(0.0, 0.0));
        }
        self.compressor.process(
            scratch,
            rx.noise(),
            rx.blanking(),
            rx.echo_in_blanking(clutter.is_some(), earliest),
        );
        self.finish_short(
            scratch,
            seed,
            frame,
            pulse.number,
            clutter.is_some(),
            earliest,
        );
    }

    /// Raw I/Q of one pulse at `beam_az_rad`, formed explicitly in time (echo record, noise,
    /// blanking, then the matched filter) — the same signals `compress_spoke` forms in the
    /// frequency domain (the long pulse's channel: in combined pulse mode the bins inside the
    /// join come from the short pulse instead), kept for figures and tests.
    pub fn raw_spoke(
        &self,
        clutter: Option<&ClutterMap>,
        groups: &EchoGroups,
        beam_az_rad: f64,
        seed: u64,
        frame: u64,
        spoke: u64,
    ) -> RawSpoke {
        let record = self.compressor.record_len();
        let mut scratch = self.compressor.scratch();
        self.impulse_response(
            clutter,
            groups,
            spoke as usize,
            beam_az_rad,
            RngKey::new(seed, frame, spoke, Stream::ClutterSpeckle),
            &mut scratch,
        );
        let mut echo = scratch.buffer.clone();
        self.compressor.synthesize_record(&mut echo, &mut scratch);
        echo[record..].fill(Complex32::new(0.0, 0.0));
        let mut received = echo.clone();
        if self.receiver.noise() {
            self.receiver
                .fill_noise(seed, frame, spoke, &mut scratch.noise[..record]);
            for (r, n) in received.iter_mut().zip(&scratch.noise[..record]) {
                *r += n;
            }
        }
        self.receiver.blank(&mut received);
        let mut compressed = received.clone();
        self.compressor
            .compress_record(&mut compressed, &mut scratch);
        echo.truncate(record);
        received.truncate(record);
        compressed.truncate(self.compressor.num_bins());
        RawSpoke {
            echo_iq: echo,
            received_iq: received,
            compressed,
        }
    }

    /// Polar output (spokes × bins, dB over noise) of one revolution from prepared groups.
    pub fn synthesize(&self, groups: &EchoGroups, seed: u64, frame: u64) -> Vec<f32> {
        let clutter = self.clutter_map(seed, frame);
        self.synthesize_with(groups, clutter.as_ref(), seed, frame)
    }

    /// As [`Simulation::synthesize`] with the revolution's clutter map already made (it must
    /// be `clutter_map(seed, frame)`).
    pub fn synthesize_with(
        &self,
        groups: &EchoGroups,
        clutter: Option<&ClutterMap>,
        seed: u64,
        frame: u64,
    ) -> Vec<f32> {
        self.synthesize_progress(groups, clutter, seed, frame, &|| {})
    }

    /// As [`Simulation::synthesize_with`], calling `spoke_done` after every spoke (from the
    /// worker threads) so that a caller can show progress.
    pub fn synthesize_progress(
        &self,
        groups: &EchoGroups,
        clutter: Option<&ClutterMap>,
        seed: u64,
        frame: u64,
        spoke_done: &(dyn Fn() + Sync),
    ) -> Vec<f32> {
        let schedule = Schedule::frozen_scan(self.scene.radar(), frame);
        self.synthesize_checked(groups, clutter, seed, &schedule, spoke_done)
    }

    /// Polar output (spokes × bins, dB over noise) of a schedule from prepared groups and its
    /// revolution's clutter map: every dwell's pulses compressed and their powers averaged into
    /// its spoke. Dwells run in parallel, each worker with its own scratch; `dwell_done` is
    /// called after every dwell. A schedule made for another number of spokes is refused.
    pub fn synthesize_schedule(
        &self,
        groups: &EchoGroups,
        clutter: Option<&ClutterMap>,
        seed: u64,
        schedule: &Schedule,
        dwell_done: &(dyn Fn() + Sync),
    ) -> Result<Vec<f32>> {
        self.check_schedule(schedule)?;
        Ok(self.synthesize_checked(groups, clutter, seed, schedule, dwell_done))
    }

    fn synthesize_checked(
        &self,
        groups: &EchoGroups,
        clutter: Option<&ClutterMap>,
        seed: u64,
        schedule: &Schedule,
        dwell_done: &(dyn Fn() + Sync),
    ) -> Vec<f32> {
        self.synthesize_capture(groups, clutter, seed, schedule, None, dwell_done)
    }

    /// [`Simulation::synthesize_checked`], keeping every pulse's received record in `iq`.
    fn synthesize_capture(
        &self,
        groups: &EchoGroups,
        clutter: Option<&ClutterMap>,
        seed: u64,
        schedule: &Schedule,
        iq: Option<&mut iq::IqCapture>,
        dwell_done: &(dyn Fn() + Sync),
    ) -> Vec<f32> {
        let spokes = self.scene.radar().spokes();
        let bins = self.compressor.num_bins();
        let record = self.compressor.record_len();
        // Schedule::new and frozen_scan guarantee one dwell per spoke.
        let mut dwell_of_spoke = vec![0usize; spokes];
        for (i, d) in schedule.dwells().iter().enumerate() {
            dwell_of_spoke[d.spoke] = i;
        }
        let mut polar = vec![0f32; spokes * bins];
        let mut iq_slabs = iq.map_or_else(|| (0..spokes).map(|_| None).collect(), |c| c.slabs());
        polar
            .par_chunks_mut(bins)
            .zip(iq_slabs.par_iter_mut())
            .enumerate()
            .for_each_init(
                || self.scratch(),
                |scratch, (k, (row, iq_slab))| {
                    let dwell = &schedule.dwells()[dwell_of_spoke[k]];
                    if let Some(wanted) = &self.spokes_rendered {
                        if !wanted.get(k).copied().unwrap_or(false) {
                            row.fill(POLAR_FLOOR_DB);
                            dwell_done();
                            return;
                        }
                    }
                    row.fill(0.0);
                    scratch.capture_received = iq_slab.is_some();
                    for (m, pulse) in dwell.pulses.iter().enumerate() {
                        self.compress_pulse(
                            clutter,
                            groups,
                            k,
                            pulse,
                            seed,
                            schedule.frame(),
                            scratch,
                        );
                        if let Some(slab) = iq_slab.as_deref_mut() {
                            slab[m * record..(m + 1) * record].copy_from_slice(&scratch.received);
                        }
                        for (o, y) in row.iter_mut().zip(&scratch.buffer[..bins]) {
                            *o += y.norm_sqr();
                        }
                    }
                    // Non-coherent integration: the mean power of the dwell's pulses (exactly
                    // the pulse's power for a one-pulse dwell).
                    let inv_pulses = 1.0 / dwell.pulses.len() as f32;
                    crate::special::power_db_in_place(row, inv_pulses, POLAR_FLOOR_DB);
                    dwell_done();
                },
            );
        polar
    }

    /// Sea and rain clutter of frame `frame` (None when the scene has neither), seen from
    /// the antenna's position at the start of the run.
    pub fn clutter_map(&self, seed: u64, frame: u64) -> Option<ClutterMap> {
        self.clutter_map_from(self.scene.radar(), seed, frame)
    }

    /// Sea and rain clutter of frame `frame` seen by `radar` (this scene's radar, carried to
    /// where the own ship has taken it).
    fn clutter_map_from(&self, radar: &Radar, seed: u64, frame: u64) -> Option<ClutterMap> {
        if !self.clutter {
            return None;
        }
        ClutterMap::new(
            radar,
            self.scene.environment(),
            seed,
            frame,
            self.compressor.record_len(),
        )
    }

    /// Ground truth of a trace of the scene as written ([`Simulation::trace`]) in the
    /// revolution that starts at t = 0 (exact for a still scene; a moving scene's truth comes
    /// with its frame). PPI pixel boxes are the PPI product's:
    /// [`crate::products::ppi::PpiGeometry::label`].
    pub fn truth(&self, set: &ScatterSet) -> Vec<ObjectTruth> {
        object_truth(&Revolution::of(&self.scene, 0.0), set, self.bvh())
    }

    /// Renders one revolution: trace, group, synthesise every spoke, label.
    pub fn render(&self, seed: u64) -> Frame {
        self.render_frame(seed, 0)
    }

    /// Renders revolution number `frame` (the clutter texture has drifted for `frame` antenna
    /// periods; noise and speckle are new each frame).
    pub fn render_frame(&self, seed: u64, frame: u64) -> Frame {
        self.render_frame_progress(seed, frame, &|| {})
    }

    /// As [`Simulation::render_frame`], calling `spoke_done` after every spoke.
    pub fn render_frame_progress(
        &self,
        seed: u64,
        frame: u64,
        spoke_done: &(dyn Fn() + Sync),
    ) -> Frame {
        let schedule =
            Schedule::for_mode(self.scene.radar(), self.scene.processing().mode(), frame);
        self.run_checked(&schedule, seed, Outputs::default(), None, spoke_done)
    }

    /// Renders revolution `frame` with the scan of `[processing] mode` and the optional
    /// `outputs` ([`Simulation::check_outputs`] says which this scene can give; a Doppler
    /// cube and radial velocities need pulse mode), calling `spoke_done` after every spoke.
    pub fn render_frame_outputs(
        &self,
        seed: u64,
        frame: u64,
        outputs: Outputs,
        spoke_done: &(dyn Fn() + Sync),
    ) -> Result<Frame> {
        self.check_outputs(outputs)?;
        let schedule =
            Schedule::for_mode(self.scene.radar(), self.scene.processing().mode(), frame);
        self.run_with(&schedule, seed, outputs, spoke_done)
    }

    /// Whether this scene can give `outputs`: a Doppler cube and radial velocities need
    /// `[processing] mode = "pulse"`; raw I/Q must stay under [`MAX_IQ_BYTES`] per revolution.
    pub fn check_outputs(&self, outputs: Outputs) -> Result<()> {
        if outputs.doppler_cube && self.scene.processing().mode() != ProcessingMode::Pulse {
            return Err(Error::invalid(
                Problem::Conflict,
                "processing.mode",
                "\"spoke\"",
                "a range-Doppler cube (--datacube) needs processing.mode = \"pulse\": the scene fires one pulse per spoke (add [processing] mode = \"pulse\" or --set processing.mode=pulse)",
            ));
        }
        if outputs.radial_velocity && self.scene.processing().mode() != ProcessingMode::Pulse {
            return Err(Error::invalid(
                Problem::Conflict,
                "processing.mode",
                "\"spoke\"",
                "radial velocities (display.doppler_colour) need processing.mode = \"pulse\": the scene fires one pulse per spoke",
            ));
        }
        if outputs.iq {
            let schedule =
                Schedule::for_mode(self.scene.radar(), self.scene.processing().mode(), 0);
            iq::IqCapture::rows(&schedule, self.compressor.record_len())?;
        }
        Ok(())
    }

    /// Seconds before a revolution's start from which its beam crossings are sought: half a
    /// spoke in pulse mode (spoke 0's first pulses come before north), none in spoke mode.
    fn revolution_lead_s(&self) -> f64 {
        match self.scene.processing().mode() {
            ProcessingMode::Spoke => 0.0,
            ProcessingMode::Pulse => {
                let scan = self.scene.radar().scan();
                0.5 * scan.period_s() / scan.spokes() as f64
            }
        }
    }

    /// The traced state of the revolution that starts at `start_time_s` and its echo groups,
    /// from the trace cache (traced on first use; a still scene is traced once for all times).
    pub fn traced(&self, start_time_s: f64) -> Arc<Traced> {
        self.traced_now(start_time_s).0
    }

    fn traced_now(&self, start_time_s: f64) -> (Arc<Traced>, bool) {
        let still = self.scene.is_still();
        let lead_s = self.revolution_lead_s();
        self.cache.get_or_trace(start_time_s, still, || {
            let revolution = Revolution::with_lead(&self.scene, start_time_s, lead_s);
            let bvh = if still {
                Arc::clone(self.bvh_shared())
            } else {
                Arc::new(build_scene_bvh(revolution.scene().objects()))
            };
            let set = trace_scene(revolution.scene(), &bvh);
            let groups = if revolution.deck_moves() {
                let tilts: Vec<f64> = revolution
                    .objects()
                    .iter()
                    .map(|o| o.beam_tilt_rad)
                    .collect();
                self.echo_groups_tilted(&set, &tilts)
            } else {
                self.echo_groups(&set)
            };
            Traced {
                revolution,
                bvh,
                set,
                groups,
            }
        })
    }

    /// Runs a schedule: the traced state it sees (cached), its revolution's clutter map,
    /// every dwell synthesised and integrated, and the labels of that state. `dwell_done` is
    /// called after every dwell (from the worker threads). A schedule made for a radar with
    /// another number of spokes is refused.
    pub fn run(
        &self,
        schedule: &Schedule,
        seed: u64,
        dwell_done: &(dyn Fn() + Sync),
    ) -> Result<Frame> {
        self.run_with(schedule, seed, Outputs::default(), dwell_done)
    }

    /// [`Simulation::run`] with optional outputs (raw I/Q for any schedule; the Doppler cube
    /// in pulse mode).
    pub fn run_with(
        &self,
        schedule: &Schedule,
        seed: u64,
        outputs: Outputs,
        dwell_done: &(dyn Fn() + Sync),
    ) -> Result<Frame> {
        self.check_schedule(schedule)?;
        let mut iq = if outputs.iq {
            Some(iq::IqCapture::new(schedule, self.compressor.record_len())?)
        } else {
            None
        };
        let mut frame = self.run_checked(schedule, seed, outputs, iq.as_mut(), dwell_done);
        frame.iq = iq.map(|c| c.finish(schedule, self.scene.radar().sample_rate_hz()));
        Ok(frame)
    }

    fn check_schedule(&self, schedule: &Schedule) -> Result<()> {
        let spokes = self.scene.radar().spokes();
        if schedule.spokes() != spokes {
            return Err(Error::invalid(
                Problem::Conflict,
                "schedule.dwells",
                schedule.spokes(),
                format!(
                    "the schedule fills {} spokes but this radar records {spokes} (radar.spokes)",
                    schedule.spokes()
                ),
            ));
        }
        Ok(())
    }

    fn run_checked(
        &self,
        schedule: &Schedule,
        seed: u64,
        outputs: Outputs,
        iq: Option<&mut iq::IqCapture>,
        dwell_done: &(dyn Fn() + Sync),
    ) -> Frame {
        let t0 = Instant::now();
        let (traced, fresh) = self.traced_now(schedule.scene_time_s());
        let trace_s = if fresh {
            t0.elapsed().as_secs_f64()
        } else {
            0.0
        };
        let t1 = Instant::now();
        // A still scene's one traced state serves every revolution; only the times the beam
        // crosses each object (in the labels) are the revolution's own.
        let own_revolution;
        let revolution = if self.scene.is_still() {
            own_revolution = Revolution::with_lead(
                &self.scene,
                schedule.scene_time_s(),
                self.revolution_lead_s(),
            );
            &own_revolution
        } else {
            &traced.revolution
        };
        let clutter = if !self.clutter {
            None
        } else if revolution.deck_moves() {
            // Each spoke's beam tilted by the deck's roll and pitch when the antenna passes it.
            let scan = *self.scene.radar().scan();
            let tilts: Vec<f64> = (0..scan.spokes())
                .map(|k| {
                    let t = revolution.start_time_s()
                        + k as f64 / scan.spokes() as f64 * scan.period_s();
                    revolution.beam_tilt_rad(t, scan.spoke_azimuth_rad(k))
                })
                .collect();
            ClutterMap::with_beam_tilts(
                revolution.scene().radar(),
                self.scene.environment(),
                seed,
                schedule.frame(),
                self.compressor.record_len(),
                &tilts,
            )
        } else {
            self.clutter_map_from(revolution.scene().radar(), seed, schedule.frame())
        };
        let (polar_db, doppler_cube, radial_velocity) = match self.scene.processing().mode() {
            ProcessingMode::Spoke => (
                self.synthesize_capture(
                    &traced.groups,
                    clutter.as_ref(),
                    seed,
                    schedule,
                    iq,
                    dwell_done,
                ),
                None,
                None,
            ),
            ProcessingMode::Pulse => self.synthesize_pulses(
                &traced.groups,
                clutter.as_ref(),
                revolution
                    .own_ship()
                    .map_or(glam::DVec3::ZERO, |s| s.velocity_mps),
                &self.movers(revolution),
                seed,
                schedule,
                outputs,
                iq,
                dwell_done,
            ),
        };
        let synthesis_s = t1.elapsed().as_secs_f64();
        let truth = object_truth(revolution, &traced.set, &traced.bvh);
        let radar = self.scene.radar();
        Frame {
            frame: schedule.frame(),
            start_time_s: revolution.start_time_s(),
            own_ship: revolution.own_ship().copied(),
            spokes: radar.spokes(),
            range_bins: self.compressor.num_bins(),
            range_bin_m: radar.range_bin_m(),
            polar_db,
            doppler_cube,
            iq: None,
            radial_velocity,
            truth,
            stats: FrameStats {
                rays_cast: traced.set.rays_cast,
                contributions: traced.set.contributions.len(),
                echo_groups: traced.groups.groups.len(),
                trace_s,
                synthesis_s,
            },
        }
    }
}
