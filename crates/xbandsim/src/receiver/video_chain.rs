//! Receiver: the video chain after detection — what a marine radar's log receiver and video
//! processor make of the calibrated record (docs/physics.md §12, "Receiver video"). In a
//! set's order, on each sweep (a spoke of the polar record):
//!
//! 1. **range sampling**: the record's bins onto `video_samples` samples over the recorded
//!    range, each sample the peak of the bins it covers (a peak-detecting sampler keeps point
//!    echoes that fall between samples);
//! 2. **sea clutter control** (STC): an attenuation `A(R)` ahead of the log amplifier —
//!    manual, `min(level, 10·k·log10(R_stc/R))` inside `R_stc`; or auto, the attenuation
//!    that brings the median power over the sweeps at each range to a set level;
//! 3. **log amplifier**: `v = min(10·log10(1 + p), D)` dB for power p over the noise, linear
//!    near the noise and logarithmic above it, saturating at the dynamic range D;
//! 4. **rain clutter control** (FTC): a differentiator on the log video along range, the
//!    first-order high-pass [`Ftc`], `y_n = a·(y_{n−1} + v_n − v_{n−1})`, `a = τ/(τ + Δt)`,
//!    whose step response decays as `aⁿ⁺¹ ≈ exp(−t/τ)`; negative video is clipped to 0;
//! 5. **interference rejection**: sweep-to-sweep correlation — a sample may exceed the
//!    stronger of the neighbouring sweeps' samples at its range by 6 dB (low) or 2 dB
//!    (medium), or the weaker by nothing (high): another radar's pulses, which land on one
//!    sweep at a time, are cut down to the neighbours' level, while an echo the beam paints
//!    on several sweeps stays;
//! 6. **azimuth sampling** onto `video_spokes` spokes (each video spoke the nearest sweep and
//!    the peak of the sweeps nearest it);
//! 7. **echo averaging** over scans, a running mean with weight `1/min(n, N)` for scan n;
//! 8. **gain and quantisation**: level 0 below the threshold `6 dB − gain`, then one level
//!    per `span/(2^bits − 1)` dB up to `2^bits − 1`;
//! 9. **noise rejection**: a non-zero sample whose four neighbours (range and azimuth) are
//!    all zero is cleared;
//! 10. **echo stretch**: each sample the largest of itself and the `n` samples before it.
//!
//! Pure over its inputs: no random numbers, so the same record gives the same video; the
//! per-sweep stages run on all cores.

use crate::choice::InterferenceRejection;
use crate::constants::SPEED_OF_LIGHT_M_PER_S;
use crate::model::receiver::{Stc, VideoSettings};
use crate::receiver::stages::Ftc;
use rayon::prelude::*;

/// A revolution of quantised video: `spokes × samples` levels `0 ..= 2^bits − 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct Video {
    /// Video spokes (rows): spoke s at azimuth `360°·s/spokes`.
    pub spokes: usize,
    /// Samples a spoke (columns): sample j covers `[j, j + 1)·sample_m`.
    pub samples: usize,
    /// Bits a level has.
    pub bits: u32,
    /// Range a sample covers, m.
    pub sample_m: f64,
    /// Log video at the threshold of level 1, dB over the noise (6 dB − gain).
    pub threshold_db: f32,
    /// Log video a level spans, dB.
    pub level_step_db: f32,
    /// The levels, row-major.
    pub levels: Vec<u8>,
}

impl Video {
    /// The largest level, `2^bits − 1`.
    pub fn max_level(&self) -> u8 {
        ((1u32 << self.bits) - 1) as u8
    }
}

/// What echo averaging remembers between scans: the running mean of the log video on the
/// video grid and how many scans it holds.
#[derive(Debug, Clone, Default)]
pub struct EchoHistory {
    mean_db: Vec<f32>,
    scans: u32,
}

impl EchoHistory {
    /// Scans averaged so far.
    pub fn scans(&self) -> u32 {
        self.scans
    }
}

/// The polar record the chain starts from.
#[derive(Debug, Clone, Copy)]
pub struct PolarRecord<'a> {
    /// spokes × bins, dB over the noise.
    pub db: &'a [f32],
    /// Spokes (sweeps).
    pub spokes: usize,
    /// Bins a spoke.
    pub bins: usize,
    /// Range of bin i is `i·bin_m`.
    pub bin_m: f64,
    /// The range the video covers, m.
    pub range_m: f64,
}

/// The log amplifier's output for power `p` over the noise: `min(10·log10(1 + p), D)` dB.
#[inline]
pub fn log_video_db(p_over_noise: f32, dynamic_range_db: f32) -> f32 {
    (10.0 * p_over_noise.ln_1p() * std::f32::consts::LOG10_E).min(dynamic_range_db)
}

/// The manual STC's attenuation at range `range_m`, dB: `min(level, 10·k·log10(R_stc/R))`
/// inside `R_stc` (ranges under 1 m count as 1 m), 0 beyond.
pub fn manual_stc_db(range_m: f64, level_db: f32, stc_range_m: f64, law: f32) -> f32 {
    if range_m >= stc_range_m {
        return 0.0;
    }
    let r = range_m.max(1.0);
    ((10.0 * f64::from(law) * (stc_range_m / r).log10()) as f32).min(level_db)
}

/// The level of log video `v_db`: 0 below `threshold_db`, else
/// `min(max_level, 1 + floor((v − threshold)/step))` with `step = span/max_level`.
#[inline]
pub fn quantise(v_db: f32, threshold_db: f32, span_db: f32, max_level: u8) -> u8 {
    // NaN and everything under the threshold: level 0.
    if v_db.is_nan() || v_db < threshold_db {
        return 0;
    }
    let step = span_db / f32::from(max_level);
    let above = ((v_db - threshold_db) / step).floor();
    if above >= f32::from(max_level) - 1.0 {
        max_level
    } else {
        1 + above as u8
    }
}

/// The bins `[first, last]` each video sample takes its peak from: those whose range falls in
/// the sample's interval, or the bin nearest its centre when none does.
fn sample_bins(record: &PolarRecord, samples: usize) -> Vec<(usize, usize)> {
    let sample_m = record.range_m / samples as f64;
    let last_bin = record.bins - 1;
    (0..samples)
        .map(|j| {
            let lo = ((j as f64 * sample_m) / record.bin_m).ceil() as usize;
            let hi = (((j + 1) as f64 * sample_m) / record.bin_m).ceil() as usize;
            if lo < hi && lo <= last_bin {
                (lo, (hi - 1).min(last_bin))
            } else {
                let c = (((j as f64 + 0.5) * sample_m) / record.bin_m).round() as usize;
                (c.min(last_bin), c.min(last_bin))
            }
        })
        .collect()
}

/// Auto STC: per sample, the attenuation that brings the median over the sweeps down to
/// `level_db` of log video (`10·log10(1 + p_med·g) = level`, so `A = P_med − 10·log10(10^{L/10}
/// − 1)` in dB, the median taken on dB values: the median of a monotone map is the map of
/// the median), none where the median is below it; then the running maximum from far to
/// near, so that it never attenuates more far than near. `peak_db` is sweeps × samples, dB
/// over the noise.
fn auto_stc_db(peak_db: &[f32], samples: usize, level_db: f32) -> Vec<f32> {
    let sweeps = peak_db.len() / samples;
    let target_db = 10.0 * (10f32.powf(0.1 * level_db) - 1.0).log10();
    let mut attenuation: Vec<f32> = (0..samples)
        .into_par_iter()
        .map_init(
            || Vec::with_capacity(sweeps),
            |column, j| {
                column.clear();
                column.extend((0..sweeps).map(|k| peak_db[k * samples + j]));
                let mid = sweeps / 2;
                let (_, median, _) = column.select_nth_unstable_by(mid, f32::total_cmp);
                (*median - target_db).max(0.0)
            },
        )
        .collect();
    for j in (0..samples.saturating_sub(1)).rev() {
        attenuation[j] = attenuation[j].max(attenuation[j + 1]);
    }
    attenuation
}

/// `10·log10(1 + 10^{−d/10})` for d = k/64 dB, k = 0 … 64·60 (beyond 60 dB it is under
/// 5·10⁻⁶ dB and taken as 0).
fn softplus_table() -> &'static [f32] {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        (0..=64 * 60 + 1)
            .map(|k| (10.0 * (1.0 + 10f64.powf(-(k as f64 / 64.0) / 10.0)).log10()) as f32)
            .collect()
    })
}

/// The log amplifier's output for an input `x_db` dB over the noise, without a logarithm:
/// `10·log10(1 + 10^{x/10}) = max(x, 0) + 10·log10(1 + 10^{−|x|/10})`, the second term from a
/// table of 1/64 dB steps interpolated linearly (within 2·10⁻⁵ dB of the exact value), then
/// saturated at `dynamic_range_db`.
#[inline]
pub fn log_video_of_db(x_db: f32, dynamic_range_db: f32) -> f32 {
    let table = softplus_table();
    let d = x_db.abs() * 64.0;
    let correction = if d < (64 * 60) as f32 {
        let k = d as usize;
        let t = d - k as f32;
        table[k] + t * (table[k + 1] - table[k])
    } else {
        0.0
    };
    (x_db.max(0.0) + correction).min(dynamic_range_db)
}

/// One sweep's log video in place: `video_db` (the sweep's samples in dB over the noise)
/// less the STC's attenuation per sample (`stc_db`), through the log amplifier saturating at
/// `dynamic_range_db`, then the FTC when given. The per-sweep stages of [`run`], for a caller
/// that refreshes sweeps one by one (the Gymnasium environments' display).
pub fn sweep_log_video(
    video_db: &mut [f32],
    stc_db: &[f32],
    dynamic_range_db: f32,
    ftc: Option<Ftc>,
) {
    for (v, a) in video_db.iter_mut().zip(stc_db) {
        *v = log_video_of_db(*v - a, dynamic_range_db);
    }
    if let Some(f) = ftc {
        f.apply(video_db);
    }
}

/// Interference rejection of sweep `k` of `video` (sweeps × samples) into `out`.
fn reject_interference(
    video: &[f32],
    samples: usize,
    k: usize,
    level: InterferenceRejection,
    out: &mut [f32],
) {
    let sweeps = video.len() / samples;
    let row = |i: usize| &video[i * samples..(i + 1) * samples];
    let (before, here, after) = (
        row((k + sweeps - 1) % sweeps),
        row(k),
        row((k + 1) % sweeps),
    );
    for j in 0..samples {
        let allowed = match level {
            InterferenceRejection::Off => f32::INFINITY,
            InterferenceRejection::Low => before[j].max(after[j]) + 6.0,
            InterferenceRejection::Medium => before[j].max(after[j]) + 2.0,
            InterferenceRejection::High => before[j].min(after[j]),
        };
        out[j] = here[j].min(allowed);
    }
}

/// Runs the chain on `record` with `settings`; `history` carries echo averaging from scan to
/// scan (None: this scan alone).
pub fn run(
    settings: &VideoSettings,
    record: &PolarRecord,
    history: Option<&mut EchoHistory>,
) -> Video {
    let n = settings.video_samples;
    let sweeps = record.spokes;
    let sample_m = record.range_m / n as f64;
    let bins = sample_bins(record, n);
    // 1. The peak over each sample's bins, dB over the noise.
    let mut video = vec![0f32; sweeps * n];
    video
        .par_chunks_mut(n)
        .zip(record.db.par_chunks(record.bins))
        .for_each(|(out, row)| {
            for (o, &(lo, hi)) in out.iter_mut().zip(&bins) {
                *o = row[lo..=hi].iter().copied().fold(f32::MIN, f32::max);
            }
        });
    // 2. STC as a gain per sample.
    let stc_db: Vec<f32> = match settings.stc {
        Stc::Off => vec![0.0; n],
        Stc::Manual {
            level_db,
            range_m,
            law,
        } => (0..n)
            .map(|j| manual_stc_db((j as f64 + 0.5) * sample_m, level_db, range_m, law))
            .collect(),
        Stc::Auto { level_db } => auto_stc_db(&video, n, level_db),
    };
    // 3–4. Log amplifier and FTC, sweep by sweep.
    let dt_s = 2.0 * sample_m / SPEED_OF_LIGHT_M_PER_S;
    let ftc = settings.ftc_time_constant_s.map(|tau| Ftc::new(tau, dt_s));
    let dynamic_range = settings.log_dynamic_range_db;
    video
        .par_chunks_mut(n)
        .for_each(|sweep| sweep_log_video(sweep, &stc_db, dynamic_range, ftc));
    let log_video = video;
    // 5. Interference rejection across sweeps.
    let log_video = if settings.interference_rejection == InterferenceRejection::Off {
        log_video
    } else {
        let mut out = vec![0f32; sweeps * n];
        out.par_chunks_mut(n).enumerate().for_each(|(k, o)| {
            reject_interference(&log_video, n, k, settings.interference_rejection, o)
        });
        out
    };
    // 6–8. Onto the video spokes (the nearest sweep, and the peak of the sweeps nearest
    // each), echo averaging, gain and quantisation. Without averaging the sweeps are
    // quantised first and sampled as levels: the quantiser is monotone, so the nearest
    // sweep's level and the peak of levels are the level of the nearest sweep and of the
    // peak — the same bytes for a fraction of the work.
    let spokes = settings.video_spokes;
    let (threshold, span, max_level) = (
        settings.threshold_db(),
        settings.video_span_db,
        settings.max_level(),
    );
    let q = |v: f32| quantise(v, threshold, span, max_level);
    let averaging = settings.echo_average_scans > 1 && history.is_some();
    let mut levels = if averaging {
        let mut grid = azimuth_sample(&log_video, sweeps, spokes, n, f32::max);
        if let Some(h) = history {
            echo_average(h, settings.echo_average_scans, &mut grid);
        }
        grid.par_iter().map(|&v| q(v)).collect()
    } else {
        let swept: Vec<u8> = log_video.par_iter().map(|&v| q(v)).collect();
        azimuth_sample(&swept, sweeps, spokes, n, u8::max)
    };
    // 9. Noise rejection.
    if settings.noise_rejection {
        let before = levels.clone();
        levels
            .par_chunks_mut(n)
            .enumerate()
            .for_each(|(s, row)| clear_lone_samples(&before, spokes, n, s, row));
    }
    // 10. Echo stretch along range.
    let stretch = settings.echo_stretch_samples;
    if stretch > 0 {
        levels
            .par_chunks_mut(n)
            .for_each(|row| stretch_row(row, stretch));
    }
    Video {
        spokes,
        samples: n,
        bits: settings.video_bits,
        sample_m,
        threshold_db: threshold,
        level_step_db: span / f32::from(max_level),
        levels,
    }
}

/// Rows of `sweeps × n` onto `spokes` rows: each the nearest sweep's row
/// (`round(s·sweeps/spokes) mod sweeps`), and with more sweeps than spokes, the `peak` with
/// every sweep whose nearest spoke it is.
fn azimuth_sample<T: Copy + Default + Send + Sync>(
    rows: &[T],
    sweeps: usize,
    spokes: usize,
    n: usize,
    peak: fn(T, T) -> T,
) -> Vec<T> {
    let mut grid = vec![T::default(); spokes * n];
    grid.par_chunks_mut(n).enumerate().for_each(|(s, o)| {
        let k = ((s as f64 * sweeps as f64 / spokes as f64).round() as usize) % sweeps;
        o.copy_from_slice(&rows[k * n..(k + 1) * n]);
    });
    if sweeps > spokes {
        for k in 0..sweeps {
            let s = ((k as f64 * spokes as f64 / sweeps as f64).round() as usize) % spokes;
            let (o, v) = (&mut grid[s * n..(s + 1) * n], &rows[k * n..(k + 1) * n]);
            for (a, &b) in o.iter_mut().zip(v) {
                *a = peak(*a, b);
            }
        }
    }
    grid
}

/// Echo averaging of this scan's log video `grid` into `history` over up to `scans` scans:
/// the running mean with weight `1/min(n, scans)`, written back into `grid`.
fn echo_average(history: &mut EchoHistory, scans: u32, grid: &mut [f32]) {
    if history.mean_db.len() != grid.len() {
        history.mean_db.clear();
        history.scans = 0;
    }
    history.scans += 1;
    if history.scans == 1 {
        history.mean_db.clear();
        history.mean_db.extend_from_slice(grid);
        return;
    }
    let w = 1.0 / history.scans.min(scans) as f32;
    for (m, g) in history.mean_db.iter_mut().zip(grid.iter_mut()) {
        *m += w * (*g - *m);
        *g = *m;
    }
}

/// Clears the samples of spoke `s` (in `row`) whose four neighbours in `levels` are all 0.
fn clear_lone_samples(levels: &[u8], spokes: usize, n: usize, s: usize, row: &mut [u8]) {
    let at = |s: usize, j: usize| levels[s * n + j];
    let (prev, next) = ((s + spokes - 1) % spokes, (s + 1) % spokes);
    for j in 0..n {
        if row[j] == 0 {
            continue;
        }
        let left = j > 0 && at(s, j - 1) > 0;
        let right = j + 1 < n && at(s, j + 1) > 0;
        let across = spokes > 1 && (at(prev, j) > 0 || at(next, j) > 0);
        if !(left || right || across) {
            row[j] = 0;
        }
    }
}

/// Each sample the largest of itself and the `stretch` samples before it, in place.
fn stretch_row(row: &mut [u8], stretch: usize) {
    for j in (0..row.len()).rev() {
        let lo = j.saturating_sub(stretch);
        row[j] = row[lo..=j].iter().copied().max().unwrap_or(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ReceiverSpec;

    fn settings(f: impl FnOnce(&mut ReceiverSpec)) -> VideoSettings {
        let mut s = ReceiverSpec::default();
        f(&mut s);
        VideoSettings::from_spec(&s).unwrap()
    }

    #[test]
    fn log_amplifier_is_linear_near_the_noise_and_saturates() {
        assert!((log_video_db(1.0, 80.0) - 10.0 * 2f32.log10()).abs() < 1e-6);
        assert!((log_video_db(1e6, 80.0) - 60.0).abs() < 1e-3);
        assert_eq!(log_video_db(1e12, 80.0), 80.0);
        assert!(log_video_db(1e-4, 80.0) < 1e-3);
    }

    /// The table-driven log amplifier against the exact `10·log10(1 + 10^{x/10})`.
    #[test]
    fn log_amplifier_of_db_matches_the_exact_curve() {
        for i in 0..200_000 {
            let x = -120.0 + i as f64 * 0.001;
            let exact = 10.0 * (1.0 + 10f64.powf(x / 10.0)).log10();
            let fast = f64::from(log_video_of_db(x as f32, 200.0));
            assert!((fast - exact).abs() < 5e-5, "{x}: {fast} vs {exact}");
        }
        assert_eq!(log_video_of_db(95.0, 80.0), 80.0);
    }

    #[test]
    fn quantiser_levels_step_from_the_threshold() {
        // 4 bits over 30 dB: 2 dB a level above the threshold 6 dB.
        assert_eq!(quantise(5.99, 6.0, 30.0, 15), 0);
        assert_eq!(quantise(6.0, 6.0, 30.0, 15), 1);
        assert_eq!(quantise(7.99, 6.0, 30.0, 15), 1);
        assert_eq!(quantise(8.0, 6.0, 30.0, 15), 2);
        assert_eq!(quantise(33.99, 6.0, 30.0, 15), 14);
        assert_eq!(quantise(34.0, 6.0, 30.0, 15), 15);
        assert_eq!(quantise(300.0, 6.0, 30.0, 15), 15);
        assert_eq!(quantise(f32::NAN, 6.0, 30.0, 15), 0);
    }

    #[test]
    fn stretch_and_noise_rejection_match_direct_rules() {
        let mut row = vec![0u8, 3, 0, 0, 5, 0, 0, 0];
        stretch_row(&mut row, 2);
        assert_eq!(row, vec![0, 3, 3, 3, 5, 5, 5, 0]);
        // 3 spokes × 4 samples: a lone 2 at (0, 1), a pair at (1, 2) and (2, 2).
        let levels = vec![0, 2, 0, 0, 0, 0, 4, 0, 0, 0, 1, 0];
        let mut out = levels.clone();
        for s in 0..3 {
            clear_lone_samples(&levels, 3, 4, s, &mut out[s * 4..(s + 1) * 4]);
        }
        assert_eq!(out, vec![0, 0, 0, 0, 0, 0, 4, 0, 0, 0, 1, 0]);
    }

    /// The whole chain on a synthetic record against the stage formulas, sample by sample.
    #[test]
    fn chain_matches_its_stages_on_a_record() {
        let (spokes, bins) = (16, 100);
        let db: Vec<f32> = (0..spokes * bins)
            .map(|i| ((i * 7919) % 37) as f32 - 5.0)
            .collect();
        let record = PolarRecord {
            db: &db,
            spokes,
            bins,
            bin_m: 10.0,
            range_m: 1000.0,
        };
        let s = settings(|s| {
            s.video_spokes = Some(32);
            s.video_samples = Some(50);
            s.video_bits = Some(8);
            s.stc = Some(crate::choice::StcMode::Manual);
            s.stc_range_m = Some(600.0);
        });
        let v = run(&s, &record, None);
        assert_eq!((v.spokes, v.samples, v.levels.len()), (32, 50, 1600));
        for sv in 0..32 {
            let k = ((sv as f64 * 0.5).round() as usize) % spokes;
            for j in 0..50 {
                let peak = db[k * bins + 2 * j].max(db[k * bins + 2 * j + 1]);
                let a = manual_stc_db((j as f64 + 0.5) * 20.0, 20.0, 600.0, 3.0);
                let video = log_video_db(10f32.powf(0.1 * (peak - a)), 80.0);
                let want = quantise(video, 6.0, 40.0, 255);
                let got = v.levels[sv * 50 + j];
                assert!(got.abs_diff(want) <= 1, "({sv}, {j}): {got} vs {want}");
            }
        }
    }
}
