//! Model: the scattering settings — which amplitude model turns ray hits into echoes and
//! the ray budgets, validated from the scene file's `[scattering]` table.

use super::checks::positive;
use crate::error::{Error, Problem, Result};
use crate::scene::ScatteringSpec;

/// Which scattering amplitude model turns ray hits into echoes.
#[derive(
    Debug, Clone, Copy, PartialEq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum ScatteringModel {
    /// Physical-optics ray tubes calibrated to the radar equation.
    #[serde(rename = "po")]
    PhysicalOptics,
    /// The seed paper's law `A = 1/(1 + ℓ²/1000)` on a uniform scan grid (uncalibrated).
    Paper,
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
        paper_rays_per_degree_az,
        paper_rays_elevation,
        paper_reference_voltage_v,
    })
}
