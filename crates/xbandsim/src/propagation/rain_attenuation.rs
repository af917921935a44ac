//! Stage: propagation — rain attenuation along a path.
//!
//! Specific attenuation (Recommendation ITU-R P.838-3, 2005): `γ = k·R^α` dB/km, with
//! `log10 k = Σ_{j=1..4} a_j·exp(−((log10 f − b_j)/c_j)²) + m_k·log10 f + c_k` and
//! `α = Σ_{j=1..5} a_j·exp(−((log10 f − b_j)/c_j)²) + m_α·log10 f + c_α` (f in GHz), with the
//! coefficients of the Recommendation's Tables 1–4 for horizontal and vertical polarisation.
//! At 10 GHz: k_H = 0.01217, α_H = 1.2571, k_V = 0.01129, α_V = 1.2156.

use crate::environment::rain::Rain;
use glam::DVec2;

const K_H: ([f64; 4], [f64; 4], [f64; 4], f64, f64) = (
    [-5.33980, -0.35351, -0.23789, -0.94158],
    [-0.10008, 1.26970, 0.86036, 0.64552],
    [1.13098, 0.45400, 0.15354, 0.16817],
    -0.18961,
    0.71147,
);
const K_V: ([f64; 4], [f64; 4], [f64; 4], f64, f64) = (
    [-3.80595, -3.44965, -0.39902, 0.50167],
    [0.56934, -0.22911, 0.73042, 1.07319],
    [0.81061, 0.51059, 0.11899, 0.27195],
    -0.16398,
    0.63297,
);
const ALPHA_H: ([f64; 5], [f64; 5], [f64; 5], f64, f64) = (
    [-0.14318, 0.29591, 0.32177, -5.37610, 16.1721],
    [1.82442, 0.77564, 0.63773, -0.96230, -3.29980],
    [-0.55187, 0.19822, 0.13164, 1.47828, 3.43990],
    0.67849,
    -1.95537,
);
const ALPHA_V: ([f64; 5], [f64; 5], [f64; 5], f64, f64) = (
    [-0.07771, 0.56727, -0.20238, -48.2991, 48.5833],
    [2.33840, 0.95545, 1.14520, 0.791669, 0.791459],
    [-0.76284, 0.54039, 0.26809, 0.116226, 0.116479],
    -0.053739,
    0.83433,
);

fn gaussian_sum<const N: usize>(t: &([f64; N], [f64; N], [f64; N], f64, f64), log_f: f64) -> f64 {
    let (a, b, c, m, k) = t;
    (0..N)
        .map(|j| a[j] * (-((log_f - b[j]) / c[j]).powi(2)).exp())
        .sum::<f64>()
        + m * log_f
        + k
}

/// ITU-R P.838-3 coefficients at `freq_ghz`: (k_H, α_H, k_V, α_V).
pub fn itu_p838_coefficients(freq_ghz: f64) -> (f64, f64, f64, f64) {
    let lf = freq_ghz.log10();
    (
        10f64.powf(gaussian_sum(&K_H, lf)),
        gaussian_sum(&ALPHA_H, lf),
        10f64.powf(gaussian_sum(&K_V, lf)),
        gaussian_sum(&ALPHA_V, lf),
    )
}

/// One-way specific attenuation `γ = k·R^α`, dB/km, for horizontal or vertical polarisation.
pub fn specific_attenuation_db_per_km(freq_ghz: f64, rate_mm_per_h: f64, horizontal: bool) -> f64 {
    if rate_mm_per_h <= 0.0 {
        return 0.0;
    }
    let (kh, ah, kv, av) = itu_p838_coefficients(freq_ghz);
    if horizontal {
        kh * rate_mm_per_h.powf(ah)
    } else {
        kv * rate_mm_per_h.powf(av)
    }
}

impl Rain {
    /// One-way attenuation (dB) from `from` to a ground range `range_m` along unit direction
    /// `dir` (horizontal), integrating γ over the chord through each cell.
    pub fn one_way_attenuation_db(
        &self,
        from: DVec2,
        dir: DVec2,
        range_m: f64,
        freq_ghz: f64,
        horizontal: bool,
    ) -> f64 {
        self.attenuator(freq_ghz, horizontal)
            .one_way_db(from, dir, range_m)
    }

    /// The specific attenuations at one frequency and polarisation, computed once.
    pub fn attenuator(&self, freq_ghz: f64, horizontal: bool) -> RainAttenuator<'_> {
        RainAttenuator {
            rain: self,
            uniform_db_per_m: specific_attenuation_db_per_km(
                freq_ghz,
                self.uniform_rate_mm_per_h,
                horizontal,
            ) / 1000.0,
            cell_db_per_m: self
                .cells
                .iter()
                .map(|c| {
                    specific_attenuation_db_per_km(freq_ghz, c.rate_mm_per_h, horizontal) / 1000.0
                })
                .collect(),
        }
    }
}

/// Rain attenuation along rays, with the specific attenuations precomputed.
#[derive(Debug, Clone)]
pub struct RainAttenuator<'a> {
    rain: &'a Rain,
    uniform_db_per_m: f64,
    cell_db_per_m: Vec<f64>,
}

impl RainAttenuator<'_> {
    /// The stretches of a ray from `from` along unit `dir` inside each cell:
    /// (start m, end m, dB/m), for repeated evaluation along one ray.
    pub fn chords(&self, from: DVec2, dir: DVec2) -> Vec<(f64, f64, f64)> {
        let mut out = Vec::new();
        for (c, &g) in self.rain.cells.iter().zip(&self.cell_db_per_m) {
            // Segment from + t·dir against the circle.
            let oc = from - c.centre_m;
            let b = oc.dot(dir);
            let disc = b * b - (oc.length_squared() - c.radius_m * c.radius_m);
            if disc > 0.0 {
                let sq = disc.sqrt();
                let (t0, t1) = ((-b - sq).max(0.0), -b + sq);
                if t1 > t0 {
                    out.push((t0, t1, g));
                }
            }
        }
        out
    }

    /// One-way attenuation (dB) to ground range `range_m` along a ray with these `chords`.
    #[inline]
    pub fn one_way_db_along(&self, chords: &[(f64, f64, f64)], range_m: f64) -> f64 {
        self.uniform_db_per_m * range_m
            + chords
                .iter()
                .map(|&(t0, t1, g)| (range_m.min(t1) - t0).max(0.0) * g)
                .sum::<f64>()
    }

    /// One-way attenuation (dB) from `from` to ground range `range_m` along unit `dir`.
    pub fn one_way_db(&self, from: DVec2, dir: DVec2, range_m: f64) -> f64 {
        self.one_way_db_along(&self.chords(from, dir), range_m)
    }

    /// The part of a straight path from height `from_z_m` to `to_z_m` that lies in the rain,
    /// `|z| ≤ top`, as an interval `[s0, s1]` of the path's fraction from its start (empty,
    /// `s0 = s1`, when none of it does). Real paths have `z ≥ 0`, where this is `z ≤ top`; a
    /// leg via the sea is drawn to its object's mirror image below the sea, and folding that
    /// straight line at z = 0 gives the real broken path, so `|z| ≤ top` picks out exactly the
    /// real path's stretch under the top (with the same ground track).
    #[inline]
    fn below_top(&self, from_z_m: f64, to_z_m: f64) -> (f64, f64) {
        let top = self.rain.top_m;
        let dz = to_z_m - from_z_m;
        if dz == 0.0 {
            return if from_z_m.abs() <= top {
                (0.0, 1.0)
            } else {
                (0.0, 0.0)
            };
        }
        // Where the line meets z = top and z = −top; between them it is in the rain.
        let (a, b) = ((top - from_z_m) / dz, (-top - from_z_m) / dz);
        let (s0, s1) = (a.min(b).max(0.0), a.max(b).min(1.0));
        if s1 > s0 {
            (s0, s1)
        } else {
            (0.0, 0.0)
        }
    }

    /// [`RainAttenuator::one_way_db_path`] along a track with these `chords`, for
    /// `ground_m` > 0 (the clutter map evaluates many ranges along one spoke's track).
    #[inline]
    pub fn one_way_db_path_along(
        &self,
        chords: &[(f64, f64, f64)],
        ground_m: f64,
        slant_m: f64,
        from_z_m: f64,
        to_z_m: f64,
    ) -> f64 {
        let (s0, s1) = self.below_top(from_z_m, to_z_m);
        if s1 <= s0 {
            return 0.0;
        }
        // The ground track's stretch under the rain top: chords are clipped to it (a whole
        // path below the top is the track from 0 to ground_m, the chords' own start ≥ 0).
        let (g0, g1) = (s0 * ground_m, s1 * ground_m);
        let on_track = self.uniform_db_per_m * (g1 - g0)
            + chords
                .iter()
                .map(|&(t0, t1, g)| (g1.min(t1) - g0.max(t0)).max(0.0) * g)
                .sum::<f64>();
        on_track * (slant_m / ground_m)
    }

    /// One-way attenuation (dB) of a straight path `slant_m` long from height `from_z_m` to
    /// `to_z_m` whose ground track runs from `from` along unit `dir` for `ground_m`: rain fills
    /// vertical columns from the sea up to the rain top, so the path loses γ over its part
    /// below the top, and each chord on the track is `slant_m / ground_m` longer along the
    /// path (docs/physics.md §2.7). A vertical path (`ground_m` 0) loses the specific
    /// attenuation where it stands times its length below the top. Targets' echoes, their
    /// labels and the clutter map all use it.
    pub fn one_way_db_path(
        &self,
        from: DVec2,
        dir: DVec2,
        ground_m: f64,
        slant_m: f64,
        from_z_m: f64,
        to_z_m: f64,
    ) -> f64 {
        if ground_m > 0.0 {
            self.one_way_db_path_along(&self.chords(from, dir), ground_m, slant_m, from_z_m, to_z_m)
        } else {
            let (s0, s1) = self.below_top(from_z_m, to_z_m);
            let here: f64 = self
                .rain
                .cells
                .iter()
                .zip(&self.cell_db_per_m)
                .filter(|(c, _)| (from - c.centre_m).length() <= c.radius_m)
                .map(|(_, &g)| g)
                .sum();
            (self.uniform_db_per_m + here) * slant_m * (s1 - s0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ITU-R P.838-3 at 10 GHz (the Recommendation's own check values).
    #[test]
    fn p838_at_10_ghz() {
        let (kh, ah, kv, av) = itu_p838_coefficients(10.0);
        assert!(
            (kh - 0.01217).abs() < 5e-5 && (ah - 1.2571).abs() < 5e-4,
            "{kh} {ah}"
        );
        assert!(
            (kv - 0.01129).abs() < 5e-5 && (av - 1.2156).abs() < 5e-4,
            "{kv} {av}"
        );
    }

    /// The part of a path under the rain top: a whole path below it loses γ·R, one above it
    /// nothing, and one that crosses it γ over the stretch below (from either end), with a
    /// rain cell's chord clipped the same way at either of its ends; a leg drawn to an object's
    /// image below the sea is charged the real broken path's stretch under the top.
    #[test]
    fn only_the_path_below_the_rain_top_is_attenuated() {
        use crate::environment::rain::{Rain, RainCell};
        let rain = Rain {
            uniform_rate_mm_per_h: 10.0,
            top_m: 100.0,
            cells: vec![RainCell {
                centre_m: DVec2::new(0.0, 300.0),
                radius_m: 100.0,
                rate_mm_per_h: 40.0,
            }],
        };
        let a = rain.attenuator(9.41, true);
        let gamma = specific_attenuation_db_per_km(9.41, 10.0, true) / 1000.0;
        let cell = specific_attenuation_db_per_km(9.41, 40.0, true) / 1000.0;
        let (o, north) = (DVec2::ZERO, DVec2::new(0.0, 1.0));
        let close = |x: f64, y: f64| (x - y).abs() < 1e-12 * y.abs().max(1.0);
        // Ground track 1000 m (the cell's chord 200..400 m), slant 1000·√2 from 0 up to 1000 m.
        let slant = 1000.0 * 2f64.sqrt();
        let below = a.one_way_db_path(o, north, 1000.0, slant, 4.0, 4.0);
        assert!(close(below, (gamma * 1000.0 + cell * 200.0) * 2f64.sqrt()));
        assert_eq!(
            a.one_way_db_path(o, north, 1000.0, slant, 150.0, 900.0),
            0.0
        );
        // Climbing from 0 to 1000 m: the first 100 m of height, the track's first 100 m.
        let up = a.one_way_db_path(o, north, 1000.0, slant, 0.0, 1000.0);
        assert!(close(up, gamma * 100.0 * 2f64.sqrt()), "{up}");
        // Descending from 1000 m to 0: the track's last 100 m (no cell there).
        let down = a.one_way_db_path(o, north, 1000.0, slant, 1000.0, 0.0);
        assert!(close(down, gamma * 100.0 * 2f64.sqrt()), "{down}");
        // Climbing from 0 to 250 m: the track's first 400 m, the whole chord.
        let part = a.one_way_db_path(o, north, 1000.0, slant, 0.0, 250.0);
        assert!(
            close(part, (gamma * 400.0 + cell * 200.0) * 2f64.sqrt()),
            "{part}"
        );
        // Climbing from 0 to 333.33 m: the first 300 m of track, half the chord.
        let half = a.one_way_db_path(o, north, 1000.0, slant, 0.0, 1000.0 / 3.0);
        assert!(
            close(half, (gamma * 300.0 + cell * 100.0) * 2f64.sqrt()),
            "{half}"
        );
        // Straight up from inside the cell: 100 m of its rain and the uniform rain.
        let up_here = a.one_way_db_path(DVec2::new(0.0, 300.0), north, 0.0, 500.0, 0.0, 500.0);
        assert!(close(up_here, (gamma + cell) * 100.0), "{up_here}");
        // Descending from 1000 m into a deeper layer (top 700 m): the track from 300 m on,
        // the cell's chord clipped at its start to 300..400 m.
        let deep = Rain {
            top_m: 700.0,
            ..rain.clone()
        };
        let d = deep.attenuator(9.41, true);
        let down_deep = d.one_way_db_path(o, north, 1000.0, slant, 1000.0, 0.0);
        assert!(
            close(down_deep, (gamma * 700.0 + cell * 100.0) * 2f64.sqrt()),
            "{down_deep}"
        );
        // A leg via the sea to an object 300 m up, drawn to its image at −300 m from a radar
        // at 15 m: the real path (down to the sea, up to 300 m) is under the 100 m top from
        // its start until it climbs through 100 m, 115/315 of it, as is the image line
        // between z = 15 and z = −100. The whole image line would be charged without the fold.
        // Its track under the top ends at 365 m, inside the cell's chord (200..400 m).
        let image = a.one_way_db_path(o, north, 1000.0, slant, 15.0, -300.0);
        let under_m = 1000.0 * 115.0 / 315.0;
        assert!(
            close(
                image,
                (gamma * under_m + cell * (under_m - 200.0)) * 2f64.sqrt()
            ),
            "{image}"
        );
        // A level path at the top is in the rain; one above it is not.
        assert!(a.one_way_db_path(o, north, 1000.0, 1000.0, 100.0, 100.0) > 0.0);
        assert_eq!(
            a.one_way_db_path(o, north, 1000.0, 1000.0, 101.0, 101.0),
            0.0
        );
    }
}
