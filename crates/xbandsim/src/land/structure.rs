//! Model: man-made structures — breakwaters, quays, piers, buildings, tanks, cranes — as
//! footprints extruded to a height (docs/formats.md `[[structure]]`, docs/physics.md §16.5).
//!
//! A structure becomes a closed-topped prism of triangles in the ray-traced scene: a quad
//! (two triangles) per footprint edge for the walls, its top triangulated by ear clipping
//! (`earcutr`, after Mapbox's earcut, which takes holes). Physical optics then gives its
//! echo as it does a ship's: the flash of a wall facing the radar, and the wall–sea dihedral
//! of a quay through the sea's multipath paths. Its footprint also joins the land's surface
//! for the clutter map, so that it hides the sea and land behind it.

use crate::error::{Error, Problem, Result};
use crate::geometry::TriangleMesh;
use glam::{DVec2, DVec3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `structure.kind`: what a structure is (its class in the ground truth).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum StructureKind {
    /// A breakwater or mole.
    Breakwater,
    /// A quay wall.
    Quay,
    /// A pier or jetty.
    Pier,
    /// A building.
    #[default]
    Building,
    /// A storage tank.
    Tank,
    /// A crane.
    Crane,
}

impl StructureKind {
    /// The name as written in a scene file (and the truth's class).
    pub fn as_str(&self) -> &'static str {
        match self {
            StructureKind::Breakwater => "breakwater",
            StructureKind::Quay => "quay",
            StructureKind::Pier => "pier",
            StructureKind::Building => "building",
            StructureKind::Tank => "tank",
            StructureKind::Crane => "crane",
        }
    }
}

/// One structure: a footprint (outer ring then holes, local metres, checked by
/// [`super::check_rings`]) between a base and a top height.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// Name.
    pub name: String,
    /// What it is.
    pub kind: StructureKind,
    /// Where it came from (`structure[0].polygon_m`, `"file": feature 2`).
    pub source: String,
    /// Outer ring then holes, without the closing corner, m.
    pub rings: Vec<Vec<DVec2>>,
    /// Height of its base over the sea, m.
    pub base_m: f64,
    /// Height of its top over the sea, m (> base).
    pub top_m: f64,
}

impl Structure {
    /// Its footprint as a surface polygon for scene object `object` (flat top at its top,
    /// vertical sides; no clutter of its own: its echo is traced).
    pub fn footprint(&self, index: usize, object: u32) -> super::LandPolygon {
        super::LandPolygon {
            name: self.name.clone(),
            table: index,
            source: self.source.clone(),
            rings: self.rings.clone(),
            top_m: self.top_m,
            edge: super::Edge::Cliff,
            terrain: super::Terrain::Urban,
            gamma_db_at_10_ghz: super::Terrain::Urban.gamma_db_at_10_ghz(),
            weibull_shape: super::Terrain::Urban.weibull_shape(),
            height_map: None,
            structure: Some(object),
        }
    }

    /// The point its mesh is placed at: the outer ring's first corner at the base.
    pub fn anchor_m(&self) -> DVec3 {
        let a = self.rings[0][0];
        DVec3::new(a.x, a.y, self.base_m)
    }

    /// The middle of its bounding box, m.
    pub fn bounding_centre_m(&self) -> DVec3 {
        let (lo, hi) = self.rings[0].iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let mid = 0.5 * (lo + hi);
        DVec3::new(mid.x, mid.y, 0.5 * (self.base_m + self.top_m))
    }

    /// Radius of the sphere about [`Structure::bounding_centre_m`] that holds it, m.
    pub fn bounding_radius_m(&self) -> f64 {
        let c = self.bounding_centre_m();
        let half_height = 0.5 * (self.top_m - self.base_m);
        self.rings[0]
            .iter()
            .map(|p| (p.x - c.x).hypot(p.y - c.y).hypot(half_height))
            .fold(0.0, f64::max)
    }

    /// Its triangles relative to [`Structure::anchor_m`]: the walls of every ring (outer and
    /// holes) and the top, triangulated with its holes. No floor: it stands on the sea or
    /// the ground, where no ray reaches its underside.
    pub fn mesh(&self) -> Result<TriangleMesh> {
        let anchor = self.anchor_m();
        let height = self.top_m - self.base_m;
        let mut vertices_m = Vec::new();
        let mut triangles = Vec::new();
        for ring in &self.rings {
            let n = ring.len();
            let start = vertices_m.len() as u32;
            for p in ring {
                let local = *p - anchor.truncate();
                vertices_m.push(DVec3::new(local.x, local.y, 0.0));
                vertices_m.push(DVec3::new(local.x, local.y, height));
            }
            for i in 0..n as u32 {
                let j = (i + 1) % n as u32;
                let (b0, t0, b1, t1) = (
                    start + 2 * i,
                    start + 2 * i + 1,
                    start + 2 * j,
                    start + 2 * j + 1,
                );
                triangles.push([b0, b1, t1]);
                triangles.push([b0, t1, t0]);
            }
        }
        // The top: earcut over the rings' corners (flat x, y list; holes start at the
        // indices given), each corner's top vertex being 2·k + 1 of the walls' numbering.
        let mut flat = Vec::new();
        let mut holes = Vec::new();
        let mut top_index = Vec::new();
        let mut base = 0u32;
        for (r, ring) in self.rings.iter().enumerate() {
            if r > 0 {
                holes.push(flat.len() / 2);
            }
            for (i, p) in ring.iter().enumerate() {
                let local = *p - anchor.truncate();
                flat.push(local.x);
                flat.push(local.y);
                top_index.push(base + 2 * i as u32 + 1);
            }
            base += 2 * ring.len() as u32;
        }
        let ears = earcutr::earcut(&flat, &holes, 2).map_err(|e| {
            Error::invalid(
                Problem::Unusable,
                self.source.clone(),
                format!("{:?}", self.name),
                format!("its footprint cannot be triangulated ({e:?})"),
            )
        })?;
        for t in ears.chunks_exact(3) {
            triangles.push([top_index[t[0]], top_index[t[1]], top_index[t[2]]]);
        }
        Ok(TriangleMesh {
            vertices_m,
            triangles,
        })
    }
}

/// The corners of a box footprint centred at `centre` with `length_m` along the heading
/// `yaw_rad` (clockwise from north) and `width_m` across.
pub fn box_footprint(centre: DVec2, length_m: f64, width_m: f64, yaw_rad: f64) -> Vec<DVec2> {
    let along = DVec2::new(yaw_rad.sin(), yaw_rad.cos()) * (0.5 * length_m);
    let across = DVec2::new(yaw_rad.cos(), -yaw_rad.sin()) * (0.5 * width_m);
    vec![
        centre + along + across,
        centre + along - across,
        centre - along - across,
        centre - along + across,
    ]
}

/// Corners of a circular footprint: a regular polygon of [`CIRCLE_SIDES`] sides whose area
/// is the circle's (its corners at `r·√(2π/(n·sin(2π/n)))`).
pub fn circle_footprint(centre: DVec2, radius_m: f64) -> Vec<DVec2> {
    let n = CIRCLE_SIDES;
    let step = std::f64::consts::TAU / n as f64;
    let r = radius_m * (std::f64::consts::TAU / (n as f64 * step.sin())).sqrt();
    (0..n)
        .map(|i| {
            let a = i as f64 * step;
            centre + DVec2::new(a.sin(), a.cos()) * r
        })
        .collect()
}

/// Sides of a circular footprint's polygon: its faces are then 2πr/48 ≈ 0.13·r wide.
pub const CIRCLE_SIDES: usize = 48;

#[cfg(test)]
mod tests {
    use super::*;

    fn square(side: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(side, 0.0),
            DVec2::new(side, side),
            DVec2::new(0.0, side),
        ]
    }

    fn structure(rings: Vec<Vec<DVec2>>) -> Structure {
        Structure {
            name: "s".into(),
            kind: StructureKind::Quay,
            source: "test".into(),
            rings,
            base_m: 0.0,
            top_m: 5.0,
        }
    }

    #[test]
    fn a_box_has_its_wall_and_top_area() {
        let mesh = structure(vec![square(10.0)]).mesh().unwrap();
        // Four walls of 10 × 5 and a top of 10 × 10.
        assert!((mesh.area_m2() - (4.0 * 50.0 + 100.0)).abs() < 1e-9);
        assert_eq!(mesh.triangles.len(), 8 + 2);
    }

    #[test]
    fn a_hole_takes_its_area_from_the_top_and_adds_its_walls() {
        let hole: Vec<DVec2> = square(4.0)
            .into_iter()
            .rev()
            .map(|p| p + DVec2::splat(3.0))
            .collect();
        let mesh = structure(vec![square(10.0), hole]).mesh().unwrap();
        let expected = 4.0 * 50.0 + 4.0 * 20.0 + (100.0 - 16.0);
        assert!(
            (mesh.area_m2() - expected).abs() < 1e-9,
            "{}",
            mesh.area_m2()
        );
    }

    #[test]
    fn a_circle_footprint_keeps_the_circle_area() {
        let ring = circle_footprint(DVec2::ZERO, 7.0);
        let area = super::super::signed_area_m2(&ring).abs();
        assert!((area - std::f64::consts::PI * 49.0).abs() < 1e-9, "{area}");
    }

    #[test]
    fn a_box_footprint_is_turned_by_its_heading() {
        let ring = box_footprint(DVec2::ZERO, 20.0, 4.0, 90f64.to_radians());
        let xs: Vec<f64> = ring.iter().map(|p| p.x).collect();
        let max_x = xs.iter().cloned().fold(f64::MIN, f64::max);
        assert!((max_x - 10.0).abs() < 1e-9, "{ring:?}");
    }
}
