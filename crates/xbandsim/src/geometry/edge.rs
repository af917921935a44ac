//! Wedge edges: the straight edges where an object's flat faces meet at an angle, or where a
//! face ends, for edge diffraction (`scattering::po::edges`, docs/physics.md §2.2).
//!
//! Faces are the object's triangles and parallelograms. Their corners are welded on a grid of
//! [`WELD_M`], an edge is the segment between two welded corners (its ends are the welded
//! points), and the faces that share it say what it is:
//! - one face: a half-plane (the edge of a plate, a bulwark, a sign), exterior angle 2π;
//! - two faces whose outward normals make it convex (each face lies behind the other's
//!   normal): a wedge of exterior angle `2π − α`, α the angle between the faces. Its
//!   exterior is measured from face 0 toward its normal;
//! - two faces nearly in one plane (a triangulated quad's diagonal, the facets of a curved
//!   hull: exterior angle within [`MIN_TURN_RAD`] of π), a concave corner (its return is the
//!   corner's own reflections, which the tubes trace), or more than two faces: no edge.
//!
//! A face's outward side is the one its corners wind about counter-clockwise (a mesh's
//! winding, a parallelogram's `edge_u × edge_v`); where two faces' windings disagree the edge
//! is taken as convex.

use super::{Primitive, PrimitiveKind};
use glam::DVec3;

/// Grid on which face corners are welded, m.
pub const WELD_M: f64 = 1e-6;

/// Faces whose planes turn by less than this at their common edge (18°) give no edge.
pub const MIN_TURN_RAD: f64 = 0.1 * std::f64::consts::PI;

/// A straight edge of a wedge or half-plane, in the world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WedgeEdge {
    /// One end, m.
    pub a_m: DVec3,
    /// The other end, m.
    pub b_m: DVec3,
    /// Unit vector in face 0, across the edge, pointing into the face.
    pub face0_dir: DVec3,
    /// Unit normal of face 0 on the exterior's side.
    pub face0_normal: DVec3,
    /// Exterior angle over π: 2 for a half-plane, 1.5 for a right-angled convex edge.
    pub wedge_n: f64,
}

impl WedgeEdge {
    /// Length, m.
    pub fn length_m(&self) -> f64 {
        (self.b_m - self.a_m).length()
    }

    /// The angle from face 0 toward its normal, in [0, 2π), of direction `d` seen across the
    /// edge (its part along the edge dropped); the exterior is `0 < φ < nπ`.
    pub fn angle_of(&self, d: DVec3) -> f64 {
        let phi = d.dot(self.face0_normal).atan2(d.dot(self.face0_dir));
        if phi < 0.0 {
            phi + std::f64::consts::TAU
        } else {
            phi
        }
    }
}

/// The polygon of a flat face (None for curved primitives).
fn face_corners(p: &Primitive) -> Option<(usize, [DVec3; 4])> {
    match p.kind {
        PrimitiveKind::Triangle { v0, e1, e2 } => Some((3, [v0, v0 + e1, v0 + e2, DVec3::ZERO])),
        PrimitiveKind::Parallelogram {
            corner,
            edge_u,
            edge_v,
        } => Some((
            4,
            [
                corner,
                corner + edge_u,
                corner + edge_u + edge_v,
                corner + edge_v,
            ],
        )),
        _ => None,
    }
}

fn weld(p: DVec3) -> [i64; 3] {
    [
        (p.x / WELD_M).round() as i64,
        (p.y / WELD_M).round() as i64,
        (p.z / WELD_M).round() as i64,
    ]
}

/// An edge's two ends on the weld grid, the lesser first.
type WeldedEnds = ([i64; 3], [i64; 3]);

/// One face's side of an edge: its outward normal and the unit vector into it across the edge.
#[derive(Clone, Copy)]
struct FaceSide {
    normal: DVec3,
    inward: DVec3,
}

/// The wedge edges of `primitives` (one object's), sorted by their welded ends, each with
/// face 0 the one of lower normal (x, then y, then z): the same edges in the same order
/// whatever order the faces come in (a BVH's order differs between its builds).
pub fn wedge_edges<'a>(primitives: impl IntoIterator<Item = &'a Primitive>) -> Vec<WedgeEdge> {
    // Every face's side of every edge under its welded ends and its place in the faces'
    // order, sorted by those ends and that place (in place: no scratch as large again).
    let mut sides: Vec<(WeldedEnds, u32, FaceSide)> = Vec::new();
    for p in primitives {
        let Some((count, corners)) = face_corners(p) else {
            continue;
        };
        let corners = &corners[..count];
        let normal = (corners[1] - corners[0]).cross(corners[count - 1] - corners[0]);
        let normal = match normal.try_normalize() {
            Some(n) => n,
            None => continue,
        };
        let centroid = corners.iter().copied().sum::<DVec3>() / count as f64;
        for i in 0..count {
            let (a, b) = (corners[i], corners[(i + 1) % count]);
            let Some(along) = (b - a).try_normalize() else {
                continue;
            };
            let to_centre = centroid - a;
            let Some(inward) = (to_centre - along * to_centre.dot(along)).try_normalize() else {
                continue;
            };
            let (wa, wb) = (weld(a), weld(b));
            let key = if wa <= wb { (wa, wb) } else { (wb, wa) };
            let place = sides.len() as u32;
            sides.push((key, place, FaceSide { normal, inward }));
        }
    }
    let unweld = |k: [i64; 3]| DVec3::new(k[0] as f64, k[1] as f64, k[2] as f64) * WELD_M;
    let by_normal = |f: &FaceSide, g: &FaceSide| {
        let (p, q) = (f.normal.to_array(), g.normal.to_array());
        (0..3)
            .map(|i| p[i].total_cmp(&q[i]))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    };
    sides.sort_unstable_by(|x, y| x.0.cmp(&y.0).then(x.1.cmp(&y.1)));
    let mut edges = Vec::new();
    for edge_sides in sides.chunk_by(|x, y| x.0 == y.0) {
        let (ka, kb) = edge_sides[0].0;
        let (a, b) = (unweld(ka), unweld(kb));
        let edge = match edge_sides {
            [(_, _, one)] => Some(WedgeEdge {
                a_m: a,
                b_m: b,
                face0_dir: one.inward,
                face0_normal: one.normal,
                wedge_n: 2.0,
            }),
            [(_, _, first), (_, _, second)] => {
                // Face 0 the one of lower normal; the first in the faces' order if equal.
                let (f0, f1) = if by_normal(second, first).is_lt() {
                    (second, first)
                } else {
                    (first, second)
                };
                // Face 1 behind face 0's normal (or, windings disagreeing, either way): convex.
                let alpha = f0.inward.dot(f1.inward).clamp(-1.0, 1.0).acos();
                let normal0 = if f1.inward.dot(f0.normal) <= 0.0 {
                    f0.normal
                } else if f0.inward.dot(f1.normal) > 0.0 {
                    // Concave by both windings: the corner's reflections, traced by tubes.
                    continue;
                } else {
                    -f0.normal
                };
                let exterior = std::f64::consts::TAU - alpha;
                ((exterior - std::f64::consts::PI).abs() >= MIN_TURN_RAD).then_some(WedgeEdge {
                    a_m: a,
                    b_m: b,
                    face0_dir: f0.inward,
                    face0_normal: normal0,
                    wedge_n: exterior / std::f64::consts::PI,
                })
            }
            _ => None,
        };
        edges.extend(edge);
    }
    edges
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parallelogram(corner: DVec3, edge_u: DVec3, edge_v: DVec3) -> Primitive {
        Primitive {
            kind: PrimitiveKind::Parallelogram {
                corner,
                edge_u,
                edge_v,
            },
            object: 0,
        }
    }

    /// A closed unit box, its faces wound outward.
    fn unit_box() -> Vec<Primitive> {
        let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
        let o = DVec3::ZERO;
        vec![
            parallelogram(o, y, x), // bottom, normal −z
            parallelogram(z, x, y), // top, +z
            parallelogram(o, x, z), // front, −y
            parallelogram(y, z, x), // back, +y
            parallelogram(o, z, y), // left, −x
            parallelogram(x, y, z), // right, +x
        ]
    }

    #[test]
    fn a_box_has_twelve_right_angled_convex_edges() {
        let edges = wedge_edges(&unit_box());
        assert_eq!(edges.len(), 12);
        for e in &edges {
            assert!((e.wedge_n - 1.5).abs() < 1e-12, "{e:?}");
            assert!((e.length_m() - 1.0).abs() < 1e-12);
            // The exterior bisector points away from the box's centre.
            let bisector_angle = 0.75 * std::f64::consts::PI;
            let out = e.face0_dir * bisector_angle.cos() + e.face0_normal * bisector_angle.sin();
            let mid = 0.5 * (e.a_m + e.b_m);
            assert!(out.dot(mid - DVec3::splat(0.5)) > 0.0, "{e:?}");
        }
    }

    #[test]
    fn a_plate_has_four_half_plane_edges_and_a_flat_diagonal_none() {
        let plate = parallelogram(DVec3::ZERO, DVec3::X * 2.0, DVec3::Y);
        let edges = wedge_edges(&[plate]);
        assert_eq!(edges.len(), 4);
        assert!(edges.iter().all(|e| e.wedge_n == 2.0));
        // The same plate as two triangles: the shared diagonal is flat, no edge.
        let tri = |v0: DVec3, e1: DVec3, e2: DVec3| Primitive {
            kind: PrimitiveKind::Triangle { v0, e1, e2 },
            object: 0,
        };
        let a = tri(DVec3::ZERO, DVec3::X * 2.0, DVec3::new(2.0, 1.0, 0.0));
        let b = tri(DVec3::ZERO, DVec3::new(2.0, 1.0, 0.0), DVec3::Y);
        assert_eq!(wedge_edges(&[a, b]).len(), 4);
    }

    /// A floor and a wall meeting at an inner corner (both wound to face the corner's open
    /// side): the corner is concave and gives no edge; wound against each other, the same
    /// faces are taken as a convex right-angled edge.
    #[test]
    fn a_concave_corner_gives_no_edge_and_disagreeing_windings_a_convex_one() {
        let floor = parallelogram(DVec3::ZERO, DVec3::X, DVec3::Y); // normal +z
        let wall = parallelogram(DVec3::ZERO, DVec3::Y, DVec3::Z); // normal +x
        let edges = wedge_edges(&[floor, wall]);
        assert_eq!(edges.len(), 6);
        assert!(edges.iter().all(|e| e.wedge_n == 2.0));
        let wall_flipped = parallelogram(DVec3::ZERO, DVec3::Z, DVec3::Y); // normal −x
        let edges = wedge_edges(&[floor, wall_flipped]);
        assert_eq!(edges.len(), 7);
        let corner: Vec<_> = edges.iter().filter(|e| e.wedge_n != 2.0).collect();
        assert_eq!(corner.len(), 1);
        assert!((corner[0].wedge_n - 1.5).abs() < 1e-12);
    }

    /// The same faces in any order give the same edges, in the same order.
    #[test]
    fn the_edges_do_not_depend_on_the_faces_order() {
        let mut faces = unit_box();
        let forward = wedge_edges(&faces);
        faces.reverse();
        faces.swap(1, 4);
        assert_eq!(wedge_edges(&faces), forward);
    }

    #[test]
    fn angles_run_from_face_zero_through_the_exterior() {
        let edges = wedge_edges(&unit_box());
        for e in &edges {
            let n = e.wedge_n;
            // Away from the box's centre lies in the exterior (0, nπ); toward it, not.
            let mid = 0.5 * (e.a_m + e.b_m);
            let away = e.angle_of(mid - DVec3::splat(0.5));
            let toward = e.angle_of(DVec3::splat(0.5) - mid);
            let exterior = n * std::f64::consts::PI;
            assert!(away > 0.0 && away < exterior, "{e:?}: {away}");
            assert!(toward > exterior, "{e:?}: {toward}");
            // Face 1 lies at nπ.
            let face1 = e.face0_dir * (n * std::f64::consts::PI).cos()
                + e.face0_normal * (n * std::f64::consts::PI).sin();
            // Face 1's own direction into it is one of the box's axes.
            let inside = mid + face1 * 0.5 - DVec3::splat(0.5);
            assert!(inside.abs().max_element() <= 0.5 + 1e-9, "{e:?}");
        }
    }
}
