//! Clutter map, stage: land echo (docs/physics.md §16). Each output cell's land power is the
//! beam-weighted mean of the visible land patches around it (`P̄ = Σ_j Gn²(jδ)·m_{k+j}`, as
//! the sea's), times a texture `T` with a Weibull amplitude: the cell's echo is
//! `√(P̄·T)·e^{jφ}`. Land stands still, so the echo is frozen: the same in every pulse of a
//! revolution and, for a radar that does not move, in every revolution (T and φ are keyed
//! on where the cell lies and on the render's seed, not on the pulse or the frame).
//!
//! **Texture.** `T = (−ln(1 − u))^{2/c} / Γ(1 + 2/c)` with `u = Φ(z)`: for uniform u the
//! amplitude `(−ln(1 − u))^{1/c}` is Weibull with shape c, and dividing by `E[A²] = Γ(1+2/c)`
//! gives `E[T] = 1`, so that the mean power is the radar equation's. `z` is a unit-variance
//! Gaussian field over the ground: independent normals on a square grid
//! [`LAND_TEXTURE_LENGTH_M`] apart, bilinearly interpolated and divided by the weights' root
//! sum of squares, so that cells closer than the grid step are correlated and the marginal
//! stays exactly Weibull (a Gaussian copula).

use super::spoke::NO_POLYGON;
use crate::land::Land;
use crate::rng::splitmix64;
use glam::DVec2;
use num_complex::Complex32;

/// Spacing of the land texture's grid, m: land cells closer than this share their texture
/// in part. Billingsley (*Low-Angle Radar Land Clutter*, 2002, ch. 2) describes low-angle
/// land clutter as patchy at the scale of terrain features; 25 m (a few range cells of a
/// marine radar) is this model's assumption.
pub const LAND_TEXTURE_LENGTH_M: f64 = 25.0;

/// A unit normal keyed on `(seed, ix, iy, salt)` (Box–Muller on two hashed uniforms).
fn hashed_normal(seed: u64, ix: i64, iy: i64, salt: u64) -> f64 {
    let h = splitmix64(splitmix64(splitmix64(seed ^ salt) ^ ix as u64) ^ iy as u64);
    let u1 = ((h >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let h2 = splitmix64(h);
    let u2 = crate::rng::unit_f64(h2);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// The unit-variance Gaussian field at `p` (ground metres) for `seed`.
pub fn texture_gaussian(seed: u64, p: DVec2) -> f64 {
    TextureField::new(seed).at(p)
}

/// The texture's Gaussian field for one seed, keeping the grid square last read: cells along
/// a spoke, a range sample apart, mostly share their four grid values (the same values).
struct TextureField {
    seed: u64,
    last: Option<((i64, i64), [f64; 4])>,
}

impl TextureField {
    fn new(seed: u64) -> TextureField {
        TextureField { seed, last: None }
    }

    /// The field at `p`.
    fn at(&mut self, p: DVec2) -> f64 {
        let q = p / LAND_TEXTURE_LENGTH_M;
        let (fx, fy) = (q.x.floor(), q.y.floor());
        let (tx, ty) = (q.x - fx, q.y - fy);
        let key = (fx as i64, fy as i64);
        let nodes = match self.last {
            Some((k, nodes)) if k == key => nodes,
            _ => {
                let (ix, iy, seed) = (key.0, key.1, self.seed);
                let nodes = [
                    hashed_normal(seed, ix, iy, 0x1a4d),
                    hashed_normal(seed, ix + 1, iy, 0x1a4d),
                    hashed_normal(seed, ix, iy + 1, 0x1a4d),
                    hashed_normal(seed, ix + 1, iy + 1, 0x1a4d),
                ];
                self.last = Some((key, nodes));
                nodes
            }
        };
        let w = [
            (1.0 - tx) * (1.0 - ty),
            tx * (1.0 - ty),
            (1.0 - tx) * ty,
            tx * ty,
        ];
        let z = w[0] * nodes[0] + w[1] * nodes[1] + w[2] * nodes[2] + w[3] * nodes[3];
        z / w.iter().map(|v| v * v).sum::<f64>().sqrt()
    }
}

/// The texture `T` (mean 1) of a cell whose field value is `z`, Weibull amplitude shape `c`.
pub fn weibull_texture(z: f64, shape: f64) -> f64 {
    weibull_texture_normed(z, shape, crate::special::ln_gamma(1.0 + 2.0 / shape).exp())
}

/// [`weibull_texture`] with its normalisation `Γ(1 + 2/c)` given.
fn weibull_texture_normed(z: f64, shape: f64, gamma_2_over_c: f64) -> f64 {
    // 1 − Φ(z) = erfc(z/√2)/2, kept away from 0 so that the log stays finite.
    let tail = (0.5 * crate::special::erfc(z / std::f64::consts::SQRT_2)).max(1e-300);
    (-tail.ln()).powf(2.0 / shape) / gamma_2_over_c
}

/// The frozen land echo of one spoke into `echo` (noise-rms units, empty where the spoke has
/// no land near): `power_rows` are every spoke's land patches, `weights` the azimuth
/// weights (index t for spoke `k + t − J`), `ground_m[n]` each sample's ground range, `dir`
/// the spoke's direction from `origin`.
#[allow(clippy::too_many_arguments)]
pub(super) fn spoke_echo(
    k: usize,
    power_rows: &[Vec<f32>],
    polygon_rows: &[Vec<u32>],
    weights: &[f32],
    land: &Land,
    seed: u64,
    origin: DVec2,
    dir: DVec2,
    ground_m: &[f64],
    echo: &mut Vec<Complex32>,
) {
    echo.clear();
    let spokes = power_rows.len();
    let half = (weights.len() / 2) as isize;
    let neighbour =
        |t: usize| (k as isize + t as isize - half).rem_euclid(spokes as isize) as usize;
    if (0..weights.len()).all(|t| power_rows[neighbour(t)].is_empty()) {
        return;
    }
    let samples = ground_m.len();
    echo.resize(samples, Complex32::new(0.0, 0.0));
    // Only the samples where some neighbouring row has land.
    let (mut lo, mut hi) = (samples, 0);
    for t in 0..weights.len() {
        let row = &power_rows[neighbour(t)];
        if let Some(first) = row.iter().position(|&p| p > 0.0) {
            let last = row.iter().rposition(|&p| p > 0.0).unwrap_or(first);
            lo = lo.min(first);
            hi = hi.max(last + 1);
        }
    }
    let mut field = TextureField::new(seed);
    let mut norm: Option<(u32, f64)> = None;
    for (n, e) in echo.iter_mut().enumerate().take(hi).skip(lo) {
        let (mut mean, mut top, mut dominant) = (0f32, 0f32, NO_POLYGON);
        for (t, &w) in weights.iter().enumerate() {
            let j = neighbour(t);
            let (Some(&p), Some(&poly)) = (power_rows[j].get(n), polygon_rows[j].get(n)) else {
                continue;
            };
            let v = w * p;
            mean += v;
            if v > top {
                top = v;
                dominant = poly;
            }
        }
        if mean <= 0.0 || dominant == NO_POLYGON {
            continue;
        }
        let cell = origin + dir * ground_m[n];
        let shape = land.polygons()[dominant as usize].weibull_shape;
        let gamma_2_over_c = match norm {
            Some((p, g)) if p == dominant => g,
            _ => {
                let g = crate::special::ln_gamma(1.0 + 2.0 / shape).exp();
                norm = Some((dominant, g));
                g
            }
        };
        let texture = weibull_texture_normed(field.at(cell), shape, gamma_2_over_c);
        let amplitude = (mean as f64 * texture).sqrt();
        let h = splitmix64(splitmix64(seed ^ 0x9a5e) ^ ((k as u64) << 32 | n as u64));
        let phase = std::f64::consts::TAU * crate::rng::unit_f64(h);
        *e = Complex32::new(
            (amplitude * phase.cos()) as f32,
            (amplitude * phase.sin()) as f32,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_texture_has_mean_one_and_the_weibull_amplitude_moments() {
        // Over many independent grid points: E[T] = 1 and E[T²] = Γ(1+4/c)/Γ(1+2/c)² (the
        // amplitude's fourth moment over its second squared), within 3 % for 2·10⁵ cells.
        for &c in &[0.6, 1.2, 2.0] {
            let n = 200_000;
            let (mut m1, mut m2) = (0.0, 0.0);
            for i in 0..n {
                let p = DVec2::new((i % 1000) as f64, (i / 1000) as f64) * LAND_TEXTURE_LENGTH_M;
                let t = weibull_texture(texture_gaussian(11, p), c);
                m1 += t;
                m2 += t * t;
            }
            m1 /= n as f64;
            m2 /= n as f64;
            let g = |x: f64| crate::special::ln_gamma(x).exp();
            let want = g(1.0 + 4.0 / c) / g(1.0 + 2.0 / c).powi(2);
            assert!((m1 - 1.0).abs() < 0.03, "c {c}: mean {m1}");
            // The fourth moment of a spiky Weibull converges slowly: 10 % there.
            assert!((m2 / want - 1.0).abs() < 0.1, "c {c}: {m2} vs {want}");
        }
    }

    #[test]
    fn the_field_has_unit_variance_between_grid_points_and_is_correlated() {
        let n = 100_000;
        let (mut v, mut cov) = (0.0, 0.0);
        for i in 0..n {
            let p = DVec2::new((i % 400) as f64 * 61.3 + 7.1, (i / 400) as f64 * 47.9 + 3.3);
            let z = texture_gaussian(5, p);
            v += z * z;
            cov += z * texture_gaussian(5, p + DVec2::new(5.0, 0.0));
        }
        v /= n as f64;
        cov /= n as f64;
        assert!((v - 1.0).abs() < 0.02, "variance {v}");
        assert!(cov > 0.6, "correlation at 5 m {cov}");
    }
}
