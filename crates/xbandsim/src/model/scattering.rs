//! Model: the scattering settings — which amplitude model turns ray hits into echoes and
//! the ray budgets, validated from the scene file's `[scattering]` table.

use super::checks::positive;
use crate::error::{Error, Problem, Result};
use crate::scene::ScatteringSpec;

pub use crate::choice::ScatteringModel;

/// Memory one PO ray tube may take while a scene is traced: its return and the
/// contribution made from it, with room for the echo groups' per-contribution data (a
/// test holds the first two's sizes below it). Used to refuse ray budgets that would not fit
/// before tracing ([`MAX_TRACE_BYTES`]).
pub const BYTES_PER_TUBE: f64 = 256.0;

/// Largest memory a scene's PO trace may need, bytes ([`BYTES_PER_TUBE`] per tube of every
/// object's grids): 4 GB, about 240 ship-sized objects at the default budget.
pub const MAX_TRACE_BYTES: f64 = 4e9;

/// The side, in cells, of the square tube grid over the bounding disk of an object of
/// bounding radius `radius_m` at tube side `spacing_m`, and whether the budget of
/// `max_rays` tubes bound it (only the cells inside the disk are traced: about π/4 of the
/// square). The PO tracer's grids and the scene's memory check both use it.
pub fn tube_grid_cells(radius_m: f64, spacing_m: f64, max_rays: usize) -> (usize, bool) {
    // (Casts from f64 saturate: an absurd ratio gives usize::MAX, then the budget binds.)
    let cells = ((2.0 * radius_m / spacing_m).ceil() as usize).max(1);
    let max_side = ((max_rays as f64 * 4.0 / std::f64::consts::PI)
        .sqrt()
        .floor() as usize)
        .max(1);
    if cells > max_side {
        (max_side, true)
    } else {
        (cells, false)
    }
}

/// The tube budget of one object's grid: `max_rays`, raised for an object whose detail
/// allows tubes no wider than `max_tube_side_m` (a detailed vessel,
/// `ShapeGeometry::max_tube_side_m`) until its bounding disk of radius `radius_m` is covered
/// at that side. The PO tracer and the scene's memory check both use it.
pub fn object_max_rays(max_rays: usize, radius_m: f64, max_tube_side_m: Option<f64>) -> usize {
    max_tube_side_m.map_or(max_rays, |side| {
        let cells = (2.0 * radius_m / side).ceil();
        max_rays.max((std::f64::consts::FRAC_PI_4 * cells * cells).ceil() as usize)
    })
}

/// Scattering settings.
#[derive(Debug, Clone, PartialEq)]
pub struct ScatteringConfig {
    /// The model.
    model: ScatteringModel,
    /// PO ray-tube spacing, wavelengths.
    ray_spacing_wavelengths: f64,
    /// PO cap on rays per object.
    max_rays_per_object: usize,
    /// Maximum bounces.
    max_bounces: usize,
    /// PO: the edges' fringe returns.
    edge_diffraction: bool,
    /// Paper model: rays per degree of azimuth.
    paper_rays_per_degree_az: usize,
    /// Paper model: rays across the elevation beamwidth.
    paper_rays_elevation: usize,
    /// Paper model: volts of a unit-amplitude ray.
    paper_reference_voltage_v: f64,
}

impl ScatteringConfig {
    /// The model.
    pub fn model(&self) -> ScatteringModel {
        self.model
    }

    /// PO ray-tube spacing, wavelengths.
    pub fn ray_spacing_wavelengths(&self) -> f64 {
        self.ray_spacing_wavelengths
    }

    /// PO cap on rays per object.
    pub fn max_rays_per_object(&self) -> usize {
        self.max_rays_per_object
    }

    /// Maximum bounces.
    pub fn max_bounces(&self) -> usize {
        self.max_bounces
    }

    /// PO: whether the objects' wedge edges add their fringe returns (docs/physics.md §2.2).
    pub fn edge_diffraction(&self) -> bool {
        self.edge_diffraction
    }

    /// Paper model: rays per degree of azimuth.
    pub fn paper_rays_per_degree_az(&self) -> usize {
        self.paper_rays_per_degree_az
    }

    /// Paper model: rays across the elevation beamwidth.
    pub fn paper_rays_elevation(&self) -> usize {
        self.paper_rays_elevation
    }

    /// Paper model: volts of a unit-amplitude ray.
    pub fn paper_reference_voltage_v(&self) -> f64 {
        self.paper_reference_voltage_v
    }
}

pub(super) fn build_scattering(s: &ScatteringSpec) -> Result<ScatteringConfig> {
    let model = s.model.unwrap_or(ScatteringModel::PhysicalOptics);
    let ray_spacing_wavelengths = positive(
        "scattering.ray_spacing_wavelengths",
        s.ray_spacing_wavelengths.unwrap_or(0.5),
    )?;
    let max_rays_per_object = s.max_rays_per_object.unwrap_or(32_768);
    if max_rays_per_object == 0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "scattering.max_rays_per_object",
            0,
            "must be at least 1",
        ));
    }
    let max_bounces = s.max_bounces.unwrap_or(3);
    if !(1..=16).contains(&max_bounces) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "scattering.max_bounces",
            max_bounces,
            "must be between 1 and 16",
        ));
    }
    let paper_rays_per_degree_az = s.paper_rays_per_degree_az.unwrap_or(100);
    if !(1..=1000).contains(&paper_rays_per_degree_az) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "scattering.paper_rays_per_degree_az",
            paper_rays_per_degree_az,
            "must be between 1 and 1000",
        ));
    }
    let paper_rays_elevation = s.paper_rays_elevation.unwrap_or(100);
    if !(1..=10_000).contains(&paper_rays_elevation) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "scattering.paper_rays_elevation",
            paper_rays_elevation,
            "must be between 1 and 10000",
        ));
    }
    let paper_reference_voltage_v = positive(
        "scattering.paper_reference_voltage_uv",
        s.paper_reference_voltage_uv.unwrap_or(1000.0),
    )? * 1e-6;
    Ok(ScatteringConfig {
        model,
        ray_spacing_wavelengths,
        max_rays_per_object,
        max_bounces,
        edge_diffraction: s.edge_diffraction.unwrap_or(true),
        paper_rays_per_degree_az,
        paper_rays_elevation,
        paper_reference_voltage_v,
    })
}
