//! Procedural target shapes, parameterised by size: the scene shapes `vessel` (a hull with
//! its deck structures as a triangle mesh, a round mast) and `buoy` (a float, a pillar and an
//! octahedral radar reflector). docs/formats.md lists their fields and defaults.
//!
//! Curved surfaces that a radar sees at specular (the vertical mast, the buoy's float and
//! pillar) are exact cylinders rather than facets: a flat facet wider than the Fresnel zone
//! `√(λR_c/2)` (a few cm at X band) flashes like a plate (docs/physics.md §2.2).

use super::mesh::{hull_mesh, TriangleMesh};
use super::outfit::{build_outfit, Outfit, OutfitParts, OutfitSizes};
use super::{Primitive, PrimitiveKind};
use glam::{DMat3, DQuat, DVec3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `object.superstructure`: the deck structures of a `vessel`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Superstructure {
    /// A bare hull (kayak, open boat).
    #[default]
    None,
    /// A low cabin or console amidships, 0.35·L long (yacht, motorboat, RIB).
    Cabin,
    /// A wheelhouse forward of amidships (fishing vessel, pilot boat).
    Wheelhouse,
    /// An accommodation block with the bridge aft and a funnel behind it (cargo ship, tanker).
    BridgeAft,
    /// An accommodation block with the bridge forward (offshore vessel, some ferries).
    BridgeFore,
    /// Passenger decks over most of the length and a funnel aft of them (ferry).
    Decks,
}

impl Superstructure {
    /// Every choice, in the order the documentation lists them.
    pub const ALL: [Superstructure; 6] = [
        Superstructure::None,
        Superstructure::Cabin,
        Superstructure::Wheelhouse,
        Superstructure::BridgeAft,
        Superstructure::BridgeFore,
        Superstructure::Decks,
    ];

    /// The name as written in a scene file.
    pub fn as_str(&self) -> &'static str {
        match self {
            Superstructure::None => "none",
            Superstructure::Cabin => "cabin",
            Superstructure::Wheelhouse => "wheelhouse",
            Superstructure::BridgeAft => "bridge-aft",
            Superstructure::BridgeFore => "bridge-fore",
            Superstructure::Decks => "decks",
        }
    }

    /// Default height above the deck, as a fraction of the beam.
    fn default_height_per_beam(&self) -> f64 {
        match self {
            Superstructure::None => 0.0,
            Superstructure::Cabin => 0.3,
            Superstructure::Wheelhouse => 0.6,
            Superstructure::BridgeAft | Superstructure::BridgeFore => 0.5,
            Superstructure::Decks => 0.45,
        }
    }

    /// Its boxes as (stern end, bow end) along the length as fractions of L (−0.5 stern …
    /// +0.5 bow), width as a fraction of the beam, height as a fraction of the structure's
    /// height; and where the mast stands (fraction of L).
    #[allow(clippy::type_complexity)]
    fn layout(&self) -> (&'static [(f64, f64, f64, f64)], f64) {
        match self {
            Superstructure::None => (&[], 0.12),
            Superstructure::Cabin => (&[(-0.25, 0.10, 0.6, 1.0)], 0.12),
            Superstructure::Wheelhouse => (&[(0.0, 0.2, 0.65, 1.0)], 0.1),
            // House, then the funnel behind it, 1.2 times as tall.
            Superstructure::BridgeAft => {
                (&[(-0.42, -0.30, 0.9, 1.0), (-0.47, -0.43, 0.3, 1.2)], -0.36)
            }
            Superstructure::BridgeFore => (&[(0.22, 0.34, 0.7, 1.0)], 0.28),
            // Passenger decks, and the funnel behind them.
            Superstructure::Decks => (&[(-0.38, 0.22, 0.9, 1.0), (-0.44, -0.39, 0.3, 1.2)], 0.15),
        }
    }
}

/// A procedural vessel (scene shape `vessel`): the hull of [`hull_mesh`] with `beam_m` and
/// `freeboard_m`, deck structures after `superstructure`, and optionally a round mast.
/// Waterline at z = 0 (the object's reference point is the waterline amidships), bow +y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VesselParams {
    /// Length overall, m.
    pub length_m: f64,
    /// Beam (deck width), m.
    pub beam_m: f64,
    /// Height of the deck above the waterline, m.
    pub freeboard_m: f64,
    /// Deck structures.
    pub superstructure: Superstructure,
    /// Height of the structures above the deck, m (0 with none).
    pub superstructure_height_m: f64,
    /// Height of the mast's top above the waterline, m (None: no mast; with an outfit,
    /// the outfit's own).
    pub mast_height_m: Option<f64>,
    /// A detailed vessel of this type (then `superstructure` is unused and
    /// `superstructure_height_m` is its deck house's height).
    pub outfit: Option<Outfit>,
    /// The draw that varies a detailed vessel's structures.
    pub outfit_seed: u64,
}

impl VesselParams {
    /// Default beam as a fraction of the length.
    pub const DEFAULT_BEAM_PER_LENGTH: f64 = 0.25;
    /// Default freeboard as a fraction of the length.
    pub const DEFAULT_FREEBOARD_PER_LENGTH: f64 = 0.1;

    /// A vessel of `length_m` with the defaults for everything else (beam 0.25·L, freeboard
    /// 0.1·L, no superstructure, no mast).
    pub fn new(length_m: f64) -> VesselParams {
        VesselParams {
            length_m,
            beam_m: Self::DEFAULT_BEAM_PER_LENGTH * length_m,
            freeboard_m: Self::DEFAULT_FREEBOARD_PER_LENGTH * length_m,
            superstructure: Superstructure::None,
            superstructure_height_m: 0.0,
            mast_height_m: None,
            outfit: None,
            outfit_seed: 0,
        }
    }

    /// Every part of the vessel in its own frame: the hull and structures as triangles, the
    /// traced cylinders (the mast of a plain vessel), and a detailed vessel's rods.
    pub fn parts(&self) -> OutfitParts {
        match self.outfit {
            Some(outfit) => build_outfit(
                outfit,
                &OutfitSizes {
                    length_m: self.length_m,
                    beam_m: self.beam_m,
                    freeboard_m: self.freeboard_m,
                    house_height_m: self.superstructure_height_m,
                    mast_height_m: self.mast_height_m,
                },
                self.outfit_seed,
            ),
            None => OutfitParts {
                mesh: self.hull(),
                cylinders: self.mast().into_iter().collect(),
                rods: Vec::new(),
            },
        }
    }

    /// The default height of `superstructure` above the deck for a beam of `beam_m`, m.
    pub fn default_superstructure_height_m(superstructure: Superstructure, beam_m: f64) -> f64 {
        superstructure.default_height_per_beam() * beam_m
    }

    /// Segments along the hull: `clamp(⌈4·√(L/m)⌉, 8, 96)`. Facets of length `L/n ∝ √L`
    /// on a bow whose radius of curvature grows with L keep the same sagitta
    /// (`(L/n)²/(8R) ∝ L/L`) at every size: a 5 m kayak gets 9, a 30 m vessel 22, a 200 m
    /// tanker 57.
    pub fn segments(&self) -> usize {
        ((4.0 * self.length_m.max(0.0).sqrt()).ceil() as usize).clamp(8, 96)
    }

    /// Radius of the mast, m: `0.04 + 0.004·L` (9 cm on a 12 m yacht, 0.84 m on a 200 m ship).
    pub fn mast_radius_m(&self) -> f64 {
        0.04 + 0.004 * self.length_m
    }

    /// The hull and its deck structures as a triangle mesh (the mast is a cylinder, see
    /// [`Self::primitives`]). Two rows up the sides (the flared sides are ruled surfaces: one
    /// row is exact in height, two keep the triangles well shaped).
    pub fn hull(&self) -> TriangleMesh {
        let (l, b, f, h) = (
            self.length_m,
            self.beam_m,
            self.freeboard_m,
            self.superstructure_height_m,
        );
        let boxes: Vec<(DVec3, DVec3)> = self
            .superstructure
            .layout()
            .0
            .iter()
            .map(|&(y0, y1, w, hz)| {
                (
                    DVec3::new(0.0, 0.5 * (y0 + y1) * l, f + 0.5 * hz * h),
                    DVec3::new(w * b, (y1 - y0) * l, hz * h),
                )
            })
            .collect();
        hull_mesh(l, b, f, self.segments(), 2, &boxes)
    }

    /// The mast as (base centre on the deck, radius, height), object frame.
    pub fn mast(&self) -> Option<(DVec3, f64, f64)> {
        let top = self.mast_height_m?;
        let y = self.superstructure.layout().1 * self.length_m;
        Some((
            DVec3::new(0.0, y, self.freeboard_m),
            self.mast_radius_m(),
            top - self.freeboard_m,
        ))
    }
}

/// A procedural buoy (scene shape `buoy`): a float (a vertical cylinder of `radius_m` from
/// the waterline, z = 0, to `height_m`), optionally a pillar up to `mast_height_m` and an
/// octahedral radar reflector at its top. Reference point: the waterline at the float's axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuoyParams {
    /// Float radius, m.
    pub radius_m: f64,
    /// Float height above the waterline, m.
    pub height_m: f64,
    /// Height of the structure's top above the waterline, m (None: the float alone, or the
    /// reflector resting on it).
    pub mast_height_m: Option<f64>,
    /// Edge of each of the reflector's eight square trihedral corners, m (None: no reflector).
    pub reflector_edge_m: Option<f64>,
}

/// Half the vertical extent of an octahedral reflector of edge `a` in the catch-rain
/// position: the corners `(±a, ±a, 0)` (and permutations) project onto the vertical
/// `(1, 1, 1)/√3` by at most `2a/√3`.
pub fn octahedral_half_height_m(edge_m: f64) -> f64 {
    2.0 * edge_m / 3f64.sqrt()
}

impl BuoyParams {
    /// Radius of the pillar, m: a fifth of the float's.
    pub fn pillar_radius_m(&self) -> f64 {
        0.2 * self.radius_m
    }

    /// Height of the structure's top above the waterline, m.
    pub fn top_m(&self) -> f64 {
        match (self.mast_height_m, self.reflector_edge_m) {
            (Some(h), _) => h,
            (None, Some(a)) => self.height_m + 2.0 * octahedral_half_height_m(a),
            (None, None) => self.height_m,
        }
    }

    /// Where the pillar stops and the reflector begins (its lowest point), m.
    pub fn pillar_top_m(&self) -> f64 {
        self.top_m()
            - self
                .reflector_edge_m
                .map_or(0.0, |a| 2.0 * octahedral_half_height_m(a))
    }
}

/// The three square plates (side 2a) of an octahedral reflector centred at the origin, in
/// the catch-rain position: the symmetry axis (1, 1, 1)/√3 of one corner turned to +z, so
/// that six of the eight corners look out 19.5° above and below the horizon, 60° apart.
/// Each plate as (corner, edge u, edge v).
pub fn octahedral_plates(edge_m: f64) -> [(DVec3, DVec3, DVec3); 3] {
    let q = DQuat::from_rotation_arc(DVec3::ONE.normalize(), DVec3::Z);
    let a = edge_m;
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let mut out = [(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO); 3];
    for (k, o) in out.iter_mut().enumerate() {
        let u = axes[(k + 1) % 3] * (2.0 * a);
        let v = axes[(k + 2) % 3] * (2.0 * a);
        let corner = -(u + v) * 0.5;
        *o = (q * corner, q * u, q * v);
    }
    out
}

/// A capped vertical cylinder from `base` (object frame) as primitives.
fn cylinder(
    base: DVec3,
    radius_m: f64,
    height_m: f64,
    to_world: &dyn Fn(DVec3) -> DVec3,
    rotation: DMat3,
    out: &mut Vec<PrimitiveKind>,
) {
    let axis = rotation * DVec3::Z;
    let b = to_world(base);
    out.push(PrimitiveKind::Cylinder {
        base: b,
        axis,
        radius_m,
        height_m,
    });
    out.push(PrimitiveKind::Disk {
        centre: b,
        normal: -axis,
        radius_m,
    });
    out.push(PrimitiveKind::Disk {
        centre: b + axis * height_m,
        normal: axis,
        radius_m,
    });
}

/// Primitives of a vessel: its triangles and traced cylinders (its rods are not
/// primitives, see [`super::Rod`]).
pub(super) fn vessel_primitives(
    parts: &OutfitParts,
    position_m: DVec3,
    rotation: DMat3,
    object: u32,
) -> Vec<Primitive> {
    let to_world = |p: DVec3| position_m + rotation * p;
    let hull = &parts.mesh;
    let mut kinds = Vec::with_capacity(hull.triangles.len() + 3 * parts.cylinders.len());
    for t in &hull.triangles {
        let v0 = to_world(hull.vertices_m[t[0] as usize]);
        let e1 = to_world(hull.vertices_m[t[1] as usize]) - v0;
        let e2 = to_world(hull.vertices_m[t[2] as usize]) - v0;
        if e1.cross(e2).length_squared() > 0.0 {
            kinds.push(PrimitiveKind::Triangle { v0, e1, e2 });
        }
    }
    for &(base, r, h) in &parts.cylinders {
        cylinder(base, r, h, &to_world, rotation, &mut kinds);
    }
    kinds
        .into_iter()
        .map(|kind| Primitive { kind, object })
        .collect()
}

/// Primitives of a buoy: float, pillar, reflector plates.
pub(super) fn buoy_primitives(
    params: &BuoyParams,
    position_m: DVec3,
    rotation: DMat3,
    object: u32,
) -> Vec<Primitive> {
    let to_world = |p: DVec3| position_m + rotation * p;
    let mut kinds = Vec::new();
    cylinder(
        DVec3::ZERO,
        params.radius_m,
        params.height_m,
        &to_world,
        rotation,
        &mut kinds,
    );
    let pillar_top = params.pillar_top_m();
    if pillar_top > params.height_m {
        cylinder(
            DVec3::new(0.0, 0.0, params.height_m),
            params.pillar_radius_m(),
            pillar_top - params.height_m,
            &to_world,
            rotation,
            &mut kinds,
        );
    }
    if let Some(a) = params.reflector_edge_m {
        let centre = DVec3::new(0.0, 0.0, pillar_top + octahedral_half_height_m(a));
        for (corner, u, v) in octahedral_plates(a) {
            kinds.push(PrimitiveKind::Parallelogram {
                corner: to_world(centre + corner),
                edge_u: rotation * u,
                edge_v: rotation * v,
            });
        }
    }
    kinds
        .into_iter()
        .map(|kind| Primitive { kind, object })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octahedral_plates_are_orthogonal_and_catch_rain() {
        let p = octahedral_plates(0.5);
        let n: Vec<DVec3> = p.iter().map(|(_, u, v)| u.cross(*v).normalize()).collect();
        for i in 0..3 {
            assert!((p[i].0 + 0.5 * (p[i].1 + p[i].2)).length() < 1e-12);
            assert!((p[i].1.length() - 1.0).abs() < 1e-12);
            assert!(n[i].dot(n[(i + 1) % 3]).abs() < 1e-12);
            // Each plate's normal makes the same angle with the vertical.
            assert!((n[i].z.abs() - 1.0 / 3f64.sqrt()).abs() < 1e-12);
        }
        let top = p
            .iter()
            .flat_map(|(c, u, v)| [*c, *c + *u, *c + *v, *c + *u + *v])
            .map(|x| x.z)
            .fold(f64::MIN, f64::max);
        assert!((top - octahedral_half_height_m(0.5)).abs() < 1e-12);
    }

    #[test]
    fn segments_follow_the_square_root_rule() {
        let n = |l: f64| VesselParams::new(l).segments();
        assert_eq!(
            (n(2.0), n(5.0), n(30.0), n(200.0), n(1000.0)),
            (8, 9, 22, 57, 96)
        );
    }
}
