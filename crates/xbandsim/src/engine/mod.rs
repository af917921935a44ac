//! Stage: engine. [`Simulation`] = a traced world ([`World`]: the scene's BVH and traces,
//! shared by every simulation made from it with [`Simulation::with_scene`]) + a receive chain
//! (pulse compressor, receiver, short-pulse channel, Doppler plan, gain and STC) with its echo
//! groups of each traced state. [`Simulation::run`] takes a [`Request`]: it runs the request's
//! [`Schedule`] (the scene's own scan by default) through the signal chain — for every dwell
//! the sources, the receiver, the matched filter and the sinks (`engine::chain`) — and labels the
//! revolution's state (docs/architecture.md, "Signal chain", "Engine").

mod chain;
mod iq;
mod request;
mod revolution;
mod trace_cache;
mod world;

pub use crate::processing::sinks::POLAR_FLOOR_DB;
pub use crate::schedule::{Dwell, Pulse, Schedule};
pub use crate::signal::targets::{Mover, MIN_GROUP_AMPLITUDE, MOVING_ECHO_FOLD_ERROR};
pub use iq::MAX_IQ_BYTES;
pub use request::Request;
pub use trace_cache::{TraceCache, Traced, TracedWorld};
pub use world::World;

use crate::echo::{EchoGroups, FractionalDelayKernel};
use crate::error::{Error, Problem, Result};
use crate::geometry::Bvh;
use crate::model::revolution::Revolution;
use crate::model::{ProcessingMode, Scene};
use crate::processing::sinks::DopplerPlan;
use crate::processing::{DopplerSpectra, PulseCompressor, SpokeScratch};
use crate::products::artefacts::{
    beacon_artefacts, blind_sector_artefacts, indirect_echo_artefacts, interference_artefacts,
    multiple_echo_artefacts, second_trace_artefacts, sidelobe_artefacts,
};
use crate::products::labels::{eclipse_loss_db_at, object_truth, ObjectTruth};
use crate::products::{Frame, FrameStats};
use crate::receiver::stages::GainStc;
use crate::receiver::video_chain::{self, PolarRecord};
use crate::receiver::Receiver;
use crate::rng::{FrameKey, Stream};
use crate::scattering::{trace_scene, via_own_ship, Contribution, ScatterSet};
use crate::signal::clutter::{ClutterSpeckle, SeaAndRainClutter};
use crate::signal::clutter_map::{ClutterMap, ClutterSurface};
use crate::signal::PulseAt;
use num_complex::Complex32;
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;

/// A scene ready to render.
#[derive(Clone)]
pub struct Simulation {
    /// The scene this simulation renders (its waveform and receiver are this chain's).
    scene: Arc<Scene>,
    /// The traced world: the scene's BVH and traces, shared by every simulation made from it
    /// with [`Simulation::with_scene`].
    world: Arc<World>,
    /// This receive chain's traced states: the world's traces and their echo groups.
    cache: Arc<TraceCache>,
    /// This receive chain's echo groups of the still objects' kept traces, kept with them.
    kept_groups: Arc<KeptGroups>,
    /// The clutter surface made last for a level beam: the next revolution with the same
    /// radar and seed draws its texture on it (a radar that stands still).
    clutter_surface: Arc<std::sync::Mutex<Option<Arc<ClutterSurface>>>>,
    compressor: PulseCompressor,
    receiver: Receiver,
    kernel: FractionalDelayKernel,
    doppler: Option<DopplerPlan>,
    short: Option<ShortChannel>,
    /// Gain and STC on the compressed signal (neutral unless [`Simulation::with_gain_stc`]).
    gain_stc: GainStc,
    /// Sea and rain clutter on (off in [`Simulation::targets_only`]).
    clutter: bool,
    /// The spokes a spoke-mode revolution renders (all when None; [`Simulation::only_spokes`]).
    spokes_rendered: Option<Arc<[bool]>>,
    /// The receiver's video chain runs when the scene has one (off in
    /// [`Simulation::targets_only`], whose record is for masks).
    video: bool,
    /// Other transmitters (interferers, racons, SARTs) are sources (off in
    /// [`Simulation::targets_only`]).
    artefact_sources: bool,
}

/// The echo groups made from each still object's kept trace (by object index), with the
/// trace they were made from: reused while the world reuses that trace (the same `Arc`).
#[derive(Default)]
struct KeptGroups {
    #[allow(clippy::type_complexity)]
    groups: std::sync::Mutex<Vec<Option<(Arc<crate::scattering::po::KeptTrace>, Arc<EchoGroups>)>>>,
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
        let doppler = (processing.mode() == ProcessingMode::Pulse)
            .then(|| DopplerPlan::new(processing.doppler_pulses(), processing.doppler_window()));
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
        let range_bin_m = scene.radar().range_bin_m();
        let scene = Arc::new(scene);
        Simulation {
            world: Arc::new(World::new(Arc::clone(&scene))),
            scene,
            compressor,
            receiver,
            kernel: FractionalDelayKernel::new(),
            cache: Arc::new(TraceCache::default()),
            kept_groups: Arc::default(),
            clutter_surface: Arc::default(),
            doppler,
            short,
            gain_stc: GainStc {
                gain_db: 0.0,
                stc_law: 0.0,
                stc_reach_m: 0.0,
                range_bin_m,
            },
            clutter: true,
            spokes_rendered: None,
            video: true,
            artefact_sources: true,
        }
    }

    /// Whether neither receiver channel adds noise (an empty pulse then compresses to zero).
    fn is_silent(&self) -> bool {
        !self.receiver.noise() && self.short.as_ref().is_none_or(|c| !c.receiver.noise())
    }

    /// The same simulation without thermal noise, sea and rain clutter, other transmitters
    /// or video: its frames
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
        s.video = false;
        s.artefact_sources = false;
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

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The BVH of the scene as written (every object at its t = 0 pose).
    pub fn bvh(&self) -> &Bvh {
        self.world.bvh()
    }

    /// The traced world it renders (shared by [`Simulation::with_scene`]).
    pub fn world(&self) -> &Arc<World> {
        &self.world
    }

    /// A simulation of `scene` sharing this one's traced world (BVH and traces), when the
    /// world serves it ([`World::serves`]): `scene` may differ from this one's only in its
    /// waveform and receiver (`radar.pulse_width_us`, `bandwidth_mhz`, `window`, `pulse_mode`,
    /// the short pulse, `receiver_blanking`), which are what the receive chain is built from,
    /// and with another pulse length only when every object is a point. Anything else would
    /// trace differently, and is refused.
    pub fn with_scene(&self, scene: Scene) -> Result<Simulation> {
        if !self.world.serves(&scene) {
            return Err(Error::invalid(
                Problem::Conflict,
                "radar",
                "a scene with another world",
                "only the waveform and the receiver (pulse width, bandwidth, window, pulse mode, short pulse, blanking) may differ from the traced world's scene, and the pulse length only when every object is a point (an extended object's trace depends on the range it can be seen to, max range + c*T/2); make a new Simulation for another scene",
            ));
        }
        let mut s = Simulation::new(scene);
        s.world = Arc::clone(&self.world);
        Ok(s)
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
        self.echo_groups_tilted(set, &[])
    }

    /// The pulse interval in samples when second-trace echoes are on and the train is not
    /// staggered (a staggered train's folds are drawn by
    /// [`crate::scattering::via_own_ship::fold_staggered`]).
    fn fold_samples(&self) -> Option<f64> {
        let radar = self.scene.radar();
        (self.scene.artefacts().second_trace && !radar.scan().stagger().is_staggered())
            .then(|| radar.sample_rate_hz() / radar.prf_hz())
    }

    /// As [`Simulation::echo_groups`], with object i's elevation pattern raised by
    /// `object_tilt_rad[i]` (the own ship's roll and pitch when the beam crosses it).
    pub fn echo_groups_tilted(&self, set: &ScatterSet, object_tilt_rad: &[f64]) -> EchoGroups {
        self.echo_groups_of(&set.contributions, object_tilt_rad)
    }

    /// Groups `contributions` (a traced set's, with any paths via the own ship), folding
    /// second-trace echoes when they are on.
    fn echo_groups_of(
        &self,
        contributions: &[Contribution],
        object_tilt_rad: &[f64],
    ) -> EchoGroups {
        let radar = self.scene.radar();
        let stagger = radar.scan().stagger();
        let staggered_folds;
        let contributions = if self.scene.artefacts().second_trace && stagger.is_staggered() {
            let record_s = self.compressor.record_len() as f64 / radar.sample_rate_hz();
            staggered_folds = crate::scattering::via_own_ship::fold_staggered(
                contributions,
                record_s,
                stagger.intervals_s(),
            );
            &staggered_folds[..]
        } else {
            contributions
        };
        EchoGroups::build_folded(
            contributions,
            radar.antenna(),
            object_tilt_rad,
            radar.sample_rate_hz(),
            self.compressor.record_len(),
            radar.noise_power_w().sqrt(),
            &self.kernel,
            self.fold_samples(),
        )
    }

    /// [`Simulation::echo_groups_of`] a traced set with no tilts, the groups of each kept
    /// still trace made once and kept with it (`KeptGroups`): the groups are made per object
    /// and joined ([`EchoGroups::concat`]), the same bytes as one build of the whole set.
    fn echo_groups_keeping(&self, set: &ScatterSet) -> EchoGroups {
        let radar = self.scene.radar();
        let staggered =
            self.scene.artefacts().second_trace && radar.scan().stagger().is_staggered();
        if set.kept.is_empty() || staggered {
            return self.echo_groups_of(&set.contributions, &[]);
        }
        // The set is one run of contributions per object, in object order: consecutive
        // objects without a kept trace form one part, built now; each kept trace is a part
        // of its own, its groups taken from `KeptGroups` when they were made from it.
        enum Part<'a> {
            Fresh(&'a [Contribution]),
            Kept(usize, &'a Arc<crate::scattering::po::KeptTrace>),
        }
        let mut parts = Vec::new();
        let (mut at, mut fresh_from) = (0, 0);
        for (object, kept) in set.kept.iter().enumerate() {
            let run = set.contributions[at..]
                .iter()
                .take_while(|c| c.object as usize == object)
                .count();
            if let Some(k) = kept {
                debug_assert_eq!(run, k.contributions.len());
                if fresh_from < at {
                    parts.push(Part::Fresh(&set.contributions[fresh_from..at]));
                }
                parts.push(Part::Kept(object, k));
                fresh_from = at + run;
            }
            at += run;
        }
        if fresh_from < set.contributions.len() {
            parts.push(Part::Fresh(&set.contributions[fresh_from..]));
        }
        let known = self.kept_groups.groups.lock().expect("kept groups").clone();
        let built: Vec<Arc<EchoGroups>> = parts
            .par_iter()
            .map(|part| match part {
                Part::Fresh(run) => Arc::new(self.echo_groups_of(run, &[])),
                Part::Kept(object, k) => match known.get(*object) {
                    Some(Some((from, groups))) if Arc::ptr_eq(from, k) => Arc::clone(groups),
                    _ => Arc::new(self.echo_groups_of(&k.contributions, &[])),
                },
            })
            .collect();
        {
            let mut known = self.kept_groups.groups.lock().expect("kept groups");
            let len = set.kept.len().max(known.len());
            known.resize(len, None);
            for (part, groups) in parts.iter().zip(&built) {
                if let Part::Kept(object, k) = part {
                    known[*object] = Some((Arc::clone(k), Arc::clone(groups)));
                }
            }
        }
        EchoGroups::concat(&built.iter().map(|g| &**g).collect::<Vec<_>>())
    }

    /// The same simulation with gain and STC `stage` on the compressed signal, before
    /// detection (its range bins must be this radar's).
    pub fn with_gain_stc(&self, stage: GainStc) -> Simulation {
        let mut s = self.clone();
        s.gain_stc = stage;
        s
    }

    /// Renders one revolution of the scene's scan: trace, group, synthesise every spoke,
    /// label. Shorthand for [`Simulation::run`] with `Request::new(seed)`.
    pub fn render(&self, seed: u64) -> Frame {
        self.run(&Request::new(seed))
            .expect("the scene's own scan with no optional outputs is always runnable")
    }

    /// Runs a request: the schedule it names (the scene's scan of its frame by default), the
    /// traced state that schedule sees (cached), its revolution's sea and rain clutter, every
    /// dwell through the signal chain into the record and the optional outputs, and the
    /// labels of that state. Refused: a schedule made for a radar with another number of
    /// spokes, outputs this scene cannot give ([`Simulation::check_outputs`]).
    pub fn run(&self, request: &Request) -> Result<Frame> {
        let own;
        let schedule = match request.schedule_given() {
            Some(s) => s,
            None => {
                own = Schedule::for_mode(
                    self.scene.radar(),
                    self.scene.processing().mode(),
                    request.frame_number(),
                );
                &own
            }
        };
        self.check_schedule(schedule)?;
        let outputs = request.outputs_asked();
        // The I/Q capture's size is checked against this schedule by IqCapture::new.
        self.check_output_modes(outputs)?;
        let mut iq = if outputs.iq {
            Some(iq::IqCapture::new(schedule, self.compressor.record_len())?)
        } else {
            None
        };
        let mut frame = self.run_checked(
            schedule,
            request.key(schedule),
            outputs,
            iq.as_mut(),
            request.progress_or_none(),
        );
        frame.iq = iq.map(|c| c.finish(schedule, self.scene.radar().sample_rate_hz()));
        if let Some(settings) = self.scene.receiver().filter(|_| self.video) {
            let record = PolarRecord {
                db: &frame.polar_db,
                spokes: frame.spokes,
                bins: frame.range_bins,
                bin_m: frame.range_bin_m,
                range_m: self.scene.radar().max_range_m(),
            };
            let video = match request.echo_history_given() {
                Some(h) => {
                    let mut h = h.lock().unwrap_or_else(|e| e.into_inner());
                    video_chain::run(settings, &record, Some(&mut h))
                }
                None => video_chain::run(settings, &record, None),
            };
            frame.video = Some(video);
        }
        Ok(frame)
    }

    /// The polar record (spokes × bins, dB over noise) of a request's schedule (the frozen
    /// scan of its frame by default) from prepared echo groups and the revolution's clutter
    /// map (`clutter_map(request.key(schedule))` or None): the spoke-mode chain — no moving echoes,
    /// fresh speckle every pulse, each dwell's powers averaged into its spoke. For checks
    /// and benchmarks of the chain alone.
    pub fn synthesize(
        &self,
        groups: &EchoGroups,
        clutter: Option<&ClutterMap>,
        request: &Request,
    ) -> Result<Vec<f32>> {
        let own;
        let schedule = match request.schedule_given() {
            Some(s) => s,
            None => {
                own = Schedule::frozen_scan(self.scene.radar(), request.frame_number());
                &own
            }
        };
        self.check_schedule(schedule)?;
        let bins = self.compressor.num_bins();
        let mut polar = vec![0f32; self.scene.radar().spokes() * bins];
        let sources = self.spoke_sources(groups, clutter);
        self.run_dwells(
            &sources,
            schedule,
            request.key(schedule),
            &self.sink_plan(ProcessingMode::Spoke, Outputs::default()),
            Self::rows(&mut polar, bins, None, None, None),
            self.spokes_rendered.as_deref(),
            request.progress_or_none(),
        );
        Ok(polar)
    }

    /// Compressed output of one spoke-mode pulse into `scratch.buffer[..bins]` (amplitude in
    /// noise-rms units): targets at the pulse's azimuth, the clutter cells of spoke `spoke`,
    /// the pulse's own speckle and noise streams, blanking, matched filter.
    pub fn compress_pulse(
        &self,
        clutter: Option<&ClutterMap>,
        groups: &EchoGroups,
        spoke: usize,
        pulse: &Pulse,
        key: FrameKey,
        scratch: &mut SpokeScratch,
    ) {
        let sources = self.spoke_sources(groups, clutter);
        let at = PulseAt {
            pulse,
            spoke,
            index: 0,
            key,
        };
        self.receive_pulse(&sources, &at, scratch);
    }

    /// Raw I/Q of spoke-mode pulse number `pulse` with the beam at `beam_az_rad` (the clutter
    /// of spoke `pulse`), formed explicitly in time (echo record, noise, blanking, then the
    /// matched filter) — the same signals [`Simulation::compress_pulse`] forms in the
    /// frequency domain (the long pulse's channel: in combined pulse mode the bins inside the
    /// join come from the short pulse instead), kept for figures and tests.
    pub fn raw_spoke(
        &self,
        clutter: Option<&ClutterMap>,
        groups: &EchoGroups,
        beam_az_rad: f64,
        key: FrameKey,
        pulse: u64,
    ) -> RawSpoke {
        use crate::signal::Source;
        let record = self.compressor.record_len();
        let mut scratch = self.compressor.scratch();
        let sources = self.spoke_sources(groups, clutter);
        let p = Pulse {
            number: pulse,
            time_s: 0.0,
            azimuth_rad: beam_az_rad,
        };
        let at = PulseAt {
            pulse: &p,
            spoke: pulse as usize,
            index: 0,
            key,
        };
        let samples = &mut scratch.buffer[..record];
        sources
            .fixed
            .add_to_pulse(&at, &mut scratch.sources, samples);
        if let Some(c) = &sources.clutter {
            c.add_to_pulse(&at, &mut scratch.sources, samples);
        }
        let mut echo = scratch.buffer.clone();
        self.compressor.synthesize_record(&mut echo, &mut scratch);
        echo[record..].fill(Complex32::new(0.0, 0.0));
        let mut received = echo.clone();
        if self.receiver.noise() {
            self.receiver.thermal_noise().add_to_pulse(
                &at,
                &mut scratch.sources,
                &mut received[..record],
            );
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

    /// Ground truth of a trace of the scene as written ([`Simulation::trace`]) in the
    /// revolution that starts at t = 0 (exact for a still scene; a moving scene's truth comes
    /// with its frame). PPI pixel boxes are the PPI product's:
    /// [`crate::products::ppi::PpiGeometry::label`].
    pub fn truth(&self, set: &ScatterSet) -> Vec<ObjectTruth> {
        object_truth(&Revolution::of(&self.scene, 0.0), set, self.bvh())
    }

    /// Whether this scene can give `outputs`: a Doppler cube and radial velocities need
    /// `[processing] mode = "pulse"`; raw I/Q of the scene's own scan must stay under
    /// [`MAX_IQ_BYTES`] per revolution.
    pub fn check_outputs(&self, outputs: Outputs) -> Result<()> {
        self.check_output_modes(outputs)?;
        if outputs.iq {
            let schedule =
                Schedule::for_mode(self.scene.radar(), self.scene.processing().mode(), 0);
            iq::IqCapture::rows(&schedule, self.compressor.record_len())?;
        }
        Ok(())
    }

    /// The products that need pulse mode.
    fn check_output_modes(&self, outputs: Outputs) -> Result<()> {
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
            let (world, _) = self.world.traced(start_time_s, lead_s);
            let revolution = Revolution::with_lead(&self.scene, start_time_s, lead_s);
            let tilts: Vec<f64> = if revolution.deck_moves() {
                revolution
                    .objects()
                    .iter()
                    .map(|o| o.beam_tilt_rad)
                    .collect()
            } else {
                Vec::new()
            };
            let artefacts = self.scene.artefacts();
            let groups = if artefacts.has_paths_via_own_ship() {
                let heading_rad = revolution.own_ship().map_or(0.0, |s| s.heading_rad);
                let abeam = artefacts
                    .multiple_echoes
                    .as_ref()
                    .map_or_else(Vec::new, |m| {
                        via_own_ship::abeam_objects(revolution.scene(), heading_rad, m)
                    });
                let view = via_own_ship::OwnShipView {
                    heading_rad,
                    artefacts,
                    abeam: &abeam,
                    wavelength_m: self.scene.radar().wavelength_m(),
                    two_way_attenuation_db_per_km: self
                        .scene
                        .environment()
                        .two_way_attenuation_db_per_km(),
                };
                // Copies that land beyond the record are not drawn (nor folded into the next
                // pulse's record: their labels would have no object to come from).
                let record_s =
                    self.compressor.record_len() as f64 / self.scene.radar().sample_rate_hz();
                let mut all = world.set.contributions.clone();
                all.extend(
                    via_own_ship::paths_via_own_ship(&world.set.contributions, &view)
                        .into_iter()
                        .filter(|c| c.delay_s() < record_s),
                );
                self.echo_groups_of(&all, &tilts)
            } else if tilts.is_empty() {
                self.echo_groups_keeping(&world.set)
            } else {
                self.echo_groups_of(&world.set.contributions, &tilts)
            };
            Traced {
                revolution,
                bvh: Arc::clone(&world.bvh),
                set: Arc::clone(&world.set),
                groups,
            }
        })
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
        key: FrameKey,
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
        let clutter = self.revolution_clutter(revolution, key);
        let land = clutter.as_ref().and_then(|map| {
            crate::products::land::LandTruth::of(
                map,
                revolution.scene().environment().land(),
                self.compressor.num_bins(),
            )
        });
        let mode = self.scene.processing().mode();
        let (movers, speckle) = match mode {
            ProcessingMode::Spoke => (Vec::new(), ClutterSpeckle::PerPulse),
            ProcessingMode::Pulse => (
                Mover::of_revolution(revolution),
                SeaAndRainClutter::doppler_speckle(
                    self.scene.radar(),
                    *self.scene.environment().clutter_doppler(),
                    revolution
                        .own_ship()
                        .map_or(glam::DVec3::ZERO, |s| s.velocity_mps),
                ),
            ),
        };
        let fs = revolution.scene().radar().sample_rate_hz();
        let spectra: Vec<DopplerSpectra> = movers
            .iter()
            .map(|m| self.compressor.doppler_spectra(m.doppler_hz, fs))
            .collect();
        let placement = revolution::Placement {
            antenna_m: revolution.scene().radar().position_m(),
            heading_rad: revolution.own_ship().map_or(0.0, |s| s.heading_rad),
        };
        let sources = self.sources(
            &traced.groups,
            clutter.as_ref(),
            speckle,
            &movers,
            &spectra,
            placement,
        );
        let skip = match mode {
            ProcessingMode::Spoke => self.spokes_rendered.as_deref(),
            // Pulse mode renders every spoke.
            ProcessingMode::Pulse => None,
        };
        let products =
            self.run_products(&sources, schedule, key, mode, outputs, iq, skip, dwell_done);
        let synthesis_s = t1.elapsed().as_secs_f64();
        let truth = object_truth(revolution, &traced.set, &traced.bvh);
        let radar = self.scene.radar();
        let blind = crate::model::artefacts::BlindView {
            sectors: &self.scene.artefacts().blind_sectors,
            heading_rad: revolution.own_ship().map_or(0.0, |s| s.heading_rad),
        };
        let mut artefacts = sidelobe_artefacts(
            &truth,
            &radar.antenna().azimuth(),
            &blind,
            radar.spokes(),
            radar.range_bin_m(),
            self.compressor.num_bins(),
        );
        // Echoes an artefact shows away from their objects (products::artefacts::echo_image).
        let mut images: Vec<ObjectTruth> = Vec::new();
        let interferers = &self.scene.artefacts().interferers;
        // (The target-only render has no other transmitters, and labels none.)
        if !interferers.is_empty() && self.artefact_sources {
            let names: Vec<String> = interferers.iter().map(|i| i.name.clone()).collect();
            artefacts.extend(interference_artefacts(
                &sources.interference,
                &names,
                schedule,
                self.compressor.record_len(),
                radar.range_bin_m(),
                self.compressor.num_bins(),
            ));
        }
        // What an echo shown at another range loses there: the eclipse at that range, the
        // atmosphere over its extra two-way path, and in combined pulse mode the difference
        // of the two ranges' channels' noise.
        let attenuation_db_per_km = self.scene.environment().two_way_attenuation_db_per_km();
        let channel_noise_db = |range_m: f64| match radar.short_pulse_noise_db() {
            Some(noise_db) => {
                let delay_samples = 2.0 * range_m / crate::constants::SPEED_OF_LIGHT_M_PER_S
                    * radar.sample_rate_hz();
                if (delay_samples.round() as usize) < radar.join_bin() {
                    noise_db
                } else {
                    0.0
                }
            }
            None => 0.0,
        };
        let shown_loss_db = |object_m: f64, shown_m: f64, extra_path_m: f64| {
            eclipse_loss_db_at(radar, shown_m).map(|e| {
                e + attenuation_db_per_km * extra_path_m / 2000.0 + channel_noise_db(shown_m)
                    - channel_noise_db(object_m)
            })
        };
        if self.scene.artefacts().second_trace {
            let c = crate::constants::SPEED_OF_LIGHT_M_PER_S;
            let folds: Vec<(f64, f64)> = if radar.scan().stagger().is_staggered() {
                via_own_ship::stagger_folds(radar.scan().stagger().intervals_s())
                    .into_iter()
                    .map(|(t, share)| (c * t / 2.0, share))
                    .collect()
            } else {
                vec![(c / (2.0 * radar.prf_hz()), 1.0)]
            };
            artefacts.extend(second_trace_artefacts(
                &truth,
                &mut images,
                &shown_loss_db,
                &folds,
                radar.max_range_m(),
                radar.spokes(),
                radar.range_bin_m(),
                self.compressor.num_bins(),
            ));
        }
        let heading_rad = revolution.own_ship().map_or(0.0, |s| s.heading_rad);
        // Indirect echoes come from the structure, not through a blind sector: their sidelobe
        // labels take no blind loss.
        let mut indirect_images: Vec<ObjectTruth> = Vec::new();
        artefacts.extend(indirect_echo_artefacts(
            &truth,
            &mut indirect_images,
            &shown_loss_db,
            &self.scene.artefacts().blind_sectors,
            heading_rad,
            radar.antenna().az_beamwidth_rad,
            radar.spokes(),
            radar.range_bin_m(),
            self.compressor.num_bins(),
        ));
        if let Some(multiple) = &self.scene.artefacts().multiple_echoes {
            let abeam = via_own_ship::abeam_objects(revolution.scene(), heading_rad, multiple);
            artefacts.extend(multiple_echo_artefacts(
                &truth,
                &mut images,
                &shown_loss_db,
                &abeam,
                multiple,
                radar.spokes(),
                radar.range_bin_m(),
                self.compressor.num_bins(),
            ));
        }
        // The echoes shown away from their objects reach other spokes through the sidelobes too.
        let no_blind = crate::model::artefacts::BlindView {
            sectors: &[],
            heading_rad,
        };
        for (images, blind) in [(&images, &blind), (&indirect_images, &no_blind)] {
            artefacts.extend(sidelobe_artefacts(
                images,
                &radar.antenna().azimuth(),
                blind,
                radar.spokes(),
                radar.range_bin_m(),
                self.compressor.num_bins(),
            ));
        }
        artefacts.extend(blind_sector_artefacts(
            &self.scene.artefacts().blind_sectors,
            revolution.own_ship().map_or(0.0, |s| s.heading_rad),
            radar.spokes(),
            radar.range_bin_m(),
            self.compressor.num_bins(),
        ));
        let beacons = &self.scene.artefacts().beacons;
        if !beacons.is_empty() && self.artefact_sources {
            artefacts.extend(beacon_artefacts(
                &sources.beacons,
                beacons,
                schedule,
                self.compressor.record_len(),
                radar.range_bin_m(),
                self.compressor.num_bins(),
            ));
        }
        Frame {
            frame: schedule.frame(),
            start_time_s: revolution.start_time_s(),
            own_ship: revolution.own_ship().copied(),
            spokes: radar.spokes(),
            range_bins: self.compressor.num_bins(),
            range_bin_m: radar.range_bin_m(),
            polar_db: products.0,
            doppler_cube: products.1,
            iq: None,
            video: None,
            artefacts,
            radial_velocity: products.2,
            truth,
            land,
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
