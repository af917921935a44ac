//! `xbandsim detect`: renders revolutions of a scene and runs the plot extractor on each
//! (`xbandsim::processing::plots`), scoring every plot against the frame's truth.

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;
use xbandsim::engine::{Request, Simulation};
use xbandsim::processing::cfar::{Cfar, CfarKind};
use xbandsim::processing::plots::{
    Plot, PlotExtractor, PlotScratch, PowerGrid, ScanCorrelator, SidelobeEditor,
};
use xbandsim::products::output::write_json;
use xbandsim::products::plot_truth::{plot_sources, PlotSource};
use xbandsim::receiver::video_chain::EchoHistory;

/// Arguments of `xbandsim detect`.
#[derive(Args, Debug, Clone)]
pub struct DetectArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output file: the plots of every revolution, scored against the truth (JSON).
    #[arg(long, default_value = "plots.json")]
    pub out: PathBuf,
    /// Random seed: the same seed gives the same plots.
    #[arg(long, default_value_t = 0, value_parser = crate::whole_number)]
    pub seed: u64,
    /// Revolutions to render and extract, one after another (everything moving).
    #[arg(long, default_value_t = 1, value_parser = crate::whole_number)]
    pub frames: u64,
    #[command(flatten)]
    pub detector: DetectorArgs,
    /// Scan-to-scan correlation M/N: keep a plot only when plots within --scan-gate-m of it
    /// were seen on M of the last N scans, this one included (e.g. 2/3).
    #[arg(long, value_name = "M/N")]
    pub scan: Option<String>,
    /// Gate of the scan-to-scan correlation, m.
    #[arg(long, default_value_t = 100.0)]
    pub scan_gate_m: f64,
    /// Override any scene field: FIELD=VALUE (repeatable), as for render.
    #[arg(long, value_name = "FIELD=VALUE")]
    pub set: Vec<String>,
}

/// The plot extractor's options (shared by `detect` and `track`).
#[derive(Args, Debug, Clone)]
pub struct DetectorArgs {
    /// What the extractor reads: "record" (the calibrated matched-filter power, polar.npy)
    /// or "video" (the receiver's video; needs a [receiver] table).
    #[arg(long, default_value = "record")]
    pub input: String,
    /// CFAR kind: "ca" (cell averaging), "go" (greatest of) or "os" (ordered statistic).
    #[arg(long, default_value = "ca")]
    pub cfar: String,
    /// Guard cells on each side of the cell under test.
    #[arg(long, default_value_t = 4, value_parser = crate::whole_number)]
    pub guard_cells: u64,
    /// Training cells on each side, past the guard cells.
    #[arg(long, default_value_t = 16, value_parser = crate::whole_number)]
    pub training_cells: u64,
    /// The ordered statistic's rank, 1 to 2 x training cells (default: three quarters of
    /// them, rounded up).
    #[arg(long, value_parser = crate::whole_number)]
    pub rank: Option<u64>,
    /// Design false-alarm probability per cell, in exponential noise [default: 1e-6 for
    /// detect, 1e-8 for track].
    #[arg(long)]
    pub pfa: Option<f64>,
    /// Smallest plot kept, cells [default: 1 for detect, 3 for track].
    #[arg(long, value_parser = crate::whole_number)]
    pub min_cells: Option<u64>,
    /// Sidelobe editing: a plot is removed as a stronger plot's echo through the antenna's
    /// sidelobes when it overlaps it in range and its peak is at most this many dB over the
    /// level the pattern gives at their bearing difference; "off" keeps every plot.
    #[arg(long, default_value = "6", value_name = "DB|off")]
    pub sidelobe_margin_db: String,
}

/// The defaults of the options that `detect` and `track` set differently: a tracker fed
/// with a plot per cell of noise would start a track on each, so `track` asks for fewer false
/// plots (docs/tracking.md, "Defaults").
#[derive(Debug, Clone, Copy)]
pub struct DetectorDefaults {
    /// Design false-alarm probability per cell.
    pub pfa: f64,
    /// Smallest plot kept, cells.
    pub min_cells: u64,
}

/// `xbandsim detect`'s defaults.
pub const DETECT_DEFAULTS: DetectorDefaults = DetectorDefaults {
    pfa: 1e-6,
    min_cells: 1,
};

/// `xbandsim track`'s defaults.
pub const TRACK_DEFAULTS: DetectorDefaults = DetectorDefaults {
    pfa: 1e-8,
    min_cells: 3,
};

impl DetectorArgs {
    /// The design false-alarm probability: the option's, or the command's default.
    pub fn pfa(&self, defaults: DetectorDefaults) -> f64 {
        self.pfa.unwrap_or(defaults.pfa)
    }

    /// The smallest plot kept: the option's, or the command's default.
    pub fn min_cells(&self, defaults: DetectorDefaults) -> u64 {
        self.min_cells.unwrap_or(defaults.min_cells)
    }

    /// The extractor these options make (with the command's `defaults`), and whether it reads
    /// the video.
    pub fn extractor(&self, defaults: DetectorDefaults) -> Result<(PlotExtractor, bool)> {
        let use_video = match self.input.as_str() {
            "record" => false,
            "video" => true,
            other => bail!("invalid --input {other:?}: must be \"record\" or \"video\""),
        };
        let training = self.training_cells as usize;
        let kind = cfar_kind(&self.cfar, self.rank, training)?;
        let cfar = Cfar::new(
            kind,
            self.guard_cells as usize,
            training,
            self.pfa(defaults),
        )?;
        self.sidelobe_margin()?;
        Ok((
            PlotExtractor::new(cfar, self.min_cells(defaults) as usize)?,
            use_video,
        ))
    }

    /// The sidelobe editor's margin, dB, or `None` when editing is off.
    pub fn sidelobe_margin(&self) -> Result<Option<f64>> {
        let text = self.sidelobe_margin_db.trim();
        if text == "off" {
            return Ok(None);
        }
        match text.parse::<f64>() {
            Ok(db) if db.is_finite() && db >= 0.0 => Ok(Some(db)),
            _ => bail!(
                "invalid --sidelobe-margin-db {text:?}: must be a number of dB, 0 or more, or \"off\""
            ),
        }
    }

    /// `extractor` with the sidelobe editing of `scene`'s azimuth pattern, when it is on.
    pub fn for_scene(
        &self,
        extractor: PlotExtractor,
        scene: &xbandsim::Scene,
    ) -> Result<PlotExtractor> {
        Ok(match self.sidelobe_margin()? {
            Some(db) => extractor.with_sidelobe_editing(SidelobeEditor::new(
                &scene.radar().antenna().azimuth(),
                db,
            )?),
            None => extractor,
        })
    }

    /// Refuses video input for a scene without a `[receiver]` table.
    pub fn check_scene(&self, scene: &xbandsim::Scene) -> Result<()> {
        if self.input == "video" && scene.receiver().is_none() {
            bail!("--input video reads the receiver's video: the scene needs a [receiver] table (docs/formats.md, \"[receiver]\"), e.g. --set receiver.gain_db=0");
        }
        Ok(())
    }
}

/// The power grid the extractor reads from `frame`: its video or its calibrated record.
pub fn grid_of(frame: &xbandsim::Frame, use_video: bool) -> PowerGrid {
    match (&frame.video, use_video) {
        (Some(video), true) => PowerGrid::from_video(video),
        _ => PowerGrid::from_record_db(
            &frame.polar_db,
            frame.spokes,
            frame.range_bins,
            frame.range_bin_m,
        ),
    }
}

/// The settings, as written into the output.
#[derive(Serialize)]
struct Settings {
    input: String,
    cfar: String,
    guard_cells: usize,
    training_cells: usize,
    rank: Option<usize>,
    pfa: f64,
    threshold_multiplier: f64,
    min_cells: usize,
    sidelobe_margin_db: Option<f64>,
    scan: Option<String>,
    scan_gate_m: Option<f64>,
}

#[derive(Serialize)]
struct PlotOut {
    #[serde(flatten)]
    plot: Plot,
    source: PlotSource,
}

#[derive(Serialize)]
struct ObjectOut {
    id: u32,
    name: String,
    class: String,
    range_m: f64,
    azimuth_deg: f64,
    expected_snr_db: Option<f64>,
    visibility: String,
    /// Whether it leaves an echo in the record (it has a polar box).
    #[serde(skip)]
    has_echo: bool,
    detected: bool,
}

#[derive(Serialize)]
struct FrameOut {
    frame: u64,
    start_time_s: f64,
    cells_tested: usize,
    plots: Vec<PlotOut>,
    false_plots: usize,
    objects: Vec<ObjectOut>,
}

#[derive(Serialize)]
struct Summary {
    frames: u64,
    plots: usize,
    false_plots: usize,
    false_plots_per_cell: f64,
    objects_in_view: usize,
    objects_detected: usize,
    /// The scene's sea state; null with sea clutter off.
    sea_state: Option<f64>,
    per_class: std::collections::BTreeMap<String, DetectionScore>,
    per_range: Vec<RangeScore>,
}

/// Object echoes and those with a plot: the measured probability of detection.
#[derive(Serialize, Default)]
struct DetectionScore {
    in_view: usize,
    detected: usize,
    /// `detected / in_view`; null with none in view.
    pd: Option<f64>,
}

impl DetectionScore {
    fn add(&mut self, detected: bool) {
        self.in_view += 1;
        self.detected += usize::from(detected);
        self.pd = Some(self.detected as f64 / self.in_view as f64);
    }
}

/// The detection score of the objects in a band of range.
#[derive(Serialize)]
struct RangeScore {
    from_m: f64,
    to_m: f64,
    #[serde(flatten)]
    score: DetectionScore,
}

/// Bands of range the summary scores detection in: quarters of the instrumented range.
const RANGE_BANDS: usize = 4;

#[derive(Serialize)]
struct Output {
    scene: String,
    seed: u64,
    settings: Settings,
    summary: Summary,
    frames: Vec<FrameOut>,
}

/// The CFAR kind named on the command line.
fn cfar_kind(name: &str, rank: Option<u64>, training_cells: usize) -> Result<CfarKind> {
    let kind = match name {
        "ca" => CfarKind::CellAveraging,
        "go" => CfarKind::GreatestOf,
        "os" => CfarKind::OrderedStatistic {
            rank: match rank {
                Some(r) => r as usize,
                None => (3 * 2 * training_cells).div_ceil(4),
            },
        },
        other => bail!("invalid --cfar {other:?}: must be \"ca\", \"go\" or \"os\""),
    };
    if rank.is_some() && name != "os" {
        bail!("--rank is the ordered statistic's: use it with --cfar os");
    }
    Ok(kind)
}

/// `M/N` of `--scan`.
fn scan_window(text: &str) -> Result<(usize, usize)> {
    let parsed = text
        .split_once('/')
        .and_then(|(m, n)| Some((m.trim().parse().ok()?, n.trim().parse().ok()?)));
    match parsed {
        Some(mn) => Ok(mn),
        None => bail!("invalid --scan {text:?}: must be M/N, e.g. 2/3"),
    }
}

/// Runs `xbandsim detect`.
pub fn run(a: &DetectArgs) -> Result<()> {
    let t0 = Instant::now();
    if a.frames == 0 {
        bail!("invalid --frames 0: must be 1 or more");
    }
    let d = &a.detector;
    let (extractor, use_video) = d.extractor(DETECT_DEFAULTS)?;
    let mut correlator = match &a.scan {
        Some(text) => {
            let (m, n) = scan_window(text)?;
            Some(ScanCorrelator::new(m, n, a.scan_gate_m)?)
        }
        None => None,
    };
    let spec = crate::render::load_spec(&a.scene, &a.set)?;
    let scene = spec.build()?;
    d.check_scene(&scene)?;
    let extractor = d.for_scene(extractor, &scene)?;
    let sea_state = scene.environment().clutter().map(|c| c.sea_state());
    let max_range_m = scene.radar().max_range_m();
    let sim = Simulation::new(scene);
    let progress = crate::progress::bar(a.frames, "detect: frames");
    let echo_history = std::sync::Mutex::new(EchoHistory::default());
    let mut scratch = PlotScratch::default();
    let mut frames = Vec::new();
    for k in 0..a.frames {
        let frame = sim.run(&Request::new(a.seed).frame(k).echo_history(&echo_history))?;
        let grid = grid_of(&frame, use_video);
        let mut plots = extractor.extract(&grid, &mut scratch);
        if let Some(c) = correlator.as_mut() {
            plots = c.confirm(plots);
        }
        let sources = plot_sources(&plots, &grid, &frame);
        let objects = frame
            .truth
            .iter()
            .map(|o| ObjectOut {
                id: o.id,
                name: o.name.clone(),
                class: o.class.clone(),
                range_m: o.range_m,
                azimuth_deg: o.azimuth_deg,
                expected_snr_db: o.expected_snr_db,
                visibility: serde_json::to_value(o.visibility)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_string))
                    .unwrap_or_default(),
                has_echo: o.visibility.has_echo(),
                detected: sources
                    .iter()
                    .any(|s| matches!(s, PlotSource::Object { id, .. } if *id == o.id)),
            })
            .collect();
        let reach = d.guard_cells as usize + d.training_cells as usize;
        frames.push(FrameOut {
            frame: k,
            start_time_s: frame.start_time_s,
            cells_tested: grid.spokes * grid.cells.saturating_sub(2 * reach),
            false_plots: sources.iter().filter(|s| **s == PlotSource::None).count(),
            plots: plots
                .into_iter()
                .zip(sources)
                .map(|(plot, source)| PlotOut { plot, source })
                .collect(),
            objects,
        });
        progress.inc(1);
    }
    progress.finish_and_clear();
    let cells: usize = frames.iter().map(|f| f.cells_tested).sum();
    let mut per_class: std::collections::BTreeMap<String, DetectionScore> = Default::default();
    let band_m = max_range_m / RANGE_BANDS as f64;
    let mut per_range: Vec<RangeScore> = (0..RANGE_BANDS)
        .map(|b| RangeScore {
            from_m: b as f64 * band_m,
            to_m: (b + 1) as f64 * band_m,
            score: DetectionScore::default(),
        })
        .collect();
    for o in frames
        .iter()
        .flat_map(|f| &f.objects)
        .filter(|o| o.has_echo)
    {
        per_class
            .entry(o.class.clone())
            .or_default()
            .add(o.detected);
        let band = ((o.range_m / band_m) as usize).min(RANGE_BANDS - 1);
        per_range[band].score.add(o.detected);
    }
    let false_plots: usize = frames.iter().map(|f| f.false_plots).sum();
    let in_view = |o: &&ObjectOut| o.has_echo;
    let summary = Summary {
        frames: a.frames,
        plots: frames.iter().map(|f| f.plots.len()).sum(),
        false_plots,
        false_plots_per_cell: false_plots as f64 / cells.max(1) as f64,
        objects_in_view: frames
            .iter()
            .map(|f| f.objects.iter().filter(in_view).count())
            .sum(),
        objects_detected: frames
            .iter()
            .map(|f| f.objects.iter().filter(|o| o.detected).count())
            .sum(),
        sea_state,
        per_class,
        per_range,
    };
    let settings = Settings {
        input: d.input.clone(),
        cfar: d.cfar.clone(),
        guard_cells: d.guard_cells as usize,
        training_cells: d.training_cells as usize,
        rank: match extractor.cfar().kind() {
            CfarKind::OrderedStatistic { rank } => Some(rank),
            _ => None,
        },
        pfa: d.pfa(DETECT_DEFAULTS),
        threshold_multiplier: extractor.cfar().alpha(),
        min_cells: d.min_cells(DETECT_DEFAULTS) as usize,
        sidelobe_margin_db: d.sidelobe_margin()?,
        scan: a.scan.clone(),
        scan_gate_m: a.scan.as_ref().map(|_| a.scan_gate_m),
    };
    crate::say!(
        "detect {}: {} frames, {} plots ({} false: {:.2e} a cell tested), {} of {} object echoes detected, {:.2} s -> {}",
        a.scene.display(),
        a.frames,
        summary.plots,
        summary.false_plots,
        summary.false_plots_per_cell,
        summary.objects_detected,
        summary.objects_in_view,
        t0.elapsed().as_secs_f64(),
        a.out.display()
    );
    let output = Output {
        scene: a.scene.display().to_string(),
        seed: a.seed,
        settings,
        summary,
        frames,
    };
    write_json(&a.out, &output).with_context(|| format!("writing {}", a.out.display()))?;
    Ok(())
}
