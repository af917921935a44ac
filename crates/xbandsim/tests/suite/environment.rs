//! Sea clutter, rain and the horizon against closed forms (through `xbandsim::validation`,
//! the code `xbandsim validate` prints) and their qualitative behaviour.

use super::common::*;
use xbandsim::environment::clutter::{git_sigma0_db, nrl_sigma0_db, wind_direction_factor};
use xbandsim::labels::Visibility;
use xbandsim::validation::{
    clutter_mean_power_db, clutter_second_moment, horizon_echo, rain_attenuation_db,
    rain_clutter_power_db,
};

#[test]
fn nrl_sigma0_check_value_and_trends() {
    assert!((nrl_sigma0_db(30.0, 2.0, true, 10.0) + 36.66).abs() < 0.01);
    // Brighter with sea state and grazing angle; VV above HH at low grazing.
    assert!(nrl_sigma0_db(9.41, 4.0, true, 1.0) > nrl_sigma0_db(9.41, 2.0, true, 1.0));
    assert!(nrl_sigma0_db(9.41, 3.0, true, 3.0) > nrl_sigma0_db(9.41, 3.0, true, 0.5));
    assert!(nrl_sigma0_db(9.41, 3.0, false, 1.0) > nrl_sigma0_db(9.41, 3.0, true, 1.0));
}

#[test]
fn upwind_is_brighter_than_crosswind() {
    let psi = 1f64.to_radians();
    assert!(
        wind_direction_factor(9.41, psi, 0.0)
            > wind_direction_factor(9.41, psi, std::f64::consts::FRAC_PI_2)
    );
    assert!(
        git_sigma0_db(9.41, 4.0, true, psi, 0.0)
            > git_sigma0_db(9.41, 4.0, true, psi, std::f64::consts::FRAC_PI_2)
    );
    // Through the pipeline: mean clutter looking upwind (wind from the north) vs crosswind.
    let text = "[environment]\nnoise = false\nmultipath = false\nsea_state = 4.0\nwind_direction_deg = 0.0\nclutter_distribution = \"rayleigh\"\n[radar]\nposition_m = [0.0, 0.0, 10.0]\nspokes = 720\nmax_range_m = 1000.0\n";
    let (_, frame) = render(text, 2);
    let sector_mean = |centre_deg: f64| {
        let mut sum = 0.0;
        let mut n = 0;
        for k in 0..frame.spokes {
            let az = k as f64 * 360.0 / frame.spokes as f64;
            let d = (az - centre_deg + 540.0) % 360.0 - 180.0;
            if d.abs() < 10.0 {
                for &v in &spoke(&frame, k)[300..600] {
                    sum += 10f64.powf(v as f64 / 10.0);
                    n += 1;
                }
            }
        }
        10.0 * (sum / n as f64).log10()
    };
    let up = sector_mean(0.0);
    let cross = sector_mean(90.0);
    assert!(
        up > cross + 1.0,
        "upwind {up:.1} dB, crosswind {cross:.1} dB"
    );
}

#[test]
fn mean_clutter_power_follows_radar_equation_and_fades_with_range() {
    let (e1, m1) = clutter_mean_power_db(400);
    let (e2, m2) = clutter_mean_power_db(800);
    assert!(
        (e1 - m1).abs() < 1.0 && (e2 - m2).abs() < 1.0,
        "{e1} {m1} {e2} {m2}"
    );
    assert!(
        m1 > m2 + 6.0,
        "clutter does not fade with range: {m1} vs {m2}"
    );
}

#[test]
fn k_distribution_second_moment() {
    for nu in [1.0, 2.0] {
        let (m, n) = clutter_second_moment(&format!("clutter_shape_nu = {nu}"));
        assert!(n >= 1_000_000, "{n} samples");
        let expected = 2.0 * (1.0 + 1.0 / nu);
        assert!(
            (m / expected - 1.0).abs() < 0.05,
            "nu {nu}: {m:.3} vs {expected}"
        );
    }
    let (m, _) = clutter_second_moment("clutter_distribution = \"rayleigh\"");
    assert!((m / 2.0 - 1.0).abs() < 0.03, "Rayleigh: {m}");
}

#[test]
fn rain_attenuation_and_reflectivity() {
    let (e, m) = rain_attenuation_db(16.0);
    assert!((e - m).abs() < 0.1, "{e} {m}");
    let (e, m) = rain_clutter_power_db(8.0, 700);
    assert!((e - m).abs() < 1.0, "{e} {m}");
}

#[test]
fn horizon_hides_targets_and_truth_says_so() {
    let horizon_m = 4120.0 * (16f64.sqrt() + 9f64.sqrt());
    let (echo, vis) = horizon_echo(horizon_m * 0.98);
    assert!(echo && vis == Visibility::Visible);
    let (echo, vis) = horizon_echo(horizon_m * 1.02);
    assert!(!echo && vis == Visibility::BeyondHorizon);
}

/// The texture drifts: frame 1's clutter is strongly correlated with frame 0's mean pattern
/// but not identical, and the same seed and frame reproduce it exactly.
#[test]
fn clutter_drifts_and_is_deterministic() {
    let text = "[environment]\nnoise = false\nmultipath = false\nsea_state = 4.0\nclutter_correlation_m = 60.0\n[radar]\nposition_m = [0.0, 0.0, 10.0]\nspokes = 256\nmax_range_m = 800.0\n";
    let sim = xbandsim::sim::Simulation::new(scene(text));
    let a = sim.render_frame(9, 0).polar_db;
    let b = sim.render_frame(9, 0).polar_db;
    assert!(a == b);
    let c = sim.render_frame(9, 1).polar_db;
    assert!(a != c);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let d = pool.install(|| sim.render_frame(9, 0).polar_db);
    assert!(a == d, "clutter depends on the thread count");
}

#[test]
fn bad_environment_values_are_named() {
    for (line, field) in [
        ("sea_state = 9.0", "environment.sea_state"),
        ("clutter_model = \"xyz\"", "environment.clutter_model"),
        (
            "clutter_distribution = \"gauss\"",
            "environment.clutter_distribution",
        ),
        (
            "rain_rate_mm_per_h = -1.0",
            "environment.rain_rate_mm_per_h",
        ),
        ("sea_temperature_c = 80.0", "environment.sea_temperature_c"),
        ("polarisation = \"XY\"", "environment.polarisation"),
    ] {
        let err = xbandsim::scene::Scene::from_toml_str(&format!("[environment]\n{line}\n"), "t")
            .unwrap_err()
            .to_string();
        assert!(err.contains(field), "{line}: {err}");
    }
    let err = xbandsim::scene::Scene::from_toml_str(
        "[environment]\n[[environment.rain_cell]]\nradius_m = 100.0\nrate_mm_per_h = 5.0\n",
        "t",
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("environment.rain_cell[0].centre_m"), "{err}");
}
