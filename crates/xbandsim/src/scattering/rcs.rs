//! Monostatic radar cross-section of one object alone in free space (no sea, no other
//! objects), lit by a plane wave: `σ = |Σ S|²` over the PO ray tubes of [`super::po`].
//!
//! Aspect (docs/formats.md): the direction from the object to the radar in the object's own
//! frame, azimuth from +y toward +x, elevation up from the object's horizontal plane; at zero
//! rotation every shape's main return is at aspect (0°, 0°).

use super::direction_from_az_el;
use super::po::{plane_wave_rcs_m2, trace_object, Illumination, ObjectOptics, SbrSettings};
use crate::constants::wavelength_m;
use crate::geometry::{Bvh, ShapeGeometry};
use crate::model::{Polarisation, SceneObject};
use crate::propagation::SeaSurface;
use glam::DMat3;
use rayon::prelude::*;
use std::sync::OnceLock;

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
    /// Add the edges' PTD fringe returns (docs/physics.md §2.2).
    pub edge_diffraction: bool,
}

impl RcsSettings {
    /// The SBR settings of one trace, with the sea `sea` (None: free space); no earth
    /// curvature.
    fn sbr(&self, sea: Option<SeaSurface>) -> SbrSettings {
        let lambda = wavelength_m(self.freq_hz);
        SbrSettings {
            wavelength_m: lambda,
            polarisation: self.polarisation,
            max_bounces: self.max_bounces,
            spacing_m: self.ray_spacing_wavelengths * lambda,
            max_rays: self.max_rays,
            sea,
            earth_curvature: false,
            edge_diffraction: self.edge_diffraction,
        }
    }
}

/// One object, ready for RCS sweeps.
pub struct RcsTarget {
    bvh: Bvh,
    shape: ShapeGeometry,
    centre_local_m: glam::DVec3,
    radius_m: f64,
    optics: ObjectOptics,
    /// Height of the object's reference point above the sea, m.
    height_m: f64,
    /// The object standing at its height on the sea, for [`RcsTarget::over_sea_m2`].
    on_the_sea: OnceLock<(Bvh, ObjectOptics)>,
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
            optics: ObjectOptics {
                rods: object.shape().rods().to_vec(),
                reflectivity: object.shape().surface_reflectivity(),
                max_tube_side_m: object.shape().max_tube_side_m(),
            },
            height_m: object.position_m().z,
            on_the_sea: OnceLock::new(),
        }
    }

    /// Effective RCS over the sea at one aspect, m²: `|Σ S|²` over every path, direct and via
    /// the sea, of a radar `radar_height_m` above the sea whose line of sight to the
    /// object's reference point at the waterline is depressed by `el_rad` (ground range
    /// `radar_height_m / tan el`), from azimuth `az_rad` of the object's bow. The object
    /// stands at its scene height; the radar is a point, so the paths are those of a
    /// rendered scene (docs/physics.md §2.5) at that range.
    pub fn over_sea_m2(
        &self,
        az_rad: f64,
        el_rad: f64,
        radar_height_m: f64,
        sea: &SeaSurface,
        s: &RcsSettings,
    ) -> f64 {
        if let ShapeGeometry::Point { rcs_m2 } = self.shape {
            return rcs_m2;
        }
        let (bvh, optics) = self.on_the_sea.get_or_init(|| {
            let at = glam::DVec3::new(0.0, 0.0, self.height_m);
            let prims = self.shape.primitives(at, DMat3::IDENTITY, 0);
            let optics = ObjectOptics {
                rods: self
                    .shape
                    .rods()
                    .iter()
                    .map(|r| r.placed(at, DMat3::IDENTITY))
                    .collect(),
                ..self.optics.clone()
            };
            (Bvh::build(prims), optics)
        });
        let ground_m = radar_height_m / el_rad.tan();
        let radar_m = glam::DVec3::new(
            ground_m * az_rad.sin(),
            ground_m * az_rad.cos(),
            radar_height_m,
        );
        let sbr = s.sbr(Some(*sea));
        let centre = self.centre_local_m + glam::DVec3::Z * self.height_m;
        trace_object(
            bvh,
            Illumination::FromPoint { radar_m },
            centre,
            self.radius_m,
            0,
            optics,
            &sbr,
        )
        .returns
        .iter()
        .map(|r| r.root_rcs_m)
        .sum::<num_complex::Complex64>()
        .norm_sqr()
    }

    /// [`RcsTarget::over_sea_m2`] at many aspects (in parallel, results in input order), m².
    pub fn over_sea_sweep_m2(
        &self,
        aspects_rad: &[(f64, f64)],
        radar_height_m: f64,
        sea: &SeaSurface,
        s: &RcsSettings,
    ) -> Vec<f64> {
        aspects_rad
            .par_iter()
            .map(|&(az, el)| self.over_sea_m2(az, el, radar_height_m, sea, s))
            .collect()
    }

    /// RCS at one aspect, m².
    pub fn rcs_m2(&self, az_rad: f64, el_rad: f64, s: &RcsSettings) -> f64 {
        if let ShapeGeometry::Point { rcs_m2 } = self.shape {
            return rcs_m2;
        }
        let sbr = s.sbr(None);
        plane_wave_rcs_m2(
            &self.bvh,
            direction_from_az_el(az_rad, el_rad),
            self.centre_local_m,
            self.radius_m,
            0,
            &self.optics,
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
