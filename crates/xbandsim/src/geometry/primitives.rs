//! Exact ray intersection with each primitive kind.

use super::{Aabb, Ray};
use glam::DVec3;

/// Rays start this far off a surface to avoid hitting it again (m).
pub const SELF_HIT_EPSILON_M: f64 = 1e-7;

/// The geometry of one primitive, in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PrimitiveKind {
    /// Triangle `v0, v0+e1, v0+e2`.
    Triangle { v0: DVec3, e1: DVec3, e2: DVec3 },
    /// Parallelogram `corner + u·edge_u + v·edge_v`, `u, v ∈ [0, 1]`.
    Parallelogram {
        corner: DVec3,
        edge_u: DVec3,
        edge_v: DVec3,
    },
    /// Sphere.
    Sphere { centre: DVec3, radius_m: f64 },
    /// Open finite cylinder (side wall only) from `base` along unit `axis` for `height_m`.
    Cylinder {
        base: DVec3,
        axis: DVec3,
        radius_m: f64,
        height_m: f64,
    },
    /// Flat disk.
    Disk {
        centre: DVec3,
        normal: DVec3,
        radius_m: f64,
    },
}

/// A primitive and the scene object it belongs to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Primitive {
    /// Geometry.
    pub kind: PrimitiveKind,
    /// Index of the owning scene object.
    pub object: u32,
}

impl Primitive {
    /// Whether this is a triangle of no area (its edges' cross product is not above zero,
    /// NaN included): a mesh's primitives leave these out.
    #[inline]
    pub fn is_degenerate_triangle(&self) -> bool {
        match self.kind {
            PrimitiveKind::Triangle { e1, e2, .. } => {
                e1.cross(e2).length_squared().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
            }
            _ => false,
        }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        match self.kind {
            PrimitiveKind::Triangle { v0, e1, e2 } => {
                b.grow(v0);
                b.grow(v0 + e1);
                b.grow(v0 + e2);
            }
            PrimitiveKind::Parallelogram {
                corner,
                edge_u,
                edge_v,
            } => {
                b.grow(corner);
                b.grow(corner + edge_u);
                b.grow(corner + edge_v);
                b.grow(corner + edge_u + edge_v);
            }
            PrimitiveKind::Sphere { centre, radius_m } => {
                b.grow(centre - DVec3::splat(radius_m));
                b.grow(centre + DVec3::splat(radius_m));
            }
            PrimitiveKind::Cylinder {
                base,
                axis,
                radius_m,
                height_m,
            } => {
                let ext = disk_extent(axis, radius_m);
                for c in [base, base + axis * height_m] {
                    b.grow(c - ext);
                    b.grow(c + ext);
                }
            }
            PrimitiveKind::Disk {
                centre,
                normal,
                radius_m,
            } => {
                let ext = disk_extent(normal, radius_m);
                b.grow(centre - ext);
                b.grow(centre + ext);
            }
        }
        b
    }

    /// Points whose convex hull holds the primitive, and how many of the eight are used: a
    /// triangle's or parallelogram's vertices, else the corners of its box.
    pub fn hull_points(&self) -> ([DVec3; 8], usize) {
        let mut points = [DVec3::ZERO; 8];
        match self.kind {
            PrimitiveKind::Triangle { v0, e1, e2 } => {
                points[..3].copy_from_slice(&[v0, v0 + e1, v0 + e2]);
                (points, 3)
            }
            PrimitiveKind::Parallelogram {
                corner,
                edge_u,
                edge_v,
            } => {
                points[..4].copy_from_slice(&[
                    corner,
                    corner + edge_u,
                    corner + edge_v,
                    corner + edge_u + edge_v,
                ]);
                (points, 4)
            }
            _ => (self.bounds().corners(), 8),
        }
    }

    /// Intersection distance and unit normal if the ray meets this primitive in
    /// `(SELF_HIT_EPSILON_M, t_max_m)`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max_m: f64) -> Option<(f64, DVec3)> {
        let o = ray.origin_m;
        let d = ray.dir;
        match self.kind {
            PrimitiveKind::Triangle { v0, e1, e2 } => {
                let t = moller_trumbore(o, d, v0, e1, e2, false, t_max_m)?;
                Some((t, e1.cross(e2).normalize()))
            }
            PrimitiveKind::Parallelogram {
                corner,
                edge_u,
                edge_v,
            } => {
                let t = moller_trumbore(o, d, corner, edge_u, edge_v, true, t_max_m)?;
                Some((t, edge_u.cross(edge_v).normalize()))
            }
            PrimitiveKind::Sphere { centre, radius_m } => {
                let oc = o - centre;
                let b = oc.dot(d);
                let c = oc.length_squared() - radius_m * radius_m;
                let disc = b * b - c;
                if disc < 0.0 {
                    return None;
                }
                let sq = disc.sqrt();
                let t = nearest_root(-b - sq, -b + sq, t_max_m)?;
                Some((t, (o + d * t - centre) / radius_m))
            }
            PrimitiveKind::Cylinder {
                base,
                axis,
                radius_m,
                height_m,
            } => {
                let oc = o - base;
                let d_perp = d - axis * d.dot(axis);
                let oc_perp = oc - axis * oc.dot(axis);
                let a = d_perp.length_squared();
                if a < 1e-300 {
                    return None;
                }
                let b = oc_perp.dot(d_perp);
                let c = oc_perp.length_squared() - radius_m * radius_m;
                let disc = b * b - a * c;
                if disc < 0.0 {
                    return None;
                }
                let sq = disc.sqrt();
                for t in [(-b - sq) / a, (-b + sq) / a] {
                    if t > SELF_HIT_EPSILON_M && t < t_max_m {
                        let h = (oc + d * t).dot(axis);
                        if (0.0..=height_m).contains(&h) {
                            let n = (oc_perp + d_perp * t) / radius_m;
                            return Some((t, n));
                        }
                    }
                }
                None
            }
            PrimitiveKind::Disk {
                centre,
                normal,
                radius_m,
            } => {
                let denom = d.dot(normal);
                if denom.abs() < 1e-300 {
                    return None;
                }
                let t = (centre - o).dot(normal) / denom;
                if !(t > SELF_HIT_EPSILON_M && t < t_max_m) {
                    return None;
                }
                ((o + d * t - centre).length_squared() <= radius_m * radius_m)
                    .then_some((t, normal))
            }
        }
    }
}

/// Möller–Trumbore ray/triangle test (Möller & Trumbore, "Fast, minimum storage
/// ray-triangle intersection", J. Graphics Tools 2(1), 1997) on the triangle `p0, p0+e1,
/// p0+e2` (`u, v ≥ 0, u + v ≤ 1`) or, with `parallelogram`, the parallelogram they span
/// (`u, v ∈ [0, 1]`): the distance if the ray meets it in `(SELF_HIT_EPSILON_M, t_max)`.
/// Each barycentric coordinate is checked as soon as it is known, so that a miss costs less.
#[inline]
fn moller_trumbore(
    o: DVec3,
    d: DVec3,
    p0: DVec3,
    e1: DVec3,
    e2: DVec3,
    parallelogram: bool,
    t_max: f64,
) -> Option<f64> {
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - p0;
    let u = s.dot(p) * inv;
    if !((0.0..=1.0).contains(&u)) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    let inside = if parallelogram {
        (0.0..=1.0).contains(&v)
    } else {
        v >= 0.0 && u + v <= 1.0
    };
    if !inside {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > SELF_HIT_EPSILON_M && t < t_max).then_some(t)
}

#[inline]
fn nearest_root(t0: f64, t1: f64, t_max: f64) -> Option<f64> {
    if t0 > SELF_HIT_EPSILON_M && t0 < t_max {
        Some(t0)
    } else if t1 > SELF_HIT_EPSILON_M && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

/// Half-extent along each world axis of a disk of `radius_m` with unit `normal`.
fn disk_extent(normal: DVec3, radius_m: f64) -> DVec3 {
    let n2 = normal * normal;
    DVec3::new(
        (1.0 - n2.x).max(0.0).sqrt(),
        (1.0 - n2.y).max(0.0).sqrt(),
        (1.0 - n2.z).max(0.0).sqrt(),
    ) * radius_m
}
