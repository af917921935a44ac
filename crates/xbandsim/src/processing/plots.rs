//! Stage: plot extraction — what a radar's plot extractor makes of a revolution
//! (docs/physics.md §15). Each spoke is run through a CFAR detector along range
//! ([`super::cfar`]); the detected cells are grouped into plots, 4-connected across range
//! and azimuth (wrapping through north); each plot has a power-weighted centroid range and a
//! circular-mean bearing `atan2(Σw·sin a, Σw·cos a)`, its extent in range and azimuth, its
//! cell count and its peak power. A scan-to-scan correlator ([`ScanCorrelator`]) keeps,
//! as an option, only the plots that recur within a gate on enough of the last scans
//! (binary M-of-N integration; Skolnik, *Radar Handbook*, 3rd ed., §7.4 on scan-to-scan
//! correlation of marine radar plots).
//!
//! The extractor runs on the calibrated record (power over the mean noise,
//! [`PowerGrid::from_record_db`]) or on the receiver's video ([`PowerGrid::from_video`]),
//! whose levels map back to the power at each level's lower edge. The design false-alarm
//! probability holds for the square-law record's exponential noise; on video it is a setting,
//! and the measured rate is what counts.
//!
//! Sidelobe editing ([`SidelobeEditor`], an option): a strong echo reaches the spokes off its
//! bearing through the antenna's sidelobes at `Gn(Δaz)²` of its peak (docs/physics.md §3), and
//! the CFAR detects it there as plots at the strong echo's range. A plot is removed as such an
//! echo when a stronger plot overlaps it in range and its peak is no more than a margin over
//! the stronger peak plus `20·log10` of the pattern's envelope at their bearing difference
//! (the plot editing of Skolnik, *Radar Handbook*, 3rd ed., §7.4; the envelope is the
//! pattern's largest value within half a first-null width on the same side beyond the first
//! null, so that a plot between two of the pattern's nulls is judged by the sidelobe it sits
//! on and never by the main lobe).
//!
//! `products::plot_truth` scores plots against a frame's truth.
//!
//! The CFAR pass allocates nothing per cell (each worker reuses its scratch); grouping is one
//! flood fill over the detection mask.

use super::cfar::Cfar;
use crate::antenna::Pattern;
use crate::error::{Error, Problem, Result};
use crate::receiver::video_chain::Video;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::VecDeque;
use std::f64::consts::TAU;

/// A revolution's cells as linear power over the mean noise, `spokes × cells` row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct PowerGrid {
    /// Spokes (rows); spoke k at azimuth `360°·k/spokes`.
    pub spokes: usize,
    /// Cells a spoke (columns).
    pub cells: usize,
    /// Range a cell spans, m.
    pub cell_m: f64,
    /// Range of cell j is `(j + range_offset_cells)·cell_m`.
    pub range_offset_cells: f64,
    /// The powers, row-major.
    pub power: Vec<f32>,
}

impl PowerGrid {
    /// The calibrated record (`polar.npy`: dB over the mean noise, bin j at `j·bin_m`).
    pub fn from_record_db(db: &[f32], spokes: usize, bins: usize, bin_m: f64) -> PowerGrid {
        assert_eq!(db.len(), spokes * bins, "spokes × bins values");
        PowerGrid {
            spokes,
            cells: bins,
            cell_m: bin_m,
            range_offset_cells: 0.0,
            power: db.iter().map(|&d| 10f32.powf(0.1 * d)).collect(),
        }
    }

    /// The receiver's video: level ℓ ≥ 1 stands for the log video at its lower edge,
    /// `v = threshold_db + (ℓ − 1)·level_step_db`, and so for the power `10^(v/10) − 1` over
    /// the noise (the log amplifier inverted, floored at 0); level 0 for power 0. Sample j
    /// spans `[j, j + 1)·sample_m`, so its range is its centre's.
    pub fn from_video(video: &Video) -> PowerGrid {
        let power_of_level: Vec<f32> = (0..=255u32)
            .map(|level| {
                if level == 0 {
                    0.0
                } else {
                    let v = video.threshold_db + (level - 1) as f32 * video.level_step_db;
                    (10f32.powf(0.1 * v) - 1.0).max(0.0)
                }
            })
            .collect();
        PowerGrid {
            spokes: video.spokes,
            cells: video.samples,
            cell_m: video.sample_m,
            range_offset_cells: 0.5,
            power: video
                .levels
                .iter()
                .map(|&l| power_of_level[l as usize])
                .collect(),
        }
    }

    /// Range of cell `j`, m.
    pub fn range_m(&self, j: usize) -> f64 {
        (j as f64 + self.range_offset_cells) * self.cell_m
    }
}

/// A plot: one group of connected detected cells.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Plot {
    /// Power-weighted range of its cells, m.
    pub range_m: f64,
    /// Power-weighted circular-mean bearing, degrees from north (0 … 360).
    pub azimuth_deg: f64,
    /// Range from its nearest to its farthest cell, both whole, m.
    pub range_extent_m: f64,
    /// Azimuth from its first to its last spoke, both whole, degrees (at most 360).
    pub azimuth_extent_deg: f64,
    /// Cells in it.
    pub cells: usize,
    /// Its strongest cell's power over the noise, dB.
    pub peak_db: f32,
    /// Its strongest cell: (spoke, cell).
    pub peak_cell: (usize, usize),
    /// Its first and last spoke, clockwise (`first > last` when it spans north).
    pub spokes: (usize, usize),
    /// Its nearest and farthest cell.
    pub range_cells: (usize, usize),
}

impl Plot {
    /// Its centroid on the radar's plane: (east, north), m.
    pub fn east_north_m(&self) -> [f64; 2] {
        let az = self.azimuth_deg.to_radians();
        [self.range_m * az.sin(), self.range_m * az.cos()]
    }
}

/// Reused buffers of the grouping pass.
#[derive(Debug, Default)]
pub struct PlotScratch {
    seen: Vec<bool>,
    stack: Vec<(usize, usize)>,
    /// Whether the plot being grown has a cell on each spoke, and those spokes.
    on_spoke: Vec<bool>,
    spokes_hit: Vec<usize>,
}

/// The clockwise span `(first, last, count)` of the sorted distinct spokes `hit` on a circle
/// of `spokes`: everything but the largest run of spokes without a cell.
fn spoke_span(hit: &[usize], spokes: usize) -> (usize, usize, usize) {
    if hit.len() == spokes {
        return (0, spokes - 1, spokes);
    }
    // The gap after hit[i] runs to hit[i + 1] (circularly); the largest one is left out.
    let (mut widest, mut after) = (0, 0);
    for i in 0..hit.len() {
        let next = hit[(i + 1) % hit.len()];
        let gap = (next + spokes - hit[i]) % spokes;
        let gap = if gap == 0 { spokes } else { gap };
        if gap > widest {
            widest = gap;
            after = i;
        }
    }
    let first = hit[(after + 1) % hit.len()];
    let last = hit[after];
    (first, last, spokes - widest + 1)
}

/// Groups the cells for which `is_hit(spoke, cell)` holds into plots, 4-connected along
/// range and azimuth (spoke `spokes − 1` next to spoke 0), in raster order of each plot's
/// first cell. Each cell weighs `weight(spoke, cell)` in the centroid; `value_db` gives the
/// peak; `range_m(cell)` the range of a cell and `cell_m` its length. Appends to `plots`.
#[allow(clippy::too_many_arguments)]
pub fn group_cells(
    spokes: usize,
    cells: usize,
    cell_m: f64,
    range_m: impl Fn(usize) -> f64,
    is_hit: impl Fn(usize, usize) -> bool,
    weight: impl Fn(usize, usize) -> f64,
    value_db: impl Fn(usize, usize) -> f32,
    scratch: &mut PlotScratch,
    plots: &mut Vec<Plot>,
) {
    let seen = &mut scratch.seen;
    seen.clear();
    seen.resize(spokes * cells, false);
    let stack = &mut scratch.stack;
    scratch.on_spoke.clear();
    scratch.on_spoke.resize(spokes, false);
    for k0 in 0..spokes {
        for j0 in 0..cells {
            if seen[k0 * cells + j0] || !is_hit(k0, j0) {
                continue;
            }
            seen[k0 * cells + j0] = true;
            stack.clear();
            stack.push((k0, j0));
            let (mut w, mut wr, mut wc, mut ws) = (0f64, 0f64, 0f64, 0f64);
            let (mut count, mut peak, mut peak_cell) = (0usize, f32::NEG_INFINITY, (k0, j0));
            let (mut j_lo, mut j_hi) = (j0, j0);
            scratch.spokes_hit.clear();
            while let Some((k, j)) = stack.pop() {
                let v = value_db(k, j);
                let cell_weight = weight(k, j);
                let az = TAU * k as f64 / spokes as f64;
                w += cell_weight;
                wr += cell_weight * range_m(j);
                wc += cell_weight * az.cos();
                ws += cell_weight * az.sin();
                count += 1;
                if v > peak {
                    peak = v;
                    peak_cell = (k, j);
                }
                j_lo = j_lo.min(j);
                j_hi = j_hi.max(j);
                if !scratch.on_spoke[k] {
                    scratch.on_spoke[k] = true;
                    scratch.spokes_hit.push(k);
                }
                let neighbours = [
                    ((k + 1) % spokes, j),
                    ((k + spokes - 1) % spokes, j),
                    (k, j + 1),
                    (k, j.wrapping_sub(1)),
                ];
                for (kn, jn) in neighbours {
                    if jn < cells && !seen[kn * cells + jn] && is_hit(kn, jn) {
                        seen[kn * cells + jn] = true;
                        stack.push((kn, jn));
                    }
                }
            }
            scratch.spokes_hit.sort_unstable();
            for &k in &scratch.spokes_hit {
                scratch.on_spoke[k] = false;
            }
            let (first, last, spanned) = spoke_span(&scratch.spokes_hit, spokes);
            plots.push(Plot {
                range_m: wr / w,
                azimuth_deg: ws.atan2(wc).rem_euclid(TAU).to_degrees(),
                range_extent_m: (j_hi - j_lo + 1) as f64 * cell_m,
                azimuth_extent_deg: 360.0 * spanned as f64 / spokes as f64,
                cells: count,
                peak_db: peak,
                peak_cell,
                spokes: (first, last),
                range_cells: (j_lo, j_hi),
            });
        }
    }
}

/// A plot extractor: a CFAR detector along range, the smallest plot kept and, as an option,
/// sidelobe editing.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotExtractor {
    cfar: Cfar,
    min_cells: usize,
    sidelobes: Option<SidelobeEditor>,
}

impl PlotExtractor {
    /// An extractor with `cfar` that keeps plots of at least `min_cells` cells (refused,
    /// naming `plots.min_cells`, below 1).
    pub fn new(cfar: Cfar, min_cells: usize) -> Result<PlotExtractor> {
        if min_cells == 0 {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "plots.min_cells",
                min_cells,
                "a plot has at least one cell",
            ));
        }
        Ok(PlotExtractor {
            cfar,
            min_cells,
            sidelobes: None,
        })
    }

    /// The same extractor, removing the plots `editor` finds to be sidelobe echoes.
    pub fn with_sidelobe_editing(self, editor: SidelobeEditor) -> PlotExtractor {
        PlotExtractor {
            sidelobes: Some(editor),
            ..self
        }
    }

    /// Its sidelobe editor, if it has one.
    pub fn sidelobe_editor(&self) -> Option<&SidelobeEditor> {
        self.sidelobes.as_ref()
    }

    /// Its detector.
    pub fn cfar(&self) -> &Cfar {
        &self.cfar
    }

    /// The detection mask of `grid`, spoke by spoke on all cores (same cells as `grid`).
    pub fn detect(&self, grid: &PowerGrid) -> Vec<bool> {
        let mut detected = vec![false; grid.power.len()];
        if grid.cells == 0 {
            return detected;
        }
        grid.power
            .par_chunks(grid.cells)
            .zip(detected.par_chunks_mut(grid.cells))
            .for_each_init(Vec::new, |scratch, (row, flags)| {
                self.cfar.detect(row, flags, scratch)
            });
        detected
    }

    /// The plots of `grid`: its detections grouped, each weighted by its power.
    pub fn extract(&self, grid: &PowerGrid, scratch: &mut PlotScratch) -> Vec<Plot> {
        let detected = self.detect(grid);
        let mut plots = Vec::new();
        let at = |k: usize, j: usize| k * grid.cells + j;
        group_cells(
            grid.spokes,
            grid.cells,
            grid.cell_m,
            |j| grid.range_m(j),
            |k, j| detected[at(k, j)],
            |k, j| f64::from(grid.power[at(k, j)]),
            |k, j| 10.0 * grid.power[at(k, j)].log10(),
            scratch,
            &mut plots,
        );
        plots.retain(|p| p.cells >= self.min_cells);
        if let Some(editor) = &self.sidelobes {
            editor.edit(&mut plots);
        }
        plots
    }
}

/// Sidelobe editing: removes the plots that a stronger plot at their range explains as its
/// echo through the antenna's azimuth sidelobes (the module's docs give the rule).
#[derive(Debug, Clone, PartialEq)]
pub struct SidelobeEditor {
    /// `20·log10` of the pattern's envelope, dB, every [`SIDELOBE_TABLE_STEP_DEG`] from −180°
    /// to 180° off the axis.
    envelope_db: Vec<f32>,
    /// Bearing differences under this are inside the main lobe and never edited, degrees.
    first_null_deg: f64,
    margin_db: f64,
}

/// Step of the sidelobe editor's envelope table, degrees.
pub const SIDELOBE_TABLE_STEP_DEG: f64 = 0.05;

impl SidelobeEditor {
    /// The editor of the one-way azimuth power pattern `pattern`, allowing a sidelobe echo
    /// `margin_db` over its expected level (refused, naming `plots.sidelobe_margin_db`, when
    /// it is not a finite number of dB at least 0).
    pub fn new(pattern: &Pattern, margin_db: f64) -> Result<SidelobeEditor> {
        if !(margin_db.is_finite() && margin_db >= 0.0) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "plots.sidelobe_margin_db",
                margin_db,
                "must be a finite number of dB, 0 or more",
            ));
        }
        // Every step from −180° to 180°: a measured cut need not be symmetric.
        let per_side = (180.0 / SIDELOBE_TABLE_STEP_DEG).round() as usize;
        let n = 2 * per_side + 1;
        let angle_deg = |i: usize| (i as f64 - per_side as f64) * SIDELOBE_TABLE_STEP_DEG;
        let two_way_db: Vec<f64> = (0..n)
            .map(|i| 20.0 * pattern.value(angle_deg(i).to_radians()).max(1e-30).log10())
            .collect();
        let first_null_deg = pattern.first_null_rad().to_degrees();
        let half = ((first_null_deg / 2.0) / SIDELOBE_TABLE_STEP_DEG).ceil() as usize;
        let null_steps = ((first_null_deg / SIDELOBE_TABLE_STEP_DEG).ceil() as usize).min(per_side);
        // The window stays on its side of the main lobe: beyond the first null.
        let envelope_db = (0..n)
            .map(|i| {
                let (mut lo, mut hi) = (i.saturating_sub(half), (i + half).min(n - 1));
                if i >= per_side {
                    lo = lo.max(per_side + null_steps);
                } else {
                    hi = hi.min(per_side - null_steps);
                }
                if lo > hi {
                    return two_way_db[i] as f32;
                }
                two_way_db[lo..=hi].iter().copied().fold(f64::MIN, f64::max) as f32
            })
            .collect();
        Ok(SidelobeEditor {
            envelope_db,
            first_null_deg,
            margin_db,
        })
    }

    /// The margin over the expected sidelobe level, dB.
    pub fn margin_db(&self) -> f64 {
        self.margin_db
    }

    /// The two-way envelope for a target `off_axis_deg` from the beam's axis (positive
    /// clockwise, wrapped into (−180°, 180°]), dB.
    pub fn envelope_db(&self, off_axis_deg: f64) -> f64 {
        let off = off_axis_deg.rem_euclid(360.0);
        let off = if off > 180.0 { off - 360.0 } else { off };
        let per_side = (self.envelope_db.len() - 1) / 2;
        let i = (off / SIDELOBE_TABLE_STEP_DEG).round() as i64 + per_side as i64;
        f64::from(self.envelope_db[i.clamp(0, self.envelope_db.len() as i64 - 1) as usize])
    }

    /// Whether `weak` may be `strong`'s echo through the sidelobes: they overlap in range
    /// (within a cell), `weak` lies beyond the main lobe's first null, and its peak is at most
    /// the margin over `strong`'s peak plus the envelope at their bearing difference.
    pub fn explains(&self, strong: &Plot, weak: &Plot) -> bool {
        let overlap = weak.range_cells.0 <= strong.range_cells.1 + 1
            && strong.range_cells.0 <= weak.range_cells.1 + 1;
        if !overlap || weak.peak_db > strong.peak_db {
            return false;
        }
        // The beam on `weak`'s bearing sees `strong` this far off its axis.
        let off = (strong.azimuth_deg - weak.azimuth_deg).rem_euclid(360.0);
        let off = if off > 180.0 { off - 360.0 } else { off };
        off.abs() >= self.first_null_deg
            && f64::from(weak.peak_db)
                <= f64::from(strong.peak_db) + self.envelope_db(off) + self.margin_db
    }

    /// Removes from `plots` every plot a stronger kept plot explains; returns how many went.
    /// The strongest are judged first, so a removed plot explains no others.
    pub fn edit(&self, plots: &mut Vec<Plot>) -> usize {
        let mut order: Vec<usize> = (0..plots.len()).collect();
        order.sort_by(|&a, &b| {
            plots[b]
                .peak_db
                .total_cmp(&plots[a].peak_db)
                .then(a.cmp(&b))
        });
        let mut kept: Vec<usize> = Vec::new();
        let mut removed = vec![false; plots.len()];
        for &i in &order {
            if kept.iter().any(|&k| self.explains(&plots[k], &plots[i])) {
                removed[i] = true;
            } else {
                kept.push(i);
            }
        }
        let before = plots.len();
        let mut index = 0;
        plots.retain(|_| {
            index += 1;
            !removed[index - 1]
        });
        before - plots.len()
    }
}

/// Scan-to-scan correlation: a plot is confirmed when plots within `gate_m` of it were seen
/// on at least `hits − 1` of the previous `scans − 1` scans (binary `hits`-of-`scans`
/// integration of plots on the radar's plane).
#[derive(Debug, Clone)]
pub struct ScanCorrelator {
    hits: usize,
    scans: usize,
    gate_m: f64,
    history: VecDeque<Vec<[f64; 2]>>,
}

impl ScanCorrelator {
    /// Refused, naming the field (`plots.scan_hits`, `plots.scan_window`,
    /// `plots.scan_gate_m`): hits outside `1 ..= scans`, more than 64 scans, a gate not
    /// positive and finite.
    pub fn new(hits: usize, scans: usize, gate_m: f64) -> Result<ScanCorrelator> {
        if !(1..=64).contains(&scans) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "plots.scan_window",
                scans,
                "must be between 1 and 64 scans",
            ));
        }
        if !(1..=scans).contains(&hits) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "plots.scan_hits",
                hits,
                format!("must be between 1 and the window's {scans} scans"),
            ));
        }
        if !(gate_m.is_finite() && gate_m > 0.0) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "plots.scan_gate_m",
                gate_m,
                "must be a positive distance in metres",
            ));
        }
        Ok(ScanCorrelator {
            hits,
            scans,
            gate_m,
            history: VecDeque::new(),
        })
    }

    /// This scan's confirmed plots; remembers the scan's plots for the next ones.
    pub fn confirm(&mut self, plots: Vec<Plot>) -> Vec<Plot> {
        let here: Vec<[f64; 2]> = plots.iter().map(Plot::east_north_m).collect();
        let gate2 = self.gate_m * self.gate_m;
        let confirmed = plots
            .into_iter()
            .zip(&here)
            .filter(|(_, p)| {
                let seen_before = self
                    .history
                    .iter()
                    .filter(|scan| {
                        scan.iter()
                            .any(|q| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) <= gate2)
                    })
                    .count();
                seen_before + 1 >= self.hits
            })
            .map(|(plot, _)| plot)
            .collect();
        if self.scans > 1 {
            if self.history.len() == self.scans - 1 {
                self.history.pop_front();
            }
            self.history.push_back(here);
        }
        confirmed
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::processing::cfar::CfarKind;

    fn grid(spokes: usize, cells: usize, power: Vec<f32>) -> PowerGrid {
        PowerGrid {
            spokes,
            cells,
            cell_m: 10.0,
            range_offset_cells: 0.0,
            power,
        }
    }

    /// Every group by a brute-force union of neighbouring hits (repeated relaxation of each
    /// cell's label to its neighbours' smallest), as sorted cell counts.
    fn naive_group_sizes(hit: &[bool], spokes: usize, cells: usize) -> Vec<usize> {
        let mut label: Vec<usize> = (0..hit.len()).collect();
        loop {
            let mut changed = false;
            for k in 0..spokes {
                for j in 0..cells {
                    let i = k * cells + j;
                    if !hit[i] {
                        continue;
                    }
                    let mut neighbours = vec![((k + 1) % spokes) * cells + j];
                    neighbours.push(((k + spokes - 1) % spokes) * cells + j);
                    if j + 1 < cells {
                        neighbours.push(i + 1);
                    }
                    if j > 0 {
                        neighbours.push(i - 1);
                    }
                    for n in neighbours {
                        if hit[n] && label[n] < label[i] {
                            label[i] = label[n];
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                break;
            }
        }
        let mut sizes = std::collections::BTreeMap::new();
        for (i, &h) in hit.iter().enumerate() {
            if h {
                *sizes.entry(label[i]).or_insert(0usize) += 1;
            }
        }
        let mut sizes: Vec<usize> = sizes.into_values().collect();
        sizes.sort_unstable();
        sizes
    }

    /// The plots of a mask of hits, each cell weighing alike (1 m cells).
    fn group_mask(hit: &[bool], spokes: usize, cells: usize) -> Vec<Plot> {
        let mut plots = Vec::new();
        group_cells(
            spokes,
            cells,
            1.0,
            |j| j as f64,
            |k, j| hit[k * cells + j],
            |_, _| 1.0,
            |_, _| 0.0,
            &mut PlotScratch::default(),
            &mut plots,
        );
        plots
    }

    #[test]
    fn grouping_matches_a_brute_force_union_of_neighbours() {
        use rand::Rng;
        let (spokes, cells) = (37, 23);
        for seed in 0..20 {
            let mut rng =
                crate::rng::RngKey::new(seed, 0, 0, crate::rng::Stream::ReceiverNoise).rng();
            let hit: Vec<bool> = (0..spokes * cells)
                .map(|_| rng.random::<f64>() < 0.35)
                .collect();
            let plots = group_mask(&hit, spokes, cells);
            let mut sizes: Vec<usize> = plots.iter().map(|p| p.cells).collect();
            sizes.sort_unstable();
            assert_eq!(sizes, naive_group_sizes(&hit, spokes, cells), "seed {seed}");
        }
    }

    #[test]
    fn a_plot_has_its_centroid_extent_and_peak() {
        let (spokes, cells) = (360, 100);
        let mut power = vec![0f32; spokes * cells];
        // Across north: spokes 358, 359, 0, 1, 2 at cells 40..=44, peak at (0, 42).
        for k in [358, 359, 0, 1, 2] {
            for j in 40..=44 {
                power[k * cells + j] = 100.0;
            }
        }
        power[42] = 1000.0;
        let hit: Vec<bool> = power.iter().map(|&p| p > 0.0).collect();
        let mut plots = Vec::new();
        let g = grid(spokes, cells, power);
        group_cells(
            spokes,
            cells,
            g.cell_m,
            |j| g.range_m(j),
            |k, j| hit[k * cells + j],
            |k, j| f64::from(g.power[k * cells + j]),
            |k, j| 10.0 * g.power[k * cells + j].log10(),
            &mut PlotScratch::default(),
            &mut plots,
        );
        assert_eq!(plots.len(), 1);
        let p = plots[0];
        assert_eq!(p.cells, 25);
        // Symmetric about spoke 0 and cell 42.
        assert!((p.range_m - 420.0).abs() < 1e-9, "{p:?}");
        assert!(p.azimuth_deg.min(360.0 - p.azimuth_deg) < 1e-9, "{p:?}");
        assert_eq!(p.range_extent_m, 50.0);
        assert_eq!(p.azimuth_extent_deg, 5.0);
        assert_eq!((p.peak_db, p.peak_cell), (30.0, (0, 42)));
        assert_eq!((p.spokes, p.range_cells), ((358, 2), (40, 44)));
    }

    /// Plots wider than half a turn, across north, and a whole ring keep their true spans.
    #[test]
    fn wide_plots_keep_their_spans() {
        let (spokes, cells) = (360, 5);
        let span_of = |ks: &[usize]| {
            let mut hit = vec![false; spokes * cells];
            for &k in ks {
                hit[k * cells + 2] = true;
            }
            let plots = group_mask(&hit, spokes, cells);
            assert_eq!(plots.len(), 1);
            (plots[0].spokes, plots[0].azimuth_extent_deg)
        };
        let wide: Vec<usize> = (10..=200).collect();
        assert_eq!(span_of(&wide), ((10, 200), 191.0));
        let across: Vec<usize> = (300..360).chain(0..=100).collect();
        assert_eq!(span_of(&across), ((300, 100), 161.0));
        let ring: Vec<usize> = (0..360).collect();
        assert_eq!(span_of(&ring), ((0, 359), 360.0));
        assert_eq!(span_of(&[7]), ((7, 7), 1.0));
    }

    #[test]
    fn the_extractor_finds_targets_and_drops_small_plots() {
        let (spokes, cells) = (64, 400);
        let mut power = vec![1f32; spokes * cells];
        // A 3-spoke target at cell 200 and a lone bright cell at spoke 40, cell 300.
        for k in 10..13 {
            power[k * cells + 200] = 1e4;
        }
        power[40 * cells + 300] = 1e4;
        let cfar = Cfar::new(CfarKind::CellAveraging, 2, 16, 1e-6).unwrap();
        let g = grid(spokes, cells, power);
        let plots = PlotExtractor::new(cfar, 1)
            .unwrap()
            .extract(&g, &mut PlotScratch::default());
        assert_eq!(plots.len(), 2);
        assert!((plots[0].azimuth_deg - 360.0 * 11.0 / 64.0).abs() < 1e-9);
        assert_eq!(plots[0].range_m, 2000.0);
        let big = PlotExtractor::new(cfar, 2)
            .unwrap()
            .extract(&g, &mut PlotScratch::default());
        assert_eq!(big.len(), 1);
        assert_eq!(big[0].cells, 3);
        assert_eq!(
            PlotExtractor::new(cfar, 0).unwrap_err().field(),
            Some("plots.min_cells")
        );
    }

    #[test]
    fn video_levels_map_back_to_power() {
        let video = Video {
            spokes: 1,
            samples: 3,
            bits: 4,
            sample_m: 8.0,
            threshold_db: 6.0,
            level_step_db: 2.0,
            levels: vec![0, 1, 3],
        };
        let g = PowerGrid::from_video(&video);
        assert_eq!(g.power[0], 0.0);
        assert!((g.power[1] - (10f32.powf(0.6) - 1.0)).abs() < 1e-5);
        assert!((g.power[2] - (10f32.powf(1.0) - 1.0)).abs() < 1e-5);
        assert_eq!(g.range_m(1), 12.0);
    }

    fn plot_at(east: f64, north: f64) -> Plot {
        Plot {
            range_m: east.hypot(north),
            azimuth_deg: east.atan2(north).rem_euclid(TAU).to_degrees(),
            range_extent_m: 1.0,
            azimuth_extent_deg: 1.0,
            cells: 1,
            peak_db: 20.0,
            peak_cell: (0, 0),
            spokes: (0, 0),
            range_cells: (0, 0),
        }
    }

    #[test]
    fn scan_correlation_keeps_plots_that_recur() {
        // 2 of 3: a plot is confirmed when one of the two scans before had one within 50 m.
        let mut c = ScanCorrelator::new(2, 3, 50.0).unwrap();
        assert!(c.confirm(vec![plot_at(1000.0, 0.0)]).is_empty());
        let second = c.confirm(vec![plot_at(1030.0, 0.0), plot_at(0.0, 2000.0)]);
        assert_eq!(second.len(), 1);
        assert!((second[0].range_m - 1030.0).abs() < 1e-9);
        // The first scan is still in the window; a plot 60 m from everything is not.
        assert_eq!(c.confirm(vec![plot_at(1000.0, 40.0)]).len(), 1);
        assert!(c.confirm(vec![plot_at(1000.0, 200.0)]).is_empty());
        // Once a scan leaves the window it no longer counts: only the last two are held.
        assert!(c.confirm(vec![plot_at(0.0, 2000.0)]).is_empty());
        // 1 of 1 keeps everything.
        let mut all = ScanCorrelator::new(1, 1, 10.0).unwrap();
        assert_eq!(all.confirm(vec![plot_at(5.0, 5.0)]).len(), 1);
        let field = |r: Result<ScanCorrelator>| r.unwrap_err().field().map(str::to_string);
        assert_eq!(
            field(ScanCorrelator::new(4, 3, 50.0)).as_deref(),
            Some("plots.scan_hits")
        );
        assert_eq!(
            field(ScanCorrelator::new(1, 0, 50.0)).as_deref(),
            Some("plots.scan_window")
        );
        assert_eq!(
            field(ScanCorrelator::new(1, 2, f64::NAN)).as_deref(),
            Some("plots.scan_gate_m")
        );
    }

    fn plot_in(azimuth_deg: f64, range_cells: (usize, usize), peak_db: f32) -> Plot {
        Plot {
            range_m: range_cells.0 as f64 * 10.0,
            azimuth_deg,
            range_extent_m: 10.0,
            azimuth_extent_deg: 1.0,
            cells: 4,
            peak_db,
            peak_cell: (0, range_cells.0),
            spokes: (0, 0),
            range_cells,
        }
    }

    /// The envelope table against a brute-force maximum of the pattern over the window, and
    /// the rule at its edges: a plot at the expected sidelobe level plus the margin goes, one
    /// 0.1 dB over it stays, as do plots at another range or inside the main lobe.
    #[test]
    fn sidelobe_editing_removes_what_the_pattern_explains_and_nothing_else() {
        let pattern = Pattern::sinc2(1.8_f64.to_radians());
        let editor = SidelobeEditor::new(&pattern, 6.0).unwrap();
        let null_deg = pattern.first_null_rad().to_degrees();
        for off in [1.1 * null_deg, 3.0, 7.3, 12.0, 25.0, 90.0] {
            // The window: half a first-null width either side, beyond the first null.
            let brute = (-2000..=2000)
                .map(|i| off + f64::from(i) * null_deg / 2.0 / 2000.0)
                .filter(|&a| a >= null_deg)
                .map(|a| 20.0 * pattern.value(a.to_radians()).max(1e-30).log10())
                .fold(f64::MIN, f64::max);
            let table = editor.envelope_db(off);
            assert!(
                (table - brute).abs() < 0.05,
                "{off}°: {table} against {brute}"
            );
            assert_eq!(editor.envelope_db(-off), table);
        }
        let strong = plot_in(100.0, (50, 52), 70.0);
        let off = 12.0;
        let expected = 70.0 + editor.envelope_db(off) as f32 + 6.0;
        let mut plots = vec![
            strong,
            plot_in(100.0 + off, (51, 51), expected - 0.01),
            plot_in(100.0 - off, (52, 53), expected + 0.1),
            plot_in(100.0 + off, (60, 61), 20.0),
            plot_in(100.0 + 0.5 * null_deg, (51, 51), 20.0),
        ];
        assert!(
            expected > 20.0,
            "the test's far plots must be under the envelope"
        );
        assert_eq!(editor.edit(&mut plots), 1);
        assert_eq!(plots.len(), 4);
        assert!(plots.iter().all(|p| p.peak_db != expected - 0.01));
        // Just past the first null the envelope is the first sidelobe's (sinc²: −26.5 dB
        // two-way), not the main lobe's: two boats at one range 1.1 nulls apart and 10 dB
        // apart are both kept.
        let first_sidelobe = editor.envelope_db(1.1 * null_deg);
        assert!((first_sidelobe + 26.5).abs() < 0.2, "{first_sidelobe}");
        let mut boats = vec![strong, plot_in(100.0 + 1.1 * null_deg, (51, 51), 60.0)];
        assert_eq!(editor.edit(&mut boats), 0);
        assert_eq!(
            SidelobeEditor::new(&pattern, -1.0)
                .err()
                .map(|e| e.to_string().contains("plots.sidelobe_margin_db")),
            Some(true)
        );
    }
}
