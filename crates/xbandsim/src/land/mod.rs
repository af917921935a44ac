//! Model: land — coastlines as polygons with an elevation model and a terrain type, the
//! surface that tells water from land (docs/physics.md §16, docs/formats.md `[[land]]`).
//!
//! A [`Land`] is validated and immutable: every polygon's rings are closed, finite, have at
//! least three distinct corners and cross neither themselves nor each other
//! ([`check_rings`]). Polygons come from GeoJSON files ([`geojson`]) in local metres or in
//! lon/lat taken to local metres by the azimuthal equidistant projection about the scene's
//! origin ([`projection`]), or from rings written in the scene.
//!
//! The surface is read along straight lines from the antenna ([`profile`]): where a line
//! crosses the coast, how high the ground is at a ground range, and the running maximum of
//! the elevation angle that decides what is seen and what lies in shadow. Land clutter is
//! built from that in `crate::signal::clutter_map` and land's shadow on the traced echoes in
//! `crate::scattering`.
//!
//! Terrain is not turned into triangles for physical optics: natural ground is rough at
//! 3 cm and scatters diffusely (constant γ, [`Terrain::gamma_db`]); smooth facets would
//! give a cliff mirror-like flashes no measured coast shows.

pub mod geojson;
pub mod height_map;
pub mod profile;
pub mod projection;
pub mod structure;

pub use height_map::HeightMap;
pub use structure::{Structure, StructureKind};

use crate::error::{Error, Problem, Result};
use glam::DVec2;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `land.terrain`: what the ground is, which sets its reflectivity γ and its amplitude
/// statistics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Terrain {
    /// Sea cliffs, bare rock, rugged hills.
    #[default]
    Rock,
    /// Beaches, dunes, sand and other flat bare ground.
    Sand,
    /// Grass, farmland, open fields.
    Grass,
    /// Forest and woods.
    Forest,
    /// Towns and cities.
    Urban,
}

impl Terrain {
    /// Every terrain, in the order the documentation lists them.
    pub const ALL: [Terrain; 5] = [
        Terrain::Rock,
        Terrain::Sand,
        Terrain::Grass,
        Terrain::Forest,
        Terrain::Urban,
    ];

    /// The name as written in a scene file.
    pub fn as_str(&self) -> &'static str {
        match self {
            Terrain::Rock => "rock",
            Terrain::Sand => "sand",
            Terrain::Grass => "grass",
            Terrain::Forest => "forest",
            Terrain::Urban => "urban",
        }
    }

    /// γ of the constant-γ model `σ0 = γ·sin ψ` at 10 GHz, dB: rugged mountains and
    /// metropolitan areas 0 dB, woods −15 dB (Long, *Radar Reflectivity of Land and Sea*,
    /// 3rd ed., 2001), farmland −15 dB, flatland −20 dB (Nathanson, *Radar Design
    /// Principles*, 2nd ed., 1999); docs/physics.md §16.
    pub fn gamma_db_at_10_ghz(&self) -> f64 {
        match self {
            Terrain::Rock => 0.0,
            Terrain::Sand => -20.0,
            Terrain::Grass => -15.0,
            Terrain::Forest => -15.0,
            Terrain::Urban => 0.0,
        }
    }

    /// γ at `freq_ghz`, dB: `γ10 + 5·log10(f/10 GHz)` (Barton, "Land clutter models for radar
    /// design and analysis", Proc. IEEE 73(2), 1985).
    pub fn gamma_db(&self, freq_ghz: f64) -> f64 {
        gamma_db_at(self.gamma_db_at_10_ghz(), freq_ghz)
    }

    /// Weibull shape `c` of a cell's amplitude (c = 2 is Rayleigh; Billingsley's spread
    /// parameter is `a_w = 2/c`). Low-angle land clutter is spikier than Rayleigh, most for
    /// the discrete returns of towns and rock, least for homogeneous forest and flat sand:
    /// Sekine et al. measured c = 1.5–2.0 over cultivated land (IEEE TAES 17(4), 1981);
    /// Billingsley's whole-terrain spreads reach a_w = 3–4 at the lowest angles (*Low-Angle
    /// Radar Land Clutter*, 2002, ch. 4), but those include the shadowed cells that this
    /// model draws as shadow, so the values here for land in view are milder
    /// (docs/physics.md §16 gives their standing).
    pub fn weibull_shape(&self) -> f64 {
        match self {
            Terrain::Rock => 1.0,
            Terrain::Sand => 1.8,
            Terrain::Grass => 1.5,
            Terrain::Forest => 1.5,
            Terrain::Urban => 0.8,
        }
    }
}

/// γ at `freq_ghz` from its value at 10 GHz, dB: `γ10 + 5·log10(f/10 GHz)` (Barton 1985;
/// docs/physics.md §16).
pub fn gamma_db_at(gamma_db_at_10_ghz: f64, freq_ghz: f64) -> f64 {
    gamma_db_at_10_ghz + 5.0 * (freq_ghz / 10.0).log10()
}

/// How the ground rises from the shoreline to the polygon's top.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Edge {
    /// A vertical face from the sea to the top at the shoreline.
    Cliff,
    /// A plane slope rising from the shoreline to the top over `width_m` inland.
    Beach {
        /// Horizontal width of the slope, m (> 0).
        width_m: f64,
    },
}

/// One land polygon: its rings in local metres (x east, y north from the scene's origin; the
/// outer ring first, then holes), its height model and its terrain.
#[derive(Debug, Clone, PartialEq)]
pub struct LandPolygon {
    /// Name: the feature's `name` property or `land[i]`.
    pub name: String,
    /// Which `[[land]]` table it came from.
    pub table: usize,
    /// Where it came from, for errors and truth: `"file": feature k ("name")` or
    /// `land[i].polygon_m`.
    pub source: String,
    /// Outer ring then holes, each without the closing corner repeated, m.
    pub rings: Vec<Vec<DVec2>>,
    /// Height of the flat top over the sea, m.
    pub top_m: f64,
    /// How it rises from the shoreline.
    pub edge: Edge,
    /// What the ground is.
    pub terrain: Terrain,
    /// γ at 10 GHz, dB (the terrain's unless the scene sets it).
    pub gamma_db_at_10_ghz: f64,
    /// Weibull amplitude shape (the terrain's unless the scene sets it).
    pub weibull_shape: f64,
    /// A height map that gives the ground's height inside it instead of the flat top (the
    /// edge's slope still applies at the shore); `top_m` is then its highest point.
    pub height_map: Option<std::sync::Arc<HeightMap>>,
    /// The scene object whose footprint this is, for a structure's (see
    /// [`Land::with_structures`]); None for land.
    pub structure: Option<u32>,
}

impl LandPolygon {
    /// Its γ at `freq_ghz`, linear ([`gamma_db_at`]).
    pub fn gamma_linear(&self, freq_ghz: f64) -> f64 {
        10f64.powf(gamma_db_at(self.gamma_db_at_10_ghz, freq_ghz) / 10.0)
    }

    /// Height of the ground at `p`, `distance_m` inland from the shoreline, m.
    #[inline]
    pub fn height_at(&self, p: DVec2, distance_m: f64) -> f64 {
        let top = match &self.height_map {
            Some(map) => map.height_at(p),
            None => self.top_m,
        };
        match self.edge {
            Edge::Cliff => top,
            Edge::Beach { width_m } => top * (distance_m / width_m).clamp(0.0, 1.0),
        }
    }

    /// Whether its height is the same everywhere but on a beach's slope (no height map).
    #[inline]
    pub fn is_flat(&self) -> bool {
        self.height_map.is_none()
    }

    /// The step at which its heights are sampled along a line, m (None: flat, a cliff's
    /// top needs no samples): an eighth of a beach's width, half a height map's cell.
    pub fn sample_step_m(&self) -> Option<f64> {
        let map = self.height_map.as_ref().map(|m| 0.5 * m.cell_m());
        let beach = match self.edge {
            Edge::Beach { width_m } => Some(width_m / 8.0),
            Edge::Cliff => None,
        };
        match (map, beach) {
            (Some(a), Some(b)) => Some(a.min(b).max(0.25)),
            (Some(a), None) | (None, Some(a)) => Some(a.max(0.25)),
            (None, None) => None,
        }
    }

    /// Whether `p` lies inside (even-odd over all rings).
    pub fn contains(&self, p: DVec2) -> bool {
        self.rings
            .iter()
            .fold(false, |inside, ring| inside ^ ring_contains(ring, p))
    }

    /// Shortest distance from `p` to its boundary, m.
    pub fn distance_to_boundary_m(&self, p: DVec2) -> f64 {
        let mut best = f64::INFINITY;
        for ring in &self.rings {
            let n = ring.len();
            for i in 0..n {
                best = best.min(point_segment_distance(p, ring[i], ring[(i + 1) % n]));
            }
        }
        best
    }
}

/// Distance from `p` to the segment `a`–`b`, m.
#[inline]
pub fn point_segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).length()
}

/// All the scene's land: validated polygons, then the footprints of its structures (the
/// surface that hides the sea in the clutter map; see [`Land::surface`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Land {
    /// Land polygons then structure footprints.
    polygons: Vec<LandPolygon>,
    /// How many of `polygons` are land.
    land_count: usize,
}

impl Land {
    /// Land of these polygons (each already checked by [`check_rings`]).
    pub fn new(polygons: Vec<LandPolygon>) -> Land {
        let land_count = polygons.len();
        Land {
            polygons,
            land_count,
        }
    }

    /// This land with structures' footprints on it (each with `structure` set), listed after
    /// the land so that the ground they stand on is theirs.
    pub fn with_structures(mut self, footprints: Vec<LandPolygon>) -> Land {
        self.polygons.truncate(self.land_count);
        self.polygons.extend(footprints);
        self
    }

    /// The land polygons, in scene order (their index is their truth id).
    pub fn polygons(&self) -> &[LandPolygon] {
        &self.polygons[..self.land_count]
    }

    /// The land polygons then the structures' footprints: every surface that is not sea.
    pub fn surface(&self) -> &[LandPolygon] {
        &self.polygons
    }

    /// Whether there is no land (structures aside).
    pub fn is_empty(&self) -> bool {
        self.land_count == 0
    }

    /// Whether there is neither land nor a structure.
    pub fn has_no_surface(&self) -> bool {
        self.polygons.is_empty()
    }

    /// The structure footprint `p` lies in, if any: its index in [`Land::surface`].
    pub fn structure_at(&self, p: DVec2) -> Option<usize> {
        (self.land_count..self.polygons.len())
            .rev()
            .find(|&i| self.polygons[i].contains(p))
    }

    /// The polygon `p` lies in (the last listed where polygons overlap), if any.
    pub fn polygon_at(&self, p: DVec2) -> Option<usize> {
        (0..self.land_count)
            .rev()
            .find(|&i| self.polygons[i].contains(p))
    }

    /// Ground height at `p`, m: 0 over water.
    pub fn height_at(&self, p: DVec2) -> f64 {
        self.polygon_at(p).map_or(0.0, |i| {
            let poly = &self.polygons[i];
            poly.height_at(p, poly.distance_to_boundary_m(p))
        })
    }

    /// Distance from `p` to the nearest coast (any polygon's boundary), m; None without land.
    pub fn distance_to_coast_m(&self, p: DVec2) -> Option<f64> {
        self.polygons()
            .iter()
            .map(|poly| poly.distance_to_boundary_m(p))
            .reduce(f64::min)
    }
}

/// Checks one polygon's rings (outer first, then holes; the closing corner already removed):
/// finite corners, at least three distinct ones each, non-zero area, and no two edges that
/// cross or touch other than neighbours at their shared corner. `what` names the polygon in
/// errors (`land[0].geojson = "coast.geojson": feature 3`), `field` is the field at fault.
pub fn check_rings(field: &str, what: &str, rings: &[Vec<DVec2>]) -> Result<()> {
    let bad = |reason: String| Error::invalid(Problem::Unusable, field, what, reason);
    if rings.is_empty() {
        return Err(bad("a polygon needs an outer ring".into()));
    }
    for (r, ring) in rings.iter().enumerate() {
        if let Some(p) = ring.iter().find(|p| !p.is_finite()) {
            return Err(bad(format!(
                "ring {r} has a corner that is not finite: {p}"
            )));
        }
        if ring.len() < 3 {
            return Err(bad(format!(
                "ring {r} has {} distinct corners; a ring needs at least 3",
                ring.len()
            )));
        }
        if let Some(i) = (0..ring.len()).find(|&i| ring[i] == ring[(i + 1) % ring.len()]) {
            return Err(bad(format!(
                "ring {r} repeats corner {i} ({}) at once",
                ring[i]
            )));
        }
    }
    // Crossing edges first: a bow tie can enclose no net area, and its crossing says why.
    if let Some((a, b)) = first_crossing(rings) {
        return Err(bad(format!(
            "edges cross: ring {} edge {} and ring {} edge {} (a polygon must not intersect itself)",
            a.0, a.1, b.0, b.1
        )));
    }
    for (r, ring) in rings.iter().enumerate() {
        if signed_area_m2(ring).abs() <= 0.0 {
            return Err(bad(format!("ring {r} encloses no area")));
        }
    }
    // A hole must lie in its outer ring (no edges cross, so one corner tells).
    let outer = &rings[0];
    for (r, hole) in rings.iter().enumerate().skip(1) {
        if !ring_contains(outer, hole[0]) {
            return Err(bad(format!(
                "ring {r} is a hole outside the outer ring (ring 0): a hole must lie inside its polygon"
            )));
        }
    }
    Ok(())
}

/// Whether `p` lies inside `ring` (even-odd).
fn ring_contains(ring: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    let n = ring.len();
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Shoelace area of a ring, m² (positive counter-clockwise).
pub fn signed_area_m2(ring: &[DVec2]) -> f64 {
    let n = ring.len();
    0.5 * (0..n)
        .map(|i| ring[i].perp_dot(ring[(i + 1) % n]))
        .sum::<f64>()
}

/// The first pair of edges `((ring, edge), (ring, edge))` that cross or touch other than at
/// the corner two neighbours share; edges are bucketed on a uniform grid so that a
/// coastline of 10⁵ corners is checked in about linear time.
fn first_crossing(rings: &[Vec<DVec2>]) -> Option<((usize, usize), (usize, usize))> {
    let edges: Vec<(usize, usize, DVec2, DVec2)> = rings
        .iter()
        .enumerate()
        .flat_map(|(r, ring)| {
            let n = ring.len();
            (0..n).map(move |i| (r, i, ring[i], ring[(i + 1) % n]))
        })
        .collect();
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let mut total_len = 0.0;
    for &(_, _, a, b) in &edges {
        lo = lo.min(a.min(b));
        hi = hi.max(a.max(b));
        total_len += (b - a).length();
    }
    let extent = (hi - lo).max(DVec2::splat(1e-9));
    // Cells about twice the mean edge long, at most 2048 a side.
    let cell = (2.0 * total_len / edges.len() as f64)
        .max(extent.max_element() / 2048.0)
        .max(1e-9);
    let nx = ((extent.x / cell).ceil() as usize).max(1);
    let ny = ((extent.y / cell).ceil() as usize).max(1);
    let mut buckets: std::collections::HashMap<(usize, usize), Vec<usize>> =
        std::collections::HashMap::new();
    let idx = |v: f64, lo: f64, n: usize| (((v - lo) / cell) as usize).min(n - 1);
    for (e, &(_, _, a, b)) in edges.iter().enumerate() {
        let (x0, x1) = (idx(a.x.min(b.x), lo.x, nx), idx(a.x.max(b.x), lo.x, nx));
        let (y0, y1) = (idx(a.y.min(b.y), lo.y, ny), idx(a.y.max(b.y), lo.y, ny));
        for ix in x0..=x1 {
            for iy in y0..=y1 {
                buckets.entry((ix, iy)).or_default().push(e);
            }
        }
    }
    let mut found: Option<(usize, usize)> = None;
    let mut keys: Vec<_> = buckets.keys().copied().collect();
    keys.sort_unstable();
    for key in keys {
        let list = &buckets[&key];
        for (i, &e) in list.iter().enumerate() {
            for &f in &list[i + 1..] {
                let (ra, ia, a0, a1) = edges[e];
                let (rb, ib, b0, b1) = edges[f];
                let neighbours = ra == rb && {
                    let n = rings[ra].len();
                    (ia + 1) % n == ib || (ib + 1) % n == ia
                };
                if segments_meet(a0, a1, b0, b1, neighbours) {
                    let pair = (e.min(f), e.max(f));
                    if found.is_none_or(|p| pair < p) {
                        found = Some(pair);
                    }
                }
            }
        }
    }
    found.map(|(e, f)| ((edges[e].0, edges[e].1), (edges[f].0, edges[f].1)))
}

/// Whether segments `a0a1` and `b0b1` share a point; for `neighbours` (consecutive edges of a
/// ring) the shared corner does not count, but folding back over each other does.
fn segments_meet(a0: DVec2, a1: DVec2, b0: DVec2, b1: DVec2, neighbours: bool) -> bool {
    let orient = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    let (d1, d2) = (orient(b0, b1, a0), orient(b0, b1, a1));
    let (d3, d4) = (orient(a0, a1, b0), orient(a0, a1, b1));
    if neighbours {
        // They share one corner; they meet elsewhere only if collinear and overlapping.
        let shared = if a1 == b0 || a1 == b1 { a1 } else { a0 };
        let other_a = if shared == a0 { a1 } else { a0 };
        let other_b = if shared == b0 { b1 } else { b0 };
        let collinear = orient(shared, other_a, other_b) == 0.0;
        return collinear && (other_a - shared).dot(other_b - shared) > 0.0;
    }
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on(b0, b1, a0))
        || (d2 == 0.0 && on(b0, b1, a1))
        || (d3 == 0.0 && on(a0, a1, b0))
        || (d4 == 0.0 && on(a0, a1, b1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, s: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(x0, y0),
            DVec2::new(x0 + s, y0),
            DVec2::new(x0 + s, y0 + s),
            DVec2::new(x0, y0 + s),
        ]
    }

    #[test]
    fn a_square_with_a_hole_is_accepted_and_contains_what_it_should() {
        let rings = vec![square(0.0, 0.0, 10.0), square(4.0, 4.0, 2.0)];
        check_rings("land[0].polygon_m", "test", &rings).unwrap();
        let poly = LandPolygon {
            name: "a".into(),
            table: 0,
            source: "test".into(),
            rings,
            top_m: 5.0,
            edge: Edge::Beach { width_m: 2.0 },
            terrain: Terrain::Rock,
            gamma_db_at_10_ghz: 0.0,
            weibull_shape: 1.0,
            height_map: None,
            structure: None,
        };
        assert!(poly.contains(DVec2::new(1.0, 1.0)));
        assert!(!poly.contains(DVec2::new(5.0, 5.0)));
        assert!(!poly.contains(DVec2::new(11.0, 5.0)));
        assert_eq!(poly.distance_to_boundary_m(DVec2::new(1.0, 5.0)), 1.0);
        assert_eq!(poly.height_at(DVec2::ZERO, 1.0), 2.5);
        assert_eq!(poly.height_at(DVec2::ZERO, 7.0), 5.0);
    }

    #[test]
    fn self_intersecting_rings_are_refused_with_the_edges_named() {
        // A bow tie: edges 0 and 2 cross.
        let bow = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(0.0, 8.0),
        ];
        let e = check_rings("land[2].geojson", "f.geojson: feature 1", &[bow]).unwrap_err();
        let text = e.to_string();
        assert!(text.contains("land[2].geojson"), "{text}");
        assert!(text.contains("feature 1"), "{text}");
        assert!(text.contains("ring 0 edge 0 and ring 0 edge 2"), "{text}");
        // A symmetric bow tie encloses no net area: its crossing is named all the same.
        let even = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(0.0, 10.0),
        ];
        let text = check_rings("f", "w", &[even]).unwrap_err().to_string();
        assert!(
            text.contains("edges cross: ring 0 edge 0 and ring 0 edge 2"),
            "{text}"
        );
        // A hole poking out of its outer ring, and one wholly outside it.
        let rings = vec![square(0.0, 0.0, 10.0), square(8.0, 4.0, 4.0)];
        assert!(check_rings("f", "w", &rings).is_err());
        let rings = vec![square(0.0, 0.0, 10.0), square(20.0, 4.0, 4.0)];
        let text = check_rings("f", "w", &rings).unwrap_err().to_string();
        assert!(text.contains("outside the outer ring"), "{text}");
        // Too few corners, a repeated corner, no area.
        assert!(check_rings("f", "w", &[square(0.0, 0.0, 1.0)[..2].to_vec()]).is_err());
        let mut rep = square(0.0, 0.0, 1.0);
        rep.insert(1, rep[0]);
        assert!(check_rings("f", "w", &[rep]).is_err());
        let flat = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(2.0, 0.0),
        ];
        assert!(check_rings("f", "w", &[flat]).is_err());
    }

    #[test]
    fn the_crossing_search_agrees_with_every_pair_on_random_rings() {
        // Brute force over all pairs against the bucketed search.
        let mut state = 7u64;
        let mut next = || {
            state = crate::rng::splitmix64(state);
            crate::rng::unit_f64(state)
        };
        for _ in 0..200 {
            let n = 4 + (next() * 8.0) as usize;
            let ring: Vec<DVec2> = (0..n)
                .map(|_| DVec2::new(next() * 100.0, next() * 100.0))
                .collect();
            let rings = vec![ring];
            let mut brute = false;
            let m = rings[0].len();
            for i in 0..m {
                for j in i + 1..m {
                    let nb = (i + 1) % m == j || (j + 1) % m == i;
                    let r = &rings[0];
                    if segments_meet(r[i], r[(i + 1) % m], r[j], r[(j + 1) % m], nb) {
                        brute = true;
                    }
                }
            }
            assert_eq!(first_crossing(&rings).is_some(), brute);
        }
    }
}
