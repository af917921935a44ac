//! Helpers shared by the integration tests: build scenes from TOML and read range profiles.
#![allow(dead_code)]

use xbandsim::constants::SPEED_OF_LIGHT_M_PER_S;
use xbandsim::scene::Scene;
use xbandsim::sim::{Frame, Simulation};

/// A scene from TOML text, panicking with the error (tests only).
pub fn scene(toml_text: &str) -> Scene {
    Scene::from_toml_str(toml_text, "test").unwrap_or_else(|e| panic!("{e}"))
}

/// Renders a scene with a seed.
pub fn render(toml_text: &str, seed: u64) -> (Simulation, Frame) {
    let sim = Simulation::new(scene(toml_text));
    let frame = sim.render(seed);
    (sim, frame)
}

/// One spoke's row of the polar output, dB.
pub fn spoke(frame: &Frame, k: usize) -> &[f32] {
    &frame.polar_db[k * frame.range_bins..(k + 1) * frame.range_bins]
}

/// Index and value of the maximum.
pub fn argmax(v: &[f32]) -> (usize, f32) {
    v.iter().enumerate().fold(
        (0, f32::MIN),
        |(bi, bv), (i, &x)| if x > bv { (i, x) } else { (bi, bv) },
    )
}

/// Range of bin `j` for a sample rate, m.
pub fn bin_range_m(j: f64, sample_rate_hz: f64) -> f64 {
    j * SPEED_OF_LIGHT_M_PER_S / (2.0 * sample_rate_hz)
}

/// A radar block with the given overrides appended (preset drs4d-nxt, radar at 4 m).
pub fn radar_block(extra: &str) -> String {
    format!("[radar]\npreset = \"drs4d-nxt\"\nposition_m = [0.0, 0.0, 4.0]\n{extra}\n")
}

/// A point object on the radar's north axis at the radar's height.
pub fn point_north(name: &str, range_m: f64, rcs_m2: f64) -> String {
    format!("[[object]]\nname = \"{name}\"\nshape = \"point\"\nrcs_m2 = {rcs_m2}\nposition_m = [0.0, {range_m}, 4.0]\n")
}

/// -3 dB width of the peak at `peak` in a dB profile, in bins (linear interpolation).
pub fn width_at_db(profile: &[f32], peak: usize, below_db: f32) -> f64 {
    let level = profile[peak] - below_db;
    let mut l = peak;
    while l > 0 && profile[l - 1] > level {
        l -= 1;
    }
    let mut r = peak;
    while r + 1 < profile.len() && profile[r + 1] > level {
        r += 1;
    }
    let left = (l - 1) as f64 + ((level - profile[l - 1]) / (profile[l] - profile[l - 1])) as f64;
    let right = r as f64 + ((profile[r] - level) / (profile[r] - profile[r + 1])) as f64;
    right - left
}
