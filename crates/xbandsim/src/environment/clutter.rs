//! Sea clutter: mean reflectivity σ0, amplitude statistics and a spatially correlated texture.
//!
//! **σ0, NRL model** (Gregers-Hansen & Mital, "An improved empirical model for radar sea
//! clutter reflectivity", IEEE Trans. AES 48(4):3512–3524, 2012), sea state SS 0–6, grazing
//! ψ in degrees, f in GHz:
//! `σ0(dB) = c1 + c2·log10(sin ψ) + (27.5 + c3·ψ)·log10 f/(1 + 0.95ψ) + c4·(SS + 1)^(1/(2 + 0.085ψ + 0.033·SS)) + c5·ψ²`, with
//! HH: c1..c5 = −73.0, 20.781, 7.351, 25.65, 0.0054; VV: −50.796, 25.93, 0.7093, 21.588,
//! 0.00211. Published check value: SS 2, ψ = 10°, 30 GHz, HH → −36.66 dB. The model averages
//! over look direction; we apply the GIT upwind factor below, normalised to unit mean over
//! azimuth, so that upwind is brighter than crosswind without changing the average.
//!
//! **σ0, GIT model** (Horst, Dyer & Tuley, "Radar sea clutter model", IEEE AP-S/URSI 1978, as
//! given in Skolnik, *Radar Handbook*, 3rd ed., ch. 15; valid 1–12 GHz here), λ in m, ψ in rad,
//! wind speed `V_w = 2.15·SS^1.04` m/s, mean wave height `h_av = 4.52e-3·V_w^2.5` m:
//! `σ_φ = (14.4λ + 5.5)ψ·h_av/(λ + 0.015)`, `A_i = σ_φ⁴/(1 + σ_φ⁴)`,
//! `A_u = exp(0.2·cos φ·(1 − 2.8ψ)·(λ + 0.015)^−0.4)` (φ from upwind),
//! `A_w = (1.94V_w/(1 + V_w/15.4))^(1.1(λ + 0.015)^−0.4)`,
//! `σ0_HH = 10·log10(3.9e-6·λ·ψ^0.4·A_i·A_u·A_w)`, and for VV
//! `σ0_VV = σ0_HH − 1.05·ln(h_av + 0.015) + 1.09·ln λ + 1.27·ln(ψ + 1e-4) + 9.70`.
//!
//! **K-distribution** (Ward, Tough & Watts, *Sea Clutter: Scattering, the K Distribution and
//! Radar Performance*, IET 2006, ch. 5–6): intensity `I = T·S`, texture T ~ Gamma(shape ν,
//! mean 1) correlated in space, speckle S exponential (complex Gaussian amplitude)
//! independent pulse to pulse; `E[I²]/E[I]² = 2(1 + 1/ν)`. Default ν from the same source's
//! empirical fit `log10 ν = (2/3)·log10 ψ° + (5/8)·log10 A_c − k_pol − cos(2θ_sw)/3`
//! (k_pol = 1.39 VV, 2.09 HH; A_c in m²; θ_sw the look direction relative to the swell, taken
//! as the wind), clamped to 0.1…20.
//!
//! The texture is a Gaussian random field (white noise smoothed by a Gaussian kernel, so the
//! correlation is `exp(−d²/L²)` with L the correlation length) mapped to Gamma(ν) through
//! its quantile function (a Gaussian copula), which keeps the Gamma marginal exactly. It is
//! periodic and drifts with the waves from frame to frame.

use crate::constants::SPEED_OF_LIGHT_M_PER_S;
use crate::special::{bessel_i0, floor_i64, gamma_p, ln_gamma, round_exact};

use crate::cache::KeptLast;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use std::sync::{Arc, OnceLock};

/// Which σ0 model (`environment.clutter_model`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Sigma0Model {
    /// Gregers-Hansen & Mital (NRL) 2012.
    Nrl,
    /// Horst, Dyer & Tuley (GIT) 1978.
    Git,
}

/// Amplitude statistics of the clutter in one output (matched-filter, beam) cell. Every
/// option is compound Gaussian: the cell's intensity is `I = T·S`, a unit-mean texture `T`
/// (the cell's local mean power, correlated in space) times exponential speckle `S` (new
/// every pulse), which is what a matched filter preserves (docs/physics.md, Sea clutter).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ClutterDistribution {
    /// K: Gamma texture of shape ν (None: Ward's empirical ν for the cell);
    /// `E[I²]/E[I]² = 2(1 + 1/ν)`.
    K { shape_nu: Option<f64> },
    /// Weibull amplitude with shape `c` (Sekine & Mao convention: c = 2 is Rayleigh, sea
    /// clutter c ≈ 1.2–2), 0 < c ≤ 2: the texture is the inverse of a positive stable
    /// variable of index c/2, which makes `I` exactly Weibull;
    /// `E[I²]/E[I]² = Γ(1 + 4/c)/Γ(1 + 2/c)²`.
    Weibull { shape: f64 },
    /// Log-normal texture: `sigma_db` is the standard deviation of `10·log10 T`;
    /// `E[I²]/E[I]² = 2·exp(s²)`, `s = sigma_db·ln10/10` (the speckle adds 5.57 dB in
    /// quadrature to the spread of `10·log10 I`).
    LogNormal { sigma_db: f64 },
    /// Complex Gaussian (Rayleigh amplitude, T = 1); `E[I²]/E[I]² = 2`.
    Rayleigh,
}

impl ClutterDistribution {
    /// `E[I²]/E[I]²` of an output cell's intensity; for K with the empirical shape, pass
    /// the cell's ν in `cell_nu`.
    pub fn intensity_second_moment(&self, cell_nu: f64) -> f64 {
        match *self {
            ClutterDistribution::K { shape_nu } => 2.0 * (1.0 + 1.0 / shape_nu.unwrap_or(cell_nu)),
            ClutterDistribution::Weibull { shape } => {
                (ln_gamma(1.0 + 4.0 / shape) - 2.0 * ln_gamma(1.0 + 2.0 / shape)).exp()
            }
            ClutterDistribution::LogNormal { sigma_db } => {
                let s = sigma_db * std::f64::consts::LN_10 / 10.0;
                2.0 * (s * s).exp()
            }
            ClutterDistribution::Rayleigh => 2.0,
        }
    }
}

/// NRL (Gregers-Hansen & Mital 2012) mean reflectivity, dB (m²/m²).
pub fn nrl_sigma0_db(freq_ghz: f64, sea_state: f64, horizontal: bool, grazing_deg: f64) -> f64 {
    let (c1, c2, c3, c4, c5) = if horizontal {
        (-73.0, 20.781, 7.351, 25.65, 0.0054)
    } else {
        (-50.796, 25.93, 0.7093, 21.588, 0.00211)
    };
    let psi = grazing_deg;
    c1 + c2 * psi.to_radians().sin().log10()
        + (27.5 + c3 * psi) * freq_ghz.log10() / (1.0 + 0.95 * psi)
        + c4 * (sea_state + 1.0).powf(1.0 / (2.0 + 0.085 * psi + 0.033 * sea_state))
        + c5 * psi * psi
}

/// Wind speed used with the GIT model for a sea state, m/s.
pub fn sea_state_wind_speed_m_per_s(sea_state: f64) -> f64 {
    2.15 * sea_state.max(0.0).powf(1.04)
}

/// GIT (Horst, Dyer & Tuley 1978) mean reflectivity, dB; `wind_rel_rad` is the look
/// direction relative to upwind. Sea state 0 returns −200 dB (the model does not cover it).
pub fn git_sigma0_db(
    freq_ghz: f64,
    sea_state: f64,
    horizontal: bool,
    grazing_rad: f64,
    wind_rel_rad: f64,
) -> f64 {
    if sea_state <= 0.0 {
        return -200.0;
    }
    let lambda = SPEED_OF_LIGHT_M_PER_S / 1e9 / freq_ghz;
    let vw = sea_state_wind_speed_m_per_s(sea_state);
    let hav = 4.52e-3 * vw.powf(2.5);
    let psi = grazing_rad.max(1e-6);
    let sigma_phi = (14.4 * lambda + 5.5) * psi * hav / (lambda + 0.015);
    let ai = sigma_phi.powi(4) / (1.0 + sigma_phi.powi(4));
    let au = (0.2 * wind_rel_rad.cos() * (1.0 - 2.8 * psi) * (lambda + 0.015).powf(-0.4)).exp();
    let aw = (1.94 * vw / (1.0 + vw / 15.4)).powf(1.1 * (lambda + 0.015).powf(-0.4));
    let hh = 10.0 * (3.9e-6 * lambda * psi.powf(0.4) * ai * au * aw).log10();
    if horizontal {
        hh
    } else {
        hh - 1.05 * (hav + 0.015).ln() + 1.09 * lambda.ln() + 1.27 * (psi + 1e-4).ln() + 9.70
    }
}

/// GIT's upwind factor `A_u(φ)` divided by its mean over φ: a unit-mean directional power
/// modulation (upwind > crosswind > downwind), used with the direction-free NRL model.
pub fn wind_direction_factor(freq_ghz: f64, grazing_rad: f64, wind_rel_rad: f64) -> f64 {
    let lambda = SPEED_OF_LIGHT_M_PER_S / 1e9 / freq_ghz;
    let b = 0.2 * (1.0 - 2.8 * grazing_rad.max(0.0)) * (lambda + 0.015).powf(-0.4);
    // Mean of exp(b cos φ) over φ is I0(b).
    (b * wind_rel_rad.cos()).exp() / bessel_i0(b)
}

/// Rms wave height σ_h for sea states 0–6, m: a quarter of the upper significant wave height
/// of WMO sea-state code 3700 (0.1, 0.5, 1.25, 2.5, 4, 6 m), calm = 0.01 m; fractional
/// states interpolate.
pub fn sea_state_rms_height_m(sea_state: f64) -> f64 {
    const TABLE: [f64; 7] = [0.01, 0.025, 0.125, 0.3125, 0.625, 1.0, 1.5];
    let s = sea_state.clamp(0.0, 6.0);
    let i = (s.floor() as usize).min(5);
    let f = s - i as f64;
    TABLE[i] * (1.0 - f) + TABLE[i + 1] * f
}

/// log10 of the empirical K shape ν (Ward, Tough & Watts 2006) before clamping.
pub fn k_shape_log10(
    grazing_deg: f64,
    cell_area_m2: f64,
    horizontal: bool,
    swell_rel_rad: f64,
) -> f64 {
    let k_pol = if horizontal { 2.09 } else { 1.39 };
    (2.0 / 3.0) * grazing_deg.max(1e-3).log10() + 0.625 * cell_area_m2.max(1e-3).log10()
        - k_pol
        - (2.0 * swell_rel_rad).cos() / 3.0
}

/// Empirical K shape ν (Ward, Tough & Watts 2006), clamped to 0.1…20.
pub fn k_shape_default(
    grazing_deg: f64,
    cell_area_m2: f64,
    horizontal: bool,
    swell_rel_rad: f64,
) -> f64 {
    10f64
        .powf(k_shape_log10(
            grazing_deg,
            cell_area_m2,
            horizontal,
            swell_rel_rad,
        ))
        .clamp(0.1, 20.0)
}

/// The standard normal CDF Φ(g).
pub fn normal_cdf(g: f64) -> f64 {
    0.5 * crate::special::erfc(-g / std::f64::consts::SQRT_2)
}

/// A texture quantile composed with Φ, `T(g) = F⁻¹(Φ(g))`, tabulated (f32) at
/// `g = −8 + i/STEPS_PER_UNIT` (the Gaussian copula's map from field value to texture,
/// docs/physics.md "Sea clutter") and interpolated by a Catmull-Rom cubic in T: within
/// 5·10⁻⁴ of the composition it replaces wherever T ≥ 1 % of the mean, its moments within
/// 10⁻⁴ (the test), while sparing each cell an erfc, a table search and an exponential. A
/// table takes 8 kB, a quarter of a linear one as accurate, so more of the few hundred
/// per-cell shape levels a clutter map visits stay in cache. Beyond the table (|g| ≳ 8,
/// probability 1.2·10⁻¹⁵) the composition is evaluated.
#[derive(Debug)]
struct NormalTable {
    t: Vec<f32>,
}

impl NormalTable {
    const G_MIN: f64 = -8.0;
    const STEPS_PER_UNIT: f64 = 128.0;
    const LEN: usize = 2049;

    fn new(quantile: impl Fn(f64) -> f64) -> NormalTable {
        let t = (0..Self::LEN)
            .map(|i| {
                let g = Self::G_MIN + i as f64 / Self::STEPS_PER_UNIT;
                quantile(normal_cdf(g)) as f32
            })
            .collect();
        NormalTable { t }
    }

    /// `quantile(Φ(g))` from the table in `cell` (made on first use), evaluated outside it.
    #[inline]
    fn lookup(cell: &OnceLock<NormalTable>, quantile: impl Fn(f64) -> f64, g: f64) -> f64 {
        cell.get_or_init(|| NormalTable::new(&quantile))
            .value(g, quantile)
    }

    /// `quantile(Φ(g))`: from the table inside it, evaluated outside it.
    #[inline]
    fn value(&self, g: f64, quantile: impl Fn(f64) -> f64) -> f64 {
        self.at(g).unwrap_or_else(|| quantile(normal_cdf(g)))
    }

    /// `T(g)`, or None outside the table's inner intervals (the cubic needs a neighbour on
    /// each side).
    #[inline]
    fn at(&self, g: f64) -> Option<f64> {
        let x = (g - Self::G_MIN) * Self::STEPS_PER_UNIT;
        if !(x >= 1.0 && x < (Self::LEN - 2) as f64) {
            return None;
        }
        let i = x as usize;
        let f = x - i as f64;
        let p = &self.t[i - 1..i + 3];
        let (p0, p1, p2, p3) = (
            f64::from(p[0]),
            f64::from(p[1]),
            f64::from(p[2]),
            f64::from(p[3]),
        );
        Some(
            p1 + 0.5
                * f
                * (p2 - p0
                    + f * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + f * (3.0 * (p1 - p2) + p3 - p0))),
        )
    }
}

/// `i mod n` in `0..n`, without an integer division in the common cases (in range, or one
/// period below it: points west or south of the field's origin).
#[inline]
fn wrap(i: i64, n: usize) -> usize {
    let n_i = n as i64;
    if (0..n_i).contains(&i) {
        i as usize
    } else if (-n_i..0).contains(&i) {
        (i + n_i) as usize
    } else {
        i.rem_euclid(n_i) as usize
    }
}

/// `(i + 1) mod n` for `i` in `0..n`, without an integer division.
#[inline]
fn next_wrapped(i: usize, n: usize) -> usize {
    if i + 1 == n {
        0
    } else {
        i + 1
    }
}

/// Quantile function of Gamma(shape ν, mean 1), tabulated on a log grid of x.
#[derive(Debug)]
pub struct GammaQuantile {
    shape: f64,
    xs: Vec<f64>,
    cdf: Vec<f64>,
    of_normal: OnceLock<NormalTable>,
}

impl GammaQuantile {
    fn new(shape: f64) -> GammaQuantile {
        // x = ν·T is Gamma(ν, 1); tabulate T over 1e-12·… up to where 1 − F < 1e-12.
        let n = 1024;
        let (lo, hi) = (
            (1e-10f64).ln(),
            ((40.0 + 30.0 / shape.sqrt()) / shape.min(1.0))
                .max(60.0)
                .ln(),
        );
        let xs: Vec<f64> = (0..n)
            .map(|i| (lo + (hi - lo) * i as f64 / (n - 1) as f64).exp())
            .collect();
        // The CDF at every point from the regularised incomplete gamma P(ν, ν·t) itself
        // (a trapezoid rule in ln t lost 2 % of E[T²] at ν = 0.1, whose mass sits in a
        // long upper tail).
        let cdf: Vec<f64> = xs.iter().map(|&t| gamma_p(shape, shape * t)).collect();
        GammaQuantile {
            shape,
            xs,
            cdf,
            of_normal: OnceLock::new(),
        }
    }

    /// Texture value (mean 1) at the standard-normal value `g`: `quantile(Φ(g))`, from a
    /// table in `ln T` ([`NormalTable`]'s accuracy).
    #[inline]
    pub fn of_normal(&self, g: f64) -> f64 {
        NormalTable::lookup(&self.of_normal, |u| self.quantile(u), g)
    }

    /// [`GammaQuantile::of_normal`] of every value of `gs`, passed to `each` with its index:
    /// the same values, with the table fetched once for all of them.
    #[inline]
    pub fn of_normal_each(&self, gs: &[f64], mut each: impl FnMut(usize, f64)) {
        let table = self
            .of_normal
            .get_or_init(|| NormalTable::new(|u| self.quantile(u)));
        for (i, &g) in gs.iter().enumerate() {
            each(i, table.value(g, |u| self.quantile(u)));
        }
    }

    /// The table for shape ν exactly, from the process-wide cache of the last
    /// [`GammaQuantile::CACHE_LEN`] shapes asked for (all the per-cell levels and a few
    /// hundred fixed shapes of varied specs).
    pub fn for_shape(shape: f64) -> Arc<GammaQuantile> {
        GAMMA_TABLES.get_or_make(
            shape.to_bits(),
            || Arc::new(GammaQuantile::new(shape)),
            |_| 0,
        )
    }

    /// Tables kept: the per-cell levels' and as many more.
    pub const CACHE_LEN: usize = 2 * Self::LEVELS;

    /// Smallest shape of the per-cell levels (the empirical formula's clamp).
    pub const LEVEL_MIN: f64 = 0.1;
    /// Largest shape of the per-cell levels.
    pub const LEVEL_MAX: f64 = 20.0;
    /// Ratio between consecutive levels, as a natural-log step (1 %).
    const LEVEL_STEP: f64 = 0.01;
    /// Number of per-cell shape levels: ν = 0.1·e^(0.01·i) up to 20, so that a cell's ν is
    /// within 0.5 % of its formula value (and exactly 0.1 at the clamp).
    pub const LEVELS: usize = 531;

    /// The level of a shape given as log10 ν (clamped to 0.1…20).
    #[inline]
    pub fn level_from_log10(log10_shape: f64) -> usize {
        let x = (log10_shape * std::f64::consts::LN_10 - Self::LEVEL_MIN.ln()) / Self::LEVEL_STEP;
        (round_exact(x).max(0.0) as usize).min(Self::LEVELS - 1)
    }

    /// The shape of a level.
    pub fn level_shape(level: usize) -> f64 {
        (Self::LEVEL_MIN * (level as f64 * Self::LEVEL_STEP).exp()).min(Self::LEVEL_MAX)
    }

    /// The (cached) table of a level.
    pub fn for_level(level: usize) -> Arc<GammaQuantile> {
        Self::for_shape(Self::level_shape(level))
    }

    /// Texture value (mean 1) at probability `u`.
    pub fn quantile(&self, u: f64) -> f64 {
        let n = self.cdf.len();
        if u <= self.cdf[0] {
            // Lower tail F ≈ (νT)^ν/Γ(ν+1).
            return ((u * ln_gamma(self.shape + 1.0).exp()).powf(1.0 / self.shape) / self.shape)
                .max(0.0);
        }
        if u >= self.cdf[n - 1] {
            // Upper tail 1 − F ∝ e^(−νT).
            let tail = (1.0 - self.cdf[n - 1]).max(1e-300);
            return self.xs[n - 1] - ((1.0 - u).max(1e-300) / tail).ln() / self.shape;
        }
        let i = self.cdf.partition_point(|&c| c < u).clamp(1, n - 1);
        let (c0, c1) = (self.cdf[i - 1], self.cdf[i]);
        let f = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.0 };
        self.xs[i - 1] * (1.0 - f) + self.xs[i] * f
    }
}

/// A periodic, unit-variance Gaussian random field on a square grid, correlation
/// `exp(−d²/L²)`.
#[derive(Debug, Clone)]
pub struct GaussianField {
    side: usize,
    spacing_m: f64,
    /// Correlation of neighbouring grid values, `exp(−(spacing/L)²)`.
    neighbour_correlation: f64,
    values: Vec<f32>,
}

impl GaussianField {
    /// A field covering `extent_m` (side) with correlation length `correlation_m`; the grid
    /// spacing is L/3, or coarser if the grid would exceed 2048².
    pub fn new(rng: &mut Pcg64Mcg, extent_m: f64, correlation_m: f64) -> GaussianField {
        let spacing_m = (correlation_m / 3.0).max(extent_m / 2048.0);
        let side = ((extent_m / spacing_m).ceil() as usize).clamp(8, 2048);
        let mut values: Vec<f32> = (0..side * side)
            .map(|_| StandardNormal.sample(rng))
            .collect();
        // Kernel std s = L/2 in grid cells; taps ±3s; Σk² = 1 per axis keeps unit variance.
        let s = (correlation_m / 2.0 / spacing_m).max(1e-3);
        let half = (3.0 * s).ceil() as isize;
        let mut kernel: Vec<f32> = (-half..=half)
            .map(|i| (-(i as f64).powi(2) / (2.0 * s * s)).exp() as f32)
            .collect();
        let norm = kernel.iter().map(|k| k * k).sum::<f32>().sqrt();
        kernel.iter_mut().for_each(|k| *k /= norm);
        // Separable circular convolution: rows, then columns (via a transpose), each line
        // copied with wrap-around margins so the inner loop has no index arithmetic.
        let h = half as usize;
        let convolve_rows = |data: &mut [f32]| {
            data.par_chunks_mut(side).for_each_init(
                || vec![0f32; side + 2 * h],
                |ext, line| {
                    // ext[i] = line[(i − h) mod side], stepping the index instead of dividing.
                    let mut j = (side - h % side) % side;
                    for e in ext.iter_mut() {
                        *e = line[j];
                        j = if j + 1 == side { 0 } else { j + 1 };
                    }
                    // out[c] = Σ_t k_t·ext[c + t], summed in t order from −0.0 as `Sum` does,
                    // one tap at a time over the whole line (a loop that vectorises).
                    line.fill(-0.0);
                    for (t, &k) in kernel.iter().enumerate() {
                        for (out, &v) in line.iter_mut().zip(&ext[t..t + side]) {
                            *out += k * v;
                        }
                    }
                },
            );
        };
        let transpose = |data: &[f32]| -> Vec<f32> {
            let mut t = vec![0f32; side * side];
            t.par_chunks_mut(side).enumerate().for_each(|(c, row)| {
                for (r, v) in row.iter_mut().enumerate() {
                    *v = data[r * side + c];
                }
            });
            t
        };
        convolve_rows(&mut values);
        let mut t = transpose(&values);
        convolve_rows(&mut t);
        let values = transpose(&t);
        GaussianField {
            side,
            spacing_m,
            neighbour_correlation: (-(spacing_m / correlation_m).powi(2)).exp(),
            values,
        }
    }

    /// Bytes its values take.
    pub fn bytes(&self) -> usize {
        self.values.len() * std::mem::size_of::<f32>()
    }

    /// Value at (x, y) metres (periodic): bilinear between grid values, divided by the
    /// standard deviation of that interpolation so that every point has unit variance
    /// (a weighted mean of correlated values has less: `v(t) = (1−t)² + t² + 2t(1−t)ρ` per
    /// axis for neighbour correlation ρ, the correlation being separable) — otherwise the
    /// copula's marginals would be less spiky between grid points.
    #[inline]
    pub fn at(&self, x_m: f64, y_m: f64) -> f64 {
        let fx = x_m / self.spacing_m;
        let fy = y_m / self.spacing_m;
        let (x0, y0) = (floor_i64(fx), floor_i64(fy));
        let (tx, ty) = ((fx - x0 as f64) as f32, (fy - y0 as f64) as f32);
        let ix = wrap(x0, self.side);
        let iy = wrap(y0, self.side);
        let ix1 = next_wrapped(ix, self.side);
        let iy1 = next_wrapped(iy, self.side);
        let v = |r: usize, c: usize| self.values[r * self.side + c];
        let a = v(iy, ix) * (1.0 - tx) + v(iy, ix1) * tx;
        let b = v(iy1, ix) * (1.0 - tx) + v(iy1, ix1) * tx;
        let rho = self.neighbour_correlation;
        let var = |t: f64| (1.0 - t) * (1.0 - t) + t * t + 2.0 * t * (1.0 - t) * rho;
        let bilinear = (a * (1.0 - ty) + b * ty) as f64;
        bilinear / (var(tx as f64) * var(ty as f64)).sqrt()
    }

    /// [`GaussianField::at`] of every point `(_, x_m, y_m)` of `points` (the first member is
    /// the caller's tag), written to `values` (cleared first): the same values, in a loop of
    /// its own, compiled apart from its callers so that its few registers are not spilled.
    #[inline(never)]
    pub fn at_each<T>(&self, points: &[(T, f64, f64)], values: &mut Vec<f64>) {
        values.clear();
        values.extend(points.iter().map(|&(_, x, y)| self.at(x, y)));
    }
}

/// Quantile function of a positive distribution tabulated from its CDF on a log grid.
#[derive(Debug)]
pub struct TabulatedQuantile {
    xs: Vec<f64>,
    cdf: Vec<f64>,
    of_normal: OnceLock<NormalTable>,
}

impl TabulatedQuantile {
    /// Tabulates `cdf` (non-decreasing) at 2048 points log-spaced over `[lo, hi]`.
    pub fn from_cdf(lo: f64, hi: f64, cdf: impl Fn(f64) -> f64) -> TabulatedQuantile {
        let n = 2048;
        let (a, b) = (lo.ln(), hi.ln());
        let xs: Vec<f64> = (0..n)
            .map(|i| (a + (b - a) * i as f64 / (n - 1) as f64).exp())
            .collect();
        let mut last = 0.0f64;
        let cdf: Vec<f64> = xs
            .iter()
            .map(|&x| {
                last = last.max(cdf(x));
                last
            })
            .collect();
        TabulatedQuantile {
            xs,
            cdf,
            of_normal: OnceLock::new(),
        }
    }

    /// The value at the standard-normal value `g`: `quantile(Φ(g))`, from a table in `ln T`
    /// ([`NormalTable`]'s accuracy).
    #[inline]
    pub fn of_normal(&self, g: f64) -> f64 {
        NormalTable::lookup(&self.of_normal, |u| self.quantile(u), g)
    }

    /// The value at probability `u` (clamped to the tabulated range).
    pub fn quantile(&self, u: f64) -> f64 {
        let n = self.cdf.len();
        if u <= self.cdf[0] {
            return self.xs[0];
        }
        if u >= self.cdf[n - 1] {
            return self.xs[n - 1];
        }
        let i = self.cdf.partition_point(|&c| c < u).clamp(1, n - 1);
        let (c0, c1) = (self.cdf[i - 1], self.cdf[i]);
        let f = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.0 };
        self.xs[i - 1] * (1.0 - f) + self.xs[i] * f
    }
}

/// Unit-mean texture that makes compound-Gaussian clutter exactly Weibull with amplitude
/// shape `c` (0 < c < 2). With `α = c/2`, the Weibull intensity survival `exp(−x^α)` is the
/// Laplace transform of a positive α-stable `Z`, so `I = S/Z` (S exponential) is Weibull
/// (Bernstein; Feller, *An Introduction to Probability Theory*, vol. II, §XIII.6). Its CDF
/// follows Kanter's representation (Kanter, Ann. Probab. 3(4), 1975):
/// `P(Z ≤ z) = (1/π)∫₀^π exp(−A(u)·z^(−α/(1−α))) du`,
/// `A(u) = (sin αu / sin u)^(1/(1−α)) · sin((1−α)u)/sin αu`, so
/// `P(1/Z ≤ t) = 1 − (1/π)∫₀^π exp(−A(u)·t^(α/(1−α))) du`; `T = (1/Z)/Γ(1 + 1/α)`.
pub fn weibull_texture_quantile(amplitude_shape: f64) -> Arc<TabulatedQuantile> {
    WEIBULL_TEXTURES.get_or_make(
        amplitude_shape.to_bits(),
        || {
            let alpha = (amplitude_shape / 2.0).clamp(1e-3, 1.0 - 1e-6);
            let nodes = 4000;
            let a: Vec<f64> = (0..nodes)
                .map(|i| {
                    let u = std::f64::consts::PI * (i as f64 + 0.5) / nodes as f64;
                    ((alpha * u).sin() / u.sin()).powf(1.0 / (1.0 - alpha))
                        * ((1.0 - alpha) * u).sin()
                        / (alpha * u).sin()
                })
                .collect();
            let mean_inverse = ln_gamma(1.0 + 1.0 / alpha).exp();
            let p = alpha / (1.0 - alpha);
            // t is the unit-mean texture; 1/Z = t·Γ(1 + 1/α).
            let cdf = |t: f64| {
                let x = (t * mean_inverse).powf(p);
                1.0 - a.iter().map(|ai| (-ai * x).exp()).sum::<f64>() / nodes as f64
            };
            // Range: where the CDF leaves 1e-12 and reaches 1 − 1e-12.
            let (mut lo, mut hi) = (1e-3, 10.0);
            while cdf(lo) > 1e-12 && lo > 1e-300 {
                lo *= 0.1;
            }
            while 1.0 - cdf(hi) > 1e-12 && hi < 1e12 {
                hi *= 2.0;
            }
            Arc::new(TabulatedQuantile::from_cdf(lo, hi, cdf))
        },
        |_| 0,
    )
}

/// The Weibull textures' tables made last, by their shape's bits (at most
/// [`WEIBULL_CACHE_LEN`]).
pub static WEIBULL_TEXTURES: KeptLast<u64, Arc<TabulatedQuantile>> =
    KeptLast::new(WEIBULL_CACHE_LEN, usize::MAX);

/// Weibull texture tables kept.
pub const WEIBULL_CACHE_LEN: usize = 64;

/// The gamma quantile tables made last, by their shape's bits (a table is about 16 kB and
/// its normal lookup table the same again: at most about 35 MB).
pub static GAMMA_TABLES: KeptLast<u64, Arc<GammaQuantile>> =
    KeptLast::new(GammaQuantile::CACHE_LEN, usize::MAX);

/// Unit-mean log-normal texture `exp(s·g − s²/2)` of a standard normal `g`,
/// `s = sigma_db·ln10/10`.
#[inline]
pub fn lognormal_texture(g: f64, sigma_db: f64) -> f64 {
    let s = sigma_db * std::f64::consts::LN_10 / 10.0;
    (s * g - 0.5 * s * s).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `of_normal_each` (the clutter map's path: a table fetched once per run of cells) gives
    /// `of_normal`'s bits for every value, inside the table, on its edges and outside it (where
    /// both evaluate the composition), each passed with its own index, on a fresh table and
    /// on one already made.
    #[test]
    fn of_normal_each_is_of_normal_per_value() {
        let mut gs: Vec<f64> = (0..=4_000).map(|k| -10.0 + k as f64 * 0.005).collect();
        gs.extend([
            -8.0,
            -8.0 + 1.0 / 128.0,
            8.0 - 2.0 / 128.0,
            8.0,
            f64::MIN_POSITIVE,
            0.0,
        ]);
        for shape in [0.1, 0.37, GammaQuantile::level_shape(300), 20.0] {
            let q = GammaQuantile::new(shape);
            for _fresh_then_made in 0..2 {
                let mut seen = vec![None; gs.len()];
                q.of_normal_each(&gs, |i, t| seen[i] = Some(t.to_bits()));
                for (i, &g) in gs.iter().enumerate() {
                    assert_eq!(seen[i], Some(q.of_normal(g).to_bits()), "nu {shape}, g {g}");
                }
            }
        }
    }

    /// The T table of the Gaussian copula (`of_normal`) against the composition
    /// `quantile(Φ(g))` it replaces, for K shapes 0.1 … 20 and a Weibull texture: within
    /// 5·10⁻⁴ relative (0.002 dB) wherever T ≥ 1 % of the mean and |g| ≤ 7.5 (beyond, at
    /// probabilities under 10⁻¹³, the composition's own 1 − u loses its digits; below 1 % of
    /// the mean the two tables' interpolations differ by up to 10⁻³ of a negligible value),
    /// and E[T], E[T²] over g ~ N(0, 1) (quadrature, step 10⁻³) within 10⁻⁴.
    #[test]
    fn texture_of_normal_matches_the_composition() {
        let weibull = weibull_texture_quantile(1.2);
        type Pair = Box<dyn Fn(f64) -> (f64, f64)>;
        let mut tables: Vec<(String, Pair)> = [0.1, 0.3, 1.0, 3.0, 20.0]
            .iter()
            .map(|&nu| {
                let q = GammaQuantile::for_shape(nu);
                let f: Pair = Box::new(move |g| (q.of_normal(g), q.quantile(normal_cdf(g))));
                (format!("K nu {nu}"), f)
            })
            .collect();
        tables.push((
            "Weibull c 1.2".into(),
            Box::new(move |g| (weibull.of_normal(g), weibull.quantile(normal_cdf(g)))),
        ));
        for (name, f) in &tables {
            let (mut worst, mut m1, mut m2) = (0f64, [0f64; 2], [0f64; 2]);
            for k in 0..=16_000 {
                let g = -8.0 + k as f64 * 0.001;
                let (a, b) = f(g);
                if b >= 0.01 && g.abs() <= 7.5 {
                    worst = worst.max((a - b).abs() / b);
                }
                let w = (-0.5 * g * g).exp() * 0.001 / (2.0 * std::f64::consts::PI).sqrt();
                m1 = [m1[0] + w * a, m1[1] + w * b];
                m2 = [m2[0] + w * a * a, m2[1] + w * b * b];
            }
            eprintln!(
                "{name}: worst {worst:.2e}, E[T] {:.2e}, E[T²] {:.2e}",
                m1[0] / m1[1] - 1.0,
                m2[0] / m2[1] - 1.0
            );
            assert!(worst < 5e-4, "{name}: worst relative error {worst:.2e}");
            assert!((m1[0] / m1[1] - 1.0).abs() < 1e-4, "{name}: E[T] {m1:?}");
            assert!((m2[0] / m2[1] - 1.0).abs() < 1e-4, "{name}: E[T²] {m2:?}");
        }
    }

    #[test]
    fn nrl_published_check_value() {
        let v = nrl_sigma0_db(30.0, 2.0, true, 10.0);
        assert!((v + 36.66).abs() < 0.01, "{v}");
    }

    #[test]
    fn gamma_tables_match_the_incomplete_gamma() {
        for nu in [0.1, 0.5, 1.0, 4.0, 20.0] {
            let q = GammaQuantile::for_shape(nu);
            for u in [0.01, 0.1, 0.5, 0.9, 0.99, 0.999] {
                let t = q.quantile(u);
                let back = gamma_p(q.shape, q.shape * t);
                assert!((back - u).abs() < 1e-3, "nu {nu}: u {u} -> t {t} -> {back}");
            }
        }
        // Exponential (ν = 1): P(1, x) = 1 − e^−x.
        assert!((gamma_p(1.0, 2.0) - (1.0 - (-2.0f64).exp())).abs() < 1e-12);
    }

    #[test]
    fn weibull_texture_gives_weibull_moments() {
        // E[T²] of the texture must be Γ(1+4/c)/(2·Γ(1+2/c)²) for the compound to be
        // Weibull(c); check by integrating the quantile over u.
        for c in [0.8, 1.2, 1.5, 1.9] {
            let q = weibull_texture_quantile(c);
            let n = 200_000;
            let (mut m1, mut m2) = (0.0, 0.0);
            for i in 0..n {
                let t = q.quantile((i as f64 + 0.5) / n as f64);
                m1 += t;
                m2 += t * t;
            }
            m1 /= n as f64;
            m2 /= n as f64;
            let want = ClutterDistribution::Weibull { shape: c }.intensity_second_moment(0.0) / 2.0;
            assert!((m1 - 1.0).abs() < 2e-3, "c {c}: mean {m1}");
            assert!(
                (m2 / want - 1.0).abs() < 5e-3,
                "c {c}: E[T²] {m2} vs {want}"
            );
        }
    }
}
