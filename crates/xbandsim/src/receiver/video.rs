//! Receiver: the operator's display controls on a spoke of video in dB over noise (the RL
//! environments' gain, sea and rain controls; docs/rl.md, "Display and plots"): the rain
//! clutter control ([`super::stages::Ftc`] on the spoke's linear power), the sea clutter
//! control (sensitivity lowered by [`super::stages::stc_loss_db`] inside [`STC_RANGE_M`]) and
//! the gain (the gray scale's floor, [`gray_level`]). Pure functions with explicit scratch,
//! no allocation once the buffers have grown.

use super::stages::{stc_loss_db, Ftc};

/// Range inside which the sea clutter control acts, m.
pub const STC_RANGE_M: f64 = 1000.0;

/// Half-width of the FTC's local mean along range, bins.
pub const FTC_HALF_WINDOW_BINS: usize = 8;

/// Span of the gray scale above the floor, dB.
pub const DISPLAY_SPAN_DB: f32 = 30.0;

/// Smallest value the FTC leaves, as a power over noise (−30 dB).
pub const FTC_FLOOR_POWER: f32 = 1e-3;

/// STC loss at range `range_m` for law `k`, dB (0 at and beyond [`STC_RANGE_M`]; ranges under
/// 1 m count as 1 m).
pub fn stc_db(range_m: f64, k: f32) -> f32 {
    stc_loss_db(range_m, k, STC_RANGE_M)
}

/// One spoke through the operator's controls: `row_db` (dB over noise) becomes the processed
/// value `FTC(row) − STC(R)` in `out` (dB). `ftc_fraction` α takes `α·mean` of the
/// `2·FTC_HALF_WINDOW_BINS + 1` cells around each cell (linear power) off it; `power` is
/// scratch of the row's length.
pub fn process_spoke(
    row_db: &[f32],
    range_bin_m: f64,
    ftc_fraction: f32,
    stc_law: f32,
    power: &mut [f32],
    out: &mut [f32],
) {
    let n = row_db.len();
    if ftc_fraction > 0.0 {
        for (p, &d) in power.iter_mut().zip(row_db) {
            *p = 10f32.powf(0.1 * d);
        }
        let ftc = Ftc {
            fraction: ftc_fraction,
            half_window_bins: FTC_HALF_WINDOW_BINS,
            floor_power: FTC_FLOOR_POWER,
        };
        ftc.apply(&power[..n], &mut out[..n]);
        for o in out[..n].iter_mut() {
            *o = 10.0 * o.log10();
        }
    } else {
        out.copy_from_slice(row_db);
    }
    if stc_law > 0.0 {
        for (j, o) in out.iter_mut().enumerate() {
            let r = j as f64 * range_bin_m;
            if r >= STC_RANGE_M {
                break;
            }
            *o -= stc_db(r, stc_law);
        }
    }
}

/// Gray level of a processed value with the gain's floor `floor_db`: 0 at the floor, 255 at
/// `floor + DISPLAY_SPAN_DB`.
#[inline]
pub fn gray_level(value_db: f32, floor_db: f32) -> u8 {
    let t = ((value_db - floor_db) / DISPLAY_SPAN_DB).clamp(0.0, 1.0);
    crate::special::round_to_u8(t * 255.0)
}
