//! Physics checks of the whole pipeline against closed forms (docs/validation.md), run by
//! `xbandsim validate` and by the test suite. Each check builds a scene, runs the real
//! pipeline (scattering → echoes → noise → matched filter → polar output, or the RCS tool)
//! and compares one measured number with its closed form. docs/validation.md lists sources.

use crate::antenna::{sinc2_pattern, uniform_aperture_gain, SINC_BEAMWIDTH_FACTOR};
use crate::constants::{linear_to_db, wavelength_m, SPEED_OF_LIGHT_M_PER_S};
use crate::geometry::{PrimitiveKind, ShapeGeometry, TriangleMesh};
use crate::scattering::rcs::{RcsSettings, RcsTarget};
use crate::scene::{Polarisation, Scene, SceneObject};
use crate::sim::{Frame, Simulation};
use glam::{DMat3, DVec3};

use serde::Serialize;
use std::f64::consts::PI;
use std::sync::Arc;

/// How far a measurement may be from its expected value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", content = "value", rename_all = "snake_case")]
pub enum Tolerance {
    /// |measured − expected| ≤ value.
    Absolute(f64),
    /// |measured/expected − 1| ≤ value.
    Relative(f64),
    /// measured ≤ value (expected is the theoretical figure).
    AtMost(f64),
    /// measured ≥ value.
    AtLeast(f64),
}

impl Tolerance {
    /// Whether `measured` is acceptable against `expected`.
    pub fn accepts(&self, expected: f64, measured: f64) -> bool {
        if !measured.is_finite() {
            return false;
        }
        match *self {
            Tolerance::Absolute(t) => (measured - expected).abs() <= t,
            Tolerance::Relative(t) => (measured / expected - 1.0).abs() <= t,
            Tolerance::AtMost(t) => measured <= t,
            Tolerance::AtLeast(t) => measured >= t,
        }
    }

    /// Human-readable form, with `unit`.
    pub fn describe(&self, unit: &str) -> String {
        match *self {
            Tolerance::Absolute(t) => format!("±{t} {unit}"),
            Tolerance::Relative(t) => format!("±{}%", t * 100.0),
            Tolerance::AtMost(t) => format!("≤ {t} {unit}"),
            Tolerance::AtLeast(t) => format!("≥ {t} {unit}"),
        }
    }
}

/// The outcome of one check.
#[derive(Debug, Clone, Serialize)]
pub struct CheckResult {
    /// What is checked.
    pub name: String,
    /// Closed-form value.
    pub expected: f64,
    /// Value measured through the pipeline.
    pub measured: f64,
    /// Unit of both.
    pub unit: String,
    /// Allowed deviation.
    pub tolerance: Tolerance,
    /// Whether it passed.
    pub pass: bool,
    /// Source of the closed form.
    pub source: String,
}

fn check(
    name: &str,
    expected: f64,
    measured: f64,
    unit: &str,
    tolerance: Tolerance,
    source: &str,
) -> CheckResult {
    CheckResult {
        name: name.into(),
        expected,
        measured,
        unit: unit.into(),
        pass: tolerance.accepts(expected, measured),
        tolerance,
        source: source.into(),
    }
}

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

/// A noise-free compressed profile of a 1 m² point target beyond c·T/2, finely sampled
/// (800 MHz: 0.19 m bins), with `window` and a 10 µs pulse (B·T = 500): (profile, bin m).
pub fn fine_profile(window: &str) -> (Vec<f32>, f64) {
    let fs_mhz = 800.0;
    let range = bin_range_m(12000.0, fs_mhz * 1e6);
    let text = format!(
        "{}{}",
        radar_block_no_noise(&format!("sample_rate_mhz = {fs_mhz}\npulse_width_us = 10.0\nwindow = \"{window}\"\nmax_range_m = 2400.0\nspokes = 90")),
        point_north("p", range, 1.0)
    );
    let (_, frame) = render_text(&text, 1);
    (spoke(&frame, 0).to_vec(), frame.range_bin_m)
}

/// Measured peak over noise minus the radar equation (with window loss), dB, for a 10⁴ m²
/// point target at 8.1 km on a bin centre.
pub fn snr_error_db(window: &str, pulse_us: f64, seed: u64) -> (f64, f64) {
    let range_m = bin_range_m(5400.0, 100e6);
    let text = format!(
        "{}{}",
        radar_block(&format!(
            "window = \"{window}\"\npulse_width_us = {pulse_us}\nmax_range_m = 9000.0"
        )),
        point_north("p", range_m, 1e4)
    );
    let (sim, frame) = render_text(&text, seed);
    let radar = &sim.scene().radar;
    let expected = linear_to_db(
        radar.point_target_snr(1e4, range_m)
            * radar.window.snr_loss_linear(radar.chirp.num_samples()),
    );
    let (_, measured) = argmax(&spoke(&frame, 0)[5300..5500]);
    (expected, measured as f64)
}

/// Mean noise power over all spokes past the blanked interval, dB.
pub fn noise_mean_db(seed: u64) -> f64 {
    let (sim, frame) = render_text(&radar_block("max_range_m = 1500.0"), seed);
    let start = sim.compressor().pulse_len() + 2;
    let (mut sum, mut n) = (0.0, 0usize);
    for k in 0..frame.spokes {
        for &d in &spoke(&frame, k)[start..] {
            sum += 10f64.powf(d as f64 / 10.0);
            n += 1;
        }
    }
    linear_to_db(sum / n as f64)
}

/// Peak (dB) of a noise-free 1 m² point target at range bin `bin` with a 2 µs pulse and
/// the matched-filter `window`, and its truth.
pub fn eclipse_peak_db(
    bin: f64,
    blanking: bool,
    window: &str,
) -> (f32, crate::labels::ObjectTruth) {
    let fs = 100e6;
    let range_m = bin_range_m(bin, fs);
    let text = format!(
        "{}{}",
        radar_block_no_noise(&format!(
            "pulse_width_us = 2.0\nmax_range_m = 600.0\nreceiver_blanking = {blanking}\nwindow = \"{window}\""
        )),
        point_north("p", range_m, 1.0)
    );
    let (_, frame) = render_text(&text, 1);
    let j = bin.round() as usize;
    (
        spoke(&frame, 0)[j - 2..=j + 2]
            .iter()
            .cloned()
            .fold(f32::MIN, f32::max),
        frame.truth[0].clone(),
    )
}

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

/// A scene holding one object with the shape `fields` (TOML lines), and its RCS target.
fn shape_target(fields: &str) -> (Scene, RcsTarget) {
    let text = format!("[[object]]\nname = \"t\"\n{fields}\nposition_m = [0.0, 100.0, 0.0]\n");
    let scene = Scene::from_toml_str(&text, "validation").expect("validation shape is valid");
    let target = RcsTarget::new(&scene.objects[0]);
    (scene, target)
}

/// RCS of a shape (TOML fields) at an aspect, m².
pub fn shape_rcs_m2(
    fields: &str,
    az_rad: f64,
    el_rad: f64,
    freq_hz: f64,
    pol: Polarisation,
) -> f64 {
    let (_, t) = shape_target(fields);
    t.rcs_m2(
        az_rad,
        el_rad,
        &RcsSettings {
            freq_hz,
            polarisation: pol,
            ray_spacing_wavelengths: 0.25,
            max_rays: 1 << 20,
            max_bounces: 3,
        },
    )
}

/// RCS of a shape (TOML fields) at an aspect with a scene's default PO settings (tube side
/// λ/2, `max_rays_per_object` 32768, 3 bounces): for ship-sized objects the ray budget binds
/// and widens the tubes, m².
pub fn shape_rcs_default_budget_m2(fields: &str, az_rad: f64, el_rad: f64) -> f64 {
    let (scene, t) = shape_target(fields);
    t.rcs_m2(
        az_rad,
        el_rad,
        &RcsSettings {
            freq_hz: scene.radar.carrier_freq_hz,
            polarisation: scene.radar.polarisation,
            ray_spacing_wavelengths: scene.scattering.ray_spacing_wavelengths,
            max_rays: scene.scattering.max_rays_per_object,
            max_bounces: scene.scattering.max_bounces,
        },
    )
}

/// Mean RCS (m², linear mean) of the procedural 30 m vessel over aspects 0°…358° in 2° steps
/// at elevation 0, with tube side λ/2 and `max_rays` tubes per aspect.
pub fn vessel_mean_rcs_m2(max_rays: usize, segments: usize) -> f64 {
    let mesh = crate::geometry::mesh::vessel(30.0, segments);
    let object = SceneObject {
        name: "vessel".into(),
        class: "ship".into(),
        shape_name: "mesh".into(),
        shape: ShapeGeometry::Mesh {
            mesh: Arc::new(mesh),
        },
        position_m: DVec3::ZERO,
        rotation: DMat3::IDENTITY,
    };
    let aspects: Vec<(f64, f64)> = (0..180)
        .map(|i| ((2.0 * i as f64).to_radians(), 0.0))
        .collect();
    let rcs = RcsTarget::new(&object).sweep_m2(
        &aspects,
        &RcsSettings {
            freq_hz: 9.41e9,
            polarisation: Polarisation::Hh,
            ray_spacing_wavelengths: 0.5,
            max_rays,
            max_bounces: 3,
        },
    );
    rcs.iter().sum::<f64>() / rcs.len() as f64
}

/// Broadside RCS of a `width_m` × `height_m` flat plate lit by a spherical wave from
/// `range_m` (the near-field loss of PO, independent of the ray tubes): the PO integral
/// `S = (√(4π)/λ)·∫∫exp(−jk(x² + y²)/R) dx dy` (two-way path 2R + (x² + y²)/R), evaluated
/// by the midpoint rule, m². Tends to 4πA²/λ² far away.
pub fn plate_near_field_rcs_m2(width_m: f64, height_m: f64, range_m: f64, freq_hz: f64) -> f64 {
    let lambda = wavelength_m(freq_hz);
    let k = 2.0 * PI / lambda;
    let line = |len: f64| {
        let n = 20_000;
        let dx = len / n as f64;
        (0..n)
            .map(|i| {
                let x = -0.5 * len + (i as f64 + 0.5) * dx;
                num_complex::Complex64::from_polar(dx, -k * x * x / range_m)
            })
            .sum::<num_complex::Complex64>()
    };
    4.0 * PI / (lambda * lambda) * (line(width_m) * line(height_m)).norm_sqr()
}

/// A ship-sized plate (`width_m` × `height_m`, broadside, due north at the range of output
/// bin `bin` so that the peak is sampled without straddle loss, radar and plate 4 m up,
/// noise off) rendered with the default ray budget (which binds): the
/// (expected SNR from the radar equation with the plate's near-field PO RCS, measured peak,
/// truth's RCS in dBsm, that RCS in dBsm).
pub fn ship_plate_render_db(width_m: f64, height_m: f64, bin: usize) -> (f64, f64, f64, f64) {
    let range_m = bin_range_m(bin as f64, 100e6);
    let text = format!(
        "{}[[object]]\nname = \"hull\"\nshape = \"plate\"\nwidth_m = {width_m}\nheight_m = {height_m}\nposition_m = [0.0, {range_m}, 4.0]\nyaw_deg = 180.0\n",
        radar_block_no_noise(&format!("max_range_m = {}", range_m + 300.0))
    );
    let (sim, frame) = render_text(&text, 1);
    let radar = &sim.scene().radar;
    let rcs = plate_near_field_rcs_m2(width_m, height_m, range_m, radar.carrier_freq_hz);
    let expected = linear_to_db(radar.point_target_snr(rcs, range_m));
    let j = (range_m / radar.range_bin_m()).round() as usize;
    let measured = spoke(&frame, 0)[j - 3..j + 4]
        .iter()
        .cloned()
        .fold(f32::MIN, f32::max) as f64;
    let truth = frame.truth[0].rcs_dbsm.unwrap_or(f64::NAN);
    (expected, measured, truth, linear_to_db(rcs))
}

/// RCS of a shape built as a triangle mesh (the same surfaces as the primitive), m².
pub fn mesh_rcs_m2(triangles: &[[DVec3; 3]], az_rad: f64, freq_hz: f64) -> f64 {
    let mesh = TriangleMesh {
        vertices_m: triangles.iter().flatten().copied().collect(),
        triangles: (0..triangles.len() as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect(),
    };
    let object = SceneObject {
        name: "mesh".into(),
        class: "mesh".into(),
        shape_name: "mesh".into(),
        shape: ShapeGeometry::Mesh {
            mesh: Arc::new(mesh),
        },
        position_m: DVec3::new(0.0, 100.0, 0.0),
        rotation: DMat3::IDENTITY,
    };
    RcsTarget::new(&object).rcs_m2(
        az_rad,
        0.0,
        &RcsSettings {
            freq_hz,
            polarisation: Polarisation::Hh,
            ray_spacing_wavelengths: 0.25,
            max_rays: 1 << 20,
            max_bounces: 3,
        },
    )
}

/// The triangles of a primitive shape (plates split in two), in its object frame.
pub fn shape_triangles(shape: &ShapeGeometry) -> Vec<[DVec3; 3]> {
    shape
        .primitives(DVec3::ZERO, DMat3::IDENTITY, 0)
        .iter()
        .flat_map(|p| match p.kind {
            PrimitiveKind::Triangle { v0, e1, e2 } => vec![[v0, v0 + e1, v0 + e2]],
            PrimitiveKind::Parallelogram {
                corner,
                edge_u,
                edge_v,
            } => vec![
                [corner, corner + edge_u, corner + edge_u + edge_v],
                [corner, corner + edge_u + edge_v, corner + edge_v],
            ],
            _ => Vec::new(),
        })
        .collect()
}

/// Peak power (dB over noise, noise off) of a 1 m² point target at ground range
/// `ground_range_m` and height `target_height_m`, radar at `radar_height_m`, with the sea
/// reflecting or not.
pub fn multipath_point_power_db(
    ground_range_m: f64,
    radar_height_m: f64,
    target_height_m: f64,
    multipath: bool,
) -> f64 {
    let text = format!(
        "[environment]\nnoise = false\nclutter = false\nsea_rms_height_m = 0.0\nmultipath = {multipath}\n[radar]\nposition_m = [0.0, 0.0, {radar_height_m}]\nspokes = 1\nsample_rate_mhz = 800.0\nmax_range_m = {}\n[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 1.0\nposition_m = [0.0, {ground_range_m}, {target_height_m}]\n",
        ground_range_m * 1.05 + 50.0
    );
    let (sim, frame) = render_text(&text, 1);
    let j = (ground_range_m / sim.scene().radar.range_bin_m()).round() as usize;
    let row = spoke(&frame, 0);
    row[j.saturating_sub(4)..(j + 5).min(row.len())]
        .iter()
        .cloned()
        .fold(f32::MIN, f32::max) as f64
}

/// Ground range of the two-ray null of order `n` (path difference nλ, sea Γ ≈ −1):
/// `Δ = √(R² + (h_r+h_t)²) − √(R² + (h_r−h_t)²) = nλ`, solved exactly (bisection).
pub fn two_ray_null_range_m(
    n: f64,
    radar_height_m: f64,
    target_height_m: f64,
    wavelength_m: f64,
) -> f64 {
    let delta = |r: f64| {
        (r * r + (radar_height_m + target_height_m).powi(2)).sqrt()
            - (r * r + (radar_height_m - target_height_m).powi(2)).sqrt()
    };
    let want = n * wavelength_m;
    let (mut lo, mut hi) = (1e-3f64, 1e9f64);
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if delta(mid) > want {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo * hi).sqrt()
}

/// Ground range where the two-ray model with the sea's own Fresnel coefficient (HH, 20 °C,
/// 35 psu, smooth) has its extremum of order `n`: nulls at integer n, lobes at n + ½, where
/// `k·Δ = 2πn − δ` with `δ = π − arg Γ_H(ψ)` (Γ ≈ −1 shifts them slightly), solved by
/// iterating on the grazing angle `ψ = atan((h_r + h_t)/R)`.
pub fn two_ray_extremum_range_m(
    n: f64,
    radar_height_m: f64,
    target_height_m: f64,
    wavelength_m: f64,
) -> f64 {
    let eps = crate::environment::sea_water_permittivity(
        SPEED_OF_LIGHT_M_PER_S / wavelength_m,
        20.0,
        35.0,
    );
    let mut r = two_ray_null_range_m(n, radar_height_m, target_height_m, wavelength_m);
    for _ in 0..5 {
        let psi = ((radar_height_m + target_height_m) / r).atan();
        let (gh, _) = crate::environment::fresnel_reflection(eps, psi);
        let delta = PI - gh.arg().rem_euclid(2.0 * PI);
        r = two_ray_null_range_m(
            n - delta / (2.0 * PI),
            radar_height_m,
            target_height_m,
            wavelength_m,
        );
    }
    r
}

/// The measured null nearest to `guess_m` (golden-section search on the pipeline's output).
pub fn find_null_range_m(guess_m: f64, radar_height_m: f64, target_height_m: f64) -> f64 {
    golden_section_min(guess_m * 0.9, guess_m * 1.1, guess_m * 1e-4, |r| {
        multipath_point_power_db(r, radar_height_m, target_height_m, true)
    })
}

/// The measured lobe peak nearest to `guess_m`.
pub fn find_lobe_range_m(guess_m: f64, radar_height_m: f64, target_height_m: f64) -> f64 {
    // The lobe is broad: search the 1/R⁴-compensated power so the peak is the lobe's.
    golden_section_min(guess_m * 0.8, guess_m * 1.25, guess_m * 1e-4, |r| {
        -(multipath_point_power_db(r, radar_height_m, target_height_m, true)
            - multipath_point_power_db(r, radar_height_m, target_height_m, false))
    })
}

/// Minimum of a unimodal `f` on [a, b] to within `tol`.
fn golden_section_min(mut a: f64, mut b: f64, tol: f64, f: impl Fn(f64) -> f64) -> f64 {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    while b - a > tol {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

/// A free-space trihedral (edge 0.5 m) facing the radar on spoke 0 at a bin-centred range:
/// (radar-equation SNR with the RCS from `xbandsim rcs`'s code, measured peak), dB.
pub fn object_snr_db(two_way_attenuation_db_per_km: f64) -> (f64, f64) {
    let range_m = bin_range_m(1400.0, 100e6);
    let text = format!(
        "[environment]\nmultipath = false\nclutter = false\ntwo_way_attenuation_db_per_km = {two_way_attenuation_db_per_km}\n[radar]\nposition_m = [0.0, 0.0, 4.0]\nmax_range_m = 2500.0\n[[object]]\nname = \"t\"\nshape = \"trihedral\"\nedge_m = 0.5\nposition_m = [0.0, {range_m}, 4.0]\nyaw_deg = 180.0\n"
    );
    let (sim, frame) = render_text(&text, 11);
    let scene = sim.scene();
    let radar = &scene.radar;
    let obj = &scene.objects[0];
    // Range and aspect of the reflector's phase reference: its RCS is computed with the
    // object alone under a plane wave from the radar's direction.
    let target = RcsTarget::new(obj);
    let rcs = target.rcs_m2(
        0.0,
        0.0,
        &RcsSettings {
            freq_hz: radar.carrier_freq_hz,
            polarisation: radar.polarisation,
            ray_spacing_wavelengths: scene.scattering.ray_spacing_wavelengths,
            max_rays: scene.scattering.max_rays_per_object,
            max_bounces: scene.scattering.max_bounces,
        },
    );
    let centre_range = (obj.bounding_centre_m() - radar.position_m).length();
    let expected = linear_to_db(
        radar.point_target_snr(rcs, centre_range)
            * scene.environment.attenuation_power(centre_range),
    );
    let row = spoke(&frame, 0);
    let j = (centre_range / radar.range_bin_m()).round() as usize;
    let measured = row[j - 3..j + 4].iter().cloned().fold(f32::MIN, f32::max) as f64;
    (expected, measured)
}

/// Mean sea-clutter power (dB over noise) in the matched-filter output around `range_m`
/// (±40 bins, 4 frames of 2048 spokes, Rayleigh clutter, HH, radar at 10 m)
/// against the radar equation with `σ = σ0·A_c` bin by bin, `A_c = R·(0.753·θ3dB)·(c/2B)·sec ψ`,
/// the elevation pattern at the depression angle and σ0 from the NRL model (its azimuth
/// mean: the wind-direction factor averages to one). Returns (expected, measured), each the
/// mean over the bins of the dB ratio's linear value.
pub fn clutter_mean_power_db(sea_state: f64, range_m: f64) -> (f64, f64) {
    let text = format!("[environment]\nnoise = false\nmultipath = false\nsea_state = {sea_state}\nwind_direction_deg = 33.0\nclutter_distribution = \"rayleigh\"\n[radar]\nposition_m = [0.0, 0.0, 10.0]\nspokes = 2048\nmax_range_m = {}\n", range_m + 200.0);
    let scene = Scene::from_toml_str(&text, "validation").expect("validation scene is valid");
    let sim = Simulation::new(scene);
    let radar = &sim.scene().radar;
    let groups = sim.echo_groups(&sim.trace());
    let centre = (range_m / radar.range_bin_m()).round() as usize;
    let bins: Vec<usize> = (centre - 40..=centre + 40).collect();
    let h = radar.position_m.z;
    let expected_at = |bin: usize| {
        let r = bin as f64 * radar.range_bin_m();
        let psi = (h / r - r / (2.0 * crate::environment::EFFECTIVE_EARTH_RADIUS_M)).asin();
        let sigma0 = 10f64.powf(
            crate::environment::clutter::nrl_sigma0_db(
                radar.carrier_freq_hz / 1e9,
                sea_state,
                true,
                psi.to_degrees(),
            ) / 10.0,
        );
        let ground = (r * r - h * h).sqrt();
        let area = ground
            * crate::environment::clutter_map::two_way_beam_integral_rad(
                radar.antenna.az_beamwidth_rad,
            )
            * SPEED_OF_LIGHT_M_PER_S
            / (2.0 * radar.chirp.bandwidth_hz)
            / psi.cos();
        let el_gain = radar.antenna.elevation_pattern(-(h / r).asin()).powi(2);
        radar.point_target_snr(sigma0 * area, r) * el_gain
    };
    let frames = 4u64;
    let mut ratio = 0.0;
    for frame in 0..frames {
        let polar = sim.synthesize(&groups, 21, frame);
        let row = radar.num_range_bins();
        for &bin in &bins {
            let e = expected_at(bin);
            let m: f64 = (0..radar.spokes)
                .map(|k| 10f64.powf(polar[k * row + bin] as f64 / 10.0))
                .sum::<f64>()
                / radar.spokes as f64;
            ratio += m / e;
        }
    }
    ratio /= (frames as usize * bins.len()) as f64;
    (0.0, linear_to_db(ratio))
}

/// Frames (seeds) over which the clutter-cell statistics are measured.
pub const CLUTTER_FRAMES: u64 = 40;

/// Relative tolerance on `E[I²]/E[I]²` of clutter cells: the 8 %, which is also about
/// three standard errors of the estimate over `CLUTTER_FRAMES` frames for ν = 1.5 (the
/// texture field gives a few thousand independent values per frame).
pub const CLUTTER_MOMENT_TOLERANCE: f64 = 0.08;

/// Statistics of sea-clutter intensity in matched-filter output cells.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ClutterCellStats {
    /// `E[I²]/E[I]²` the documented distribution gives (averaged over the cells' own ν for
    /// the empirical K shape).
    pub expected_moment: f64,
    /// Measured `E[X²]/E[X]²` of `X = I/mean`, each cell's output power over its texture-free
    /// mean (which varies with range and look direction).
    pub measured_moment: f64,
    /// Correlation coefficient of X between cells 15 m apart in range (texture shared).
    pub correlation_15_m: f64,
    /// The same 300 m apart (the texture has decorrelated).
    pub correlation_300_m: f64,
    /// Cells used.
    pub cells: usize,
}

/// Renders sea clutter with the default radar and environment plus `environment_lines`
/// (noise off) for `frames` seeds, and measures the output cells from 200 m to 1400 m.
pub fn clutter_cell_statistics(environment_lines: &str, frames: u64) -> ClutterCellStats {
    use crate::environment::clutter::{k_shape_default, ClutterDistribution};
    let text = format!("[environment]\nnoise = false\nmultipath = false\n{environment_lines}\n");
    let scene = Scene::from_toml_str(&text, "validation").expect("validation scene is valid");
    let sim = Simulation::new(scene);
    let scene = sim.scene();
    let radar = &scene.radar;
    let clutter = scene.environment.clutter.as_ref().expect("clutter is on");
    let groups = sim.echo_groups(&sim.trace());
    let bin_m = radar.range_bin_m();
    let (first, last) = ((200.0 / bin_m) as usize, (1400.0 / bin_m) as usize);
    let row = radar.num_range_bins();
    let h = radar.position_m.z;
    let resolution_m = SPEED_OF_LIGHT_M_PER_S / (2.0 * radar.chirp.bandwidth_hz);
    // Each cell's expected moment (closed form; ν from Ward's formula where it is the default).
    let expected_moment_at = |k: usize, n: usize| {
        let r = n as f64 * bin_m;
        let psi = (h / r - r / (2.0 * crate::environment::EFFECTIVE_EARTH_RADIUS_M)).asin();
        let ground = (r * r - h * h).sqrt();
        let area = ground * radar.antenna.az_beamwidth_rad * resolution_m / psi.cos();
        let swell_rel = radar.spoke_azimuth_rad(k) - clutter.swell_from_rad;
        let nu = k_shape_default(
            psi.to_degrees(),
            area,
            radar.polarisation == Polarisation::Hh,
            swell_rel,
        );
        clutter.distribution.intensity_second_moment(nu)
    };
    let lag_near = (15.0 / bin_m).round() as usize;
    let lag_far = (300.0 / bin_m).round() as usize;
    let (mut s1, mut s2, mut expected, mut cells) = (0.0, 0.0, 0.0, 0usize);
    // Pairs (x, y) sums for the two lags: Σx, Σy, Σx², Σy², Σxy, count.
    let mut near = [0f64; 6];
    let mut far = [0f64; 6];
    let add = |acc: &mut [f64; 6], x: f64, y: f64| {
        acc[0] += x;
        acc[1] += y;
        acc[2] += x * x;
        acc[3] += y * y;
        acc[4] += x * y;
        acc[5] += 1.0;
    };
    let pearson = |a: &[f64; 6]| {
        let n = a[5];
        let cov = a[4] / n - a[0] / n * a[1] / n;
        let vx = a[2] / n - (a[0] / n).powi(2);
        let vy = a[3] / n - (a[1] / n).powi(2);
        cov / (vx * vy).sqrt()
    };
    for frame in 0..frames {
        let seed = 100 + frame;
        let map = sim.clutter_map(seed, 0).expect("clutter is on");
        let polar = sim.synthesize_with(&groups, Some(&map), seed, 0);
        for k in 0..radar.spokes {
            let x: Vec<f64> = (first..=last)
                .map(|n| 10f64.powf(polar[k * row + n] as f64 / 10.0) / map.mean_power(k, n) as f64)
                .collect();
            for (i, &v) in x.iter().enumerate() {
                s1 += v;
                s2 += v * v;
                cells += 1;
                if frame == 0 {
                    expected += expected_moment_at(k, first + i);
                }
                if let Some(&y) = x.get(i + lag_near) {
                    add(&mut near, v, y);
                }
                if let Some(&y) = x.get(i + lag_far) {
                    add(&mut far, v, y);
                }
            }
        }
    }
    let m1 = s1 / cells as f64;
    let _ = ClutterDistribution::Rayleigh;
    ClutterCellStats {
        expected_moment: expected / (cells as f64 / frames as f64),
        measured_moment: s2 / cells as f64 / (m1 * m1),
        correlation_15_m: pearson(&near),
        correlation_300_m: pearson(&far),
        cells,
    }
}

/// Power loss (dB) of a point target at 3 km behind uniform rain of `rate` mm/h, against
/// the same scene without rain: (expected −2·γ·R, measured).
pub fn rain_attenuation_db(rate_mm_per_h: f64) -> (f64, f64) {
    let range_m = bin_range_m(2000.0, 100e6);
    let run = |rain: f64| {
        let text = format!("[environment]\nnoise = false\nclutter = false\nmultipath = false\nrain_rate_mm_per_h = {rain}\nrain_top_m = 1.0\n[radar]\nposition_m = [0.0, 0.0, 4.0]\nmax_range_m = 3200.0\n{}", point_north("p", range_m, 10.0));
        let (_, frame) = render_text(&text, 1);
        spoke(&frame, 0)[1998..2003]
            .iter()
            .cloned()
            .fold(f32::MIN, f32::max) as f64
    };
    let gamma = crate::environment::rain::specific_attenuation_db_per_km(9.41, rate_mm_per_h, true);
    (
        -2.0 * gamma * range_m / 1000.0,
        run(rate_mm_per_h) - run(0.0),
    )
}

/// Mean rain clutter-to-noise (dB) in bin `bin` for a radar 1 km up inside uniform rain
/// (the whole beam filled), against `η·V` with `V = R²·(0.753θaz)(0.753θel)·(c/2B)` and the
/// two-way path attenuation.
pub fn rain_clutter_power_db(rate_mm_per_h: f64, bin: usize) -> (f64, f64) {
    let text = format!("[environment]\nnoise = false\nclutter = false\nmultipath = false\nearth_curvature = false\nrain_rate_mm_per_h = {rate_mm_per_h}\nrain_top_m = 20000.0\n[radar]\nposition_m = [0.0, 0.0, 1000.0]\nspokes = 1024\nmax_range_m = 1500.0\n");
    let (sim, frame) = render_text(&text, 3);
    let radar = &sim.scene().radar;
    let r = bin as f64 * radar.range_bin_m();
    let ant = &radar.antenna;
    let beam = |bw: f64| crate::environment::clutter_map::two_way_beam_integral_rad(bw);
    let volume =
        r * r * beam(ant.az_beamwidth_rad) * beam(ant.el_beamwidth_rad) * SPEED_OF_LIGHT_M_PER_S
            / (2.0 * radar.chirp.bandwidth_hz);
    let eta = crate::environment::rain::volume_reflectivity_m2_per_m3(
        rate_mm_per_h,
        radar.wavelength_m(),
    );
    let gamma = crate::environment::rain::specific_attenuation_db_per_km(
        radar.carrier_freq_hz / 1e9,
        rate_mm_per_h,
        true,
    );
    let expected = linear_to_db(radar.point_target_snr(eta * volume, r)) - 2.0 * gamma * r / 1000.0;
    let mean: f64 = (0..frame.spokes)
        .map(|k| 10f64.powf(spoke(&frame, k)[bin] as f64 / 10.0))
        .sum::<f64>()
        / frame.spokes as f64;
    (expected, linear_to_db(mean))
}

/// Whether a point target (h 9 m, radar 16 m) at `ground_range_m` returns an echo and is
/// labelled visible.
pub fn horizon_echo(ground_range_m: f64) -> (bool, crate::labels::Visibility) {
    let text = format!("[environment]\nnoise = false\nclutter = false\nmultipath = false\n[radar]\nposition_m = [0.0, 0.0, 16.0]\nmax_range_m = 31000.0\nspokes = 4\nsample_rate_mhz = 50.0\nbandwidth_mhz = 25.0\n[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 1e6\nposition_m = [0.0, {ground_range_m}, 9.0]\n");
    let (sim, frame) = render_text(&text, 1);
    (
        !sim.trace().contributions.is_empty(),
        frame.truth[0].visibility,
    )
}

/// The checks as they are made, told to an observer (for progress).
struct Checks<'a> {
    done: Vec<CheckResult>,
    on_check: &'a mut dyn FnMut(&CheckResult),
}

impl Checks<'_> {
    fn push(&mut self, c: CheckResult) {
        (self.on_check)(&c);
        self.done.push(c);
    }
}

/// Runs every check.
pub fn run_all() -> Vec<CheckResult> {
    run_all_with(&mut |_| {})
}

/// Runs every check, telling `on_check` about each as it completes.
pub fn run_all_with(on_check: &mut dyn FnMut(&CheckResult)) -> Vec<CheckResult> {
    let mut out = Checks {
        done: Vec::new(),
        on_check,
    };
    let c = SPEED_OF_LIGHT_M_PER_S;
    let b = 50e6;
    let f0 = 9.41e9;
    let lambda = wavelength_m(f0);
    const RICHARDS: &str = "Richards, Fundamentals of Radar Signal Processing, 2nd ed., §4.6";
    const SKOLNIK: &str = "Skolnik, Introduction to Radar Systems, 3rd ed., eq. 2.51";
    const KNOTT: &str = "Knott, Shaeffer & Tuley, Radar Cross Section, 2nd ed., Table 5.1";
    const BALANIS: &str = "Balanis, Antenna Theory, 4th ed., §12.5";

    // Range bin of a point target.
    let range_m = 777.7;
    let text = format!(
        "{}{}",
        radar_block_no_noise("max_range_m = 1500.0"),
        point_north("p", range_m, 10.0)
    );
    let (sim, frame) = render_text(&text, 1);
    let expected_bin = 2.0 * range_m / c * sim.scene().radar.sample_rate_hz();
    out.push(check(
        "point target range bin (777.7 m)",
        expected_bin,
        argmax(spoke(&frame, 0)).0 as f64,
        "bin",
        Tolerance::Absolute(0.5),
        "τ = 2R/c, bin = τ·fs",
    ));

    // Compressed pulse: IRW, first null, PSLR.
    let (p, bin_m) = fine_profile("none");
    let (peak, _) = argmax(&p);
    out.push(check(
        "3-dB width 0.886·c/2B (B = 50 MHz)",
        0.886 * c / (2.0 * b),
        width_at_db(&p, peak, 3.0103) * bin_m,
        "m",
        Tolerance::Relative(0.03),
        RICHARDS,
    ));
    out.push(check(
        "first null at c/2B",
        c / (2.0 * b),
        first_null_bins(&p, peak) as f64 * bin_m,
        "m",
        Tolerance::Relative(0.03 + bin_m / (c / (2.0 * b))),
        RICHARDS,
    ));
    out.push(check(
        "PSLR, no window",
        -13.26,
        pslr_db(&p) as f64,
        "dB",
        Tolerance::Absolute(0.5),
        RICHARDS,
    ));
    let (p, _) = fine_profile("hamming");
    out.push(check(
        "PSLR, Hamming (window transform −42.7 dB)",
        -42.7,
        pslr_db(&p) as f64,
        "dB",
        Tolerance::AtMost(-40.0),
        "Harris, Proc. IEEE 66(1), 1978",
    ));
    let (p, _) = fine_profile("taylor");
    out.push(check(
        "PSLR, Taylor n̄=4, −35 dB",
        -35.0,
        pslr_db(&p) as f64,
        "dB",
        Tolerance::Absolute(0.5),
        "Carrara et al., Spotlight SAR, App. D",
    ));

    // Noise and SNR.
    out.push(check(
        "noise floor k·T0·F·fs (mean over noise)",
        0.0,
        noise_mean_db(7),
        "dB",
        Tolerance::Absolute(0.1),
        "Skolnik, Radar Handbook, 3rd ed., §2.3",
    ));
    for (w, t) in [("none", 1.0), ("hamming", 1.0), ("taylor", 5.0)] {
        let (e, m) = snr_error_db(w, t, 3);
        out.push(check(
            &format!("single-pulse SNR = radar equation ({w}, {t} us, 10⁴ m², 8.1 km)"),
            e,
            m,
            "dB",
            Tolerance::Absolute(0.25),
            SKOLNIK,
        ));
    }

    // Calibration of a scattering object: SNR from the radar equation with its PO RCS.
    let (e, m) = object_snr_db(0.0);
    out.push(check(
        "trihedral (a = 0.5 m, 2.1 km) SNR = radar equation with its PO RCS",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.1),
        SKOLNIK,
    ));
    let (e2, m2) = object_snr_db(1.5);
    out.push(check(
        "two-way attenuation 1.5 dB/km over 2.1 km",
        e2 - e,
        m2 - m,
        "dB",
        Tolerance::Absolute(0.1),
        "uniform specific attenuation",
    ));

    // Eclipsing: τ = T/2 keeps half the chirp → −6.02 dB; the label carries the loss.
    let (blanked, truth) = eclipse_peak_db(100.0, true, "none");
    let half = blanked - eclipse_peak_db(100.0, false, "none").0;
    out.push(check(
        "eclipsing loss at τ = T/2: 20·log10(τ/T)",
        -6.0206,
        half as f64,
        "dB",
        Tolerance::Absolute(0.02),
        "blanking while transmitting (docs/physics.md, Eclipsing)",
    ));
    out.push(check(
        "eclipse loss in the label = measured loss at τ = 0.3T, Hamming",
        {
            let (b, _) = eclipse_peak_db(60.0, true, "hamming");
            (eclipse_peak_db(60.0, false, "hamming").0 - b) as f64
        },
        eclipse_peak_db(60.0, true, "hamming")
            .1
            .losses_db
            .eclipse
            .unwrap_or(f64::NAN),
        "dB",
        Tolerance::Absolute(0.02),
        "Σ of the window over the received tail / Σ of the window",
    ));
    let _ = truth;

    // Multipath over the sea: two-ray nulls (radar 10 m, target 5 m).
    for n in [1.0, 2.0] {
        let expected = two_ray_null_range_m(n, 10.0, 5.0, lambda);
        out.push(check(
            &format!("four-path null {n}: path difference {n}λ (h 10 m / 5 m)"),
            expected,
            find_null_range_m(expected, 10.0, 5.0),
            "m",
            Tolerance::Relative(0.01),
            "two-ray model, Long, Radar Reflectivity of Land and Sea, §3",
        ));
    }
    let lobe = two_ray_extremum_range_m(1.5, 10.0, 5.0, lambda);
    out.push(check(
        "four-path lobe peak: path difference 1.5λ (h 10 m / 5 m)",
        lobe,
        find_lobe_range_m(lobe, 10.0, 5.0),
        "m",
        Tolerance::Relative(0.01),
        "two-ray model, Long, Radar Reflectivity of Land and Sea, §3",
    ));
    out.push(check(
        "four-path lobe peak: +12 dB over free space (|1+|Γ||⁴)",
        12.0,
        multipath_point_power_db(lobe, 10.0, 5.0, true)
            - multipath_point_power_db(lobe, 10.0, 5.0, false),
        "dB",
        Tolerance::Absolute(0.15),
        "two-ray model with Γ ≈ −1 at low grazing",
    ));

    // Sea clutter and rain.
    out.push(check(
        "NRL σ0 check value: SS 2, 10°, 30 GHz, HH",
        -36.66,
        crate::environment::clutter::nrl_sigma0_db(30.0, 2.0, true, 10.0),
        "dB",
        Tolerance::Absolute(0.01),
        "Gregers-Hansen & Mital, IEEE TAES 48(4), 2012",
    ));
    for range_m in [600.0, 1200.0] {
        let (e, m) = clutter_mean_power_db(3.0, range_m);
        out.push(check(
            &format!("mean clutter power = σ0·A_c·radar equation ({range_m:.0} m, SS 3)"),
            e,
            m,
            "dB",
            Tolerance::Absolute(0.3),
            "radar equation with σ = σ0·A_c (Skolnik 2001, §7.4)",
        ));
    }
    for (label, lines, source) in [
        (
            "K, ν = 1.5: 2(1+1/ν)",
            "clutter_shape_nu = 1.5",
            "Ward, Tough & Watts, Sea Clutter, 2006, §6",
        ),
        (
            "K, default ν (Ward's empirical ν per cell): 2(1+⟨1/ν⟩)",
            "",
            "Ward, Tough & Watts, Sea Clutter, 2006, §6",
        ),
        (
            "Weibull amplitude c = 1.5: Γ(1+4/c)/Γ(1+2/c)²",
            "clutter_distribution = \"weibull\"\nclutter_weibull_shape = 1.5",
            "Sekine & Mao, Weibull Radar Clutter, 1990",
        ),
        (
            "log-normal texture 3 dB: 2·exp(s²)",
            "clutter_distribution = \"lognormal\"\nclutter_lognormal_sigma_db = 3.0",
            "compound log-normal texture × speckle",
        ),
    ] {
        let st = clutter_cell_statistics(lines, CLUTTER_FRAMES);
        out.push(check(
            &format!(
                "clutter cells after the matched filter, defaults, {label} ({:.1} M cells)",
                st.cells as f64 / 1e6
            ),
            st.expected_moment,
            st.measured_moment,
            "",
            Tolerance::Relative(CLUTTER_MOMENT_TOLERANCE),
            source,
        ));
    }
    let (kh, ah, _, _) = crate::environment::rain::itu_p838_coefficients(10.0);
    out.push(check(
        "ITU-R P.838-3 k_H at 10 GHz",
        0.01217,
        kh,
        "",
        Tolerance::Relative(0.005),
        "ITU-R P.838-3, Table 5",
    ));
    out.push(check(
        "ITU-R P.838-3 α_H at 10 GHz",
        1.2571,
        ah,
        "",
        Tolerance::Relative(0.001),
        "ITU-R P.838-3, Table 5",
    ));
    let (e, m) = rain_attenuation_db(16.0);
    out.push(check(
        "two-way rain attenuation 2γR, 16 mm/h, 3 km",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.1),
        "ITU-R P.838-3",
    ));
    let (e, m) = rain_clutter_power_db(8.0, 700);
    out.push(check(
        "rain clutter power = η·V·radar equation (8 mm/h, 1 km)",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.25),
        "Doviak & Zrnić, eq. 4.34; Z = 200R^1.6",
    ));
    let horizon_km = 4.12 * (16f64.sqrt() + 9f64.sqrt());
    let (echo_in, vis_in) = horizon_echo(horizon_km * 1000.0 * 0.98);
    let (echo_out, vis_out) = horizon_echo(horizon_km * 1000.0 * 1.02);
    let both = echo_in
        && !echo_out
        && vis_in == crate::labels::Visibility::Visible
        && vis_out == crate::labels::Visibility::BeyondHorizon;
    out.push(check(
        "horizon 4.12(√h1+√h2) km: echo at 0.98×, none at 1.02× (h 16 m / 9 m)",
        1.0,
        if both { 1.0 } else { 0.0 },
        "",
        Tolerance::Absolute(0.0),
        "Skolnik 2001, §8.2 (4/3 earth)",
    ));
    out.push(check(
        "radar horizon of a 16 m mast",
        4.12 * 4.0,
        crate::environment::horizon_distance_m(16.0) / 1000.0,
        "km",
        Tolerance::Relative(0.002),
        "Skolnik 2001, §8.2",
    ));

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

    // Canonical RCS at 9.41 GHz.
    let hh = Polarisation::Hh;
    let r = 20.0 / (2.0 * PI / lambda);
    out.push(check(
        "sphere πr² (ka = 20)",
        linear_to_db(PI * r * r),
        linear_to_db(shape_rcs_m2(
            &format!("shape = \"sphere\"\nradius_m = {r}"),
            0.3,
            0.2,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.3),
        KNOTT,
    ));
    out.push(check(
        "sphere πr² (r = 1 m)",
        linear_to_db(PI),
        linear_to_db(shape_rcs_m2(
            "shape = \"sphere\"\nradius_m = 1.0",
            0.3,
            0.2,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.3),
        KNOTT,
    ));
    let a = 0.5;
    out.push(check(
        "plate 4πA²/λ², 1 m × 0.5 m, normal",
        linear_to_db(4.0 * PI * a * a / (lambda * lambda)),
        linear_to_db(shape_rcs_m2(
            "shape = \"plate\"\nwidth_m = 1.0\nheight_m = 0.5",
            0.0,
            0.0,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.1),
        KNOTT,
    ));
    let null1 = (lambda / 2.0).asin();
    let (mut best, mut best_v) = (0.0, f64::MAX);
    for i in 0..=80 {
        let ang = null1 * (0.8 + 0.4 * i as f64 / 80.0);
        let v = shape_rcs_m2(
            "shape = \"plate\"\nwidth_m = 1.0\nheight_m = 0.5",
            ang,
            0.0,
            f0,
            hh,
        );
        if v < best_v {
            best = ang;
            best_v = v;
        }
    }
    out.push(check(
        "plate first null at sin θ = λ/2W (W = 1 m)",
        null1.to_degrees(),
        best.to_degrees(),
        "deg",
        Tolerance::Relative(0.10),
        KNOTT,
    ));
    out.push(check(
        "dihedral 8πa²b²/λ², 0.5 m × 0.5 m",
        linear_to_db(8.0 * PI * 0.0625 / (lambda * lambda)),
        linear_to_db(shape_rcs_m2(
            "shape = \"dihedral\"\nwidth_m = 0.5\nheight_m = 0.5",
            0.0,
            0.0,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.3),
        KNOTT,
    ));
    out.push(check(
        "trihedral 4πa⁴/(3λ²), a = 0.5 m",
        linear_to_db(4.0 * PI * 0.0625 / (3.0 * lambda * lambda)),
        linear_to_db(shape_rcs_m2(
            "shape = \"trihedral\"\nedge_m = 0.5",
            0.0,
            0.0,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.1),
        KNOTT,
    ));
    for (name, shape, fields, az_deg) in [
        (
            "mesh plate (2 triangles) = primitive, 2° off normal",
            ShapeGeometry::Plate {
                width_m: 0.8,
                height_m: 0.5,
            },
            "shape = \"plate\"\nwidth_m = 0.8\nheight_m = 0.5",
            2.0f64,
        ),
        (
            "mesh trihedral (3 triangles) = primitive, 20° off axis",
            ShapeGeometry::Trihedral { edge_m: 0.5 },
            "shape = \"trihedral\"\nedge_m = 0.5",
            20.0,
        ),
    ] {
        let az = az_deg.to_radians();
        out.push(check(
            name,
            linear_to_db(shape_rcs_m2(fields, az, 0.0, f0, hh)),
            linear_to_db(mesh_rcs_m2(&shape_triangles(&shape), az, f0)),
            "dBsm",
            Tolerance::Absolute(0.25),
            "same PO surfaces, meshed",
        ));
    }
    out.push(check(
        "cylinder broadside 2πrh²/λ, r = 0.3 m, h = 1 m",
        linear_to_db(2.0 * PI * 0.3 / lambda),
        linear_to_db(shape_rcs_m2(
            "shape = \"cylinder\"\nradius_m = 0.3\nheight_m = 1.0",
            0.7,
            0.0,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.25),
        KNOTT,
    ));
    // Ship-sized objects at the default ray budget (the cap binds and widens the tubes).
    let (w, h) = (8.0, 3.0);
    out.push(check(
        "plate 4πA²/λ², 8 m × 3 m, normal, default ray budget",
        linear_to_db(4.0 * PI * (w * h) * (w * h) / (lambda * lambda)),
        linear_to_db(shape_rcs_default_budget_m2(
            &format!("shape = \"plate\"\nwidth_m = {w}\nheight_m = {h}"),
            0.0,
            0.0,
        )),
        "dBsm",
        // Tubes are counted by their centre ray: the lit area is known to ±δ per edge
        // (δ = 4.2 cm here), 2·(δ/W + δ/H) = 3.9 % of σ at worst.
        Tolerance::Absolute(0.2),
        KNOTT,
    ));
    out.push(check(
        "dihedral 8πa²b²/λ², 3 m × 2 m, default ray budget",
        linear_to_db(8.0 * PI * 9.0 * 4.0 / (lambda * lambda)),
        linear_to_db(shape_rcs_default_budget_m2(
            "shape = \"dihedral\"\nwidth_m = 3.0\nheight_m = 2.0",
            0.0,
            0.0,
        )),
        "dBsm",
        Tolerance::Absolute(0.3),
        KNOTT,
    ));
    out.push(check(
        "trihedral 4πa⁴/(3λ²), a = 2 m, default ray budget",
        linear_to_db(4.0 * PI * 16.0 / (3.0 * lambda * lambda)),
        linear_to_db(shape_rcs_default_budget_m2(
            "shape = \"trihedral\"\nedge_m = 2.0",
            0.0,
            0.0,
        )),
        "dBsm",
        Tolerance::Absolute(0.2),
        KNOTT,
    ));
    let (e, m, truth, rcs_db) = ship_plate_render_db(8.0, 3.0, 600);
    out.push(check(
        "8 m × 3 m plate at 899 m rendered: SNR = radar equation with its near-field PO RCS",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.15),
        SKOLNIK,
    ));
    out.push(check(
        "8 m × 3 m plate at 899 m: truth RCS = near-field PO integral",
        rcs_db,
        truth,
        "dBsm",
        Tolerance::Absolute(0.1),
        "PO surface integral with the two-way Fresnel phase, by quadrature",
    ));
    let base = vessel_mean_rcs_m2(32_768, 128);
    let doubled = vessel_mean_rcs_m2(65_536, 128);
    out.push(check(
        "30 m vessel mesh: mean RCS over aspect, ray budget 32768 → 65536",
        linear_to_db(base),
        linear_to_db(doubled),
        "dBsm",
        Tolerance::Absolute(0.5),
        "convergence criterion (docs/validation.md)",
    ));
    out.done
}
