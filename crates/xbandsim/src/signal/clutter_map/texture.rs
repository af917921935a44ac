//! Clutter map, stage: texture. The sea's spiky amplitude statistics come from a spatially
//! correlated Gaussian field (one per seed, drifting downwind frame to frame) mapped cell by
//! cell to the texture's marginal — K (gamma texture, its shape ν fixed or from the
//! empirical model per cell), Weibull or log-normal (docs/physics.md, "Sea clutter").

use super::geometry::CellGeometry;
use crate::cache::KeptLast;
use crate::environment::clutter::TabulatedQuantile;
use crate::environment::clutter::{
    lognormal_texture, weibull_texture_quantile, ClutterDistribution, GammaQuantile, GaussianField,
};
use crate::model::{Environment, Radar, SeaClutter};
use crate::rng::FrameKey;
use glam::DVec2;
use std::sync::{Arc, OnceLock};

/// How far the texture field has drifted downwind by revolution `frame` (`frame` rotation
/// periods at the sea's drift speed), m; zero without sea clutter.
pub(super) fn drift_m(radar: &Radar, env: &Environment, frame: u64) -> DVec2 {
    let t_s = frame as f64 * 60.0 / radar.rotation_rpm();
    env.clutter().map_or(DVec2::ZERO, |c| {
        // Downwind is opposite to where the wind comes from.
        let to = c.wind_from_rad() + std::f64::consts::PI;
        DVec2::new(to.sin(), to.cos()) * c.drift_m_per_s() * t_s
    })
}

/// The texture field of scene seed `seed` over `extent_m` with correlation length
/// `correlation_m`: a pure function of the three (its own random stream), so the few made
/// last are kept and shared — every frame of a run drifts the same field, and making one takes
/// longer than the rest of a small clutter map. At most [`FIELD_CACHE_LEN`] fields and
/// [`FIELD_CACHE_BYTES`] of values are kept.
pub(crate) fn texture_field(seed: u64, extent_m: f64, correlation_m: f64) -> Arc<GaussianField> {
    TEXTURE_FIELDS.get_or_make(
        (seed, extent_m.to_bits(), correlation_m.to_bits()),
        || {
            let mut rng = FrameKey::new(seed, 0).texture().rng();
            Arc::new(GaussianField::new(&mut rng, extent_m, correlation_m))
        },
        |f| f.bytes(),
    )
}

/// The texture fields made last ([`FIELD_CACHE_LEN`], [`FIELD_CACHE_BYTES`]).
pub(crate) static TEXTURE_FIELDS: KeptLast<FieldKey, Arc<GaussianField>> =
    KeptLast::new(FIELD_CACHE_LEN, FIELD_CACHE_BYTES);

/// A texture field's inputs: seed, extent and correlation length (their bits).
type FieldKey = (u64, u64, u64);

/// Texture fields kept by [`texture_field`].
const FIELD_CACHE_LEN: usize = 8;

/// Bytes of texture-field values kept (a 2048² field, the largest, takes 16 MB).
const FIELD_CACHE_BYTES: usize = 64 << 20;

/// The texture stage of one map: the drifting field and the marginal's quantile tables.
pub(super) struct TextureStage<'a> {
    clutter: &'a SeaClutter,
    field: Arc<GaussianField>,
    fixed_gamma: Option<Arc<GammaQuantile>>,
    weibull: Option<Arc<TabulatedQuantile>>,
    /// The quantile tables of the per-cell K shapes (empty unless that is the distribution),
    /// fetched from the process-wide cache once per map, not per spoke.
    tables: Vec<OnceLock<Arc<GammaQuantile>>>,
    radar: &'a Radar,
}

/// Reusable buffers of one spoke's texture.
#[derive(Debug, Default)]
pub(super) struct TextureScratch {
    /// Sample index and field coordinates (m) of each sea cell.
    pub(super) cells: Vec<(usize, f64, f64)>,
    /// The field's normalised value at each cell.
    values: Vec<f64>,
}

impl<'a> TextureStage<'a> {
    /// The stage of `env`'s sea clutter over `cells` for the render seeded `key.seed`; None
    /// for Rayleigh clutter or no sea clutter (no texture).
    pub(super) fn new(
        radar: &'a Radar,
        env: &'a Environment,
        cells: &[Option<CellGeometry>],
        key: FrameKey,
    ) -> Option<TextureStage<'a>> {
        let clutter = env.clutter()?;
        let distribution = clutter.distribution();
        if distribution == ClutterDistribution::Rayleigh {
            return None;
        }
        // Texture field (per scene seed), drifting downwind with time.
        let max_ground = cells
            .iter()
            .rev()
            .find_map(|r| r.as_ref().map(|r| r.ground_m))
            .unwrap_or(1.0);
        let field = texture_field(
            key.seed,
            2.0 * max_ground + 4.0 * clutter.correlation_m(),
            clutter.correlation_m(),
        );
        let fixed_gamma = match distribution {
            ClutterDistribution::K { shape_nu: Some(nu) } => Some(GammaQuantile::for_shape(nu)),
            _ => None,
        };
        let weibull = match distribution {
            ClutterDistribution::Weibull { shape } => Some(weibull_texture_quantile(shape)),
            _ => None,
        };
        let per_cell_levels = fixed_gamma.is_none();
        let tables = (0..if per_cell_levels {
            GammaQuantile::LEVELS
        } else {
            0
        })
            .map(|_| OnceLock::new())
            .collect();
        Some(TextureStage {
            clutter,
            field,
            fixed_gamma,
            weibull,
            tables,
            radar,
        })
    }

    /// The texture of spoke `k`'s sea cells into `texture_row` (zero elsewhere): each cell
    /// `n` of `cells` reads the field at its point on the spoke less the `drift`. The
    /// field's values are read in one pass of their own (whose iterations overlap), then
    /// mapped to the marginal.
    pub(super) fn fill_row(
        &self,
        k: usize,
        cells: &[Option<CellGeometry>],
        drift: DVec2,
        scratch: &mut TextureScratch,
        texture_row: &mut [f32],
    ) {
        let radar_xy = self.radar.position_m().truncate();
        let az = self.radar.spoke_azimuth_rad(k);
        let dir = DVec2::new(az.sin(), az.cos());
        scratch.cells.clear();
        for (n, row) in cells.iter().enumerate() {
            if let Some(row) = row {
                let x = radar_xy + dir * row.ground_m - drift;
                scratch.cells.push((n, x.x, x.y));
            }
        }
        let textured_cells = &scratch.cells;
        let values = &mut scratch.values;
        self.field.at_each(textured_cells, values);
        let pairs = textured_cells.iter().zip(values.iter());
        match self.clutter.distribution() {
            ClutterDistribution::K { .. } => match &self.fixed_gamma {
                Some(q) => {
                    for (&(n, _, _), &g) in pairs {
                        texture_row[n] = q.of_normal(g) as f32;
                    }
                }
                None => {
                    let az = self.radar.spoke_azimuth_rad(k);
                    let swell_rel = az - self.clutter.swell_from_rad();
                    let cos_2swell = (2.0 * swell_rel).cos();
                    // Consecutive cells mostly share a shape level: each run of one level
                    // looks its table up once.
                    let level_of = |i: usize| {
                        let n = textured_cells[i].0;
                        let log_nu = cells[n].as_ref().map_or(0.0, |r| r.log_nu_row);
                        GammaQuantile::level_from_log10(log_nu - cos_2swell / 3.0)
                    };
                    let mut start = 0;
                    while start < values.len() {
                        let level = level_of(start);
                        let mut end = start + 1;
                        while end < values.len() && level_of(end) == level {
                            end += 1;
                        }
                        self.tables[level]
                            .get_or_init(|| GammaQuantile::for_level(level))
                            .of_normal_each(&values[start..end], |i, t| {
                                texture_row[textured_cells[start + i].0] = t as f32;
                            });
                        start = end;
                    }
                }
            },
            ClutterDistribution::Weibull { .. } => {
                for (&(n, _, _), &g) in pairs {
                    texture_row[n] = self.weibull.as_ref().map_or(1.0, |q| q.of_normal(g)) as f32;
                }
            }
            ClutterDistribution::LogNormal { sigma_db } => {
                for (&(n, _, _), &g) in pairs {
                    texture_row[n] = lognormal_texture(g, sigma_db) as f32;
                }
            }
            // Rayleigh clutter has no texture stage.
            ClutterDistribution::Rayleigh => {}
        }
    }
}
