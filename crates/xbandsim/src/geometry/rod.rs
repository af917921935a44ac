//! Rods: the thin round members of a structure (rails and stanchions, stays and shrouds,
//! yards, booms, pipes, crane jibs) as straight circular cylinders, kept apart from the
//! traced primitives. A ray tube a few decimetres wide cannot sample a member a few
//! centimetres thick, so rods are not in the BVH: the PO of each is computed in closed form
//! along its length (`scattering::po::rods`, docs/physics.md §2.2), and rays pass through
//! them (a thin member shadows a negligible part of what is behind it).

use super::Aabb;
use glam::{DMat3, DVec3};

/// A straight round member from `a_m` to `b_m` of radius `radius_m`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rod {
    /// One end of the axis, m.
    pub a_m: DVec3,
    /// The other end of the axis, m.
    pub b_m: DVec3,
    /// Radius, m.
    pub radius_m: f64,
    /// Amplitude reflection coefficient of its surface at normal incidence: 1 for a
    /// conductor, `|(√ε − 1)/(√ε + 1)|` for a dielectric of permittivity ε.
    pub reflectivity: f64,
}

impl Rod {
    /// A conducting rod from `a_m` to `b_m` of radius `radius_m`.
    pub fn new(a_m: DVec3, b_m: DVec3, radius_m: f64) -> Rod {
        Rod {
            a_m,
            b_m,
            radius_m,
            reflectivity: 1.0,
        }
    }

    /// The same rod made of a material of amplitude reflectivity `reflectivity`.
    pub fn of(self, reflectivity: f64) -> Rod {
        Rod {
            reflectivity,
            ..self
        }
    }

    /// Its length, m.
    pub fn length_m(&self) -> f64 {
        (self.b_m - self.a_m).length()
    }

    /// The rod placed at `position_m` with `rotation` (object to world).
    pub fn placed(&self, position_m: DVec3, rotation: DMat3) -> Rod {
        Rod {
            a_m: position_m + rotation * self.a_m,
            b_m: position_m + rotation * self.b_m,
            ..*self
        }
    }

    /// Its bounding box, m.
    pub fn bounds(&self) -> Aabb {
        let r = DVec3::splat(self.radius_m);
        Aabb {
            min: self.a_m.min(self.b_m) - r,
            max: self.a_m.max(self.b_m) + r,
        }
    }
}
