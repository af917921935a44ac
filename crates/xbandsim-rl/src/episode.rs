//! An episode: the MDP of docs/rl.md. State: the scene (targets moving, the sea's texture
//! drifting) and the display; action: [`Action`]; transition: one antenna revolution of
//! scene time (2.5 s at 24 rpm) simulated by the library with the action's pulse and
//! schedule, then the display chain and the plot extractor ([`crate::display`]), whose plots
//! the baseline ARPA tracker (`xbandsim_track`) tracks; reward: plots, or on request the
//! tracker's confirmed tracks, scored against the ground truth ([`Episode::step`]).

use crate::action::{Action, Scan, FTC_TIME_CONSTANT_US, PULSES_PER_SPOKE, QUADRANTS, STC_LAW};
use crate::curriculum::{draw_scene, EpisodeScene, Task, LEVELS, MAX_RANGE_M};
use crate::display::{
    extract_plots, gate_distance, gray_level, stc_db, Plot, PlotScratch, DETECTION_MARGIN_DB,
    LOG_DYNAMIC_RANGE_DB,
};
use std::path::Path;
use xbandsim::constants::SPEED_OF_LIGHT_M_PER_S;
use xbandsim::engine::Request;
use xbandsim::engine::{Dwell, Pulse, Schedule};
use xbandsim::processing::plots::SidelobeEditor;
use xbandsim::products::ppi::{colour, Colormap, ScanConverter};
use xbandsim::receiver::stages::Ftc;
use xbandsim::receiver::video_chain::sweep_log_video;
use xbandsim::{Error, LoadedSpec, Problem, Result, Simulation};
use xbandsim_track::{Scan as TrackerScan, TrackReport, Tracker, TrackerSettings};

/// Reward per target found for the first time (Detection).
pub const REWARD_NEW_DETECTION: f64 = 1.0;
/// Reward per revolution spent (Detection): finding them sooner pays.
pub const REWARD_PER_REVOLUTION: f64 = -0.1;
/// Reward per false plot (both tasks), every one counted: with no cap, turning the gain up
/// until clutter plots fall in every target's gate by chance never pays.
pub const REWARD_PER_FALSE_PLOT: f64 = -0.01;
/// Tracking: share of a target detected this revolution (divided by the targets in range).
pub const REWARD_DETECTED: f64 = 1.0;
/// Tracking: extra share when it was also detected the revolution before (continuity).
pub const REWARD_CONTINUITY: f64 = 0.5;
/// Tracking with [`Reward::Tracks`]: share of a target held by a confirmed track (divided by
/// the targets observed this step).
pub const REWARD_TRACKED: f64 = 1.0;
/// Tracking with [`Reward::Tracks`]: per confirmed track on no target.
pub const REWARD_PER_FALSE_TRACK: f64 = -0.1;
/// Sidelobe editing's margin for the tracker's plots, dB (as `xbandsim track`'s default).
pub const SIDELOBE_MARGIN_DB: f64 = 6.0;
/// A confirmed track and a target are paired within this distance, m (nearest first).
pub const TRACK_TRUTH_GATE_M: f64 = 100.0;

/// What the Tracking task pays for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reward {
    /// Plots in the targets' gates, with continuity (the default).
    #[default]
    Plots,
    /// The baseline tracker's confirmed tracks: held targets, less false tracks.
    Tracks,
}
/// How an environment is made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpisodeConfig {
    /// The task.
    pub task: Task,
    /// Curriculum level, 0..4.
    pub level: usize,
    /// Side of the observation image, pixels (16 … 2048).
    pub image_size_px: u32,
    /// Revolutions before truncation (0: the task's default).
    pub max_steps: usize,
    /// Worker threads of the episode's own pool (1: one core, as the benchmark measures).
    pub threads: usize,
    /// Sea clutter on (the default); off leaves noise, rain and the targets.
    pub sea_clutter: bool,
    /// What the Tracking task pays for (the Detection task pays for plots).
    pub reward: Reward,
}

impl EpisodeConfig {
    /// A configuration with defaults: 256 pixels, the task's episode length, one thread.
    pub fn new(task: Task, level: usize) -> EpisodeConfig {
        EpisodeConfig {
            task,
            level,
            image_size_px: 256,
            max_steps: 0,
            threads: 1,
            sea_clutter: true,
            reward: Reward::Plots,
        }
    }

    fn check(&self) -> Result<()> {
        if self.level >= LEVELS {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "level",
                self.level,
                format!("must be 0 … {} (the curriculum levels)", LEVELS - 1),
            ));
        }
        if !(16..=2048).contains(&self.image_size_px) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "image_size_px",
                self.image_size_px,
                "must be 16 … 2048",
            ));
        }
        if self.reward == Reward::Tracks && self.task != Task::Tracking {
            return Err(Error::invalid(
                Problem::Conflict,
                "reward",
                "tracks",
                "the track reward is the tracking task's",
            ));
        }
        if !(1..=256).contains(&self.threads) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "threads",
                self.threads,
                "must be 1 … 256",
            ));
        }
        Ok(())
    }
}

/// A target's state after a step.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetReport {
    /// Its name in the scene (`target-i`).
    pub name: String,
    /// Its class (`buoy`, `boat`, `ship`).
    pub class: String,
    /// Range when the beam crossed it, m.
    pub range_m: f64,
    /// Azimuth when the beam crossed it, degrees from north.
    pub azimuth_deg: f64,
    /// Its RCS, m².
    pub rcs_m2: Option<f64>,
    /// The library's single-pulse SNR of its echo, dB (None without an echo).
    pub expected_snr_db: Option<f64>,
    /// The library's visibility (`visible`, `eclipsed`, `below_noise`, ...).
    pub visibility: String,
    /// Inside the instrumented range and in the spokes the step refreshed.
    pub observed: bool,
    /// A plot fell in its gate this step.
    pub detected: bool,
    /// Detected in at least 2 of the last 3 revolutions (Tracking's "in track").
    pub in_track: bool,
    /// Where it was when the beam crossed it, ENU m (the tracks' frame).
    pub position_m: [f64; 2],
    /// The baseline tracker's confirmed track paired with it (within
    /// [`TRACK_TRUTH_GATE_M`], nearest pairs first), if any.
    pub track_id: Option<u32>,
}

/// What a step returns.
#[derive(Debug, Clone)]
pub struct StepOutcome {
    /// Reward of the step.
    pub reward: f64,
    /// Detection: every target found. Tracking: never (episodes end by truncation).
    pub terminated: bool,
    /// The episode reached its length.
    pub truncated: bool,
    /// Plots the extractor made in the refreshed spokes.
    pub plots: Vec<Plot>,
    /// Plots in no target's gate.
    pub false_plots: usize,
    /// Targets, in scene order.
    pub targets: Vec<TargetReport>,
    /// Pulses the step transmitted.
    pub pulses: usize,
    /// The baseline tracker's confirmed tracks after this revolution.
    pub tracks: Vec<TrackReport>,
    /// Confirmed tracks paired with no target.
    pub false_tracks: usize,
}

/// One environment: an episode's scene, its simulations (one per pulse choice, made on first
/// use), the display and the scoring state.
pub struct Episode {
    config: EpisodeConfig,
    /// The episode's own workers: everything it runs runs there, never on rayon's global pool
    /// (which a forked vector-environment worker inherits without its threads).
    pool: std::sync::Arc<rayon::ThreadPool>,
    seed: u64,
    scene: EpisodeScene,
    sims: [Option<Simulation>; 4],
    converter: Option<ScanConverter>,
    spokes: usize,
    bins: usize,
    range_bin_m: f64,
    step: usize,
    /// Processed values (dB) the display shows, spokes × bins.
    display_db: Vec<f32>,
    refreshed: Vec<bool>,
    floor_db: f32,
    /// The STC's attenuation per bin for this step's sea clutter level, dB.
    stc_db: Vec<f32>,
    row: Vec<f32>,
    ppi_db: Vec<f32>,
    plot_scratch: PlotScratch,
    /// Per target: found in this episode; detection history (newest last, 3 kept).
    found: Vec<bool>,
    history: Vec<[bool; 3]>,
    /// The baseline tracker, fed each revolution's plots.
    tracker: Tracker,
    /// The sidelobe editing of the tracker's plots (the episode's antenna; made at reset).
    sidelobes: Option<SidelobeEditor>,
}

impl Episode {
    /// A new environment; [`Episode::reset`] starts its first episode.
    pub fn new(config: EpisodeConfig) -> Result<Episode> {
        config.check()?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(config.threads)
            .build()
            .map_err(|e| {
                Error::invalid(Problem::Unusable, "threads", config.threads, e.to_string())
            })
            .map(std::sync::Arc::new)?;
        let scene = draw_scene(config.task, config.level, 0, config.image_size_px);
        Ok(Episode {
            config,
            pool,
            seed: 0,
            scene,
            sims: [None, None, None, None],
            converter: None,
            spokes: 0,
            bins: 0,
            range_bin_m: 0.0,
            step: 0,
            display_db: Vec::new(),
            refreshed: Vec::new(),
            floor_db: Action::default().floor_db(),
            stc_db: Vec::new(),
            row: Vec::new(),
            ppi_db: Vec::new(),
            plot_scratch: PlotScratch::default(),
            found: Vec::new(),
            history: Vec::new(),
            tracker: Tracker::new(TrackerSettings::default())?,
            sidelobes: None,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &EpisodeConfig {
        &self.config
    }

    /// Revolutions before truncation.
    pub fn max_steps(&self) -> usize {
        if self.config.max_steps == 0 {
            self.config.task.max_steps()
        } else {
            self.config.max_steps
        }
    }

    /// The episode's scene (its text re-renders with `xbandsim render`).
    pub fn scene(&self) -> &EpisodeScene {
        &self.scene
    }

    /// Revolutions done in this episode.
    pub fn steps_done(&self) -> usize {
        self.step
    }

    /// Starts an episode from `seed`: a new scene from the curriculum, a blank display, then
    /// one full revolution with [`Action::default`] so that the first observation shows
    /// something. Returns that revolution's outcome (its reward is not part of the episode).
    pub fn reset(&mut self, seed: u64) -> Result<StepOutcome> {
        let pool = std::sync::Arc::clone(&self.pool);
        pool.install(|| self.reset_here(seed))
    }

    fn reset_here(&mut self, seed: u64) -> Result<StepOutcome> {
        self.seed = seed;
        self.scene = draw_scene(
            self.config.task,
            self.config.level,
            seed,
            self.config.image_size_px,
        );
        self.sims = [None, None, None, None];
        self.step = 0;
        self.found = vec![false; self.scene.targets];
        self.history = vec![[false; 3]; self.scene.targets];
        self.tracker = Tracker::new(TrackerSettings::default())?;
        let sim = self.simulation(Action::default().pulse)?;
        let radar = sim.scene().radar();
        let (spokes, bins, bin_m) = (radar.spokes(), radar.num_range_bins(), radar.range_bin_m());
        // Every pulse choice shares the antenna: one editor serves the episode.
        let sidelobes = SidelobeEditor::new(&radar.antenna().azimuth(), SIDELOBE_MARGIN_DB)?;
        self.sidelobes = Some(sidelobes);
        if self.converter.is_none() || (spokes, bins) != (self.spokes, self.bins) {
            self.converter = Some(ScanConverter::new(
                self.config.image_size_px,
                MAX_RANGE_M,
                spokes,
                bins,
                bin_m,
            ));
        }
        (self.spokes, self.bins, self.range_bin_m) = (spokes, bins, bin_m);
        self.display_db.clear();
        self.display_db.resize(spokes * bins, f32::NEG_INFINITY);
        self.refreshed.clear();
        self.refreshed.resize(spokes, false);
        self.stc_db.resize(bins, 0.0);
        self.row.resize(bins, 0.0);
        let outcome = self.revolution(&Action::default())?;
        // The warm-up revolution is frame 0; the agent's first step is frame 1.
        self.found.iter_mut().for_each(|f| *f = false);
        self.history.iter_mut().for_each(|h| *h = [false; 3]);
        self.step = 0;
        Ok(outcome)
    }

    /// One revolution with `action`: simulate, process, extract plots, score.
    pub fn step(&mut self, action: &Action) -> Result<StepOutcome> {
        let pool = std::sync::Arc::clone(&self.pool);
        pool.install(|| self.step_here(action))
    }

    fn step_here(&mut self, action: &Action) -> Result<StepOutcome> {
        if self.display_db.is_empty() {
            return Err(Error::invalid(
                Problem::Conflict,
                "step",
                "before reset",
                "call reset(seed) before step",
            ));
        }
        self.step += 1;
        let mut outcome = self.revolution(action)?;
        let n_observed = outcome.targets.iter().filter(|t| t.observed).count();
        let mut reward = REWARD_PER_FALSE_PLOT * outcome.false_plots as f64;
        match self.config.task {
            Task::Detection => {
                reward += REWARD_PER_REVOLUTION;
                for (i, t) in outcome.targets.iter().enumerate() {
                    if t.detected && !self.found[i] {
                        self.found[i] = true;
                        reward += REWARD_NEW_DETECTION;
                    }
                }
                outcome.terminated = !self.found.is_empty() && self.found.iter().all(|&f| f);
            }
            Task::Tracking if self.config.reward == Reward::Tracks => {
                let held = outcome
                    .targets
                    .iter()
                    .filter(|t| t.observed && t.track_id.is_some())
                    .count();
                reward = REWARD_PER_FALSE_TRACK * outcome.false_tracks as f64;
                if n_observed > 0 {
                    reward += REWARD_TRACKED * held as f64 / n_observed as f64;
                }
            }
            Task::Tracking => {
                for (i, t) in outcome.targets.iter().enumerate() {
                    if t.detected && n_observed > 0 {
                        let previous = self.history[i][2];
                        reward += (REWARD_DETECTED
                            + if previous { REWARD_CONTINUITY } else { 0.0 })
                            / n_observed as f64;
                    }
                }
            }
        }
        for (i, t) in outcome.targets.iter_mut().enumerate() {
            let h = &mut self.history[i];
            *h = [h[1], h[2], t.detected];
            t.in_track = h.iter().filter(|&&d| d).count() >= 2;
        }
        outcome.reward = reward;
        outcome.truncated = !outcome.terminated && self.step >= self.max_steps();
        Ok(outcome)
    }

    /// The simulation of a pulse choice (made on first use in the episode, sharing the
    /// episode's traced world).
    fn simulation(&mut self, pulse: crate::action::PulseChoice) -> Result<&Simulation> {
        let i = crate::action::PulseChoice::ALL
            .iter()
            .position(|&p| p == pulse)
            .unwrap_or(0);
        if self.sims[i].is_none() {
            let mut settings = pulse.settings();
            if !self.config.sea_clutter {
                settings.push("environment.clutter=false".into());
            }
            let spec = LoadedSpec::from_toml(&self.scene.toml, "episode scene", Path::new("."))?
                .with_overrides(&settings)?;
            let scene = spec.build()?;
            // Every pulse choice sees the same world: the first simulation made traces it,
            // the others share its traces and rebuild only their receive chain (when the
            // world serves them: the curriculum's targets are points, so it does).
            self.sims[i] = Some(match self.sims.iter().flatten().next() {
                Some(traced) if traced.world().serves(&scene) => traced.with_scene(scene)?,
                _ => Simulation::new(scene),
            });
        }
        Ok(self.sims[i].as_ref().expect("made above"))
    }

    /// The schedule of a step: revolution `frame`; a full scan gives every spoke `n` pulses,
    /// a quadrant dwell gives its spokes `QUADRANTS·n` (the antenna sweeps it `QUADRANTS`
    /// times) and the others one pulse each, rendered but not shown (the engine fills every
    /// spoke of a record).
    fn schedule(&self, sim: &Simulation, action: &Action, frame: u64) -> Result<Schedule> {
        let radar = sim.scene().radar();
        let period_s = radar.scan().period_s();
        let pri_s = 1.0 / radar.prf_hz();
        let n = PULSES_PER_SPOKE[action.integration];
        let spokes = self.spokes;
        let dwells = (0..spokes)
            .map(|k| {
                let pulses = match action.scan {
                    Scan::Full => n,
                    Scan::Quadrant(q) if quadrant_of(k, spokes) == q => QUADRANTS * n,
                    Scan::Quadrant(_) => 1,
                };
                let az = std::f64::consts::TAU * k as f64 / spokes as f64;
                Dwell {
                    spoke: k,
                    pulses: (0..pulses)
                        .map(|m| Pulse {
                            number: (k * 64 + m) as u64,
                            time_s: (frame as f64 + k as f64 / spokes as f64) * period_s
                                + m as f64 * pri_s,
                            azimuth_rad: az,
                        })
                        .collect(),
                }
            })
            .collect();
        Schedule::new(radar, frame, frame as f64 * period_s, dwells)
    }

    fn revolution(&mut self, action: &Action) -> Result<StepOutcome> {
        let frame = self.step as u64;
        let seed = self.seed;
        self.simulation(action.pulse)?;
        let i = crate::action::PulseChoice::ALL
            .iter()
            .position(|&p| p == action.pulse)
            .unwrap_or(0);
        let sim = self.sims[i].as_ref().expect("made above");
        let radar = sim.scene().radar();
        if (radar.spokes(), radar.num_range_bins()) != (self.spokes, self.bins) {
            return Err(Error::invalid(
                Problem::Conflict,
                "action.pulse",
                action.pulse.name(),
                "this pulse changes the record's shape",
            ));
        }
        let schedule = self.schedule(sim, action, frame)?;
        let pulses = schedule.num_pulses();
        let frame_out = sim.run(&Request::new(seed).schedule(&schedule))?;
        // The display: refreshed spokes through the operator's controls. With the combined
        // pulse each channel is shown over its own noise, as a radar's per-channel gain does:
        // the short pulse's bins (under the join) sit `short_pulse_noise_db` over the long
        // pulse's noise in the record (docs/physics.md §11).
        let (spokes, bins) = (self.spokes, self.bins);
        let short_noise_db = radar.short_pulse_noise_db().unwrap_or(0.0) as f32;
        let join = radar.join_bin().min(bins);
        let law = STC_LAW[action.sea];
        for (j, a) in self.stc_db.iter_mut().enumerate() {
            *a = stc_db(j as f64 * self.range_bin_m, law);
        }
        let sample_s = 2.0 * self.range_bin_m / SPEED_OF_LIGHT_M_PER_S;
        let ftc = FTC_TIME_CONSTANT_US[action.rain].map(|tau_us| Ftc::new(tau_us * 1e-6, sample_s));
        for k in 0..spokes {
            self.refreshed[k] = match action.scan {
                Scan::Full => true,
                Scan::Quadrant(q) => quadrant_of(k, spokes) == q,
            };
            if self.refreshed[k] {
                self.row
                    .copy_from_slice(&frame_out.polar_db[k * bins..(k + 1) * bins]);
                if short_noise_db != 0.0 {
                    self.row[..join]
                        .iter_mut()
                        .for_each(|v| *v -= short_noise_db);
                }
                // STC, the log amplifier and the FTC.
                let out = &mut self.display_db[k * bins..(k + 1) * bins];
                out.copy_from_slice(&self.row);
                sweep_log_video(out, &self.stc_db, LOG_DYNAMIC_RANGE_DB, ftc);
            }
        }
        self.floor_db = action.floor_db();
        let mut plots = Vec::new();
        extract_plots(
            &self.display_db,
            spokes,
            bins,
            self.range_bin_m,
            &self.refreshed,
            self.floor_db + DETECTION_MARGIN_DB,
            &mut self.plot_scratch,
            &mut plots,
        );
        // Score: each plot to the nearest gate it falls in.
        let mut targets: Vec<TargetReport> = frame_out
            .truth
            .iter()
            .map(|o| {
                let spoke = ((o.azimuth_deg / 360.0 * spokes as f64).round() as usize) % spokes;
                TargetReport {
                    name: o.name.clone(),
                    class: o.class.clone(),
                    range_m: o.range_m,
                    azimuth_deg: o.azimuth_deg,
                    rcs_m2: o.rcs_m2,
                    expected_snr_db: o.expected_snr_db,
                    visibility: visibility_name(o.visibility),
                    observed: o.range_m <= MAX_RANGE_M && self.refreshed[spoke],
                    detected: false,
                    in_track: false,
                    position_m: [o.position_m[0], o.position_m[1]],
                    track_id: None,
                }
            })
            .collect();
        let mut false_plots = 0;
        for p in &plots {
            let best = targets
                .iter()
                .enumerate()
                .filter(|(_, t)| t.observed)
                .filter_map(|(i, t)| {
                    gate_distance(p.range_m, p.azimuth_deg, t.range_m, t.azimuth_deg)
                        .map(|d| (i, d))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match best {
                Some((i, _)) => targets[i].detected = true,
                None => false_plots += 1,
            }
        }
        // The baseline tracker on this revolution's plots (a quadrant dwell's other spokes
        // gave none: their tracks coast), its confirmed tracks paired with the targets.
        let (antenna, velocity) = match frame_out.own_ship {
            Some(s) => (s.antenna_position_m, [s.velocity_mps.x, s.velocity_mps.y]),
            None => (radar.position_m(), [0.0, 0.0]),
        };
        // The tracker is fed the plots with the antenna's sidelobe echoes edited out, as the
        // `xbandsim track` extractor does (xbandsim::processing::plots::SidelobeEditor).
        let mut edited = plots.clone();
        if let Some(editor) = &self.sidelobes {
            editor.edit(&mut edited);
        }
        let report = self.tracker.step(&TrackerScan {
            start_time_s: frame_out.start_time_s,
            period_s: radar.scan().period_s(),
            antenna_position_m: [antenna.x, antenna.y, antenna.z],
            antenna_velocity_mps: velocity,
            plots: &edited,
        });
        let tracks: Vec<TrackReport> = report.confirmed().cloned().collect();
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (ti, t) in tracks.iter().enumerate() {
            for (oi, o) in targets.iter().enumerate() {
                let d =
                    (t.position_m[0] - o.position_m[0]).hypot(t.position_m[1] - o.position_m[1]);
                if d <= TRACK_TRUTH_GATE_M {
                    pairs.push((d, ti, oi));
                }
            }
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut paired = vec![false; tracks.len()];
        for (_, ti, oi) in pairs {
            if !paired[ti] && targets[oi].track_id.is_none() {
                paired[ti] = true;
                targets[oi].track_id = Some(tracks[ti].id);
            }
        }
        let false_tracks = paired.iter().filter(|p| !**p).count();
        Ok(StepOutcome {
            reward: 0.0,
            terminated: false,
            truncated: false,
            plots,
            false_plots,
            targets,
            pulses,
            tracks,
            false_tracks,
        })
    }

    /// The observation: the display as a gray image (side `image_size_px`, row-major, north
    /// up, the radar at the centre); 0 at or under the gain's floor, 255 at 30 dB over it.
    pub fn observation(&mut self) -> Vec<u8> {
        self.display_image();
        let floor = self.floor_db;
        self.ppi_db.iter().map(|&v| gray_level(v, floor)).collect()
    }

    /// The display in colour (a phosphor-green map of the same gray levels), size² × 3 bytes.
    pub fn render_rgb(&mut self) -> Vec<u8> {
        self.display_image();
        let floor = self.floor_db;
        let mut rgb = Vec::with_capacity(self.ppi_db.len() * 3);
        for &v in &self.ppi_db {
            let t = f32::from(gray_level(v, floor)) / 255.0;
            rgb.extend_from_slice(&colour(Colormap::Green, t));
        }
        rgb
    }

    fn display_image(&mut self) {
        let size = self.config.image_size_px as usize;
        self.ppi_db.resize(size * size, f32::NEG_INFINITY);
        if let Some(c) = &self.converter {
            c.convert(&self.display_db, f32::NEG_INFINITY, &mut self.ppi_db);
        }
    }
}

/// Quadrant (0 = north-east … 3 = north-west) of spoke `k` of `spokes`.
pub fn quadrant_of(k: usize, spokes: usize) -> usize {
    (k * QUADRANTS / spokes).min(QUADRANTS - 1)
}

fn visibility_name(v: xbandsim::Visibility) -> String {
    let debug = format!("{v:?}");
    let mut s = String::new();
    for (i, c) in debug.chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 {
                s.push('_');
            }
            s.push(c.to_ascii_lowercase());
        } else {
            s.push(c);
        }
    }
    s
}
