//! Monostatic radar cross-section of one object alone in free space (no sea, no other
//! objects), lit by a plane wave: `σ = |Σ S|²` over the PO ray tubes of [`super::po`].
//!
//! Aspect (docs/formats.md): the direction from the object to the radar in the object's own
//! frame, azimuth from +y toward +x, elevation up from the object's horizontal plane; at zero
//! rotation every shape's main return is at aspect (0°, 0°).

use super::direction_from_az_el;
use super::po::{plane_wave_rcs_m2, SbrSettings};
use crate::constants::wavelength_m;
use crate::geometry::{Bvh, ShapeGeometry};
use crate::model::{Polarisation, SceneObject};
use glam::DMat3;
use rayon::prelude::*;

/// How an RCS is computed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RcsSettings {
    /// Carrier frequency, Hz.
    pub freq_hz: f64,
    /// Polarisation (HH or VV).
    pub polarisation: Polarisation,
    /// Ray-tube side in wavelengths.
    pub ray_spacing_wavelengths: f64,
    /// Cap on tubes per aspect.
    pub max_rays: usize,
    /// Maximum bounces.
    pub max_bounces: usize,
}

/// One object, ready for RCS sweeps.
pub struct RcsTarget {
    bvh: Bvh,
    shape: ShapeGeometry,
    centre_local_m: glam::DVec3,
    radius_m: f64,
}

impl RcsTarget {
    /// The object's geometry alone, in its own frame (position at the origin, no rotation).
    pub fn new(object: &SceneObject) -> RcsTarget {
        let prims = object
            .shape()
            .primitives(glam::DVec3::ZERO, DMat3::IDENTITY, 0);
        let centre_local_m = object.bounding_centre_m() - object.position_m();
        let centre_local_m = object.rotation().transpose() * centre_local_m;
        RcsTarget {
            bvh: Bvh::build(prims),
            shape: object.shape().clone(),
            centre_local_m,
            radius_m: object.shape().bounding_radius_m(),
        }
    }

    /// RCS at one aspect, m².
    pub fn rcs_m2(&self, az_rad: f64, el_rad: f64, s: &RcsSettings) -> f64 {
        if let ShapeGeometry::Point { rcs_m2 } = self.shape {
            return rcs_m2;
        }
        let lambda = wavelength_m(s.freq_hz);
        let sbr = SbrSettings {
            wavelength_m: lambda,
            polarisation: s.polarisation,
            max_bounces: s.max_bounces,
            spacing_m: s.ray_spacing_wavelengths * lambda,
            max_rays: s.max_rays,
            sea: None,
            earth_curvature: false,
        };
        plane_wave_rcs_m2(
            &self.bvh,
            direction_from_az_el(az_rad, el_rad),
            self.centre_local_m,
            self.radius_m,
            0,
            &sbr,
        )
    }

    /// RCS at many aspects (in parallel, results in input order), m².
    pub fn sweep_m2(&self, aspects_rad: &[(f64, f64)], s: &RcsSettings) -> Vec<f64> {
        self.sweep_m2_progress(aspects_rad, s, &|| {})
    }

    /// As [`RcsTarget::sweep_m2`], calling `aspect_done` after every aspect.
    pub fn sweep_m2_progress(
        &self,
        aspects_rad: &[(f64, f64)],
        s: &RcsSettings,
        aspect_done: &(dyn Fn() + Sync),
    ) -> Vec<f64> {
        aspects_rad
            .par_iter()
            .map(|&(az, el)| {
                let v = self.rcs_m2(az, el, s);
                aspect_done();
                v
            })
            .collect()
    }
}
