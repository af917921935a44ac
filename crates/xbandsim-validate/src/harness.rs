//! Building blocks of the checks: validation scenes as TOML text, rendering them through the
//! real pipeline, and measuring compressed profiles.

use xbandsim::constants::SPEED_OF_LIGHT_M_PER_S;
use xbandsim::model::Scene;
use xbandsim::{Frame, Simulation};

/// A free-space scene head (no sea reflections) and a `[radar]` block on the drs4d-nxt
/// preset at 4 m with extra lines: the closed forms below are for free space.
pub fn radar_block(extra: &str) -> String {
    format!("[environment]\nmultipath = false\nclutter = false\n[radar]\npreset = \"drs4d-nxt\"\nposition_m = [0.0, 0.0, 4.0]\n{extra}\n")
}

/// As [`radar_block`], with receiver noise off too.
pub fn radar_block_no_noise(extra: &str) -> String {
    format!("[environment]\nmultipath = false\nclutter = false\nnoise = false\n[radar]\npreset = \"drs4d-nxt\"\nposition_m = [0.0, 0.0, 4.0]\n{extra}\n")
}

/// A point object at `range_m` due north at the radar's height.
pub fn point_north(name: &str, range_m: f64, rcs_m2: f64) -> String {
    format!("[[object]]\nname = \"{name}\"\nshape = \"point\"\nrcs_m2 = {rcs_m2}\nposition_m = [0.0, {range_m}, 4.0]\n")
}

/// Range of bin `j` for sample rate `fs`, m.
pub fn bin_range_m(j: f64, sample_rate_hz: f64) -> f64 {
    j * SPEED_OF_LIGHT_M_PER_S / (2.0 * sample_rate_hz)
}

/// Renders scene TOML (which must be valid: validation scenes are built here).
pub fn render_text(text: &str, seed: u64) -> (Simulation, Frame) {
    let scene = Scene::from_toml_str(text, "validation").expect("validation scene is valid");
    let sim = Simulation::new(scene);
    let frame = sim.render(seed);
    (sim, frame)
}

/// Row `k` of a frame's polar output.
pub fn spoke(frame: &Frame, k: usize) -> &[f32] {
    &frame.polar_db[k * frame.range_bins..(k + 1) * frame.range_bins]
}

/// Index and value of the largest element.
pub fn argmax(v: &[f32]) -> (usize, f32) {
    v.iter().enumerate().fold(
        (0, f32::MIN),
        |(bi, bv), (i, &x)| if x > bv { (i, x) } else { (bi, bv) },
    )
}

/// Width of the peak at `peak` where it is `below_db` down, in bins (linear interpolation).
pub fn width_at_db(profile: &[f32], peak: usize, below_db: f32) -> f64 {
    let level = profile[peak] - below_db;
    let (mut l, mut r) = (peak, peak);
    while l > 1 && profile[l - 1] > level {
        l -= 1;
    }
    while r + 2 < profile.len() && profile[r + 1] > level {
        r += 1;
    }
    let left = (l - 1) as f64 + ((level - profile[l - 1]) / (profile[l] - profile[l - 1])) as f64;
    let right = r as f64 + ((profile[r] - level) / (profile[r] - profile[r + 1])) as f64;
    right - left
}

/// Distance from the peak to the first local minimum on its right, bins.
pub fn first_null_bins(profile: &[f32], peak: usize) -> usize {
    let mut j = peak + 1;
    while j + 1 < profile.len() && profile[j + 1] < profile[j] {
        j += 1;
    }
    j - peak
}

/// Peak sidelobe level of a compressed profile, dB (largest value outside the main lobe's
/// first nulls, relative to the peak).
pub fn pslr_db(p: &[f32]) -> f32 {
    let (peak, pv) = argmax(p);
    let r = peak + first_null_bins(p, peak);
    let mut l = peak.saturating_sub(1);
    while l > 0 && p[l - 1] < p[l] {
        l -= 1;
    }
    let side = p[..l]
        .iter()
        .chain(&p[r..])
        .cloned()
        .fold(f32::MIN, f32::max);
    side - pv
}
