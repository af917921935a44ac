//! Plot-extraction checks: the CFAR detector's false-alarm rate on the pipeline's own
//! receiver noise against its closed form, and its rate in the pipeline's sea clutter
//! against the design value (docs/validation.md, "CFAR").

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use num_complex::Complex64;
use xbandsim::processing::cfar::{Cfar, CfarKind};

/// The autocorrelation of the compressed noise at lags `0 ..= max_lag` bins, `ρ(k) =
/// Σ_m h[m + k]·h*[m]` with `h = w·s/‖w·s‖` the matched filter's reference (docs/physics.md
/// §7): white noise of unit power through the filter has covariance `ρ(i − j)` between bins
/// i and j.
pub fn compressed_noise_correlation(sim: &xbandsim::Simulation, max_lag: usize) -> Vec<Complex64> {
    let radar = sim.scene().radar();
    let s = radar.chirp().samples();
    let w = radar.window().coefficients(s.len());
    let h: Vec<Complex64> = s.iter().zip(&w).map(|(x, wi)| x * wi).collect();
    let norm: f64 = h.iter().map(|x| x.norm_sqr()).sum();
    (0..=max_lag)
        .map(|k| {
            (0..h.len().saturating_sub(k))
                .map(|m| h[m + k] * h[m].conj())
                .sum::<Complex64>()
                / norm
        })
        .collect()
}

/// The lower Cholesky factor `L` of a Hermitian positive-definite matrix (`A = L·Lᴴ`,
/// row-major n × n).
fn cholesky(a: &[Complex64], n: usize) -> Vec<Complex64> {
    let mut l = vec![Complex64::new(0.0, 0.0); n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut sum = a[i * n + j];
            for k in 0..j {
                sum -= l[i * n + k] * l[j * n + k].conj();
            }
            l[i * n + j] = if i == j {
                Complex64::new(sum.re.sqrt(), 0.0)
            } else {
                sum / l[j * n + j]
            };
        }
    }
    l
}

/// The eigenvalues of a Hermitian matrix (row-major n × n), ascending: those of its real
/// form `[[Re, −Im], [Im, Re]]` (each twice) by cyclic Jacobi rotations (Golub & Van Loan,
/// *Matrix Computations*, 4th ed., §8.5), every other one kept.
fn hermitian_eigenvalues(h: &[Complex64], n: usize) -> Vec<f64> {
    let m = 2 * n;
    let mut a = vec![0.0; m * m];
    for i in 0..n {
        for j in 0..n {
            let z = h[i * n + j];
            a[i * m + j] = z.re;
            a[(i + n) * m + j + n] = z.re;
            a[i * m + j + n] = -z.im;
            a[(i + n) * m + j] = z.im;
        }
    }
    for _sweep in 0..100 {
        let off: f64 = (0..m)
            .flat_map(|i| (0..m).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * m + j] * a[i * m + j])
            .sum();
        if off < 1e-26 {
            break;
        }
        for p in 0..m {
            for q in p + 1..m {
                let apq = a[p * m + q];
                if apq.abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q * m + q] - a[p * m + p]) / (2.0 * apq);
                let sign = if theta >= 0.0 { 1.0 } else { -1.0 };
                let t = sign / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..m {
                    let (akp, akq) = (a[k * m + p], a[k * m + q]);
                    a[k * m + p] = c * akp - s * akq;
                    a[k * m + q] = s * akp + c * akq;
                }
                for k in 0..m {
                    let (apk, aqk) = (a[p * m + k], a[q * m + k]);
                    a[p * m + k] = c * apk - s * aqk;
                    a[q * m + k] = s * apk + c * aqk;
                }
            }
        }
    }
    let mut values: Vec<f64> = (0..m).map(|i| a[i * m + i]).collect();
    values.sort_by(f64::total_cmp);
    values.into_iter().step_by(2).collect()
}

/// Cell averaging's false-alarm probability on compressed noise whose bins are correlated
/// (bin covariance `ρ(i − j)`), the cell under test included. The detection statistic is the
/// complex Gaussian quadratic form `T = vᴴQv`, v the cell under test and the N training cells
/// (covariance C), `Q = diag(1, −α, …, −α)`; with `C = L·Lᴴ`, T is `Σ μ_i·E_i` over the
/// eigenvalues μ of `LᴴQL` and independent unit exponentials `E_i` (Kay, *Fundamentals of
/// Statistical Signal Processing*, vol. 2, 1998, §2.3), one μ₀ > 0 and N < 0, so
/// `Pfa = P(T > 0) = Π_{i≥1} μ₀/(μ₀ − μ_i)`. With `C = I` it is `(1 + α)^{−N}`.
pub fn correlated_cell_averaging_pfa(
    rho: &[Complex64],
    guard_cells: usize,
    training_cells: usize,
    alpha: f64,
) -> f64 {
    let reach = (guard_cells + training_cells) as i64;
    // The cell under test first, then the training cells.
    let offsets: Vec<i64> = std::iter::once(0)
        .chain((-reach..=reach).filter(|d| d.unsigned_abs() as usize > guard_cells))
        .collect();
    let n = offsets.len();
    let mut c = vec![Complex64::new(0.0, 0.0); n * n];
    for (i, &p) in offsets.iter().enumerate() {
        for (j, &q) in offsets.iter().enumerate() {
            let lag = (p - q).unsigned_abs() as usize;
            let r = rho.get(lag).copied().unwrap_or_default();
            // C_ij = E[v_i v_j*]: ρ(p − q) for p ≥ q, its conjugate otherwise.
            c[i * n + j] = if p >= q { r } else { r.conj() };
        }
    }
    let l = cholesky(&c, n);
    let q = |i: usize| if i == 0 { 1.0 } else { -alpha };
    // (LᴴQL)_ij = Σ_k conj(L_ki)·q_k·L_kj.
    let mut m = vec![Complex64::new(0.0, 0.0); n * n];
    for i in 0..n {
        for j in 0..n {
            m[i * n + j] = (0..n)
                .map(|k| l[k * n + i].conj() * q(k) * l[k * n + j])
                .sum();
        }
    }
    let mu = hermitian_eigenvalues(&m, n);
    let (mu0, rest) = mu.split_last().expect("at least the cell under test");
    rest.iter().map(|&mi| mu0 / (mu0 - mi)).product()
}

/// Detections of `cfar` on every spoke of `frame`'s record from bin `first` on, and the
/// cells it tested (those with a whole window): (detections, cells tested).
fn false_alarms_in(cfar: &Cfar, frame: &xbandsim::Frame, first: usize) -> (usize, usize) {
    let power: Vec<f32> = frame
        .polar_db
        .iter()
        .map(|&d| 10f32.powf(0.1 * d))
        .collect();
    let mut detected = vec![false; frame.range_bins - first];
    let mut scratch = Vec::new();
    let (mut hits, mut tested) = (0, 0);
    for k in 0..frame.spokes {
        let row = &power[k * frame.range_bins + first..(k + 1) * frame.range_bins];
        cfar.detect(row, &mut detected, &mut scratch);
        hits += detected.iter().filter(|&&d| d).count();
        tested += row.len().saturating_sub(2 * cfar.reach());
    }
    (hits, tested)
}

/// False alarms of `cfar` over the noise-only revolutions of seeds `1 ..= frames` (the
/// default radar, 1500 m, free space), testing every cell whose window lies past the blanked
/// interval: (false alarms, cells tested, the simulation of the last frame).
fn noise_false_alarms(cfar: &Cfar, frames: u64) -> (usize, usize, xbandsim::Simulation) {
    let (mut hits, mut tested) = (0, 0);
    let mut last = None;
    for seed in 1..=frames {
        let (sim, frame) = render_text(&radar_block("max_range_m = 1500.0"), seed);
        let (h, t) = false_alarms_in(cfar, &frame, sim.compressor().pulse_len() + 2);
        hits += h;
        tested += t;
        last = Some(sim);
    }
    (hits, tested, last.expect("at least one frame"))
}

/// Cell averaging (g = 4, n = 16) at the design 10⁻³ on the pipeline's receiver noise, over
/// `frames` revolutions: (closed form with the compressed noise's correlation, the design
/// value of independent cells, measured rate, cells tested).
pub fn cell_averaging_noise_false_alarms(frames: u64) -> (f64, f64, f64, usize) {
    let (g, n, design) = (4, 16, 1e-3);
    let cfar = Cfar::new(CfarKind::CellAveraging, g, n, design).expect("valid detector");
    let (hits, tested, sim) = noise_false_alarms(&cfar, frames);
    let rho = compressed_noise_correlation(&sim, 2 * (g + n));
    let closed = correlated_cell_averaging_pfa(&rho, g, n, cfar.alpha());
    (closed, design, hits as f64 / tested as f64, tested)
}

/// The false-alarm rate of `kind` (g = 4, n = 16, design `pfa`) in the sea clutter of
/// `scenes/sea-state-4-rain.toml` without its rain, multipath and objects (K-distributed,
/// docs/physics.md §2.7), over the cells from 300 m to 3 km, seeds `1 ..= frames`: (design, measured).
pub fn sea_clutter_false_alarm_rate(kind: CfarKind, pfa: f64, frames: u64) -> (f64, f64) {
    let cfar = Cfar::new(kind, 4, 16, pfa).expect("valid detector");
    let text = "[environment]\nmultipath = false\nsea_state = 4.0\nwind_direction_deg = 0.0\nclutter = true\nclutter_model = \"nrl\"\nclutter_distribution = \"k\"\nclutter_correlation_m = 30.0\n[radar]\npreset = \"drs4d-nxt\"\nposition_m = [0.0, 0.0, 10.0]\npulse_width_us = 1.0\nwindow = \"hamming\"\nmax_range_m = 3000.0\nspokes = 720\n";
    let (mut hits, mut tested) = (0, 0);
    for seed in 1..=frames {
        let (_, frame) = render_text(text, seed);
        let (h, t) = false_alarms_in(&cfar, &frame, (300.0 / frame.range_bin_m) as usize);
        hits += h;
        tested += t;
    }
    (pfa, hits as f64 / tested as f64)
}

pub(crate) fn checks(out: &mut Checks) {
    let (closed, _, measured, tested) = cell_averaging_noise_false_alarms(4);
    // 4.5 binomial σ of the measured rate, relative.
    let sigma = (closed * (1.0 - closed) / tested as f64).sqrt() / closed;
    out.push(check(
        "CFAR: cell-averaging false alarms in receiver noise (g = 4, n = 16, design 1e-3)",
        closed,
        measured,
        "",
        Tolerance::Relative(4.5 * sigma),
        "1/det(I + αR), R the compressed noise's correlation (Kay 1998 §2.3); (1 + α)^-N for independent cells (Richards §6.5)",
    ));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn independent_cells_give_the_textbook_form() {
        let rho = vec![Complex64::new(1.0, 0.0)];
        for alpha in [0.1, 0.5, 2.0] {
            let got = correlated_cell_averaging_pfa(&rho, 2, 8, alpha);
            let want = (1.0f64 + alpha).powi(-16);
            assert!((got / want - 1.0).abs() < 1e-12, "{got} {want}");
        }
        // Neighbours correlated (ρ(1) = 0.45·e^{0.3j}, a valid MA(1) correlation), the cell under test apart from them
        // (g = 1): each side's N/2 cells a tridiagonal block, `Pfa = 1/det(I + αR)` with
        // the determinant by its three-term recurrence D_k = (1 + α)·D_{k−1} − α²|ρ₁|²·D_{k−2}.
        let rho1 = Complex64::from_polar(0.45, 0.3);
        let rho = vec![Complex64::new(1.0, 0.0), rho1];
        let alpha = 0.4;
        let (mut d_prev, mut d) = (1.0, 1.0 + alpha);
        for _ in 1..8 {
            (d_prev, d) = (
                d,
                (1.0 + alpha) * d - alpha * alpha * rho1.norm_sqr() * d_prev,
            );
        }
        let want = 1.0 / (d * d);
        let got = correlated_cell_averaging_pfa(&rho, 1, 8, alpha);
        assert!((got / want - 1.0).abs() < 1e-10, "{got} {want}");
    }
}
