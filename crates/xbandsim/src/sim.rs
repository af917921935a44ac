//! Stage: orchestration. `Simulation` = Scene + its BVH + FFT plans; `render` traces the scene
//! once, groups the contributions, and for every spoke weights them by the antenna pattern,
//! adds noise, blanks and compresses (docs/physics.md, "Pipeline"). Nothing else lives here.

use crate::echo::{EchoGroups, FractionalDelayKernel};
use crate::environment::clutter_map::ClutterMap;
use crate::geometry::Bvh;
use crate::labels::{object_truth, ObjectTruth};
use crate::model::Scene;
use crate::processing::PulseCompressor;
use crate::receiver::Receiver;
use crate::scattering::{build_scene_bvh, trace_scene, ScatterSet};
use num_complex::Complex32;
use rayon::prelude::*;
use std::time::Instant;

/// Groups weaker than this after the azimuth weight (noise-rms units, −80 dB) are skipped.
pub const MIN_GROUP_AMPLITUDE: f32 = 1e-4;

/// Smallest power written to the polar output, dB over noise (for noise-free runs).
pub const POLAR_FLOOR_DB: f32 = -120.0;

/// A scene ready to render.
pub struct Simulation {
    scene: Scene,
    bvh: Bvh,
    compressor: PulseCompressor,
    receiver: Receiver,
    kernel: FractionalDelayKernel,
}

/// Timings and counts of one frame.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FrameStats {
    /// Rays cast by the scattering model.
    pub rays_cast: u64,
    /// Scattering contributions.
    pub contributions: usize,
    /// Echo groups after binning.
    pub echo_groups: usize,
    /// Seconds spent tracing.
    pub trace_s: f64,
    /// Seconds spent on echoes, noise and matched filtering.
    pub synthesis_s: f64,
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

/// One rendered revolution.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Spokes (rows of `polar_db`).
    pub spokes: usize,
    /// Range bins (columns).
    pub range_bins: usize,
    /// Range of bin j is `j·range_bin_m`.
    pub range_bin_m: f64,
    /// Matched-filter output power over mean noise power, dB, spokes × bins row-major.
    pub polar_db: Vec<f32>,
    /// Per-object ground truth.
    pub truth: Vec<ObjectTruth>,
    /// Counts and timings.
    pub stats: FrameStats,
}

impl Simulation {
    /// Builds the BVH and the FFT plans.
    pub fn new(scene: Scene) -> Simulation {
        let bvh = build_scene_bvh(&scene);
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
        Simulation {
            scene,
            bvh,
            compressor,
            receiver,
            kernel: FractionalDelayKernel::new(),
        }
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The scene's BVH.
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// The receiver (noise, blanking).
    pub fn receiver(&self) -> &Receiver {
        &self.receiver
    }

    /// The pulse compressor.
    pub fn compressor(&self) -> &PulseCompressor {
        &self.compressor
    }

    /// Traces the scene once.
    pub fn trace(&self) -> ScatterSet {
        trace_scene(&self.scene, &self.bvh)
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

    /// Adds one pulse's band-limited impulse response (targets weighted by the azimuth pattern
    /// for a beam at `beam_az_rad`, plus clutter) into `impulse_response` (noise-rms units);
    /// returns the earliest target sample written.
    fn impulse_response(
        &self,
        clutter: Option<&ClutterMap>,
        groups: &EchoGroups,
        beam_az_rad: f64,
        seed: u64,
        frame: u64,
        spoke: u64,
        impulse_response: &mut [Complex32],
    ) -> Option<usize> {
        let earliest = groups.accumulate(
            self.scene.radar().antenna(),
            beam_az_rad,
            MIN_GROUP_AMPLITUDE,
            impulse_response,
        );
        if let Some(c) = clutter {
            c.add_to_spoke(spoke as usize, seed, frame, impulse_response);
        }
        earliest
    }

    /// Compressed output of one spoke at `beam_az_rad` into `scratch.buffer[..bins]`
    /// (amplitude in noise-rms units).
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
        let record = self.compressor.record_len();
        scratch.buffer.fill(Complex32::new(0.0, 0.0));
        let earliest = self.impulse_response(
            clutter,
            groups,
            beam_az_rad,
            seed,
            frame,
            spoke,
            &mut scratch.buffer[..record],
        );
        let rx = &self.receiver;
        if rx.noise() {
            rx.fill_noise(seed, frame, spoke, &mut scratch.noise[..record]);
            scratch.noise[record..].fill(Complex32::new(0.0, 0.0));
        }
        self.compressor.process(
            scratch,
            rx.noise(),
            rx.blanking(),
            rx.echo_in_blanking(clutter.is_some(), earliest),
        );
    }

    /// Raw I/Q of one pulse at `beam_az_rad`, formed explicitly in time (echo record, noise,
    /// blanking, then the matched filter) — the same signals `compress_spoke` forms in the
    /// frequency domain, kept for figures, raw-IQ users and tests.
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
            beam_az_rad,
            seed,
            frame,
            spoke,
            &mut scratch.buffer[..record],
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
        let radar = self.scene.radar();
        let bins = self.compressor.num_bins();
        let mut polar = vec![0f32; radar.spokes() * bins];
        polar.par_chunks_mut(bins).enumerate().for_each_init(
            || self.compressor.scratch(),
            |scratch, (k, row)| {
                self.compress_spoke(
                    clutter,
                    groups,
                    radar.spoke_azimuth_rad(k),
                    seed,
                    frame,
                    k as u64,
                    scratch,
                );
                for (o, y) in row.iter_mut().zip(&scratch.buffer[..bins]) {
                    *o = (10.0 * y.norm_sqr().log10()).max(POLAR_FLOOR_DB);
                }
                spoke_done();
            },
        );
        polar
    }

    /// Sea and rain clutter of frame `frame` (None when the scene has neither).
    pub fn clutter_map(&self, seed: u64, frame: u64) -> Option<ClutterMap> {
        ClutterMap::new(&self.scene, seed, frame, self.compressor.record_len())
    }

    /// Ground truth for a traced scene state (PPI pixel boxes are the PPI product's:
    /// [`crate::ppi::PpiGeometry::label`]).
    pub fn truth(&self, set: &ScatterSet) -> Vec<ObjectTruth> {
        object_truth(&self.scene, set, &self.bvh)
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
        let t0 = Instant::now();
        let set = self.trace();
        let trace_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let groups = self.echo_groups(&set);
        let clutter = self.clutter_map(seed, frame);
        let polar_db = self.synthesize_progress(&groups, clutter.as_ref(), seed, frame, spoke_done);
        let synthesis_s = t1.elapsed().as_secs_f64();
        let truth = self.truth(&set);
        let radar = self.scene.radar();
        Frame {
            spokes: radar.spokes(),
            range_bins: self.compressor.num_bins(),
            range_bin_m: radar.range_bin_m(),
            polar_db,
            truth,
            stats: FrameStats {
                rays_cast: set.rays_cast,
                contributions: set.contributions.len(),
                echo_groups: groups.groups.len(),
                trace_s,
                synthesis_s,
            },
        }
    }
}
