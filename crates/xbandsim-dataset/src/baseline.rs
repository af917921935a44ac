//! The classical baseline every dataset carries (docs/tracking.md, "Dataset baseline"): each
//! frame's picture through a CFAR plot extractor (`xbandsim::processing::plots`) and, over a
//! sequence's frames, through the ARPA-class tracker (`xbandsim_track`), scored against the
//! truth: which objects gave a plot, how many plots were false, and the tracks' MOTA, MOTP
//! and HOTA ([`xbandsim_track::score`]). A sample's results are its `baseline.json`; the
//! dataset's are summed in [`BaselineTally`], which `xbandsim dataset stats` and the dataset
//! card report.
//!
//! The settings are `xbandsim track`'s defaults, so that `xbandsim track` on a sample's
//! scene, with the frames and render seed its scene.toml names, gives the same tracks:
//! cell-averaging CFAR with 4 guard and 16 training cells a side at a design false-alarm
//! probability of 10⁻⁸, plots of at least 3 cells, sidelobe editing at 6 dB, the tracker's
//! default settings, tracks scored within 100 m of an object.

use crate::error::{DatasetError, Result};
use serde_json::json;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use xbandsim::processing::plots::{PlotExtractor, PlotScratch, PowerGrid};
use xbandsim::products::plot_truth::{plot_sources, PlotSource};
use xbandsim::Frame;
use xbandsim_track::score::HOTA_ALPHAS;
use xbandsim_track::{Scan, SequenceScorer, Tracker, TrackerSettings, TrackingScore};

pub use xbandsim_track::baseline::{
    GUARD_CELLS, MIN_CELLS, PFA, SIDELOBE_MARGIN_DB, TRAINING_CELLS, TRUTH_GATE_M,
};

/// The baseline's result for one object of a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectBaseline {
    /// Whether a plot of the frame is this object's echo; `None` for an object that leaves
    /// no echo (nothing to detect).
    pub detected: Option<bool>,
    /// The confirmed track scored against this object in this frame (CLEAR MOT's pairing);
    /// `None` when none is, or for single-frame samples (no tracker runs).
    pub track_id: Option<u32>,
}

/// Runs the baseline over one sample's frames, in order.
pub struct SampleBaseline {
    extractor: PlotExtractor,
    scratch: PlotScratch,
    /// The tracker and its scorer, for a sequence.
    tracking: Option<(Tracker, SequenceScorer)>,
    period_s: f64,
    /// The radar's position when there is no own ship, m.
    radar_position_m: [f64; 3],
    frames: Vec<serde_json::Value>,
}

/// The settings written into each `baseline.json`.
pub fn settings_json() -> serde_json::Value {
    let t = TrackerSettings::default();
    json!({
        "cfar": "ca",
        "guard_cells": GUARD_CELLS,
        "training_cells": TRAINING_CELLS,
        "pfa": PFA,
        "min_cells": MIN_CELLS,
        "sidelobe_margin_db": SIDELOBE_MARGIN_DB,
        "initiation": format!("{}/{}", t.initiation_hits, t.initiation_scans),
        "lost_after_misses": t.lost_after_misses,
        "track_score": t.track_score,
        "truth_gate_m": TRUTH_GATE_M,
    })
}

impl SampleBaseline {
    /// The baseline for sample `index` of `frames` frames on `scene`'s radar (the tracker
    /// runs when there are two frames or more).
    pub fn new(scene: &xbandsim::Scene, frames: u64, index: u64) -> Result<SampleBaseline> {
        let err = |error| DatasetError::Scene { index, error };
        let extractor = xbandsim_track::baseline::extractor(scene).map_err(err)?;
        let tracking = if frames > 1 {
            let tracker = Tracker::new(TrackerSettings::default()).map_err(err)?;
            let scorer = SequenceScorer::new(TRUTH_GATE_M).expect("the truth gate is positive");
            Some((tracker, scorer))
        } else {
            None
        };
        Ok(SampleBaseline {
            extractor,
            scratch: PlotScratch::default(),
            tracking,
            period_s: scene.radar().scan().period_s(),
            radar_position_m: scene.radar().position_m().to_array(),
            frames: Vec::new(),
        })
    }

    /// Runs the next frame: its video when it has one, else its calibrated record. Returns
    /// each truth object's result, in the frame's truth order.
    pub fn add_frame(&mut self, frame: &Frame) -> Vec<ObjectBaseline> {
        let grid = match &frame.video {
            Some(video) => PowerGrid::from_video(video),
            None => PowerGrid::from_record_db(
                &frame.polar_db,
                frame.spokes,
                frame.range_bins,
                frame.range_bin_m,
            ),
        };
        let plots = self.extractor.extract(&grid, &mut self.scratch);
        let sources = plot_sources(&plots, &grid, frame);
        let detected = |id: u32| {
            sources
                .iter()
                .any(|s| matches!(s, PlotSource::Object { id: o, .. } if *o == id))
        };
        let mut out: Vec<ObjectBaseline> = frame
            .truth
            .iter()
            .map(|o| ObjectBaseline {
                detected: o.visibility.has_echo().then(|| detected(o.id)),
                track_id: None,
            })
            .collect();
        let reach = GUARD_CELLS + TRAINING_CELLS;
        // False plots and the cells the CFAR tested (those with a full window), per range band.
        let mut false_by_band = [0u64; RANGE_BANDS];
        for (p, s) in plots.iter().zip(&sources) {
            if *s == PlotSource::None {
                false_by_band[range_band(p.range_m)] += 1;
            }
        }
        let mut cells_by_band = [0u64; RANGE_BANDS];
        for j in reach..grid.cells.saturating_sub(reach) {
            cells_by_band[range_band(grid.range_m(j))] += grid.spokes as u64;
        }
        let mut record = json!({
            "frame": self.frames.len(),
            "plots": plots.len(),
            "false_plots": false_by_band.iter().sum::<u64>(),
            "cells_tested": cells_by_band.iter().sum::<u64>(),
            "false_plots_by_range_band": false_by_band,
            "cells_tested_by_range_band": cells_by_band,
            "objects_with_echo": out.iter().filter(|o| o.detected.is_some()).count(),
            "objects_detected": out.iter().filter(|o| o.detected == Some(true)).count(),
        });
        if let Some((tracker, scorer)) = &mut self.tracking {
            let (antenna_position_m, velocity) = match &frame.own_ship {
                Some(s) => (
                    s.antenna_position_m.to_array(),
                    [s.velocity_mps.x, s.velocity_mps.y],
                ),
                None => (self.radar_position_m, [0.0, 0.0]),
            };
            let report = tracker.step(&Scan {
                start_time_s: frame.start_time_s,
                period_s: self.period_s,
                antenna_position_m,
                antenna_velocity_mps: velocity,
                plots: &plots,
            });
            let tracks: Vec<(u32, [f64; 2])> =
                report.confirmed().map(|t| (t.id, t.position_m)).collect();
            let truth: Vec<(usize, (u32, [f64; 2]))> = frame
                .truth
                .iter()
                .enumerate()
                .filter(|(_, o)| o.visibility.has_echo())
                .map(|(i, o)| (i, (o.id, [o.position_m[0], o.position_m[1]])))
                .collect();
            let objects: Vec<(u32, [f64; 2])> = truth.iter().map(|t| t.1).collect();
            let paired = scorer.add_frame(&objects, &tracks);
            for ((i, _), track) in truth.iter().zip(&paired) {
                out[*i].track_id = *track;
            }
            record["truth"] = json!(objects
                .iter()
                .map(|(id, p)| json!({"id": id, "position_m": p}))
                .collect::<Vec<_>>());
            record["tracks"] = json!(report
                .confirmed()
                .map(|t| json!({
                    "id": t.id,
                    "position_m": t.position_m,
                    "velocity_mps": t.velocity_mps,
                    "object_id": truth
                        .iter()
                        .zip(&paired)
                        .find(|(_, p)| **p == Some(t.id))
                        .map(|(o, _)| o.1 .0),
                }))
                .collect::<Vec<_>>());
        }
        self.frames.push(record);
        out
    }

    /// The sample's `baseline.json`: the settings, each frame's counts (and, for a
    /// sequence, its truth and confirmed tracks) and the sequence's tracking counts;
    /// `sea_state` is the sea clutter's, `None` without clutter.
    pub fn finish(self, sample: u64, sea_state: Option<f64>) -> serde_json::Value {
        let tracking = self.tracking.map(|(_, scorer)| scorer.finish());
        json!({
            "sample": sample,
            "sea_state": sea_state,
            "settings": settings_json(),
            "frames": self.frames,
            "tracking": tracking.as_ref().map(|t| json!({
                "counts": t,
                "figures": t.figures(),
            })),
        })
    }
}

/// Range bands of the detection report, km: lower edges (the last band is open).
pub const RANGE_BAND_EDGES_KM: [f64; RANGE_BANDS] = [0.0, 0.5, 1.0, 2.0, 4.0, 8.0];

/// Number of range bands.
pub const RANGE_BANDS: usize = 6;

/// The range band of a range, m ([`RANGE_BAND_EDGES_KM`]).
pub fn range_band(range_m: f64) -> usize {
    RANGE_BAND_EDGES_KM
        .iter()
        .filter(|&&e| range_m / 1e3 >= e)
        .count()
        .saturating_sub(1)
}

/// The range band's name, km.
fn range_band_name(band: usize) -> String {
    match RANGE_BAND_EDGES_KM.get(band + 1) {
        Some(hi) => format!("{} to {}", RANGE_BAND_EDGES_KM[band], hi),
        None => format!("{} and more", RANGE_BAND_EDGES_KM[band]),
    }
}

/// A sea state's name (`None`: no sea clutter).
fn sea_state_name(state: &Option<u64>) -> String {
    match state {
        Some(state) => format!("{state} to {}", state + 1),
        None => "no sea clutter".to_string(),
    }
}

/// Detection counts of one class, range band or sea state.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DetectionCounts {
    /// Objects that leave an echo (summed over frames).
    pub echoes: u64,
    /// Of them, those a plot was on.
    pub detected: u64,
    /// Plots on nothing the truth knows (not counted per class).
    pub false_plots: u64,
    /// Cells the CFAR tested (not counted per class).
    pub cells_tested: u64,
}

impl DetectionCounts {
    /// Pd, or `None` without echoes.
    pub fn pd(&self) -> Option<f64> {
        (self.echoes > 0).then(|| self.detected as f64 / self.echoes as f64)
    }

    /// False plots per cell tested, or `None` without cells.
    pub fn false_plots_per_cell(&self) -> Option<f64> {
        (self.cells_tested > 0).then(|| self.false_plots as f64 / self.cells_tested as f64)
    }

    fn pd_text(&self) -> String {
        self.pd().map_or("-".to_string(), |p| format!("{p:.3}"))
    }

    fn pfa_text(&self) -> String {
        self.false_plots_per_cell()
            .map_or("-".to_string(), |p| format!("{p:.2e}"))
    }
}

/// A dataset's baseline results summed: detection per class, range band and sea state, false
/// plots per range band and sea state, and the tracking counts of its sequences.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BaselineTally {
    /// Samples with a baseline.
    pub samples: u64,
    /// Frames with a baseline.
    pub frames: u64,
    /// Plots over all frames.
    pub plots: u64,
    /// Per class (from the targets table): echoes and detected.
    pub per_class: BTreeMap<String, DetectionCounts>,
    /// Per range band ([`RANGE_BAND_EDGES_KM`]): echoes and detected (from the targets
    /// table), false plots and cells tested (from baseline.json).
    pub per_range: [DetectionCounts; RANGE_BANDS],
    /// Per whole sea state (rounded down; `None`: no sea clutter), from baseline.json.
    pub per_sea_state: BTreeMap<Option<u64>, DetectionCounts>,
    /// The sequences' tracking counts (none for single-frame samples).
    pub tracking: Option<TrackingScore>,
}

impl BaselineTally {
    /// All frames' false plots and cells tested.
    pub fn total(&self) -> DetectionCounts {
        let mut t = DetectionCounts::default();
        for c in self.per_sea_state.values() {
            t.echoes += c.echoes;
            t.detected += c.detected;
            t.false_plots += c.false_plots;
            t.cells_tested += c.cells_tested;
        }
        t
    }

    /// The range bands with anything in them, each with its name.
    fn range_rows(&self) -> Vec<(String, DetectionCounts)> {
        (self.per_range.iter().enumerate())
            .filter(|(_, v)| v.echoes > 0 || v.cells_tested > 0)
            .map(|(i, v)| (range_band_name(i), *v))
            .collect()
    }

    /// The sea states, each with its name.
    fn sea_state_rows(&self) -> Vec<(String, DetectionCounts)> {
        (self.per_sea_state.iter())
            .map(|(state, v)| (sea_state_name(state), *v))
            .collect()
    }

    /// Adds one targets-table row (its class, range and `baseline_detected`).
    pub fn add_row(&mut self, row: &serde_json::Value) {
        let Some(detected) = row["baseline_detected"].as_bool() else {
            return;
        };
        let class = row["class"].as_str().unwrap_or("?").to_string();
        let entry = self.per_class.entry(class).or_default();
        entry.echoes += 1;
        entry.detected += u64::from(detected);
        if let Some(range_m) = row["range_m"].as_f64() {
            let band = &mut self.per_range[range_band(range_m)];
            band.echoes += 1;
            band.detected += u64::from(detected);
        }
    }

    /// Adds one sample's `baseline.json`; a file that is not one (no frames, tracking counts
    /// that do not read) is refused with what is wrong, and nothing is added.
    pub fn add_sample(&mut self, b: &serde_json::Value) -> std::result::Result<(), String> {
        let Some(frames) = b["frames"].as_array() else {
            return Err("baseline.json without a frames list".into());
        };
        let tracking = match &b["tracking"] {
            serde_json::Value::Null => None,
            t => {
                let counts = serde_json::from_value::<TrackingScore>(t["counts"].clone())
                    .map_err(|e| format!("baseline.json tracking.counts: {e}"))?;
                let per_threshold = [
                    &counts.hota_tp,
                    &counts.hota_fn,
                    &counts.hota_fp,
                    &counts.association_sum,
                    &counts.localisation_sum,
                ];
                if per_threshold.iter().any(|v| v.len() != HOTA_ALPHAS) {
                    return Err(format!(
                        "baseline.json tracking.counts: HOTA's counts must have {HOTA_ALPHAS} thresholds"
                    ));
                }
                Some(counts)
            }
        };
        let bands =
            |f: &serde_json::Value, key: &str| -> std::result::Result<[u64; RANGE_BANDS], String> {
                let list = f[key].as_array().filter(|l| l.len() == RANGE_BANDS);
                let list = list.ok_or_else(|| {
                    format!("baseline.json frames[].{key}: must list {RANGE_BANDS} counts")
                })?;
                let mut out = [0u64; RANGE_BANDS];
                for (o, v) in out.iter_mut().zip(list) {
                    *o = v.as_u64().ok_or_else(|| {
                        format!("baseline.json frames[].{key}: {v} is not a count")
                    })?;
                }
                Ok(out)
            };
        let mut per_frame = Vec::with_capacity(frames.len());
        for f in frames {
            per_frame.push((
                bands(f, "false_plots_by_range_band")?,
                bands(f, "cells_tested_by_range_band")?,
            ));
        }
        self.samples += 1;
        let sea_state = b["sea_state"].as_f64().map(|s| s.max(0.0).floor() as u64);
        for (f, (false_plots, cells)) in frames.iter().zip(per_frame) {
            self.frames += 1;
            let n = |k: &str| f[k].as_u64().unwrap_or(0);
            self.plots += n("plots");
            let state = self.per_sea_state.entry(sea_state).or_default();
            state.echoes += n("objects_with_echo");
            state.detected += n("objects_detected");
            state.false_plots += false_plots.iter().sum::<u64>();
            state.cells_tested += cells.iter().sum::<u64>();
            for (band, (fp, c)) in self
                .per_range
                .iter_mut()
                .zip(false_plots.iter().zip(&cells))
            {
                band.false_plots += fp;
                band.cells_tested += c;
            }
        }
        if let Some(counts) = tracking {
            self.tracking
                .get_or_insert_with(TrackingScore::default)
                .merge(&counts);
        }
        Ok(())
    }

    /// The report's baseline section (plain text), or a line saying the dataset has none.
    pub fn report(&self) -> String {
        let mut s = String::new();
        if self.samples == 0 {
            s.push_str("baseline: none (the dataset was made without baseline.json files)\n");
            return s;
        }
        let total = self.total();
        let _ = writeln!(
            s,
            "baseline: CA-CFAR at Pfa {PFA:e}, plots of {MIN_CELLS}+ cells, sidelobe editing at {SIDELOBE_MARGIN_DB} dB{} (docs/tracking.md, \"Dataset baseline\")",
            if self.tracking.is_some() {
                ", then the ARPA tracker"
            } else {
                ""
            }
        );
        let _ = writeln!(
            s,
            "  {} frames, {} plots, {} false ({:.2} a frame; {} a cell tested)",
            self.frames,
            self.plots,
            total.false_plots,
            total.false_plots as f64 / self.frames.max(1) as f64,
            total.pfa_text()
        );
        s.push_str("\n  detection, class      echoes       Pd\n");
        for (c, v) in &self.per_class {
            let _ = writeln!(s, "  {c:<20} {:>9} {:>8}", v.echoes, v.pd_text());
        }
        s.push_str("\n  range, km             echoes       Pd  false plots  a cell\n");
        let row = |s: &mut String, (label, v): (String, DetectionCounts)| {
            let _ = writeln!(
                s,
                "  {label:<20} {:>9} {:>8} {:>12} {:>8}",
                v.echoes,
                v.pd_text(),
                v.false_plots,
                v.pfa_text()
            );
        };
        for r in self.range_rows() {
            row(&mut s, r);
        }
        s.push_str("\n  sea state             echoes       Pd  false plots  a cell\n");
        for r in self.sea_state_rows() {
            row(&mut s, r);
        }
        if let Some(t) = &self.tracking {
            let f = t.figures();
            let opt =
                |x: Option<f64>, unit: &str| x.map_or("-".to_string(), |v| format!("{v:.3}{unit}"));
            let _ = writeln!(
                s,
                "\n  tracking over {} sequences ({} frames, {} object echoes):\n  MOTA {}  MOTP {}  HOTA {:.3}  DetA {:.3}  AssA {:.3}  LocA {:.3}\n  {} misses, {} false positives (confirmed tracks on no object), {} switches",
                t.sequences,
                t.frames,
                t.objects,
                opt(f.mota, ""),
                opt(f.motp_m, " m"),
                f.hota,
                f.det_a,
                f.ass_a,
                f.loc_a,
                t.misses,
                t.false_positives,
                t.switches
            );
        }
        s
    }

    /// The dataset card's section: the same figures as Markdown tables.
    pub fn markdown(&self) -> String {
        let mut c = String::from("\n## Baseline: CFAR plots and ARPA tracks\n\n");
        if self.samples == 0 {
            c.push_str("No sample of this dataset has a `baseline.json`.\n");
            return c;
        }
        let total = self.total();
        let _ = write!(
            c,
            "The number a learned model must beat: every frame through a cell-averaging CFAR \
             ({GUARD_CELLS} guard and {TRAINING_CELLS} training cells a side, design false-alarm \
             probability {PFA:e} a cell, plots of at least {MIN_CELLS} cells, sidelobe editing at \
             {SIDELOBE_MARGIN_DB} dB){}, scored against the truth (xbandsim's docs/tracking.md, \
             \"Dataset baseline\"). Each sample's results are in its `baseline.json`, all of \
             them in `baseline.jsonl`; each object's in `targets.jsonl` (`baseline_detected`, \
             `baseline_track_id`). Pd is over the objects that leave an echo; a false plot is a \
             plot on nothing the truth knows, counted per cell the CFAR tested.\n\n\
             - frames: {}, plots: {}, false plots: {} ({:.2} a frame, {} a cell tested)\n",
            if self.tracking.is_some() {
                " and, over each sequence, the ARPA-class tracker"
            } else {
                ""
            },
            self.frames,
            self.plots,
            total.false_plots,
            total.false_plots as f64 / self.frames.max(1) as f64,
            total.pfa_text()
        );
        c.push_str("\n| class | objects with an echo | Pd |\n|---|---|---|\n");
        for (class, v) in &self.per_class {
            let _ = writeln!(c, "| {class} | {} | {} |", v.echoes, v.pd_text());
        }
        c.push_str(
            "\n| range, km | objects with an echo | Pd | false plots | a cell tested |\n|---|---|---|---|---|\n",
        );
        let row = |c: &mut String, (label, v): (String, DetectionCounts)| {
            let _ = writeln!(
                c,
                "| {label} | {} | {} | {} | {} |",
                v.echoes,
                v.pd_text(),
                v.false_plots,
                v.pfa_text()
            );
        };
        for r in self.range_rows() {
            row(&mut c, r);
        }
        c.push_str(
            "\n| sea state | objects with an echo | Pd | false plots | a cell tested |\n|---|---|---|---|---|\n",
        );
        for r in self.sea_state_rows() {
            row(&mut c, r);
        }
        if let Some(t) = &self.tracking {
            let f = t.figures();
            let opt = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.3}"));
            let _ = write!(
                c,
                "\nTracking over {} sequences ({} frames, {} object echoes; a confirmed track \
                 pairs with an object within {TRUTH_GATE_M} m, by CLEAR MOT's rule):\n\n\
                 | MOTA | MOTP, m | HOTA | DetA | AssA | LocA | misses | false positives | switches |\n\
                 |---|---|---|---|---|---|---|---|---|\n\
                 | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} | {} |\n",
                t.sequences,
                t.frames,
                t.objects,
                opt(f.mota),
                opt(f.motp_m),
                f.hota,
                f.det_a,
                f.ass_a,
                f.loc_a,
                t.misses,
                t.false_positives,
                t.switches
            );
        }
        c
    }
}
