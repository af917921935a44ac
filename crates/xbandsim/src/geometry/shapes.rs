//! Scene shapes as primitives in the world frame.
//!
//! Object frame (docs/formats.md): at zero rotation every shape faces its own +y axis, so its
//! main return is seen from +y. Plate: normal +y, `width_m` along x, `height_m` along z,
//! centred on the position. Trihedral: corner vertex at the position, three mutually
//! perpendicular triangular faces with edges `edge_m`, symmetry axis (opening) along +y, one
//! edge in the y–z plane pointing up. Dihedral: fold line vertical (z) through the position,
//! each face `width_m` (away from the fold) × `height_m` (along it), bisector along +y.
//! Cylinder: axis z, centred on the position, capped. Box: centred, `size_m` along x, y, z.
//! Sphere: centred.
//!
//! Rotation: yaw turns the object's +y toward +x (clockwise seen from above, like a heading),
//! then pitch raises +y toward +z, then roll turns +x toward −z about +y:
//! `R = Rz(−yaw)·Rx(pitch)·Ry(roll)` applied to object coordinates.

use super::mesh::TriangleMesh;
use super::outfit::OutfitParts;
use super::procedural::{buoy_primitives, vessel_primitives, BuoyParams, VesselParams};
use super::{Aabb, Primitive, PrimitiveKind, Rod};
use crate::choice::ShapeName;
use glam::{DMat3, DVec3};
use std::sync::Arc;

/// The shape of a scene object, sizes in metres.
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeGeometry {
    /// Ideal point scatterer of fixed RCS (no geometry; m²).
    Point { rcs_m2: f64 },
    /// Sphere of radius `radius_m`.
    Sphere { radius_m: f64 },
    /// Rectangular flat plate.
    Plate { width_m: f64, height_m: f64 },
    /// Triangular trihedral corner reflector with edge length `edge_m`.
    Trihedral { edge_m: f64 },
    /// Right-angle dihedral, each face `width_m` × `height_m`.
    Dihedral { width_m: f64, height_m: f64 },
    /// Closed circular cylinder, vertical axis.
    Cylinder { radius_m: f64, height_m: f64 },
    /// Rectangular box with edges `size_m` (x, y, z).
    Box { size_m: DVec3 },
    /// Triangle mesh in the object frame, m.
    Mesh { mesh: Arc<TriangleMesh> },
    /// Procedural vessel: `parts` is `params.parts()` (built once).
    Vessel {
        params: VesselParams,
        parts: Arc<OutfitParts>,
        /// Its box in its own frame, made once with the parts (every frame asks for it).
        bounds: Aabb,
    },
    /// Procedural buoy: float, pillar and reflector.
    Buoy { params: BuoyParams },
}

/// Rotation from object to world coordinates for yaw, pitch and roll in radians.
pub fn object_frame(yaw_rad: f64, pitch_rad: f64, roll_rad: f64) -> DMat3 {
    DMat3::from_rotation_z(-yaw_rad)
        * DMat3::from_rotation_x(pitch_rad)
        * DMat3::from_rotation_y(roll_rad)
}

impl ShapeGeometry {
    /// Whether it is a point scatterer (no geometry).
    pub fn is_point(&self) -> bool {
        matches!(self, ShapeGeometry::Point { .. })
    }

    /// The shape's kind, as a scene file names it (`shape = "..."`).
    pub fn kind(&self) -> ShapeName {
        match self {
            ShapeGeometry::Point { .. } => ShapeName::Point,
            ShapeGeometry::Sphere { .. } => ShapeName::Sphere,
            ShapeGeometry::Plate { .. } => ShapeName::Plate,
            ShapeGeometry::Trihedral { .. } => ShapeName::Trihedral,
            ShapeGeometry::Dihedral { .. } => ShapeName::Dihedral,
            ShapeGeometry::Cylinder { .. } => ShapeName::Cylinder,
            ShapeGeometry::Box { .. } => ShapeName::Box,
            ShapeGeometry::Mesh { .. } => ShapeName::Mesh,
            ShapeGeometry::Vessel { .. } => ShapeName::Vessel,
            ShapeGeometry::Buoy { .. } => ShapeName::Buoy,
        }
    }

    /// The shape's name as a scene file writes it.
    pub fn name(&self) -> &'static str {
        self.kind().as_str()
    }

    /// Radius of a sphere about the object's position that holds the whole shape, m.
    pub fn bounding_radius_m(&self) -> f64 {
        match self {
            ShapeGeometry::Point { .. } => 0.0,
            ShapeGeometry::Sphere { radius_m } => *radius_m,
            ShapeGeometry::Plate { width_m, height_m } => 0.5 * width_m.hypot(*height_m),
            // About the bounding centre below (not the corner vertex / fold line).
            ShapeGeometry::Trihedral { edge_m } => *edge_m,
            ShapeGeometry::Dihedral { width_m, height_m } => width_m.hypot(0.5 * height_m),
            ShapeGeometry::Cylinder { radius_m, height_m } => radius_m.hypot(0.5 * height_m),
            ShapeGeometry::Box { size_m } => 0.5 * size_m.length(),
            ShapeGeometry::Mesh { mesh } => mesh.bounding_radius_m(),
            ShapeGeometry::Vessel { .. } | ShapeGeometry::Buoy { .. } => {
                let b = self.local_bounds();
                0.5 * (b.max - b.min).length()
            }
        }
    }

    /// Centre of the bounding sphere in object coordinates, m.
    pub fn bounding_centre_local_m(&self) -> DVec3 {
        match self {
            ShapeGeometry::Trihedral { edge_m } => DVec3::new(0.0, edge_m / 3f64.sqrt(), 0.0) * 0.5,
            ShapeGeometry::Dihedral { width_m, .. } => {
                DVec3::new(0.0, width_m / 2f64.sqrt(), 0.0) * 0.5
            }
            ShapeGeometry::Mesh { mesh } => mesh.bounds_centre_m(),
            ShapeGeometry::Vessel { .. } | ShapeGeometry::Buoy { .. } => {
                let b = self.local_bounds();
                0.5 * (b.min + b.max)
            }
            _ => DVec3::ZERO,
        }
    }

    /// A procedural vessel, its hull built from `params`.
    pub fn vessel(params: VesselParams) -> ShapeGeometry {
        let mut shape = ShapeGeometry::Vessel {
            parts: Arc::new(params.parts()),
            params,
            bounds: Aabb::EMPTY,
        };
        let made = shape.bounds_of_parts();
        if let ShapeGeometry::Vessel { bounds, .. } = &mut shape {
            *bounds = made;
        }
        shape
    }

    /// Amplitude reflectivity of the shape's traced surfaces (1, a conductor, but for the
    /// plastic hulls of detailed small craft).
    pub fn surface_reflectivity(&self) -> f64 {
        match self {
            ShapeGeometry::Vessel { params, .. } => {
                params.outfit.map_or(1.0, |o| o.hull_reflectivity())
            }
            _ => 1.0,
        }
    }

    /// The widest ray tube the shape's detail allows, m: 1 m for a detailed vessel, whose
    /// median RCS over aspect has converged to 0.5 dB at that side (docs/targets.md); None
    /// for every other shape (the scene's budget as set).
    pub fn max_tube_side_m(&self) -> Option<f64> {
        match self {
            ShapeGeometry::Vessel { params, .. } if params.outfit.is_some() => Some(1.0),
            _ => None,
        }
    }

    /// The shape's rods in its own frame (only a detailed vessel has any).
    pub fn rods(&self) -> &[Rod] {
        match self {
            ShapeGeometry::Vessel { parts, .. } => &parts.rods,
            _ => &[],
        }
    }

    /// Bounding box of the shape's primitives in object coordinates (empty for a point).
    pub fn local_bounds(&self) -> Aabb {
        match self {
            ShapeGeometry::Vessel { bounds, .. } => *bounds,
            _ => self.bounds_of_parts(),
        }
    }

    /// [`ShapeGeometry::local_bounds`] made from the primitives and rods.
    fn bounds_of_parts(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in self.primitives(DVec3::ZERO, DMat3::IDENTITY, 0) {
            let pb = p.bounds();
            b.grow(pb.min);
            b.grow(pb.max);
        }
        for rod in self.rods() {
            let rb = rod.bounds();
            b.grow(rb.min);
            b.grow(rb.max);
        }
        b
    }

    /// Primitives of this shape placed at `position_m` with `rotation`, tagged `object`.
    pub fn primitives(&self, position_m: DVec3, rotation: DMat3, object: u32) -> Vec<Primitive> {
        let to_world = |p: DVec3| position_m + rotation * p;
        let dir = |v: DVec3| rotation * v;
        match self {
            ShapeGeometry::Vessel { parts, .. } => {
                return vessel_primitives(parts, position_m, rotation, object)
            }
            ShapeGeometry::Buoy { params } => {
                return buoy_primitives(params, position_m, rotation, object)
            }
            _ => {}
        }
        let mut out = Vec::new();
        let mut push = |kind| out.push(Primitive { kind, object });
        match self.clone() {
            ShapeGeometry::Point { .. } => {}
            ShapeGeometry::Sphere { radius_m } => push(PrimitiveKind::Sphere {
                centre: position_m,
                radius_m,
            }),
            ShapeGeometry::Plate { width_m, height_m } => {
                // Edge order makes the normal edge_u × edge_v point along +y.
                let corner = DVec3::new(width_m / 2.0, 0.0, -height_m / 2.0);
                push(PrimitiveKind::Parallelogram {
                    corner: to_world(corner),
                    edge_u: dir(DVec3::new(-width_m, 0.0, 0.0)),
                    edge_v: dir(DVec3::new(0.0, 0.0, height_m)),
                });
            }
            ShapeGeometry::Trihedral { edge_m } => {
                let s3 = 3f64.sqrt();
                let e3 = DVec3::new(0.0, 1.0 / s3, (2.0f64 / 3.0).sqrt());
                let e1 = DVec3::new(-1.0 / 2f64.sqrt(), 1.0 / s3, -1.0 / 6f64.sqrt());
                let e2 = DVec3::new(1.0 / 2f64.sqrt(), 1.0 / s3, -1.0 / 6f64.sqrt());
                let v0 = to_world(DVec3::ZERO);
                for (a, b) in [(e1, e2), (e2, e3), (e3, e1)] {
                    push(PrimitiveKind::Triangle {
                        v0,
                        e1: dir(a * edge_m),
                        e2: dir(b * edge_m),
                    });
                }
            }
            ShapeGeometry::Dihedral { width_m, height_m } => {
                let h = 1.0 / 2f64.sqrt();
                let bottom = DVec3::new(0.0, 0.0, -height_m / 2.0);
                for side in [DVec3::new(-h, h, 0.0), DVec3::new(h, h, 0.0)] {
                    push(PrimitiveKind::Parallelogram {
                        corner: to_world(bottom),
                        edge_u: dir(side * width_m),
                        edge_v: dir(DVec3::new(0.0, 0.0, height_m)),
                    });
                }
            }
            ShapeGeometry::Cylinder { radius_m, height_m } => {
                let axis = dir(DVec3::Z);
                let base = to_world(DVec3::new(0.0, 0.0, -height_m / 2.0));
                push(PrimitiveKind::Cylinder {
                    base,
                    axis,
                    radius_m,
                    height_m,
                });
                push(PrimitiveKind::Disk {
                    centre: base,
                    normal: -axis,
                    radius_m,
                });
                push(PrimitiveKind::Disk {
                    centre: base + axis * height_m,
                    normal: axis,
                    radius_m,
                });
            }
            ShapeGeometry::Box { size_m } => {
                let h = size_m / 2.0;
                // Each face: corner and two edges ordered so the normal points outward.
                let faces = [
                    (
                        DVec3::new(h.x, -h.y, -h.z),
                        DVec3::new(0.0, size_m.y, 0.0),
                        DVec3::new(0.0, 0.0, size_m.z),
                    ),
                    (
                        DVec3::new(-h.x, -h.y, -h.z),
                        DVec3::new(0.0, 0.0, size_m.z),
                        DVec3::new(0.0, size_m.y, 0.0),
                    ),
                    (
                        DVec3::new(-h.x, h.y, -h.z),
                        DVec3::new(0.0, 0.0, size_m.z),
                        DVec3::new(size_m.x, 0.0, 0.0),
                    ),
                    (
                        DVec3::new(-h.x, -h.y, -h.z),
                        DVec3::new(size_m.x, 0.0, 0.0),
                        DVec3::new(0.0, 0.0, size_m.z),
                    ),
                    (
                        DVec3::new(-h.x, -h.y, h.z),
                        DVec3::new(size_m.x, 0.0, 0.0),
                        DVec3::new(0.0, size_m.y, 0.0),
                    ),
                    (
                        DVec3::new(-h.x, -h.y, -h.z),
                        DVec3::new(0.0, size_m.y, 0.0),
                        DVec3::new(size_m.x, 0.0, 0.0),
                    ),
                ];
                for (c, u, v) in faces {
                    push(PrimitiveKind::Parallelogram {
                        corner: to_world(c),
                        edge_u: dir(u),
                        edge_v: dir(v),
                    });
                }
            }
            ShapeGeometry::Mesh { mesh } => {
                for t in 0..mesh.triangles.len() {
                    let p = mesh.placed_triangle(t, position_m, rotation, object);
                    if !p.is_degenerate_triangle() {
                        out.push(p);
                    }
                }
            }
            ShapeGeometry::Vessel { .. } | ShapeGeometry::Buoy { .. } => {}
        }
        out
    }
}
