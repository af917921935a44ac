//! Signal source data: sea and rain clutter of one antenna revolution as distributed
//! scatterers entering the echo before the matched filter (docs/physics.md, Sea clutter and
//! Rain), made in named stages: [`geometry`] (each range sample's cell geometry and the
//! azimuth weights), [`spoke`] (σ0 and rain along each spoke), [`texture`] (each output
//! cell's texture) and [`speckle`] (each pulse's or dwell's complex Gaussian echo).
//!
//! The sea within the record is cut into patches: one azimuth step δ = 2π/spokes wide (at the
//! spokes' azimuths) and one range sample Δr = c/(2fs) deep. A patch at slant range R,
//! ground range g and grazing angle ψ has area `A = g·δ·Δr·sec ψ` and mean power
//! (in noise units) `m = σ0(ψ, wind)·A·Pt·G0²·λ²·Gn_el(−ψ)²/((4π)³·R⁴·L·N)`, times the two-way
//! rain and atmospheric attenuation. Rain adds `η·V` with `V = R²·δ·Δr·∫Gn_el²(θ)dθ` over the
//! elevations filled with rain. Because speckle is independent pulse to pulse, the echo of
//! spoke k in sample n is complex Gaussian with variance
//! `P_k[n] = T_k[n]·Σ_j Gn²(j·δ)·m_{k+j}[n] + Σ_j Gn²(j·δ)·rain_{k+j}[n]` — the same in
//! distribution as summing every patch's scatterers weighted by the two-way azimuth pattern,
//! at the cost of one draw per sample. The weights are scaled so that Σ_j Gn²(jδ)
//! equals the two-way beam integral `∫Gn²(θ)dθ = (2π/3)·θ3dB/2.783 = 0.753·θ3dB`, so that the
//! mean clutter power of a cell equals the radar equation with `σ = σ0·A_c`,
//! `A_c = R·(0.753·θ3dB)·(c/2B)·sec ψ` after the matched filter.
//!
//! **Texture of a cell.** `T_k[n]` is the texture of the output cell at spoke k's beam centre
//! and range sample n: the spatially correlated field's value there (drifting with the
//! waves), mapped to the documented marginal. It multiplies the beam-weighted mean rather than
//! each patch, because the shape parameters describe resolution cells (Ward's empirical ν
//! is fitted to cells of area A_c): texturing patches and then averaging them over the beam
//! would dilute the spikiness a second time. The matched filter then only mixes samples within
//! the compressed pulse (c/2B, a few metres against the field's tens of metres), so output
//! cells keep the marginal (`E[I²]/E[I]²` checked in `xbandsim validate`) while neighbouring
//! cells stay correlated over the field's correlation length.
//!
//! Grazing angle over the 4/3 earth: `sin ψ = h/R − R/(2a_e)`; patches with ψ ≤ 0 are beyond
//! the horizon and return nothing.

mod geometry;
mod speckle;
mod spoke;
mod texture;

pub use speckle::{doppler_lines, DwellClutterScratch, GaussianDoppler, MAX_DOPPLER_LINES};
#[cfg(test)]
pub(crate) use texture::{texture_field, TEXTURE_FIELDS};

use crate::environment::clutter::ClutterDistribution;
use crate::model::{Environment, Radar};
use crate::rng::FrameKey;
use geometry::MapGeometry;
use rayon::prelude::*;
use spoke::SpokeStage;
use texture::{TextureScratch, TextureStage};

/// The clutter of one revolution: mean powers of every (spoke, sample) patch before azimuth
/// weighting, and the texture of every output cell.
pub struct ClutterMap {
    spokes: usize,
    samples: usize,
    /// Texture-free mean sea power per patch, noise units, one row of samples per spoke.
    sea: Vec<Vec<f32>>,
    /// Rain power per patch (rows empty without rain).
    rain: Vec<Vec<f32>>,
    /// Texture of each output cell (rows empty for Rayleigh clutter).
    texture: Vec<Vec<f32>>,
    /// Azimuth weights Gn²(jδ) for j = −J..=J, scaled to sum to the beam integral / δ.
    weights: Vec<f32>,
    distribution: ClutterDistribution,
}

impl ClutterMap {
    /// The clutter of revolution `key` (the texture drifts with time `frame × rotation
    /// period`) for records of `samples` samples; None when there is neither sea clutter
    /// nor rain.
    pub fn new(
        radar: &Radar,
        env: &Environment,
        key: FrameKey,
        samples: usize,
    ) -> Option<ClutterMap> {
        ClutterMap::with_beam_tilts(radar, env, key, samples, &[])
    }

    /// As [`ClutterMap::new`], with spoke k's beam axis raised by `beam_tilt_rad[k]` (the own
    /// ship's roll and pitch when the beam passes it; an empty slice for a level deck): the
    /// sea's elevation gain `Gn²(ψ_d − tilt − δ)` and the rain's elevation integral
    /// `∫_{lo−δ}^{hi−δ} Gn²` = the level integral `+ ∫_{lo−δ}^{lo} − ∫_{hi−δ}^{hi}` (each edge
    /// by an 8-point midpoint rule). The stages: cell geometry, then per spoke (in parallel)
    /// σ0 and rain, then texture.
    pub fn with_beam_tilts(
        radar: &Radar,
        env: &Environment,
        key: FrameKey,
        samples: usize,
        beam_tilt_rad: &[f64],
    ) -> Option<ClutterMap> {
        if env.clutter().is_none() && env.rain().is_none() {
            return None;
        }
        let geometry = MapGeometry::of(radar);
        let weights = geometry.azimuth_weights();
        let cells = geometry.cells(env, samples);
        let distribution = env
            .clutter()
            .map_or(ClutterDistribution::Rayleigh, |c| c.distribution());
        let textures = TextureStage::new(radar, env, &cells, key);
        let spoke_stage = SpokeStage::new(radar, env, &geometry, &cells, key.frame, beam_tilt_rad);
        let has_rain = env.rain().is_some();
        let per_spoke: Vec<(Vec<f32>, Vec<f32>, Vec<f32>)> = (0..geometry.spokes)
            .into_par_iter()
            .map_init(TextureScratch::default, |scratch, k| {
                scratch.cells.clear();
                let mut sea_row = vec![0f32; samples];
                let mut rain_row = vec![0f32; if has_rain { samples } else { 0 }];
                let mut texture_row = vec![0f32; if textures.is_some() { samples } else { 0 }];
                spoke_stage.fill_rows(
                    k,
                    textures.is_some(),
                    &mut scratch.cells,
                    &mut sea_row,
                    &mut rain_row,
                );
                if let Some(t) = &textures {
                    t.fill_row(k, &cells, scratch, &mut texture_row);
                }
                (sea_row, rain_row, texture_row)
            })
            .collect();
        let mut sea = Vec::with_capacity(geometry.spokes);
        let mut rain = Vec::with_capacity(geometry.spokes);
        let mut texture = Vec::with_capacity(geometry.spokes);
        for (s_row, r_row, t_row) in per_spoke {
            sea.push(s_row);
            rain.push(r_row);
            texture.push(t_row);
        }
        Some(ClutterMap {
            spokes: geometry.spokes,
            samples,
            sea,
            rain,
            texture,
            weights,
            distribution,
        })
    }

    /// Spoke index `k + t − J` wrapped around the revolution.
    #[inline]
    fn neighbour(&self, k: usize, t: usize) -> usize {
        let half = (self.weights.len() / 2) as isize;
        (k as isize + t as isize - half).rem_euclid(self.spokes as isize) as usize
    }

    /// Texture-free mean clutter power (sea and rain) of spoke `k`, sample `n`, after
    /// azimuth weighting (noise units).
    pub fn mean_power(&self, k: usize, n: usize) -> f32 {
        let (sea, rain) = self.weighted(k, n);
        sea + rain
    }

    /// Beam-weighted sea and rain power of spoke `k`, sample `n`.
    #[inline]
    fn weighted(&self, k: usize, n: usize) -> (f32, f32) {
        let (mut sea, mut rain) = (0f32, 0f32);
        for (t, w) in self.weights.iter().enumerate() {
            let j = self.neighbour(k, t);
            sea += w * self.sea[j][n];
            if let Some(r) = self.rain[j].get(n) {
                rain += w * r;
            }
        }
        (sea, rain)
    }

    /// The texture of output cell (spoke `k`, sample `n`); 1 for Rayleigh clutter.
    pub fn texture(&self, k: usize, n: usize) -> f32 {
        self.texture[k].get(n).copied().unwrap_or(1.0)
    }

    /// Clutter power of spoke `k`, sample `n` with its texture (noise units).
    #[inline]
    pub fn power(&self, k: usize, n: usize) -> f32 {
        let (sea, rain) = self.weighted(k, n);
        self.texture(k, n) * sea + rain
    }

    /// The amplitude statistics.
    pub fn distribution(&self) -> ClutterDistribution {
        self.distribution
    }

    /// Spokes × samples of the map.
    pub fn shape(&self) -> (usize, usize) {
        (self.spokes, self.samples)
    }
}
