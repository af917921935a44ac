//! The operator's display and the plot extractor (docs/rl.md, "Display and plots"): each
//! refreshed spoke of the polar record goes through the library's receiver video chain
//! (`xbandsim::receiver::video_chain`: the sea clutter control's STC ahead of the log
//! amplifier, then the rain clutter control's FTC differentiator), and the gain sets the
//! threshold of the picture's gray scale; then plots: the 4-connected groups of cells at
//! least [`DETECTION_MARGIN_DB`] over the threshold, each with its power-weighted centre. Pure
//! functions with explicit scratch, no allocation per step once the buffers have grown.

use xbandsim::processing::plots::group_cells;
use xbandsim::receiver::video_chain::{manual_stc_db, quantise};

/// Range inside which the sea clutter control acts, m.
pub const STC_RANGE_M: f64 = 1000.0;

/// Span of the gray scale above the gain's threshold, dB.
pub const DISPLAY_SPAN_DB: f32 = 30.0;

/// The log amplifier's dynamic range in the display chain, dB over the noise.
pub const LOG_DYNAMIC_RANGE_DB: f32 = 80.0;

/// The STC's attenuation at `range_m` for law `k`, dB (0 at and beyond [`STC_RANGE_M`]).
pub fn stc_db(range_m: f64, k: f32) -> f32 {
    manual_stc_db(range_m, f32::INFINITY, STC_RANGE_M, k)
}

/// Gray level of log video `value_db` with the gain's threshold `floor_db`: 0 under it, then
/// 255 levels over [`DISPLAY_SPAN_DB`] (the receiver's 8-bit quantiser).
#[inline]
pub fn gray_level(value_db: f32, floor_db: f32) -> u8 {
    quantise(value_db, floor_db, DISPLAY_SPAN_DB, 255)
}

/// A cell is a hit when its processed value is at least this much over the gain's floor, dB.
pub const DETECTION_MARGIN_DB: f32 = 6.0;

pub use xbandsim::processing::plots::{Plot, PlotScratch};

/// Plots among the spokes `rows` (indices into the `spokes × bins` record `processed_db`) of
/// cells at least `threshold_db`, grouped by the library's extractor
/// (`xbandsim::processing::plots::group_cells`): groups join across neighbouring spokes
/// (wrapping through north) and neighbouring bins, each cell weighted by its linear power over
/// the threshold. Appends to `plots`.
#[allow(clippy::too_many_arguments)]
pub fn extract_plots(
    processed_db: &[f32],
    spokes: usize,
    bins: usize,
    range_bin_m: f64,
    rows: &[bool],
    threshold_db: f32,
    scratch: &mut PlotScratch,
    plots: &mut Vec<Plot>,
) {
    let value = |k: usize, j: usize| processed_db[k * bins + j];
    group_cells(
        spokes,
        bins,
        range_bin_m,
        |j| j as f64 * range_bin_m,
        |k, j| rows[k] && value(k, j) >= threshold_db,
        |k, j| 10f64.powf(0.1 * f64::from(value(k, j) - threshold_db)),
        value,
        scratch,
        plots,
    );
}

/// Range gate of a plot-to-target match, m.
pub const RANGE_GATE_M: f64 = 45.0;

/// Azimuth gate of a plot-to-target match, degrees (about the beamwidth).
pub const AZIMUTH_GATE_DEG: f64 = 4.0;

/// Whether a plot at (`range_m`, `azimuth_deg`) falls in the gate of a target at
/// (`target_range_m`, `target_azimuth_deg`); the normalised distance when it does.
pub fn gate_distance(
    range_m: f64,
    azimuth_deg: f64,
    target_range_m: f64,
    target_azimuth_deg: f64,
) -> Option<f64> {
    let dr = (range_m - target_range_m).abs() / RANGE_GATE_M;
    let da = ((azimuth_deg - target_azimuth_deg + 180.0).rem_euclid(360.0) - 180.0).abs()
        / AZIMUTH_GATE_DEG;
    (dr <= 1.0 && da <= 1.0).then(|| dr.hypot(da))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stc_follows_its_law() {
        assert_eq!(stc_db(500.0, 0.0), 0.0);
        assert_eq!(stc_db(STC_RANGE_M, 3.0), 0.0);
        assert!((stc_db(100.0, 3.0) - 30.0).abs() < 1e-4);
        assert!((stc_db(100.0, 2.0) - 20.0).abs() < 1e-4);
        assert!((stc_db(500.0, 1.0) - 10.0 * 2f32.log10()).abs() < 1e-4);
        assert!((stc_db(10.0, 3.0) - 60.0).abs() < 1e-4);
    }

    #[test]
    fn plots_group_connected_cells_across_north() {
        let (spokes, bins) = (8, 10);
        let mut rec = vec![0f32; spokes * bins];
        // One group across north (spokes 7 and 0 at bin 4), one lone cell at spoke 3, bin 8.
        rec[7 * bins + 4] = 20.0;
        rec[4] = 20.0;
        rec[3 * bins + 8] = 15.0;
        let rows = vec![true; spokes];
        let mut plots = Vec::new();
        extract_plots(
            &rec,
            spokes,
            bins,
            10.0,
            &rows,
            10.0,
            &mut PlotScratch::default(),
            &mut plots,
        );
        assert_eq!(plots.len(), 2);
        let across = plots.iter().find(|p| p.cells == 2).unwrap();
        assert!((across.range_m - 40.0).abs() < 1e-9);
        // Equal weights at 315° and 0°: the circular mean 337.5°.
        assert!((across.azimuth_deg - 337.5).abs() < 1e-9, "{across:?}");
        let lone = plots.iter().find(|p| p.cells == 1).unwrap();
        assert!((lone.azimuth_deg - 135.0).abs() < 1e-9 && lone.peak_db == 15.0);
        // Rows not refreshed give no plots.
        let mut rows = vec![true; spokes];
        rows[3] = false;
        plots.clear();
        extract_plots(
            &rec,
            spokes,
            bins,
            10.0,
            &rows,
            10.0,
            &mut PlotScratch::default(),
            &mut plots,
        );
        assert_eq!(plots.len(), 1);
    }

    #[test]
    fn gates() {
        assert!(gate_distance(1000.0, 359.0, 1010.0, 1.0).is_some());
        assert!(gate_distance(1000.0, 10.0, 1010.0, 1.0).is_none());
        assert!(gate_distance(1100.0, 1.0, 1000.0, 1.0).is_none());
    }
}
