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
pub mod land;
mod speckle;
mod spoke;
mod texture;

pub use speckle::{doppler_lines, DwellClutterScratch, GaussianDoppler, MAX_DOPPLER_LINES};
#[cfg(test)]
pub(crate) use texture::{texture_field, TEXTURE_FIELDS};

use crate::environment::clutter::ClutterDistribution;
use crate::model::{Environment, Radar};
use crate::rng::FrameKey;
use geometry::{CellGeometry, MapGeometry};
use rayon::prelude::*;
use spoke::SpokeStage;
use std::sync::Arc;
use texture::{TextureScratch, TextureStage};

/// The clutter of one revolution: the surface's mean powers of every (spoke, sample) patch
/// before azimuth weighting with the land's echo ([`ClutterSurface`]), and the texture of
/// every output cell.
pub struct ClutterMap {
    surface: Arc<ClutterSurface>,
    /// Texture of each output cell (rows empty for Rayleigh clutter).
    texture: Vec<Vec<f32>>,
}

/// What a clutter map keeps while the radar stands still: every patch's texture-free sea and
/// rain power and the land's rows and frozen echo. They depend on the radar (its pose, its
/// beam), the environment, the render's seed and the record's length, not on the revolution:
/// only the sea's texture drifts with time. A radar ashore or on a moored ship makes them
/// once and draws each revolution's texture on them ([`ClutterMap::on_surface`]).
pub struct ClutterSurface {
    /// The radar it was made for.
    radar: Radar,
    /// The environment it was made in.
    env: Environment,
    /// The render's seed (the land's frozen echo and the texture field are drawn from it).
    seed: u64,
    /// Whether every spoke's beam is level (no beam tilts): only such a surface is reused.
    level: bool,
    /// Each range sample's cell geometry.
    cells: Vec<Option<CellGeometry>>,
    spokes: usize,
    samples: usize,
    /// Texture-free mean sea power per patch, noise units, one row of samples per spoke.
    sea: Vec<Vec<f32>>,
    /// Rain power per patch (rows empty without rain).
    rain: Vec<Vec<f32>>,
    /// Azimuth weights Gn²(jδ) for j = −J..=J, scaled to sum to the beam integral / δ.
    weights: Vec<f32>,
    distribution: ClutterDistribution,
    /// Each output cell's frozen land echo, noise-rms units (rows empty where a spoke has no
    /// land near; [`land`]).
    land_echo: Vec<Vec<num_complex::Complex32>>,
    /// Each land patch's mean power before azimuth weighting (noise units; rows empty where a
    /// spoke meets no land).
    land_power: Vec<Vec<f32>>,
    /// The land polygon each patch shows the radar ([`spoke::NO_POLYGON`] for water and land
    /// in shadow; rows empty where a spoke meets no land).
    land_polygon: Vec<Vec<u32>>,
    /// How many of the surface's polygons are land (the rest are structures' footprints).
    land_count: usize,
    /// Whether each patch's surface is seen: false where land or its shadow hides the sea
    /// (rows empty where a spoke meets no land).
    sea_seen: Vec<Vec<bool>>,
}

impl ClutterSurface {
    /// The surface of `radar` in `env` for the render seeded `seed`, records of `samples`
    /// samples, spoke k's beam axis raised by `beam_tilt_rad[k]` (empty for a level deck;
    /// [`ClutterMap::with_beam_tilts`]); None when there is neither sea clutter, rain nor
    /// land. The stages: cell geometry, then per spoke (in parallel) σ0, rain and land, then
    /// the land's frozen echo.
    pub fn new(
        radar: &Radar,
        env: &Environment,
        seed: u64,
        samples: usize,
        beam_tilt_rad: &[f64],
    ) -> Option<ClutterSurface> {
        if env.clutter().is_none() && env.rain().is_none() && env.land().has_no_surface() {
            return None;
        }
        let geometry = MapGeometry::of(radar);
        let weights = geometry.azimuth_weights();
        let cells = geometry.cells(env, samples);
        let distribution = env
            .clutter()
            .map_or(ClutterDistribution::Rayleigh, |c| c.distribution());
        let spoke_stage = SpokeStage::new(radar, env, &geometry, &cells, beam_tilt_rad);
        let has_rain = env.rain().is_some();
        let radar_xy = radar.position_m().truncate();
        let view = (!env.land().has_no_surface())
            .then(|| crate::land::profile::LandView::surface(env.land(), radar_xy));
        type Rows = (Vec<f32>, Vec<f32>, Vec<f32>, Vec<u32>, Vec<bool>);
        let per_spoke: Vec<Rows> = (0..geometry.spokes)
            .into_par_iter()
            .map_init(Vec::new, |crossings, k| {
                let mut sea_row = vec![0f32; samples];
                let mut rain_row = vec![0f32; if has_rain { samples } else { 0 }];
                if env.clutter().is_some() || has_rain {
                    spoke_stage.fill_rows(k, &mut sea_row, &mut rain_row);
                }
                let (mut land_row, mut polygon_row, mut seen) =
                    (Vec::new(), Vec::new(), Vec::new());
                if let Some(view) = &view {
                    land_row = vec![0f32; samples];
                    polygon_row = vec![spoke::NO_POLYGON; samples];
                    seen = vec![true; samples];
                    if !spoke_stage.fill_land_row(
                        k,
                        view,
                        crossings,
                        &mut land_row,
                        &mut polygon_row,
                        &mut seen,
                        &mut sea_row,
                    ) {
                        (land_row, polygon_row, seen) = (Vec::new(), Vec::new(), Vec::new());
                    }
                }
                (sea_row, rain_row, land_row, polygon_row, seen)
            })
            .collect();
        let mut sea = Vec::with_capacity(geometry.spokes);
        let mut rain = Vec::with_capacity(geometry.spokes);
        let mut land_power = Vec::with_capacity(geometry.spokes);
        let mut land_polygon = Vec::with_capacity(geometry.spokes);
        let mut sea_seen = Vec::with_capacity(geometry.spokes);
        for (s_row, r_row, l_row, p_row, seen) in per_spoke {
            sea.push(s_row);
            rain.push(r_row);
            land_power.push(l_row);
            land_polygon.push(p_row);
            sea_seen.push(seen);
        }
        let land_echo: Vec<Vec<num_complex::Complex32>> = match &view {
            None => vec![Vec::new(); geometry.spokes],
            Some(view) => {
                let ground_m: Vec<f64> = (0..samples)
                    .map(|n| {
                        let r = n as f64 * geometry.dr;
                        (r * r - geometry.h * geometry.h).max(0.0).sqrt()
                    })
                    .collect();
                (0..geometry.spokes)
                    .into_par_iter()
                    .map(|k| {
                        let az = radar.spoke_azimuth_rad(k);
                        let mut echo = Vec::new();
                        land::spoke_echo(
                            k,
                            &land_power,
                            &land_polygon,
                            &weights,
                            view.land(),
                            seed,
                            radar_xy,
                            glam::DVec2::new(az.sin(), az.cos()),
                            &ground_m,
                            &mut echo,
                        );
                        echo
                    })
                    .collect()
            }
        };
        Some(ClutterSurface {
            radar: radar.clone(),
            env: env.clone(),
            seed,
            level: beam_tilt_rad.is_empty(),
            cells,
            spokes: geometry.spokes,
            samples,
            sea,
            rain,
            weights,
            distribution,
            land_echo,
            land_power,
            land_polygon,
            land_count: env.land().polygons().len(),
            sea_seen,
        })
    }

    /// Whether this surface is the one [`ClutterSurface::new`] would make for a level beam
    /// with these inputs, so that a revolution may draw its texture on it.
    pub fn serves(&self, radar: &Radar, env: &Environment, seed: u64, samples: usize) -> bool {
        self.level
            && self.seed == seed
            && self.samples == samples
            && self.radar == *radar
            && self.env.is_same(env)
    }
}

impl ClutterMap {
    /// The clutter of revolution `key` (the texture drifts with time `frame × rotation
    /// period`) for records of `samples` samples; None when there is neither sea clutter,
    /// rain nor land.
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
    /// by an 8-point midpoint rule). The surface ([`ClutterSurface::new`]), then the texture
    /// ([`ClutterMap::on_surface`]).
    pub fn with_beam_tilts(
        radar: &Radar,
        env: &Environment,
        key: FrameKey,
        samples: usize,
        beam_tilt_rad: &[f64],
    ) -> Option<ClutterMap> {
        let surface = ClutterSurface::new(radar, env, key.seed, samples, beam_tilt_rad)?;
        Some(ClutterMap::on_surface(Arc::new(surface), key.frame))
    }

    /// The clutter of revolution `frame` on `surface`: the sea's texture drifted to that
    /// revolution, per spoke in parallel. The same map as [`ClutterMap::with_beam_tilts`]
    /// with the surface's inputs.
    pub fn on_surface(surface: Arc<ClutterSurface>, frame: u64) -> ClutterMap {
        let s = &*surface;
        let key = FrameKey::new(s.seed, frame);
        let texture = match TextureStage::new(&s.radar, &s.env, &s.cells, key) {
            None => vec![Vec::new(); s.spokes],
            Some(stage) => {
                let drift = texture::drift_m(&s.radar, &s.env, frame);
                (0..s.spokes)
                    .into_par_iter()
                    .map_init(TextureScratch::default, |scratch, k| {
                        let mut row = vec![0f32; s.samples];
                        stage.fill_row(k, &s.cells, drift, scratch, &mut row);
                        row
                    })
                    .collect()
            }
        };
        ClutterMap { surface, texture }
    }

    /// The surface the map's texture is drawn on.
    pub fn surface(&self) -> &Arc<ClutterSurface> {
        &self.surface
    }

    /// Spoke index `k + t − J` wrapped around the revolution.
    #[inline]
    fn neighbour(&self, k: usize, t: usize) -> usize {
        let half = (self.surface.weights.len() / 2) as isize;
        (k as isize + t as isize - half).rem_euclid(self.surface.spokes as isize) as usize
    }

    /// Texture-free mean clutter power (sea and rain) of spoke `k`, sample `n`, after
    /// azimuth weighting (noise units).
    pub fn mean_power(&self, k: usize, n: usize) -> f32 {
        let (sea, rain) = self.weighted(k, n);
        sea + rain
    }

    /// The frozen land echo of output cell (spoke `k`, sample `n`), noise-rms units (zero
    /// away from land).
    pub fn land_echo(&self, k: usize, n: usize) -> num_complex::Complex32 {
        self.surface.land_echo[k]
            .get(n)
            .copied()
            .unwrap_or(num_complex::Complex32::new(0.0, 0.0))
    }

    /// The land's beam-weighted mean power at output cell (spoke `k`, sample `n`) before its
    /// texture (noise units): what `|land_echo|²` averages to.
    pub fn land_mean_power(&self, k: usize, n: usize) -> f32 {
        let mut sum = 0f32;
        for (t, w) in self.surface.weights.iter().enumerate() {
            if let Some(p) = self.surface.land_power[self.neighbour(k, t)].get(n) {
                sum += w * p;
            }
        }
        sum
    }

    /// The land polygon whose visible surface patch (spoke `k`, sample `n`) is, if any: the
    /// cell's echo is that land's.
    pub fn land_polygon(&self, k: usize, n: usize) -> Option<usize> {
        self.surface.land_polygon[k]
            .get(n)
            .filter(|&&p| (p as usize) < self.surface.land_count)
            .map(|&p| p as usize)
    }

    /// The structure whose footprint patch (spoke `k`, sample `n`) is and is seen, if any: its
    /// index among the structures ([`crate::land::Land::surface`] less the land).
    pub fn structure_at(&self, k: usize, n: usize) -> Option<usize> {
        self.surface.land_polygon[k]
            .get(n)
            .filter(|&&p| p != spoke::NO_POLYGON && (p as usize) >= self.surface.land_count)
            .map(|&p| p as usize - self.surface.land_count)
    }

    /// Whether the surface at patch (spoke `k`, sample `n`) is in view: false where land or
    /// its shadow hides it (always true without land near).
    pub fn surface_seen(&self, k: usize, n: usize) -> bool {
        self.surface.sea_seen[k].get(n).copied().unwrap_or(true)
    }

    /// Whether any spoke meets land.
    pub fn has_land(&self) -> bool {
        self.surface.land_polygon.iter().any(|r| !r.is_empty())
    }

    /// Beam-weighted sea and rain power of spoke `k`, sample `n`.
    #[inline]
    fn weighted(&self, k: usize, n: usize) -> (f32, f32) {
        let (mut sea, mut rain) = (0f32, 0f32);
        for (t, w) in self.surface.weights.iter().enumerate() {
            let j = self.neighbour(k, t);
            sea += w * self.surface.sea[j][n];
            if let Some(r) = self.surface.rain[j].get(n) {
                rain += w * r;
            }
        }
        (sea, rain)
    }

    /// The texture of output cell (spoke `k`, sample `n`); 1 for Rayleigh clutter.
    pub fn texture(&self, k: usize, n: usize) -> f32 {
        self.texture[k].get(n).copied().unwrap_or(1.0)
    }

    /// Clutter power of spoke `k`, sample `n` with its texture (noise units), land's
    /// included.
    #[inline]
    pub fn power(&self, k: usize, n: usize) -> f32 {
        let (sea, rain) = self.weighted(k, n);
        self.texture(k, n) * sea + rain + self.land_echo(k, n).norm_sqr()
    }

    /// The amplitude statistics.
    pub fn distribution(&self) -> ClutterDistribution {
        self.surface.distribution
    }

    /// Spokes × samples of the map.
    pub fn shape(&self) -> (usize, usize) {
        (self.surface.spokes, self.surface.samples)
    }
}
