//! Antenna checks: the sinc² pattern's beamwidth and gain (docs/validation.md).

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use std::f64::consts::PI;
use xbandsim::antenna::{sinc2_pattern, uniform_aperture_gain, SINC_BEAMWIDTH_FACTOR};
use xbandsim::constants::linear_to_db;

/// Peak (dB) of a noise-free point target at 900 m, `az_deg` off spoke 0.
pub fn off_axis_peak_db(az_deg: f64) -> f64 {
    let range_m = bin_range_m(600.0, 100e6);
    let (x, y) = (
        range_m * az_deg.to_radians().sin(),
        range_m * az_deg.to_radians().cos(),
    );
    let text = format!("{}[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 100.0\nposition_m = [{x}, {y}, 4.0]\n", radar_block_no_noise("spokes = 360\nmax_range_m = 1200.0"));
    let (_, frame) = render_text(&text, 1);
    argmax(spoke(&frame, 0)).1 as f64
}

/// The checks of this area, in the order `xbandsim validate` prints them.
pub(crate) fn checks(out: &mut Checks) {
    const BALANIS: &str = "Balanis, Antenna Theory, 4th ed., §12.5";

    // Antenna.
    let bw = 3.9f64.to_radians();
    out.push(check(
        "antenna −3 dB at θ3dB/2",
        -3.0103,
        linear_to_db(sinc2_pattern(bw / 2.0, bw)),
        "dB",
        Tolerance::Absolute(0.01),
        BALANIS,
    ));
    let null = PI * bw / SINC_BEAMWIDTH_FACTOR;
    let sl = (0..=2000)
        .map(|i| sinc2_pattern(null * (1.0 + i as f64 / 2000.0), bw))
        .fold(0.0, f64::max);
    out.push(check(
        "antenna first sidelobe",
        -13.26,
        linear_to_db(sl),
        "dB",
        Tolerance::Absolute(0.02),
        BALANIS,
    ));
    out.push(check(
        "peak gain 4π·0.8859²/(θaz·θel), 3.9°×25°",
        25.2,
        linear_to_db(uniform_aperture_gain(bw, 25f64.to_radians())),
        "dBi",
        Tolerance::Absolute(0.05),
        BALANIS,
    ));
    let two_way = off_axis_peak_db(1.95) - off_axis_peak_db(0.0);
    out.push(check(
        "two-way pattern through the pipeline at θ3dB/2",
        -6.02,
        two_way,
        "dB",
        Tolerance::Absolute(0.1),
        "voltage ∝ G0·Gn (docs/physics.md §3)",
    ));
}
