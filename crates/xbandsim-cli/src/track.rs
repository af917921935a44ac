//! `xbandsim track`: renders revolutions of a scene, extracts their plots and tracks them
//! with the ARPA-class tracker (`xbandsim_track`), each confirmed track scored against the
//! truth.

use crate::detect::{grid_of, DetectorArgs, TRACK_DEFAULTS};
use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;
use xbandsim::engine::{Request, Simulation};
use xbandsim::model::motion::KNOT_M_PER_S;
use xbandsim::processing::plots::PlotScratch;
use xbandsim::products::output::write_json;
use xbandsim::receiver::video_chain::EchoHistory;
use xbandsim_track::accuracy::angle_difference_deg;
use xbandsim_track::{
    AccuracySample, AccuracyTally, RowResult, Scan, SequenceScorer, TrackEnd, TrackReport, Tracker,
    TrackerSettings, TrackingFigures, TrackingScore,
};

/// Arguments of `xbandsim track`.
#[derive(Args, Debug, Clone)]
pub struct TrackArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output file: every scan's tracks, scored against the truth (JSON).
    #[arg(long, default_value = "tracks.json")]
    pub out: PathBuf,
    /// Random seed: the same seed gives the same tracks.
    #[arg(long, default_value_t = 0, value_parser = crate::whole_number)]
    pub seed: u64,
    /// Revolutions (scans) to render and track.
    #[arg(long, default_value_t = 40, value_parser = crate::whole_number)]
    pub frames: u64,
    #[command(flatten)]
    pub detector: DetectorArgs,
    /// Track initiation M/N: a track is confirmed when M of its first N scans had a plot.
    #[arg(long, default_value = "3/4", value_name = "M/N")]
    pub initiation: String,
    /// Scans in a row without a plot after which a confirmed track is lost.
    #[arg(long, default_value_t = 6, value_parser = crate::whole_number)]
    pub lost_after: u64,
    /// Association gate on the squared Mahalanobis distance (13.82: 99.9 % of true plots).
    #[arg(long, default_value_t = 13.82)]
    pub gate: f64,
    /// Standard deviation of a plot's range, m.
    #[arg(long, default_value_t = 5.0)]
    pub sigma_range_m: f64,
    /// Standard deviation of a plot's bearing, degrees.
    #[arg(long, default_value_t = 0.5)]
    pub sigma_bearing_deg: f64,
    /// Turn rate of the IMM's coordinated-turn models, deg/s.
    #[arg(long, default_value_t = 2.0)]
    pub turn_rate_deg_s: f64,
    /// Probability that a target gives a plot on a scan, as the track score assumes it.
    #[arg(long, default_value_t = 0.8)]
    pub detection_probability: f64,
    /// Probability of confirming a track made of false plots (the track score's threshold).
    #[arg(long, default_value_t = 1e-4)]
    pub false_track_probability: f64,
    /// Confirm tracks by M-of-N alone, without the track score.
    #[arg(long)]
    pub no_track_score: bool,
    /// Distance within which a confirmed track is scored against a truth object, m.
    #[arg(long, default_value_t = 100.0)]
    pub truth_gate_m: f64,
    /// Also draw the last revolution's PPI with every confirmed track on it (its history,
    /// its one-minute true vector and its number): a PNG.
    #[arg(long, value_name = "FILE.png")]
    pub ppi: Option<PathBuf>,
    /// Override any scene field: FIELD=VALUE (repeatable), as for render.
    #[arg(long, value_name = "FIELD=VALUE")]
    pub set: Vec<String>,
}

/// Minutes of a track's true vector on the tracked PPI (ARPA's vector time).
const VECTOR_MINUTES: f64 = 1.0;

/// The last revolution's colour PPI (`display` of the scene) with each confirmed track drawn
/// over it: its past positions (`history`, ENU, drawn from where the antenna was at the
/// revolution's start, `antenna_m`), a circle where it is (`tracks`: id, position from the
/// antenna at the track's time, velocity), its true vector over [`VECTOR_MINUTES`] and its
/// number. Returns (side px, RGB).
fn tracked_ppi(
    display: &xbandsim::products::ppi::PpiSettings,
    radar: &xbandsim::model::radar::Radar,
    frame: &xbandsim::Frame,
    antenna_m: [f64; 2],
    tracks: &[(u32, [f64; 2], [f64; 2])],
    history: &std::collections::HashMap<u32, Vec<[f64; 2]>>,
) -> Result<(u32, Vec<u8>)> {
    use plotters::prelude::*;
    use xbandsim::products::ppi::colour_image;
    let conv = display.frame_scan_converter(radar, frame.own_ship.as_ref());
    let geometry = conv.geometry();
    let size = conv.size_px();
    let mut ppi = vec![0f32; (size * size) as usize];
    conv.convert(&frame.polar_db, f32::NAN, &mut ppi);
    let mut rgb = colour_image(
        &conv,
        &ppi,
        display.colormap,
        display.min_db,
        display.max_db,
        display.range_ring_spacing_m,
    );
    crate::figures::register_fonts()?;
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (size, size)).into_drawing_area();
        let err = |e| anyhow::anyhow!("drawing the tracked PPI failed: {e:?}");
        let rel_px = |p: [f64; 2]| {
            let (x, y) = geometry.pixel_of(p[0], p[1]);
            (x.round() as i32, y.round() as i32)
        };
        let track_colour = RGBColor(255, 220, 0);
        for &(id, position, velocity) in tracks {
            for &p in history.get(&id).into_iter().flatten() {
                let dot = rel_px([p[0] - antenna_m[0], p[1] - antenna_m[1]]);
                root.draw(&Circle::new(dot, 1, WHITE.filled()))
                    .map_err(err)?;
            }
            let here = rel_px(position);
            let ahead = rel_px([
                position[0] + velocity[0] * 60.0 * VECTOR_MINUTES,
                position[1] + velocity[1] * 60.0 * VECTOR_MINUTES,
            ]);
            root.draw(&Circle::new(here, 7, track_colour.stroke_width(2)))
                .map_err(err)?;
            root.draw(&PathElement::new(
                vec![here, ahead],
                track_colour.stroke_width(2),
            ))
            .map_err(err)?;
            root.draw(&Text::new(
                id.to_string(),
                (here.0 + 9, here.1 - 18),
                (crate::figures::FONT, 15).into_font().color(&track_colour),
            ))
            .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    Ok((size, rgb))
}

#[derive(Serialize)]
struct TruthMatch {
    object_id: u32,
    name: String,
    position_error_m: f64,
    course_error_deg: Option<f64>,
    speed_error_kn: f64,
}

#[derive(Serialize)]
struct TrackOut {
    #[serde(flatten)]
    track: TrackReport,
    truth: Option<TruthMatch>,
}

#[derive(Serialize)]
struct ObjectOut {
    id: u32,
    name: String,
    class: String,
    position_m: [f64; 2],
    course_deg: Option<f64>,
    speed_kn: f64,
    has_echo: bool,
    track_id: Option<u32>,
}

/// A plot as the tracker measured it (what a peer tracker is fed).
#[derive(Serialize)]
struct MeasurementOut {
    time_s: f64,
    position_m: [f64; 2],
    covariance_m2: [[f64; 2]; 2],
    range_m: f64,
    azimuth_deg: f64,
    peak_db: f32,
}

#[derive(Serialize)]
struct ScanOut {
    frame: u64,
    start_time_s: f64,
    period_s: f64,
    antenna_position_m: [f64; 3],
    antenna_velocity_mps: [f64; 2],
    plots: usize,
    measurements: Vec<MeasurementOut>,
    tracks: Vec<TrackOut>,
    ended: Vec<(u32, TrackEnd)>,
    objects: Vec<ObjectOut>,
}

#[derive(Serialize)]
struct Summary {
    scans: u64,
    object_echoes: usize,
    object_echoes_tracked: usize,
    confirmed_tracks: usize,
    false_track_scans: usize,
    track_switches: usize,
    mean_position_error_m: Option<f64>,
    accuracy: Vec<RowResult>,
    /// MOTA, MOTP and HOTA over the scans (`xbandsim_track::score`).
    scores: Scores,
}

#[derive(Serialize)]
struct Scores {
    figures: TrackingFigures,
    counts: TrackingScore,
}

#[derive(Serialize)]
struct Output {
    scene: String,
    seed: u64,
    tracker: serde_json::Value,
    summary: Summary,
    scans: Vec<ScanOut>,
}

/// A change of an object's velocity from one scan to the next over which it is manoeuvring,
/// m/s (the IMO table is for targets that hold course and speed).
const STEADY_VELOCITY_CHANGE_MPS: f64 = 0.05;

/// Runs `xbandsim track`.
pub fn run(a: &TrackArgs) -> Result<()> {
    let t0 = Instant::now();
    if a.frames == 0 {
        bail!("invalid --frames 0: must be 1 or more");
    }
    let (extractor, use_video) = a.detector.extractor(TRACK_DEFAULTS)?;
    let Some((m, n)) = a.initiation.split_once('/').and_then(|(m, n)| {
        Some((
            m.trim().parse::<usize>().ok()?,
            n.trim().parse::<usize>().ok()?,
        ))
    }) else {
        bail!(
            "invalid --initiation {:?}: must be M/N, e.g. 3/4",
            a.initiation
        );
    };
    if !(a.truth_gate_m.is_finite() && a.truth_gate_m > 0.0) {
        bail!(
            "invalid --truth-gate-m {}: must be a positive distance",
            a.truth_gate_m
        );
    }
    let settings = TrackerSettings {
        initiation_hits: m,
        initiation_scans: n,
        lost_after_misses: a.lost_after as usize,
        gate: a.gate,
        sigma_range_m: a.sigma_range_m,
        sigma_bearing_deg: a.sigma_bearing_deg,
        turn_rate_deg_s: a.turn_rate_deg_s,
        detection_probability: a.detection_probability,
        false_track_probability: a.false_track_probability,
        track_score: !a.no_track_score,
        ..TrackerSettings::default()
    };
    let mut tracker = Tracker::new(settings.clone())?;
    let mut scorer = SequenceScorer::new(a.truth_gate_m).expect("the truth gate is checked");
    let spec = crate::render::load_spec(&a.scene, &a.set)?;
    let scene = spec.build()?;
    let display = match &a.ppi {
        Some(path) => {
            let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
            if let Some(dir) = parent.filter(|d| !d.is_dir()) {
                bail!(
                    "invalid --ppi {}: its folder {} does not exist",
                    path.display(),
                    dir.display()
                );
            }
            Some(spec.ppi_settings()?)
        }
        None => None,
    };
    a.detector.check_scene(&scene)?;
    let extractor = a.detector.for_scene(extractor, &scene)?;
    let sim = Simulation::new(scene);
    let radar = sim.scene().radar();
    let period_s = radar.scan().period_s();
    let progress = crate::progress::bar(a.frames, "track: scans");
    let echo_history = std::sync::Mutex::new(EchoHistory::default());
    let mut scratch = PlotScratch::default();
    let mut tracker_s = 0.0;
    let mut scans = Vec::new();
    let mut last_track_of: std::collections::HashMap<u32, u32> = Default::default();
    let (mut switches, mut echoes, mut tracked, mut false_tracks) = (0, 0, 0, 0);
    let mut confirmed_ids = std::collections::BTreeSet::new();
    let (mut error_sum, mut error_count) = (0.0, 0usize);
    // For the IMO accuracy table: the scan and time each track was acquired (its first
    // plot), the object each was last matched to, when each (track, object) pairing began,
    // and the scan since which each object has held its course and speed (with the velocity
    // it held).
    let mut acquired: std::collections::HashMap<u32, (u64, f64)> = Default::default();
    let mut last_object_of: std::collections::HashMap<u32, u32> = Default::default();
    let mut pair_since: std::collections::HashMap<(u32, u32), (u64, f64)> = Default::default();
    let mut steady_since: std::collections::HashMap<u32, (u64, [f64; 2])> = Default::default();
    let mut accuracy = AccuracyTally::new();
    // For the tracked PPI: each confirmed track's positions, and the last revolution.
    let mut history: std::collections::HashMap<u32, Vec<[f64; 2]>> = Default::default();
    let mut last = None;
    for k in 0..a.frames {
        let frame = sim.run(&Request::new(a.seed).frame(k).echo_history(&echo_history))?;
        let plots = extractor.extract(&grid_of(&frame, use_video), &mut scratch);
        let (antenna, velocity) = match frame.own_ship {
            Some(s) => (s.antenna_position_m, [s.velocity_mps.x, s.velocity_mps.y]),
            None => (radar.position_m(), [0.0, 0.0]),
        };
        let scan = Scan {
            start_time_s: frame.start_time_s,
            period_s,
            antenna_position_m: [antenna.x, antenna.y, antenna.z],
            antenna_velocity_mps: velocity,
            plots: &plots,
        };
        let t_step = Instant::now();
        let report = tracker.step(&scan);
        tracker_s += t_step.elapsed().as_secs_f64();
        let measurements = plots
            .iter()
            .map(|p| {
                let m = scan.measurement(p, tracker.settings());
                MeasurementOut {
                    time_s: m.time_s,
                    position_m: m.position_m,
                    covariance_m2: m.covariance,
                    range_m: p.range_m,
                    azimuth_deg: p.azimuth_deg,
                    peak_db: p.peak_db,
                }
            })
            .collect();
        // Confirmed tracks to truth objects, nearest pairs first, one to one.
        let confirmed: Vec<&TrackReport> = report.confirmed().collect();
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (ti, t) in confirmed.iter().enumerate() {
            for (oi, o) in frame.truth.iter().enumerate() {
                let d =
                    (t.position_m[0] - o.position_m[0]).hypot(t.position_m[1] - o.position_m[1]);
                if d <= a.truth_gate_m {
                    pairs.push((d, ti, oi));
                }
            }
        }
        pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut object_of = vec![None; confirmed.len()];
        let mut track_of = vec![None; frame.truth.len()];
        for (d, ti, oi) in pairs {
            if object_of[ti].is_none() && track_of[oi].is_none() {
                object_of[ti] = Some((oi, d));
                track_of[oi] = Some(confirmed[ti].id);
            }
        }
        let echoing: Vec<(u32, [f64; 2])> = frame
            .truth
            .iter()
            .filter(|o| o.visibility.has_echo())
            .map(|o| (o.id, [o.position_m[0], o.position_m[1]]))
            .collect();
        let confirmed_positions: Vec<(u32, [f64; 2])> =
            confirmed.iter().map(|t| (t.id, t.position_m)).collect();
        scorer.add_frame(&echoing, &confirmed_positions);
        let tracks: Vec<TrackOut> = confirmed
            .iter()
            .zip(&object_of)
            .map(|(t, matched)| TrackOut {
                track: (*t).clone(),
                truth: matched.map(|(oi, d)| {
                    let o = &frame.truth[oi];
                    TruthMatch {
                        object_id: o.id,
                        name: o.name.clone(),
                        position_error_m: d,
                        course_error_deg: match (t.course_deg, o.course_deg) {
                            (Some(tc), Some(oc)) => Some(angle_difference_deg(tc, oc)),
                            _ => None,
                        },
                        speed_error_kn: t.speed_kn - o.speed_kn,
                    }
                }),
            })
            .collect();
        // An object is steady while its velocity stays within the threshold of the velocity
        // its steady spell began with (a slow turn adds up); the spell restarts at the scan
        // where it leaves it.
        for o in &frame.truth {
            let v = [o.velocity_mps[0], o.velocity_mps[1]];
            let entry = steady_since.entry(o.id).or_insert((k, v));
            if (v[0] - entry.1[0]).hypot(v[1] - entry.1[1]) > STEADY_VELOCITY_CHANGE_MPS {
                *entry = (k, v);
            }
        }
        for t in &report.tracks {
            acquired.entry(t.id).or_insert((k, t.time_s));
        }
        for t in &tracks {
            let Some(m) = &t.truth else { continue };
            // Tracking time counts from acquisition (the track's first plot), or from the
            // scan its track moved to this object.
            let moved = last_object_of.insert(t.track.id, m.object_id);
            let (since_scan, since_s) =
                *pair_since
                    .entry((t.track.id, m.object_id))
                    .or_insert(match moved {
                        Some(other) if other != m.object_id => (k, t.track.time_s),
                        _ => acquired[&t.track.id],
                    });
            let o = frame
                .truth
                .iter()
                .find(|o| o.id == m.object_id)
                .expect("a matched object is in the frame");
            if steady_since[&o.id].0 < since_scan || steady_since[&o.id].0 == 0 {
                // Both at the track's time: the truth moved on along its velocity.
                let dt = t.track.time_s - o.beam_time_s;
                let own = scan.antenna_at(t.track.time_s);
                accuracy.add(&AccuracySample {
                    minutes_tracked: (t.track.time_s - since_s) / 60.0,
                    track_relative_position_m: [
                        t.track.position_m[0] - own[0],
                        t.track.position_m[1] - own[1],
                    ],
                    track_velocity_mps: t.track.velocity_mps,
                    true_relative_position_m: [
                        o.position_m[0] + o.velocity_mps[0] * dt - own[0],
                        o.position_m[1] + o.velocity_mps[1] * dt - own[1],
                    ],
                    true_velocity_mps: [o.velocity_mps[0], o.velocity_mps[1]],
                    own_velocity_mps: velocity,
                });
            }
        }
        for t in &tracks {
            confirmed_ids.insert(t.track.id);
            match &t.truth {
                Some(m) => {
                    error_sum += m.position_error_m;
                    error_count += 1;
                }
                None => false_tracks += 1,
            }
        }
        let objects: Vec<ObjectOut> = frame
            .truth
            .iter()
            .zip(&track_of)
            .map(|(o, &track_id)| {
                let has_echo = o.visibility.has_echo();
                echoes += usize::from(has_echo);
                if let Some(id) = track_id {
                    tracked += usize::from(has_echo);
                    if let Some(previous) = last_track_of.insert(o.id, id) {
                        switches += usize::from(previous != id);
                    }
                }
                ObjectOut {
                    id: o.id,
                    name: o.name.clone(),
                    class: o.class.clone(),
                    position_m: [o.position_m[0], o.position_m[1]],
                    course_deg: o.course_deg,
                    speed_kn: o.speed_kn,
                    has_echo,
                    track_id,
                }
            })
            .collect();
        for t in &tracks {
            history
                .entry(t.track.id)
                .or_default()
                .push(t.track.position_m);
        }
        let antenna_now = scan.antenna_at(scan.start_time_s);
        // Each confirmed track where it is from the antenna at its own time, and its velocity.
        let confirmed_now: Vec<(u32, [f64; 2], [f64; 2])> = tracks
            .iter()
            .map(|t| {
                let a = scan.antenna_at(t.track.time_s);
                let p = t.track.position_m;
                (t.track.id, [p[0] - a[0], p[1] - a[1]], t.track.velocity_mps)
            })
            .collect();
        scans.push(ScanOut {
            frame: k,
            start_time_s: frame.start_time_s,
            period_s,
            antenna_position_m: [antenna.x, antenna.y, antenna.z],
            antenna_velocity_mps: velocity,
            plots: plots.len(),
            measurements,
            tracks,
            ended: report.ended,
            objects,
        });
        last = Some((frame, antenna_now, confirmed_now));
        progress.inc(1);
    }
    progress.finish_and_clear();
    let picture = match (&display, &last) {
        (Some(display), Some((frame, antenna_now, confirmed_now))) => Some(tracked_ppi(
            display,
            radar,
            frame,
            *antenna_now,
            confirmed_now,
            &history,
        )?),
        _ => None,
    };
    let summary = Summary {
        scans: a.frames,
        object_echoes: echoes,
        object_echoes_tracked: tracked,
        confirmed_tracks: confirmed_ids.len(),
        false_track_scans: false_tracks,
        track_switches: switches,
        mean_position_error_m: (error_count > 0).then(|| error_sum / error_count as f64),
        accuracy: accuracy.results(),
        scores: {
            let counts = scorer.finish();
            Scores {
                figures: counts.figures(),
                counts,
            }
        },
    };
    crate::say!(
        "track {}: {} scans, {} confirmed tracks; {} of {} object echoes in a track, {} track switches, {} false-track scans, mean position error {}, tracker {:.3} ms, {:.2} s -> {}",
        a.scene.display(),
        a.frames,
        summary.confirmed_tracks,
        summary.object_echoes_tracked,
        summary.object_echoes,
        summary.track_switches,
        summary.false_track_scans,
        summary
            .mean_position_error_m
            .map_or("none".to_string(), |e| format!("{e:.1} m")),
        tracker_s * 1e3,
        t0.elapsed().as_secs_f64(),
        a.out.display()
    );
    let s = &settings;
    let tracker_json = serde_json::json!({
        "initiation": format!("{}/{}", s.initiation_hits, s.initiation_scans),
        "lost_after_misses": s.lost_after_misses,
        "gate": s.gate,
        "sigma_range_m": s.sigma_range_m,
        "sigma_bearing_deg": s.sigma_bearing_deg,
        "max_speed_kn": s.max_speed_kn,
        "sigma_a_cv_mps2": s.sigma_a_cv_mps2,
        "sigma_a_turn_mps2": s.sigma_a_turn_mps2,
        "turn_rate_deg_s": s.turn_rate_deg_s,
        "model_stay_probability": s.model_stay_probability,
        "merge_distance_m": s.merge_distance_m,
        "merge_speed_mps": s.merge_speed_mps,
        "merge_scans": s.merge_scans,
        "track_score": s.track_score,
        "detection_probability": s.detection_probability,
        "false_track_probability": s.false_track_probability,
        "true_track_rejection_probability": s.true_track_rejection_probability,
        "confirmation_score": s.confirmation_score(),
        "deletion_score": s.deletion_score(),
        "clutter_cell_m": s.clutter_cell_m,
        "clutter_sector_deg": s.clutter_sector_deg,
        "clutter_memory_scans": s.clutter_memory_scans,
        "clutter_floor_per_km2": s.clutter_floor_per_km2,
        "detector": {
            "input": a.detector.input,
            "cfar": a.detector.cfar,
            "rank": a.detector.rank,
            "guard_cells": a.detector.guard_cells,
            "training_cells": a.detector.training_cells,
            "pfa": a.detector.pfa(TRACK_DEFAULTS),
            "min_cells": a.detector.min_cells(TRACK_DEFAULTS),
            "sidelobe_margin_db": a.detector.sidelobe_margin()?,
        },
        "truth_gate_m": a.truth_gate_m,
        "knot_mps": KNOT_M_PER_S,
    });
    let output = Output {
        scene: a.scene.display().to_string(),
        seed: a.seed,
        tracker: tracker_json,
        summary,
        scans,
    };
    // Both encoded before either is written; each is then replaced whole.
    let png = match (&a.ppi, picture) {
        (Some(path), Some((size, rgb))) => Some((
            path,
            xbandsim::products::output::png_bytes(path, size, size, 3, &rgb)?,
        )),
        _ => None,
    };
    write_json(&a.out, &output).with_context(|| format!("writing {}", a.out.display()))?;
    if let Some((path, bytes)) = png {
        xbandsim::products::output::write_atomic(path, &bytes)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}
