//! Land checks: a flat land top's mean return against the constant-γ radar equation through
//! the matched filter, the shadow behind a cliff and the horizon against geometry, and a
//! target hidden by land leaving no echo (docs/physics.md §16, docs/validation.md).

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use xbandsim::constants::{linear_to_db, SPEED_OF_LIGHT_M_PER_S};
use xbandsim::engine::{Request, Simulation};
use xbandsim::land::profile::elevation_rad;
use xbandsim::model::Scene;
use xbandsim::propagation::EFFECTIVE_EARTH_RADIUS_M;
use xbandsim::rng::FrameKey;
use xbandsim::signal::clutter_map::ClutterMap;

const SOURCE: &str = "constant-γ land clutter σ0 = γ·sin ψ (Long, Radar Reflectivity of Land and Sea, 2001; Nathanson, Radar Design Principles, 1999); docs/physics.md §16";

/// A scene with one rectangular island `[x0, y0, x1, y1]` of `island` (its table's lines).
fn island_text(radar: &str, environment: &str, rect: [f64; 4], island: &str) -> String {
    let [x0, y0, x1, y1] = rect;
    format!(
        "[radar]\n{radar}\n[environment]\n{environment}\n[[land]]\nname = \"isle\"\npolygon_m = [[{x0}, {y0}], [{x1}, {y0}], [{x1}, {y1}], [{x0}, {y1}]]\n{island}\n"
    )
}

/// Mean land power (dB over the radar equation) of a flat land top 5 m high seen from 30 m,
/// in the matched-filter output from 2.2 to 2.4 km over the island's 2048-spoke bearings
/// (±40°, γ −12 dB, Weibull shape 4, noise off), against `γ·sin ψ·A_c` bin by bin,
/// `A_c = g·(∫Gn²)·(c/2B)·sec ψ`, `sin ψ = (h − H)/r − r/2a_e`, the elevation gain at the
/// land's elevation. Returns (expected 0, measured).
pub fn flat_land_mean_power_db() -> (f64, f64) {
    let text = island_text(
        "position_m = [0.0, 0.0, 30.0]\nmax_range_m = 2600.0\nspokes = 2048",
        "noise = false\nclutter = false\nmultipath = false",
        [-2600.0, 1500.0, 2600.0, 3000.0],
        "height_m = 5.0\ngamma_db = -12.0\nweibull_shape = 4.0",
    );
    let scene = Scene::from_toml_str(&text, "validation").expect("validation scene is valid");
    let sim = Simulation::new(scene);
    let radar = sim.scene().radar();
    let env = sim.scene().environment();
    let (h, top) = (radar.position_m().z, 5.0);
    let gamma = 10f64.powf((-12.0 + 5.0 * (radar.carrier_freq_hz() / 1e10).log10()) / 10.0);
    let beam = radar.antenna().azimuth().two_way_integral_rad();
    let expected_at = |bin: usize| {
        let r = bin as f64 * radar.range_bin_m();
        let g = (r * r - h * h).sqrt();
        let sin_psi = (h - top) / r - r / (2.0 * EFFECTIVE_EARTH_RADIUS_M);
        let psi = sin_psi.asin();
        let area =
            g * beam * SPEED_OF_LIGHT_M_PER_S / (2.0 * radar.chirp().bandwidth_hz) / psi.cos();
        let alpha = elevation_rad(top, g, h, true);
        radar.point_target_snr(gamma * sin_psi * area, r)
            * radar.antenna().elevation_pattern(alpha).powi(2)
            * env.attenuation_power(r)
    };
    let groups = sim.echo_groups(&sim.trace());
    let map = sim.clutter_map(FrameKey::new(5, 0));
    let polar = sim
        .synthesize(&groups, map.as_ref(), &Request::new(5))
        .expect("the frozen scan of this radar");
    let row = radar.num_range_bins();
    let spokes: Vec<usize> = (0..radar.spokes())
        .filter(|&k| {
            radar.spoke_azimuth_rad(k).sin().abs() < 40f64.to_radians().sin()
                && radar.spoke_azimuth_rad(k).cos() > 0.0
        })
        .collect();
    let (lo, hi) = (
        (2200.0 / radar.range_bin_m()) as usize,
        (2400.0 / radar.range_bin_m()) as usize,
    );
    let (mut got, mut want) = (0.0, 0.0);
    for bin in lo..hi {
        want += expected_at(bin) * spokes.len() as f64;
        got += spokes
            .iter()
            .map(|&k| 10f64.powf(polar[k * row + bin] as f64 / 10.0))
            .sum::<f64>();
    }
    (0.0, linear_to_db(got / want))
}

/// Where the sea behind a 10 m cliff-edged island (far edge 1400 m north) is seen again from
/// 20 m: the map's first sample in view past the island on spoke 0, and the geometry's
/// `−h/g − g/2a_e = (H − h)/g_e − g_e/2a_e`. Returns (expected m, measured m, range bin m).
pub fn cliff_shadow_end_m() -> (f64, f64, f64) {
    let text = island_text(
        "position_m = [0.0, 0.0, 20.0]\nmax_range_m = 6000.0\nspokes = 360",
        "sea_state = 3\nclutter = true",
        [-2000.0, 1000.0, 2000.0, 1400.0],
        "height_m = 10.0",
    );
    let scene = Scene::from_toml_str(&text, "validation").expect("validation scene is valid");
    let radar = scene.radar();
    let (h, top, edge) = (radar.position_m().z, 10.0, 1400.0);
    let dr = radar.range_bin_m();
    let samples = (radar.max_range_m() / dr) as usize + 2;
    let map = ClutterMap::new(radar, scene.environment(), FrameKey::new(3, 0), samples)
        .expect("land makes a map");
    let a2 = 2.0 * EFFECTIVE_EARTH_RADIUS_M;
    let c = (top - h) / edge - edge / a2;
    let expected = (-c - (c * c - 4.0 * h / a2).sqrt()) / (2.0 / a2);
    let ground = |n: usize| ((n as f64 * dr).powi(2) - h * h).max(0.0).sqrt();
    let first = (0..samples)
        .find(|&n| ground(n) > edge + 1.0 && map.surface_seen(0, n))
        .expect("the sea comes back into view");
    (expected, ground(first), dr)
}

/// The echo of a mountain `top_m` high whose cliff face stands 40 km off, seen from 15 m
/// (radar horizon 16 km): the map's mean land power summed over the face's samples on
/// spoke 0, and γ times its part above the hidden height `(d − √(2a_e·h))²/2a_e` through
/// the radar equation (0 when it is wholly hidden). Returns (closed form, measured), linear.
pub fn mountain_face_power(top_m: f64) -> (f64, f64) {
    let text = island_text(
        "position_m = [0.0, 0.0, 15.0]\nmax_range_m = 42000.0\nspokes = 90\npulse_width_us = 1.0",
        "clutter = false\ntwo_way_attenuation_db_per_km = 0.0",
        [-8000.0, 40000.0, 8000.0, 41000.0],
        &format!("height_m = {top_m}\ngamma_db = 0.0"),
    );
    let scene = Scene::from_toml_str(&text, "validation").expect("validation scene is valid");
    let radar = scene.radar();
    let h = radar.position_m().z;
    let dr = radar.range_bin_m();
    let samples = (radar.max_range_m() / dr) as usize + 2;
    let map = ClutterMap::new(radar, scene.environment(), FrameKey::new(3, 0), samples)
        .expect("land makes a map");
    let d = 40000.0;
    let hidden = (d - (2.0 * EFFECTIVE_EARTH_RADIUS_M * h).sqrt()).powi(2)
        / (2.0 * EFFECTIVE_EARTH_RADIUS_M);
    let n0 = (d / dr) as usize;
    let measured: f64 = (n0 - 3..n0 + 4)
        .map(|n| map.land_mean_power(0, n) as f64)
        .sum();
    let gamma = 10f64.powf(5.0 * (radar.carrier_freq_hz() / 1e10).log10() / 10.0);
    let k_noise = radar.radar_equation_constant_w_m2() / radar.noise_power_w();
    let beam = radar.antenna().azimuth().two_way_integral_rad();
    let alpha = elevation_rad(0.5 * (top_m + hidden), d, h, true);
    let want = gamma
        * d
        * beam
        * (top_m - hidden).max(0.0)
        * k_noise
        * radar.antenna().elevation_pattern(alpha).powi(2)
        / d.powi(4);
    (want, measured)
}

/// The largest change, dB, a boat hidden behind a 30 m island (seen from 15 m, clutter and
/// noise on) makes to any cell of the polar output: 0 when land takes all of its echo.
pub fn hidden_boat_change_db() -> f64 {
    let island = "[radar]\nposition_m = [0.0, 0.0, 15.0]\nmax_range_m = 2500.0\nspokes = 360\n[environment]\nsea_state = 3\nclutter = true\n[[land]]\npolygon_m = [[-300.0, 1000.0], [300.0, 1000.0], [300.0, 1400.0], [-300.0, 1400.0]]\nheight_m = 30.0\n";
    let boat = "[[object]]\nname = \"hidden\"\nshape = \"sphere\"\nradius_m = 2.0\nposition_m = [0.0, 1700.0, 2.0]\n";
    let (_, without) = render_text(island, 7);
    let (_, with) = render_text(&format!("{island}{boat}"), 7);
    assert_eq!(
        with.truth[0].visibility,
        xbandsim::Visibility::ShadowedByLand,
        "the boat behind the island is labelled shadowed by land"
    );
    with.polar_db
        .iter()
        .zip(&without.polar_db)
        .map(|(a, b)| (a - b).abs() as f64)
        .fold(0.0, f64::max)
}

/// RCS (dBsm) of a quay wall at the sea's edge: a box structure `width_m` wide across the
/// beam, 10 m deep and `height_m` high whose face stands broadside at ground range
/// `range_m` from an antenna `antenna_m` high, the sea smooth and reflecting. Measured: its
/// matched-filter peak over that of a 1 m² point at the face's middle without multipath.
/// Expected: physical optics of the face lit directly and via the sea (image theory; Knott,
/// Shaeffer & Tuley, *Radar Cross Section*, 2nd ed., ch. 5 and §13 on dihedrals), each
/// height `z` of the face lit by `E(z) = e^{−jkr_d} + Γ_H·e^{−jkr_r}` (`r_d`, `r_r` from
/// the antenna and from its image below the sea) and radiating back the same way:
/// `σ = (4π/λ²)·W²·|∫₀^H E(z)² dz|²`. The middle term `2Γ_H·H` is the wall–sea dihedral:
/// `σ → 16π|Γ|²W²H²/λ²`, four times the face alone. Returns (expected, measured).
pub fn quay_wall_rcs_dbsm(range_m: f64, antenna_m: f64, width_m: f64, height_m: f64) -> (f64, f64) {
    let radar = format!(
        "position_m = [0.0, 0.0, {antenna_m}]\nspokes = 1\nsample_rate_mhz = 800.0\nmax_range_m = {}",
        range_m + 200.0
    );
    let env = |multipath: bool| {
        format!("noise = false\nclutter = false\nsea_rms_height_m = 0.0\nearth_curvature = false\nmultipath = {multipath}")
    };
    let (w, h2) = (0.5 * width_m, range_m + 10.0);
    let quay = format!(
        "[radar]\n{radar}\n[environment]\n{}\n[[structure]]\nname = \"quay\"\nkind = \"quay\"\npolygon_m = [[{}, {range_m}], [{w}, {range_m}], [{w}, {h2}], [{}, {h2}]]\nheight_m = {height_m}\n",
        env(true), -w, -w
    );
    let point = format!(
        "[radar]\n{radar}\n[environment]\n{}\n[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 1.0\nposition_m = [0.0, {range_m}, {}]\n",
        env(false),
        0.5 * height_m
    );
    let peak = |text: &str| {
        let (sim, frame) = render_text(text, 1);
        let j = (range_m / sim.scene().radar().range_bin_m()).round() as usize;
        let row = spoke(&frame, 0);
        let p = row[j.saturating_sub(6)..(j + 7).min(row.len())]
            .iter()
            .cloned()
            .fold(f32::MIN, f32::max) as f64;
        (p, sim)
    };
    let (p_quay, sim) = peak(&quay);
    let (p_point, _) = peak(&point);
    let scene = sim.scene();
    let lambda = scene.radar().wavelength_m();
    let k = 2.0 * std::f64::consts::PI / lambda;
    let sea = scene.environment().sea().expect("the sea reflects");
    // ∫₀^H E(z)² dz by the midpoint rule, 4000 steps (phase steps under 0.01 rad).
    let steps = 4000;
    let dz = height_m / steps as f64;
    let r0 = (range_m * range_m + antenna_m * antenna_m).sqrt();
    let mut sum = num_complex::Complex64::new(0.0, 0.0);
    for i in 0..steps {
        let z = (i as f64 + 0.5) * dz;
        let r_d = (range_m * range_m + (antenna_m - z).powi(2)).sqrt();
        let r_r = (range_m * range_m + (antenna_m + z).powi(2)).sqrt();
        let grazing = ((antenna_m + z) / range_m).atan();
        let (gamma_h, _) = sea.reflection(grazing, lambda);
        let e = num_complex::Complex64::from_polar(1.0, -k * (r_d - r0))
            + gamma_h * num_complex::Complex64::from_polar(1.0, -k * (r_r - r0));
        sum += e * e * dz;
    }
    let sigma = 4.0 * std::f64::consts::PI / (lambda * lambda) * width_m * width_m * sum.norm_sqr();
    (linear_to_db(sigma), p_quay - p_point)
}

pub(crate) fn checks(out: &mut Checks) {
    let (e, m) = quay_wall_rcs_dbsm(1500.0, 15.0, 4.0, 3.0);
    out.push(check(
        "land: a quay wall (4 m × 3 m) at the sea's edge returns its wall–sea dihedral RCS",
        e,
        m,
        "dBsm",
        Tolerance::Absolute(0.3),
        "physical optics with image theory over the sea (Knott, Shaeffer & Tuley, Radar Cross Section, 2nd ed., ch. 5); docs/physics.md §16",
    ));
    let (e, m) = flat_land_mean_power_db();
    out.push(check(
        "land: mean return of a flat land top (5 m, seen from 30 m) = γ·sin ψ·A_c radar equation",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.3),
        SOURCE,
    ));
    let (e, m, bin) = cliff_shadow_end_m();
    out.push(check(
        "land: the sea's shadow behind a 10 m cliff seen from 20 m ends where geometry says",
        e,
        m,
        "m",
        Tolerance::Absolute(bin),
        "line of sight over the 4/3 earth (Skolnik, Introduction to Radar Systems, 3rd ed., §8.2); docs/physics.md §16",
    ));
    let (e, m) = mountain_face_power(200.0);
    out.push(check(
        "land: a 200 m mountain 40 km off returns γ times its face above the hidden height",
        0.0,
        linear_to_db(m / e),
        "dB",
        Tolerance::Absolute(0.1),
        "hidden height (d − √(2a_e·h))²/2a_e over the 4/3 earth; docs/physics.md §16",
    ));
    out.push(check(
        "land: a boat behind a 30 m island changes no cell of the picture",
        0.0,
        hidden_boat_change_db(),
        "dB",
        Tolerance::Absolute(0.0),
        "land blocks the line of sight and the sea paths; docs/physics.md §16",
    ));
}
