//! Sea clutter, rain and the horizon against closed forms (through `xbandsim_validate`,
//! the code `xbandsim validate` prints) and their qualitative behaviour.

use super::common::*;
use xbandsim::engine::Request;
use xbandsim::environment::clutter::{git_sigma0_db, nrl_sigma0_db, wind_direction_factor};
use xbandsim::products::labels::Visibility;
use xbandsim_validate::{
    clutter_cell_statistics, clutter_mean_power_db, horizon_echo, rain_attenuation_db,
    rain_clutter_power_db, CLUTTER_FRAMES, CLUTTER_MOMENT_TOLERANCE,
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

/// The azimuth mean of the clutter power equals σ0·A_c in the radar equation (the
/// wind-direction factor has unit mean) within 0.3 dB, at other sea states and ranges than
/// `validate` uses.
#[test]
fn mean_clutter_power_follows_radar_equation() {
    let (e1, m1) = clutter_mean_power_db(5.0, 450.0);
    let (e2, m2) = clutter_mean_power_db(1.0, 900.0);
    assert!(
        (e1 - m1).abs() < 0.3 && (e2 - m2).abs() < 0.3,
        "SS 5 at 450 m: {m1:.2} dB from expected; SS 1 at 900 m: {m2:.2} dB"
    );
}

/// The exp(b·cos φ) wind-direction factor averages to one over look directions.
#[test]
fn wind_direction_factor_has_unit_mean() {
    for psi_deg in [0.3, 1.0, 5.0] {
        let n = 3600;
        let mean: f64 = (0..n)
            .map(|i| {
                wind_direction_factor(
                    9.41,
                    f64::to_radians(psi_deg),
                    std::f64::consts::TAU * i as f64 / n as f64,
                )
            })
            .sum::<f64>()
            / n as f64;
        assert!((mean - 1.0).abs() < 1e-9, "{psi_deg}°: {mean}");
    }
}

/// Matched-filter output cells at the default radar and clutter settings have the second
/// moment the documented parameters give (within 8 %), for shapes other than those
/// `validate` uses, and keep the texture's spatial correlation.
#[test]
fn clutter_cells_have_the_documented_statistics() {
    for lines in [
        "clutter_shape_nu = 0.8",
        "clutter_shape_nu = 4.0",
        "sea_state = 4.0\nwind_direction_deg = 120.0\nswell_direction_deg = 75.0",
        "clutter_distribution = \"weibull\"\nclutter_weibull_shape = 1.2",
        "clutter_distribution = \"lognormal\"\nclutter_lognormal_sigma_db = 4.5",
        "clutter_distribution = \"rayleigh\"",
    ] {
        let st = clutter_cell_statistics(lines, CLUTTER_FRAMES);
        eprintln!("{lines}: {st:?}");
        assert!(
            (st.measured_moment / st.expected_moment - 1.0).abs() < CLUTTER_MOMENT_TOLERANCE,
            "{lines}: E[I²]/E[I]² measured {:.3}, expected {:.3} ({} cells)",
            st.measured_moment,
            st.expected_moment,
            st.cells
        );
        if !lines.contains("rayleigh") {
            assert!(
                st.correlation_15_m > 0.1 && st.correlation_300_m.abs() < 0.03,
                "{lines}: correlation {:.3} at 15 m, {:.3} at 300 m",
                st.correlation_15_m,
                st.correlation_300_m
            );
        } else {
            assert!(st.correlation_15_m.abs() < 0.03, "{st:?}");
        }
    }
}

#[test]
fn rain_attenuation_and_reflectivity() {
    // The rain layer's own echo in the target's cell moves the peak by under 0.03 dB.
    let (e, m) = rain_attenuation_db(16.0);
    assert!((e - m).abs() < 0.05, "{e} {m}");
    // The mean of 41 bins × 1024 spokes of speckle: about 0.035 dB rms from seed to seed.
    let (e, m) = rain_clutter_power_db(8.0, 700);
    assert!((e - m).abs() < 0.15, "{e} {m}");
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
    let sim = xbandsim::engine::Simulation::new(scene(text));
    let a = sim.run(&Request::new(9)).unwrap().polar_db;
    let b = sim.run(&Request::new(9)).unwrap().polar_db;
    assert!(a == b);
    let c = sim.run(&Request::new(9).frame(1)).unwrap().polar_db;
    assert!(a != c);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let d = pool.install(|| sim.run(&Request::new(9)).unwrap().polar_db);
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
        let err = xbandsim::Scene::from_toml_str(&format!("[environment]\n{line}\n"), "t")
            .unwrap_err()
            .to_string();
        // Range errors name the dotted field; unknown choices are reported by the parser
        // with the line and the key as written.
        let key = field.rsplit('.').next().unwrap();
        assert!(
            err.contains(field) || (err.contains("line 2") && err.contains(key)),
            "{line}: {err}"
        );
    }
    let err = xbandsim::Scene::from_toml_str(
        "[environment]\n[[environment.rain_cell]]\nradius_m = 100.0\nrate_mm_per_h = 5.0\n",
        "t",
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("environment.rain_cell[0].centre_m"), "{err}");
}

/// The sea's rms height follows the sea state unless given (as documented), and the
/// roughness model is Miller–Brown–Vegh unless Ament is asked for.
#[test]
fn sea_roughness_defaults_follow_the_docs() {
    use xbandsim::environment::clutter::sea_state_rms_height_m;
    use xbandsim::propagation::SeaRoughness;
    let sea = |lines: &str| {
        scene(&format!("[environment]\n{lines}\n"))
            .environment()
            .sea()
            .copied()
            .expect("multipath is on by default")
    };
    let s = sea("sea_state = 4.0");
    assert_eq!(s.rms_height_m, sea_state_rms_height_m(4.0));
    assert!(s.rms_height_m > 0.5);
    assert_eq!(s.roughness, SeaRoughness::MillerBrownVegh);
    let s = sea("sea_state = 4.0\nsea_rms_height_m = 0.2\nsea_roughness = \"ament\"");
    assert_eq!(s.rms_height_m, 0.2);
    assert_eq!(s.roughness, SeaRoughness::Ament);
}

/// `Environment::is_same` is `==`: a clone, or the same scene parsed twice (its land in
/// another allocation), is the same; another land, sea state or rain is not.
#[test]
fn is_same_environment_is_equality() {
    let island = "[[land]]\npolygon_m = [[-50.0, 500.0], [50.0, 500.0], [50.0, 600.0], [-50.0, 600.0]]\nheight_m = 10.0\n";
    let env_of = |text: &str| {
        xbandsim::Scene::from_toml_str(text, "t")
            .unwrap()
            .environment()
            .clone()
    };
    let base = format!("[environment]\nsea_state = 3\n{island}");
    let env = env_of(&base);
    assert!(env.is_same(&env.clone()));
    assert!(env.is_same(&env_of(&base)) && env == env_of(&base));
    for other in [
        base.replace("height_m = 10.0", "height_m = 11.0"),
        base.replace("sea_state = 3", "sea_state = 4"),
        format!("{base}[[environment.rain_cell]]\ncentre_m = [0.0, 300.0]\nradius_m = 100.0\nrate_mm_per_h = 4.0\n"),
    ] {
        let other = env_of(&other);
        assert!(!env.is_same(&other) && env != other);
    }
}
