//! Stage: geometry. Exact ray–primitive intersection (triangle, parallelogram, sphere, finite
//! cylinder, disk), a bounding-volume hierarchy over them, and the construction of each scene
//! shape's primitives in the world frame (ENU metres, z up).
//!
//! Intersections: Möller & Trumbore, "Fast, minimum storage ray/triangle intersection",
//! J. Graphics Tools 2(1), 1997; quadric roots as in Pharr, Jakob & Humphreys, *Physically
//! Based Rendering*, 4th ed., ch. 6. The BVH is built with binned SAH (Wald, "On fast
//! construction of SAH-based bounding volume hierarchies", IEEE RT 2007).

mod bvh;
mod bvh_build;
mod edge;
pub mod mesh;
pub mod outfit;
mod primitives;
pub mod procedural;
mod rod;
mod shapes;

pub use bvh::{Bvh, BvhTemplate, PlacedCopy, PACKET_RAYS};
pub use edge::{wedge_edges, WedgeEdge, MIN_TURN_RAD};
pub use mesh::{MeshUnit, TriangleMesh};
pub use outfit::{Outfit, OutfitParts};
pub use primitives::{Primitive, PrimitiveKind};
pub use procedural::{BuoyParams, Superstructure, VesselParams};
pub use rod::Rod;
pub use shapes::{object_frame, ShapeGeometry};

use glam::DVec3;

/// A ray with unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Start point, m.
    pub origin_m: DVec3,
    /// Unit direction.
    pub dir: DVec3,
}

impl Ray {
    /// A ray from `origin_m` along `dir` (normalised here).
    pub fn new(origin_m: DVec3, dir: DVec3) -> Self {
        Ray {
            origin_m,
            dir: dir.normalize(),
        }
    }

    /// The point at distance `t_m`.
    #[inline]
    pub fn at(&self, t_m: f64) -> DVec3 {
        self.origin_m + self.dir * t_m
    }
}

/// The closest intersection of a ray with the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray, m.
    pub t_m: f64,
    /// Unit surface normal at the hit (not oriented toward the ray).
    pub normal: DVec3,
    /// Index of the primitive hit, in [`Bvh::primitives`] of the level that holds it (a
    /// two-level BVH's static level has primitives of its own: [`Bvh::static_level`]).
    pub primitive: u32,
    /// Scene object the primitive belongs to.
    pub object: u32,
}

/// Axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Minimum corner, m.
    pub min: DVec3,
    /// Maximum corner, m.
    pub max: DVec3,
}

impl Aabb {
    /// The empty box (grows with [`Aabb::grow`]).
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// Smallest box holding both.
    #[inline]
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Grows to hold a point.
    #[inline]
    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// Surface area (for the SAH), m².
    #[inline]
    pub fn surface_area(&self) -> f64 {
        let d = (self.max - self.min).max(DVec3::ZERO);
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Centre point, m.
    #[inline]
    pub fn centre(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// The eight corners (bit 0 of the index picks x's maximum, bit 1 y's, bit 2 z's).
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|c| {
            DVec3::new(
                if c & 1 == 0 { self.min.x } else { self.max.x },
                if c & 2 == 0 { self.min.y } else { self.max.y },
                if c & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// Slab test: entry distance if the ray meets the box before `t_max`.
    #[inline]
    pub fn hit_distance(&self, origin: DVec3, inv_dir: DVec3, t_max: f64) -> Option<f64> {
        // Compare-and-select (minsd/maxsd) rather than IEEE minNum/maxNum, which cost a NaN
        // check each. The near plane is picked by the direction's sign (a zero component's
        // reciprocal is ±∞), so that a NaN distance (0·∞: a ray parallel to a face, starting
        // in its plane) leaves the bound as it was and the box is kept, as the BVH's f32 test
        // keeps it (taking min and max of the two distances instead dropped it at a minimum
        // face).
        #[inline(always)]
        fn lo(a: f64, b: f64) -> f64 {
            if a < b {
                a
            } else {
                b
            }
        }
        #[inline(always)]
        fn hi(a: f64, b: f64) -> f64 {
            if a > b {
                a
            } else {
                b
            }
        }
        let (mut tmin, mut tmax) = (0.0f64, t_max);
        for axis in 0..3 {
            let inv = inv_dir[axis];
            let (near, far) = if inv < 0.0 {
                (self.max[axis], self.min[axis])
            } else {
                (self.min[axis], self.max[axis])
            };
            tmin = hi((near - origin[axis]) * inv, tmin);
            tmax = lo((far - origin[axis]) * inv, tmax);
        }
        (tmin <= tmax).then_some(tmin)
    }
}

/// Closest hit by testing every primitive: the reference the BVH is tested against.
pub fn closest_hit_brute_force(primitives: &[Primitive], ray: &Ray, t_max_m: f64) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    let mut t_best = t_max_m;
    for (i, p) in primitives.iter().enumerate() {
        if let Some((t, n)) = p.intersect(ray, t_best) {
            t_best = t;
            best = Some(Hit {
                t_m: t,
                normal: n,
                primitive: i as u32,
                object: p.object,
            });
        }
    }
    best
}
