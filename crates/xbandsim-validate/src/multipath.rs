//! Propagation checks: four-path multipath nulls and lobes over the sea (two-ray model) and
//! the radar horizon (docs/validation.md).

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use std::f64::consts::PI;
use xbandsim::constants::{wavelength_m, SPEED_OF_LIGHT_M_PER_S};

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
    let j = (ground_range_m / sim.scene().radar().range_bin_m()).round() as usize;
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
    let eps = xbandsim::propagation::sea_water_permittivity(
        SPEED_OF_LIGHT_M_PER_S / wavelength_m,
        20.0,
        35.0,
    );
    let mut r = two_ray_null_range_m(n, radar_height_m, target_height_m, wavelength_m);
    for _ in 0..5 {
        let psi = ((radar_height_m + target_height_m) / r).atan();
        let (gh, _) = xbandsim::propagation::fresnel_reflection(eps, psi);
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

/// The checks of this area, in the order `xbandsim validate` prints them.
pub(crate) fn checks(out: &mut Checks) {
    let f0 = 9.41e9;
    let lambda = wavelength_m(f0);

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
}
