//! Stage: plot extraction — constant-false-alarm-rate (CFAR) detection along range
//! (docs/physics.md §15). Each cell under test is compared with a threshold `T = α·Z` made from
//! `n` training cells on each side of it, past `g` guard cells, in square-law (power) units.
//! In exponentially distributed noise (a Rayleigh envelope) the false-alarm probability of each
//! kind has a closed form, and `α` is solved from it for the design `Pfa`:
//!
//! - **cell averaging** (CA), `Z` the sum of the `N = 2n` cells: `Pfa = (1 + α)^{−N}`
//!   (Richards, *Fundamentals of Radar Signal Processing*, 2nd ed., §6.5);
//! - **greatest of** (GO), `Z` the larger of the two sides' sums:
//!   `Pfa = 2(1 + α)^{−n} − 2·Σ_{k=0}^{n−1} C(n−1+k, k)·(2 + α)^{−(n+k)}` (Richards §6.5);
//! - **ordered statistic** (OS), `Z` the k-th smallest of the `N` cells:
//!   `Pfa = Π_{i=0}^{k−1} (N − i)/(N − i + α)` (Rohling, "Radar CFAR thresholding in clutter
//!   and multiple target situations", IEEE Trans. AES 19(4), 1983).
//!
//! Cells without `g + n` cells on both sides are not tested. The kernel ([`Cfar::detect`])
//! keeps running sums (CA, GO) or sorts each window into a caller's scratch (OS): it allocates
//! nothing per cell; [`tests`] checks it against a direct evaluation of each cell's window.

use crate::error::{Error, Problem, Result};

/// How the training cells make the noise estimate `Z`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CfarKind {
    /// The sum of all `2n` training cells.
    CellAveraging,
    /// The larger of the two sides' sums (robust at clutter edges).
    GreatestOf,
    /// The `rank`-th smallest of the `2n` cells, 1-based (robust to interfering targets).
    OrderedStatistic {
        /// Which order statistic, `1 ..= 2n`.
        rank: usize,
    },
}

/// A CFAR detector along range with its threshold multiplier solved for its design `Pfa`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cfar {
    kind: CfarKind,
    guard_cells: usize,
    training_cells: usize,
    pfa: f64,
    alpha: f64,
}

/// The largest number of training cells on each side.
pub const MAX_TRAINING_CELLS: usize = 256;

impl Cfar {
    /// A detector of `kind` with `guard_cells` and `training_cells` on each side of the cell
    /// under test, for the false-alarm probability `pfa` in exponential noise. Refused, naming
    /// the field (`cfar.*`): no training cells or more than [`MAX_TRAINING_CELLS`], `pfa`
    /// outside (0, 0.5), an order statistic's rank outside `1 ..= 2n`.
    pub fn new(
        kind: CfarKind,
        guard_cells: usize,
        training_cells: usize,
        pfa: f64,
    ) -> Result<Cfar> {
        if !(1..=MAX_TRAINING_CELLS).contains(&training_cells) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "cfar.training_cells",
                training_cells,
                format!("must be between 1 and {MAX_TRAINING_CELLS} on each side"),
            ));
        }
        if !(pfa > 0.0 && pfa < 0.5) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "cfar.pfa",
                pfa,
                "must be a probability above 0 and below 0.5",
            ));
        }
        if let CfarKind::OrderedStatistic { rank } = kind {
            if !(1..=2 * training_cells).contains(&rank) {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    "cfar.rank",
                    rank,
                    format!(
                        "must be between 1 and the {} training cells",
                        2 * training_cells
                    ),
                ));
            }
        }
        let alpha = solve_alpha(|a| false_alarm_probability(kind, training_cells, a), pfa);
        Ok(Cfar {
            kind,
            guard_cells,
            training_cells,
            pfa,
            alpha,
        })
    }

    /// Its kind.
    pub fn kind(&self) -> CfarKind {
        self.kind
    }

    /// The threshold multiplier α on `Z`.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// The design false-alarm probability.
    pub fn pfa(&self) -> f64 {
        self.pfa
    }

    /// Cells from the cell under test to the far edge of its window.
    pub fn reach(&self) -> usize {
        self.guard_cells + self.training_cells
    }

    /// Marks in `detected` (as long as `power`) the cells of `power` (square-law, linear
    /// units) above their threshold; cells without a whole window are false. `scratch` is the
    /// ordered statistic's sorting buffer (any length; grown once).
    pub fn detect(&self, power: &[f32], detected: &mut [bool], scratch: &mut Vec<f32>) {
        assert_eq!(power.len(), detected.len(), "one flag per cell");
        detected.fill(false);
        let (g, n) = (self.guard_cells, self.training_cells);
        let reach = self.reach();
        if power.len() < 2 * reach + 1 {
            return;
        }
        let alpha = self.alpha as f32;
        match self.kind {
            CfarKind::CellAveraging | CfarKind::GreatestOf => {
                // Running sums of the two sides, in f64 (a long row's sums drift in f32).
                let first = reach;
                let mut left: f64 = power[first - reach..first - g]
                    .iter()
                    .map(|&p| p as f64)
                    .sum();
                let mut right: f64 = power[first + g + 1..=first + reach]
                    .iter()
                    .map(|&p| p as f64)
                    .sum();
                for i in first..power.len() - reach {
                    if i > first {
                        left += power[i - g - 1] as f64 - power[i - reach - 1] as f64;
                        right += power[i + reach] as f64 - power[i + g] as f64;
                    }
                    let z = match self.kind {
                        CfarKind::GreatestOf => left.max(right),
                        _ => left + right,
                    };
                    detected[i] = power[i] > alpha * z as f32;
                }
            }
            CfarKind::OrderedStatistic { rank } => {
                scratch.resize(2 * n, 0.0);
                for i in reach..power.len() - reach {
                    scratch[..n].copy_from_slice(&power[i - reach..i - g]);
                    scratch[n..].copy_from_slice(&power[i + g + 1..=i + reach]);
                    let (_, kth, _) = scratch.select_nth_unstable_by(rank - 1, f32::total_cmp);
                    detected[i] = power[i] > alpha * *kth;
                }
            }
        }
    }
}

/// The false-alarm probability of `kind` with `n` training cells a side at multiplier
/// `alpha`, in exponential noise (the closed forms of the module's doc).
pub fn false_alarm_probability(kind: CfarKind, n: usize, alpha: f64) -> f64 {
    let big_n = 2 * n;
    match kind {
        CfarKind::CellAveraging => (1.0 + alpha).powi(-(big_n as i32)),
        CfarKind::GreatestOf => {
            // C(n−1+k, k) built up term by term.
            let mut sum = 0.0;
            let mut binomial = 1.0;
            for k in 0..n {
                if k > 0 {
                    binomial *= (n - 1 + k) as f64 / k as f64;
                }
                sum += binomial * (2.0 + alpha).powi(-((n + k) as i32));
            }
            2.0 * (1.0 + alpha).powi(-(n as i32)) - 2.0 * sum
        }
        CfarKind::OrderedStatistic { rank } => (0..rank)
            .map(|i| (big_n - i) as f64 / ((big_n - i) as f64 + alpha))
            .product(),
    }
}

/// The α > 0 at which the decreasing `pfa_of(α)` equals `pfa`, by bisection on log α.
fn solve_alpha(pfa_of: impl Fn(f64) -> f64, pfa: f64) -> f64 {
    let (mut lo, mut hi) = (1e-9f64, 1.0f64);
    while pfa_of(hi) > pfa {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if pfa_of(mid) > pfa {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi / lo < 1.0 + 1e-13 {
            break;
        }
    }
    (lo * hi).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    /// Each cell's window evaluated directly (f64), the detector's reference.
    fn naive(cfar: &Cfar, power: &[f32]) -> Vec<bool> {
        let (g, n) = (cfar.guard_cells, cfar.training_cells);
        let reach = g + n;
        (0..power.len())
            .map(|i| {
                if i < reach || i + reach >= power.len() {
                    return false;
                }
                let left: Vec<f64> = (i - reach..i - g).map(|j| power[j] as f64).collect();
                let right: Vec<f64> = (i + g + 1..=i + reach).map(|j| power[j] as f64).collect();
                let z = match cfar.kind {
                    CfarKind::CellAveraging => left.iter().sum::<f64>() + right.iter().sum::<f64>(),
                    CfarKind::GreatestOf => left.iter().sum::<f64>().max(right.iter().sum()),
                    CfarKind::OrderedStatistic { rank } => {
                        let mut all: Vec<f64> = left.iter().chain(&right).copied().collect();
                        all.sort_by(f64::total_cmp);
                        all[rank - 1]
                    }
                };
                power[i] as f64 > cfar.alpha * z
            })
            .collect()
    }

    fn exponential_noise(len: usize, seed: u64) -> Vec<f32> {
        let mut rng = crate::rng::RngKey::new(seed, 0, 0, crate::rng::Stream::ReceiverNoise).rng();
        (0..len)
            .map(|_| -(1.0 - rng.random::<f64>()).ln() as f32)
            .collect()
    }

    fn kinds() -> [CfarKind; 3] {
        [
            CfarKind::CellAveraging,
            CfarKind::GreatestOf,
            CfarKind::OrderedStatistic { rank: 24 },
        ]
    }

    #[test]
    fn the_kernel_matches_each_window_evaluated_directly() {
        let mut power = exponential_noise(3000, 7);
        // Targets and a clutter edge.
        for (i, p) in [(400, 300.0), (405, 80.0), (1500, 40.0)] {
            power[i] = p;
        }
        for p in &mut power[2000..2600] {
            *p *= 30.0;
        }
        let mut scratch = Vec::new();
        for kind in kinds() {
            let cfar = Cfar::new(kind, 2, 16, 1e-3).unwrap();
            let mut detected = vec![false; power.len()];
            cfar.detect(&power, &mut detected, &mut scratch);
            let want = naive(&cfar, &power);
            let differ = detected.iter().zip(&want).filter(|(a, b)| a != b).count();
            // Float rounding may flip a cell sitting on its threshold; none do here.
            assert_eq!(differ, 0, "{kind:?}");
            assert!(detected[400] && detected[1500], "{kind:?}");
        }
    }

    #[test]
    fn alpha_meets_the_closed_forms() {
        for kind in kinds() {
            for pfa in [1e-2, 1e-4, 1e-6] {
                let cfar = Cfar::new(kind, 2, 16, pfa).unwrap();
                let got = false_alarm_probability(kind, 16, cfar.alpha());
                assert!((got / pfa - 1.0).abs() < 1e-9, "{kind:?} {pfa}: {got}");
            }
        }
        // CA's closed form inverted: α = Pfa^(−1/N) − 1.
        let cfar = Cfar::new(CfarKind::CellAveraging, 0, 8, 1e-4).unwrap();
        assert!((cfar.alpha() - (1e-4f64.powf(-1.0 / 16.0) - 1.0)).abs() < 1e-12);
    }

    /// In exponential noise the measured false-alarm rate over 2·10⁶ cells is the design 10⁻³
    /// within 4.5 binomial standard deviations (about 10 %).
    #[test]
    fn measured_pfa_in_noise_is_the_design_value() {
        let power = exponential_noise(2_000_000, 11);
        let mut scratch = Vec::new();
        for kind in kinds() {
            let cfar = Cfar::new(kind, 2, 16, 1e-3).unwrap();
            let mut detected = vec![false; power.len()];
            cfar.detect(&power, &mut detected, &mut scratch);
            let tested = (power.len() - 2 * 18) as f64;
            let hits = detected.iter().filter(|&&d| d).count() as f64;
            let expected = tested * 1e-3;
            let sigma = (tested * 1e-3 * (1.0 - 1e-3)).sqrt();
            assert!(
                (hits - expected).abs() < 4.5 * sigma,
                "{kind:?}: {hits} false alarms, expected {expected:.0} ± {sigma:.0}"
            );
        }
    }

    /// The fraction of `trials` windows that the kernel declares a detection at the cell
    /// under test: each window a row of 2(g + n) + 1 cells, filled by `fill(row, cut)` with
    /// independent draws (`cut` the index of the cell under test).
    fn detection_rate(cfar: &Cfar, trials: usize, mut fill: impl FnMut(&mut [f32], usize)) -> f64 {
        let reach = cfar.reach();
        let mut row = vec![0f32; 2 * reach + 1];
        let mut detected = vec![false; row.len()];
        let mut scratch = Vec::new();
        let mut hits = 0usize;
        for _ in 0..trials {
            fill(&mut row, reach);
            cfar.detect(&row, &mut detected, &mut scratch);
            hits += usize::from(detected[reach]);
        }
        hits as f64 / trials as f64
    }

    fn unit_exponential(rng: &mut impl Rng) -> f64 {
        -(1.0 - rng.random::<f64>()).ln()
    }

    /// Swerling 1 (a Rayleigh-fluctuating target, exponential power of mean `1 + S` in the cell
    /// under test): `Pd = Pfa(α/(1 + S))` for every kind — the closed forms with α scaled
    /// (Richards §6.5; Rohling 1983) — measured within 4.5 binomial σ.
    #[test]
    fn swerling_1_detection_follows_the_closed_forms() {
        let mut rng = crate::rng::RngKey::new(5, 0, 0, crate::rng::Stream::ReceiverNoise).rng();
        for kind in kinds() {
            let cfar = Cfar::new(kind, 2, 16, 1e-4).unwrap();
            for snr_db in [10.0, 15.0, 20.0] {
                let snr = 10f64.powf(snr_db / 10.0);
                let want = false_alarm_probability(kind, 16, cfar.alpha() / (1.0 + snr));
                let trials = 40_000;
                let got = detection_rate(&cfar, trials, |row, cut| {
                    for (i, cell) in row.iter_mut().enumerate() {
                        let scale = if i == cut { 1.0 + snr } else { 1.0 };
                        *cell = (scale * unit_exponential(&mut rng)) as f32;
                    }
                });
                let sigma = (want * (1.0 - want) / trials as f64).sqrt();
                assert!(
                    (got - want).abs() < 4.5 * sigma,
                    "{kind:?} at {snr_db} dB: Pd {got:.4}, closed form {want:.4} ± {sigma:.4}"
                );
            }
        }
    }

    /// Swerling 0 (a steady target of SNR S: a Rician envelope) with cell averaging: given the
    /// training sum Z ~ Gamma(N, 1), `Pd = Q₁(√(2S), √(2αZ))` (Marcum's function), so
    /// `Pd = ∫ Q₁(√(2S), √(2αz)) z^{N−1}e^{−z}/Γ(N) dz` (Richards §6.5), integrated here by
    /// the midpoint rule on a 10⁻³ grid; the kernel's rate within 4.5 binomial σ.
    #[test]
    fn steady_target_detection_follows_marcum() {
        use rand_distr::{Distribution, StandardNormal};
        let n_total = 32;
        let cfar = Cfar::new(CfarKind::CellAveraging, 2, 16, 1e-4).unwrap();
        let mut rng = crate::rng::RngKey::new(6, 0, 0, crate::rng::Stream::ReceiverNoise).rng();
        for snr_db in [12.0, 15.0] {
            let snr = 10f64.powf(snr_db / 10.0);
            let rice = xbandsim_validate::RiceCdf::new((2.0 * snr).sqrt());
            let ln_gamma_n = crate::special::ln_gamma(n_total as f64);
            let dz = 1e-3;
            let want: f64 = (0..200_000)
                .map(|i| {
                    let z = (i as f64 + 0.5) * dz;
                    let density = ((n_total - 1) as f64 * z.ln() - z - ln_gamma_n).exp();
                    rice.marcum_q1((2.0 * cfar.alpha() * z).sqrt()) * density * dz
                })
                .sum();
            let trials = 40_000;
            let amplitude = snr.sqrt();
            let got = detection_rate(&cfar, trials, |row, cut| {
                for (i, cell) in row.iter_mut().enumerate() {
                    // Complex noise of unit mean power, the echo's amplitude added in phase.
                    let re: f64 = StandardNormal.sample(&mut rng);
                    let im: f64 = StandardNormal.sample(&mut rng);
                    let re = re * std::f64::consts::FRAC_1_SQRT_2
                        + if i == cut { amplitude } else { 0.0 };
                    let im = im * std::f64::consts::FRAC_1_SQRT_2;
                    *cell = (re * re + im * im) as f32;
                }
            });
            let sigma = (want * (1.0 - want) / trials as f64).sqrt();
            assert!(
                (got - want).abs() < 4.5 * sigma,
                "at {snr_db} dB: Pd {got:.4}, Marcum {want:.4} ± {sigma:.4}"
            );
        }
    }

    /// K-distributed clutter (Ward, Tough & Watts, *Sea Clutter*, IET 2006, ch. 4): each cell
    /// a gamma texture τ of shape ν and mean 1 times unit exponential speckle. With the
    /// texture independent from cell to cell (the spikiest case), cell averaging's false-alarm
    /// rate given the textures is `Π_i (1 + α·τ_i/τ₀)^{−1}`; its mean over drawn textures
    /// (Rao–Blackwellised, 2·10⁵ windows) is the reference for the rate the kernel measures
    /// on drawn cells (2·10⁵ windows), within 4.5 σ of the two estimates together. At ν = 0.5
    /// the rate is about 29 times the design 10⁻³ of exponential noise: cell averaging's loss in
    /// spiky clutter. With one texture over the whole window the design rate holds (the
    /// detector is scale invariant).
    #[test]
    fn cell_averaging_in_k_distributed_clutter() {
        use rand_distr::{Distribution, Gamma};
        let design = 1e-3;
        let cfar = Cfar::new(CfarKind::CellAveraging, 2, 8, design).unwrap();
        let mut rng = crate::rng::RngKey::new(8, 0, 0, crate::rng::Stream::ReceiverNoise).rng();
        let trials = 200_000;
        for shape in [0.5, 2.0] {
            let texture = Gamma::new(shape, 1.0 / shape).unwrap();
            let conditional: Vec<f64> = (0..trials)
                .map(|_| {
                    let tau0: f64 = texture.sample(&mut rng);
                    (0..16)
                        .map(|_| 1.0 / (1.0 + cfar.alpha() * texture.sample(&mut rng) / tau0))
                        .product()
                })
                .collect();
            let want = conditional.iter().sum::<f64>() / trials as f64;
            let var_want = conditional.iter().map(|p| (p - want).powi(2)).sum::<f64>()
                / (trials as f64 * (trials - 1) as f64);
            let got = detection_rate(&cfar, trials, |row, _| {
                for cell in row.iter_mut() {
                    let tau: f64 = texture.sample(&mut rng);
                    *cell = (tau * unit_exponential(&mut rng)) as f32;
                }
            });
            let sigma = (got * (1.0 - got) / trials as f64 + var_want).sqrt();
            println!("K clutter ν = {shape}: CA measured {got:.3e}, reference {want:.3e}");
            assert!(
                (got - want).abs() < 4.5 * sigma,
                "ν = {shape}: measured {got:.5}, reference {want:.5} ± {sigma:.5}"
            );
            if shape == 0.5 {
                assert!(
                    got > 20.0 * design,
                    "ν = 0.5: {got} against the design {design}"
                );
            }
            // One texture over the whole window: the design rate.
            let constant = detection_rate(&cfar, trials, |row, _| {
                let tau: f64 = texture.sample(&mut rng);
                for cell in row.iter_mut() {
                    *cell = (tau * unit_exponential(&mut rng)) as f32;
                }
            });
            let sigma = (design * (1.0 - design) / trials as f64).sqrt();
            assert!(
                (constant - design).abs() < 4.5 * sigma,
                "ν = {shape}, one texture: {constant:.5} against {design}"
            );
        }
    }

    #[test]
    fn bad_settings_are_refused_naming_the_field() {
        let field = |r: Result<Cfar>| r.unwrap_err().field().map(str::to_string);
        assert_eq!(
            field(Cfar::new(CfarKind::CellAveraging, 2, 0, 1e-3)).as_deref(),
            Some("cfar.training_cells")
        );
        assert_eq!(
            field(Cfar::new(CfarKind::CellAveraging, 2, 8, 0.7)).as_deref(),
            Some("cfar.pfa")
        );
        assert_eq!(
            field(Cfar::new(
                CfarKind::OrderedStatistic { rank: 17 },
                2,
                8,
                1e-3
            ))
            .as_deref(),
            Some("cfar.rank")
        );
    }
}
