//! Land along lines from the antenna: the coast crossings of a ray, the ground height at
//! each ground range, and the elevation angle that decides visibility (docs/physics.md §16).
//!
//! [`LandView`] indexes every coast edge by the bearings it spans from the antenna (bins of
//! 2π/[`ANGLE_BINS`]), so that a ray meets only the edges of its bin: a ray costs the edges
//! near its bearing, not the whole coastline. Crossings follow the even-odd rule with
//! half-open sides (an edge counts when its ends lie on strictly different sides of the
//! ray's line, one side inclusive), so a ray through a corner counts it once and a ray that
//! grazes a corner counts it twice or not at all, as parity needs.
//!
//! Over the 4/3 earth a point at ground range g and height z is seen from an antenna at
//! height h at the elevation `α = atan2(z − h − g²/(2a_e), g)` (flat earth: no g² term). A
//! point is seen when its α is at least every nearer point's on the same bearing; this is
//! the shadow test for land, sea and targets alike.

use super::{Edge, Land, LandPolygon};
use crate::propagation::EFFECTIVE_EARTH_RADIUS_M;
use glam::DVec2;

/// Angle bins of the edge index.
pub const ANGLE_BINS: usize = 4096;

/// The elevation angle, rad, of a point `z_m` high at ground range `ground_m` seen from an
/// antenna `antenna_m` high, over the 4/3 earth when `curvature`.
#[inline]
pub fn elevation_rad(z_m: f64, ground_m: f64, antenna_m: f64, curvature: bool) -> f64 {
    rise_m(z_m, ground_m, antenna_m, curvature).atan2(ground_m)
}

/// The rise of that point above the antenna's horizontal, m: its elevation is
/// `rise.atan2(ground_m)` ([`elevation_rad`]).
#[inline]
pub fn rise_m(z_m: f64, ground_m: f64, antenna_m: f64, curvature: bool) -> f64 {
    let drop = if curvature {
        ground_m * ground_m / (2.0 * EFFECTIVE_EARTH_RADIUS_M)
    } else {
        0.0
    };
    z_m - antenna_m - drop
}

/// Whether the point (`rise`, `ground`) is seen lower than (`rise_max`, `ground_max`) (both
/// grounds above 0), exactly as their [`elevation_rad`]s compare: by the slopes
/// `rise/ground` where they differ by more than 10⁻⁹ of themselves (the angles' rounding,
/// a unit in the last place, cannot turn that around), else by the angles.
#[inline]
pub fn seen_lower(rise: f64, ground: f64, rise_max: f64, ground_max: f64) -> bool {
    let (s, s_max) = (rise / ground, rise_max / ground_max);
    let scale = s.abs().max(s_max.abs());
    if (s - s_max).abs() > 1e-9 * scale && scale < 1e6 {
        s < s_max
    } else {
        rise.atan2(ground) < rise_max.atan2(ground_max)
    }
}

/// Where a ray crosses a coast.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// Ground range from the antenna, m.
    pub ground_m: f64,
    /// The polygon whose boundary it is.
    pub polygon: u32,
    /// |sin| of the angle between the ray and the coast edge (perpendicular distance to the
    /// coast per metre along the ray).
    pub sin_incidence: f64,
}

/// The land seen from one antenna position.
#[derive(Debug, Clone)]
pub struct LandView<'a> {
    land: &'a Land,
    /// The polygons it sees: the land's, or the land's and the structures' footprints.
    polygons: &'a [LandPolygon],
    origin: DVec2,
    /// Edges as (a, b, polygon).
    edges: Vec<(DVec2, DVec2, u32)>,
    /// Edge indices of each angle bin: `index[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<u32>,
    index: Vec<u32>,
    /// The polygons the antenna stands in.
    inside_at_origin: Vec<u32>,
}

/// Bearing (nautical, 0..2π) of `v`.
#[inline]
fn bearing(v: DVec2) -> f64 {
    v.x.atan2(v.y).rem_euclid(std::f64::consts::TAU)
}

impl<'a> LandView<'a> {
    /// The view of `land` from the ground point `origin` (the antenna's x, y): its land
    /// polygons only.
    pub fn new(land: &'a Land, origin: DVec2) -> LandView<'a> {
        Self::of(land, land.polygons(), origin)
    }

    /// The view of the whole surface that is not sea: land and structures' footprints
    /// ([`Land::surface`]).
    pub fn surface(land: &'a Land, origin: DVec2) -> LandView<'a> {
        Self::of(land, land.surface(), origin)
    }

    fn of(land: &'a Land, polygons: &'a [LandPolygon], origin: DVec2) -> LandView<'a> {
        let mut edges = Vec::new();
        for (p, poly) in polygons.iter().enumerate() {
            for ring in &poly.rings {
                let n = ring.len();
                for i in 0..n {
                    edges.push((ring[i], ring[(i + 1) % n], p as u32));
                }
            }
        }
        let bin_of = |theta: f64| {
            ((theta / std::f64::consts::TAU * ANGLE_BINS as f64) as usize).min(ANGLE_BINS - 1)
        };
        // Each edge's bins: from the bearing of one end the short way round to the other's;
        // an edge through the antenna itself spans every bin.
        let spans: Vec<(usize, usize)> = edges
            .iter()
            .map(|&(a, b, _)| {
                let (va, vb) = (a - origin, b - origin);
                if va.perp_dot(vb).abs() <= 1e-12 * va.length() * vb.length() && va.dot(vb) <= 0.0 {
                    return (0, ANGLE_BINS);
                }
                let (ta, tb) = (bearing(va), bearing(vb));
                let mut d = tb - ta;
                if d > std::f64::consts::PI {
                    d -= std::f64::consts::TAU;
                } else if d < -std::f64::consts::PI {
                    d += std::f64::consts::TAU;
                }
                let start = if d >= 0.0 { ta } else { tb };
                let first = bin_of(start);
                let last = bin_of((start + d.abs()).rem_euclid(std::f64::consts::TAU));
                // One bin more on each side: a ray whose bearing rounds into the next bin at
                // a corner still meets the edge.
                let count = (last + ANGLE_BINS - first) % ANGLE_BINS + 3;
                ((first + ANGLE_BINS - 1) % ANGLE_BINS, count)
            })
            .collect();
        let mut counts = vec![0u32; ANGLE_BINS + 1];
        for &(first, count) in &spans {
            for j in 0..count.min(ANGLE_BINS) {
                counts[(first + j) % ANGLE_BINS + 1] += 1;
            }
        }
        for i in 0..ANGLE_BINS {
            counts[i + 1] += counts[i];
        }
        let offsets = counts;
        let mut fill = offsets.clone();
        let mut index = vec![0u32; offsets[ANGLE_BINS] as usize];
        for (e, &(first, count)) in spans.iter().enumerate() {
            for j in 0..count.min(ANGLE_BINS) {
                let bin = (first + j) % ANGLE_BINS;
                index[fill[bin] as usize] = e as u32;
                fill[bin] += 1;
            }
        }
        let inside_at_origin = polygons
            .iter()
            .enumerate()
            .filter(|(_, p)| p.contains(origin))
            .map(|(i, _)| i as u32)
            .collect();
        LandView {
            land,
            polygons,
            origin,
            edges,
            offsets,
            index,
            inside_at_origin,
        }
    }

    /// The land.
    pub fn land(&self) -> &Land {
        self.land
    }

    /// The polygons it sees (indexed as the crossings' `polygon`).
    pub fn polygons(&self) -> &'a [LandPolygon] {
        self.polygons
    }

    /// The antenna's ground point.
    pub fn origin(&self) -> DVec2 {
        self.origin
    }

    /// Whether the antenna stands on the water (in none of the polygons it sees).
    pub fn starts_at_sea(&self) -> bool {
        self.inside_at_origin.is_empty()
    }

    /// Whether no land can lie on the bearing `az_rad`: no coast edge in its bin and the
    /// antenna on the water (a ray there crosses nothing and starts at sea).
    pub fn clear_bearing(&self, az_rad: f64) -> bool {
        let theta = az_rad.rem_euclid(std::f64::consts::TAU);
        let bin =
            ((theta / std::f64::consts::TAU * ANGLE_BINS as f64) as usize).min(ANGLE_BINS - 1);
        self.offsets[bin] == self.offsets[bin + 1] && self.starts_at_sea()
    }

    /// The crossings of the ray at bearing `az_rad` into `out`, by increasing ground range.
    pub fn crossings(&self, az_rad: f64, out: &mut Vec<Crossing>) {
        out.clear();
        let theta = az_rad.rem_euclid(std::f64::consts::TAU);
        let bin =
            ((theta / std::f64::consts::TAU * ANGLE_BINS as f64) as usize).min(ANGLE_BINS - 1);
        let dir = DVec2::new(theta.sin(), theta.cos());
        let o = self.origin;
        let range = self.offsets[bin] as usize..self.offsets[bin + 1] as usize;
        for &e in &self.index[range] {
            let (a, b, polygon) = self.edges[e as usize];
            let (sa, sb) = (dir.perp_dot(a - o), dir.perp_dot(b - o));
            if (sa > 0.0) == (sb > 0.0) {
                continue;
            }
            // The point of the edge on the ray's line, and its distance along the ray.
            let u = sa / (sa - sb);
            let p = a + (b - a) * u;
            let t = (p - o).dot(dir);
            if t < 0.0 {
                continue;
            }
            let along = (b - a).normalize_or_zero();
            out.push(Crossing {
                ground_m: t,
                polygon,
                sin_incidence: dir.perp_dot(along).abs(),
            });
        }
        out.sort_by(|x, y| {
            x.ground_m
                .total_cmp(&y.ground_m)
                .then(x.polygon.cmp(&y.polygon))
        });
    }

    /// A walk outward on the bearing `az_rad` along a ray whose crossings are `crossings`
    /// (from [`LandView::crossings`]).
    pub fn walk<'c>(&'c self, az_rad: f64, crossings: &'c [Crossing]) -> Walk<'c> {
        let active = self.inside_at_origin.iter().map(|&p| (p, None)).collect();
        Walk {
            view: self,
            dir: DVec2::new(az_rad.sin(), az_rad.cos()),
            crossings,
            next: 0,
            active,
        }
    }

    /// The highest elevation angle of the land on the bearing `az_rad` nearer than
    /// `ground_m`, rad (None where the ray crosses no land first), for an antenna
    /// `antenna_m` high: exact for cliffs (a flat top's α is largest at an end of its stretch
    /// or where `dα/dg = 0`, at `g = √(2a_e(h − H))`), slopes sampled every eighth of their
    /// width.
    pub fn max_land_elevation_rad(
        &self,
        az_rad: f64,
        ground_m: f64,
        antenna_m: f64,
        curvature: bool,
        scratch: &mut Vec<Crossing>,
    ) -> Option<f64> {
        self.crossings(az_rad, scratch);
        self.max_land_elevation_along(az_rad, scratch, ground_m, antenna_m, curvature)
    }

    /// [`LandView::max_land_elevation_rad`] on a ray whose crossings are `crossings`.
    pub fn max_land_elevation_along(
        &self,
        az_rad: f64,
        crossings: &[Crossing],
        ground_m: f64,
        antenna_m: f64,
        curvature: bool,
    ) -> Option<f64> {
        let scratch = crossings;
        let mut walk = self.walk(az_rad, scratch);
        let mut best: Option<f64> = None;
        let mut consider = |z: f64, g: f64| {
            let a = elevation_rad(z, g, antenna_m, curvature);
            best = Some(best.map_or(a, |b: f64| b.max(a)));
        };
        // Stretches between consecutive crossings (and from the antenna to the first).
        let mut stops: Vec<f64> = Vec::with_capacity(scratch.len() + 2);
        stops.push(0.0);
        stops.extend(scratch.iter().map(|c| c.ground_m).filter(|&g| g < ground_m));
        stops.push(ground_m);
        for w in stops.windows(2) {
            let (g0, g1) = (w[0], w[1]);
            if g1 <= g0 {
                continue;
            }
            let mid = 0.5 * (g0 + g1);
            let Some((p, _)) = walk.at(mid) else { continue };
            let poly = &self.polygons[p];
            let start = g0.max(1e-3);
            match poly.sample_step_m() {
                None => {
                    let h = poly.top_m;
                    consider(h, start);
                    consider(h, g1);
                    if curvature && antenna_m > h {
                        let g_star = (2.0 * EFFECTIVE_EARTH_RADIUS_M * (antenna_m - h)).sqrt();
                        if g_star > start && g_star < g1 {
                            consider(h, g_star);
                        }
                    }
                }
                Some(step) => {
                    let n = ((g1 - start) / step).ceil().clamp(1.0, 1e5) as usize;
                    let mut w2 = self.walk(az_rad, scratch);
                    for i in 0..=n {
                        let g = start + (g1 - start) * i as f64 / n as f64;
                        if let Some((_, z)) = w2.at(g.min(g1 - 1e-9).max(start)) {
                            consider(z, g);
                        }
                    }
                }
            }
        }
        best
    }
}

impl LandView<'_> {
    /// Whether land on the bearing `az_rad` rises above the straight segment from
    /// `(g0, z0)` to `(g1, z1)` (ground range, height; g0 < g1), over a flat earth (the legs
    /// this serves, via the sea's specular point, are short): flat tops are tested at their
    /// stretch's ends within the segment (a line against a constant height), slopes every
    /// eighth of their width.
    pub fn blocks_segment(
        &self,
        az_rad: f64,
        from: (f64, f64),
        to: (f64, f64),
        scratch: &mut Vec<Crossing>,
    ) -> bool {
        self.crossings(az_rad, scratch);
        self.blocks_segment_along(az_rad, scratch, from, to)
    }

    /// [`LandView::blocks_segment`] on a ray whose crossings are `crossings`.
    pub fn blocks_segment_along(
        &self,
        az_rad: f64,
        crossings: &[Crossing],
        (g0, z0): (f64, f64),
        (g1, z1): (f64, f64),
    ) -> bool {
        if g1 <= g0 {
            return false;
        }
        let scratch = crossings;
        let line = |g: f64| z0 + (z1 - z0) * (g - g0) / (g1 - g0);
        let mut stops: Vec<f64> = vec![g0];
        stops.extend(
            scratch
                .iter()
                .map(|c| c.ground_m)
                .filter(|&g| g > g0 && g < g1),
        );
        stops.push(g1);
        let mut walk = self.walk(az_rad, scratch);
        for w in stops.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b <= a {
                continue;
            }
            let Some((p, _)) = walk.at(0.5 * (a + b)) else {
                continue;
            };
            let poly = &self.polygons[p];
            let blocked = match poly.sample_step_m() {
                None => poly.top_m > line(a) || poly.top_m > line(b),
                Some(step) => {
                    let n = (((b - a) / step).ceil() as usize).clamp(1, 100_000);
                    let mut w2 = self.walk(az_rad, scratch);
                    (0..=n).any(|i| {
                        let g = a + (b - a) * i as f64 / n as f64;
                        w2.at(g.clamp(a + 1e-9, b - 1e-9))
                            .is_some_and(|(_, z)| z > line(g))
                    })
                }
            };
            if blocked {
                return true;
            }
        }
        false
    }
}

/// A walk outward along one ray: the land (polygon and height) at increasing ground ranges.
#[derive(Debug, Clone)]
pub struct Walk<'c> {
    view: &'c LandView<'c>,
    /// The ray's unit direction on the ground.
    dir: DVec2,
    crossings: &'c [Crossing],
    next: usize,
    /// Polygons the walk is inside, with the crossing it entered by (None: the antenna
    /// stands in it). Where polygons overlap, the last listed is the ground (as
    /// [`Land::polygon_at`]).
    active: Vec<(u32, Option<Crossing>)>,
}

impl Walk<'_> {
    /// The polygon and ground height at ground range `ground_m` (not less than the previous
    /// call's), None over water.
    pub fn at(&mut self, ground_m: f64) -> Option<(usize, f64)> {
        while let Some(c) = self.crossings.get(self.next) {
            if c.ground_m > ground_m {
                break;
            }
            if let Some(i) = self.active.iter().position(|(p, _)| *p == c.polygon) {
                self.active.remove(i);
            } else {
                self.active.push((c.polygon, Some(*c)));
            }
            self.next += 1;
        }
        let &(p, entry) = self.active.iter().max_by_key(|(p, _)| *p)?;
        let poly = &self.view.polygons[p as usize];
        let point = || self.view.origin + self.dir * ground_m;
        let height = match poly.edge {
            Edge::Cliff if poly.is_flat() => poly.top_m,
            Edge::Cliff => poly.height_at(point(), 0.0),
            Edge::Beach { .. } => {
                // Distance to the coast: the perpendicular to the edge it entered by and to
                // the edge it will leave by, the nearer.
                let before = entry.map(|c| (ground_m - c.ground_m) * c.sin_incidence);
                let after = self.crossings[self.next..]
                    .iter()
                    .find(|c| c.polygon == p)
                    .map(|c| (c.ground_m - ground_m) * c.sin_incidence);
                let d = match (before, after) {
                    (Some(x), Some(y)) => x.min(y),
                    (Some(x), None) | (None, Some(x)) => x,
                    (None, None) => {
                        let o = self.view.origin;
                        poly.distance_to_boundary_m(o)
                    }
                };
                poly.height_at(point(), d)
            }
        };
        Some((p as usize, height))
    }
}

#[cfg(test)]
mod tests {
    use super::super::Terrain;
    use super::*;

    /// `seen_lower` against the angles it stands for, over points spread from the radar's
    /// foot to far out, above and below it, and over near ties (the same slope scaled, and
    /// slopes a few units in the last place apart).
    #[test]
    fn seen_lower_decides_as_the_angles_do() {
        let mut state = 12345u64;
        let mut next = || {
            state = crate::rng::splitmix64(state);
            crate::rng::unit_f64(state)
        };
        let mut ties = 0;
        for _ in 0..200_000 {
            let g1 = 10f64.powf(next() * 5.0 - 1.0);
            let r1 = (next() - 0.7) * 10f64.powf(next() * 4.0);
            let (g2, r2) = match (next() * 3.0) as u32 {
                0 => (
                    10f64.powf(next() * 5.0 - 1.0),
                    (next() - 0.7) * 10f64.powf(next() * 4.0),
                ),
                1 => {
                    let k = 1.0 + next() * 5.0;
                    (g1 * k, r1 * k)
                }
                _ => {
                    let ulps = (next() * 8.0) as u64;
                    (g1, f64::from_bits(r1.to_bits() + ulps))
                }
            };
            let exact = r1.atan2(g1) < r2.atan2(g2);
            ties += usize::from(r1.atan2(g1) == r2.atan2(g2));
            assert_eq!(
                seen_lower(r1, g1, r2, g2),
                exact,
                "({r1}, {g1}) vs ({r2}, {g2})"
            );
        }
        assert!(ties > 1000, "near ties tested: {ties}");
    }

    fn poly(rings: Vec<Vec<DVec2>>, top_m: f64, edge: Edge) -> LandPolygon {
        LandPolygon {
            name: "p".into(),
            table: 0,
            source: "test".into(),
            rings,
            top_m,
            edge,
            terrain: Terrain::Rock,
            gamma_db_at_10_ghz: 0.0,
            weibull_shape: 1.0,
            height_map: None,
            structure: None,
        }
    }

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<DVec2> {
        vec![
            DVec2::new(x0, y0),
            DVec2::new(x1, y0),
            DVec2::new(x1, y1),
            DVec2::new(x0, y1),
        ]
    }

    #[test]
    fn walking_a_ray_agrees_with_point_in_polygon_everywhere() {
        // An island with a lake and an islet in the lake (overlapping polygons), and a
        // star-shaped cape; rays at many bearings, from outside and from inside the land.
        let mut star = Vec::new();
        for i in 0..14 {
            let a = i as f64 * std::f64::consts::TAU / 14.0;
            let r = if i % 2 == 0 { 900.0 } else { 400.0 };
            star.push(DVec2::new(-1500.0 + r * a.sin(), 300.0 + r * a.cos()));
        }
        let land = Land::new(vec![
            poly(
                vec![
                    rect(200.0, -500.0, 1200.0, 800.0),
                    rect(500.0, -200.0, 900.0, 400.0),
                ],
                10.0,
                Edge::Cliff,
            ),
            poly(vec![rect(600.0, 0.0, 800.0, 200.0)], 20.0, Edge::Cliff),
            poly(vec![star], 30.0, Edge::Beach { width_m: 100.0 }),
        ]);
        for origin in [
            DVec2::new(0.0, 0.0),
            DVec2::new(300.0, 700.0),
            DVec2::new(-1500.0, 300.0),
        ] {
            let view = LandView::new(&land, origin);
            let mut crossings = Vec::new();
            for k in 0..720 {
                let az = k as f64 * std::f64::consts::TAU / 720.0 + 1e-4;
                view.crossings(az, &mut crossings);
                let mut walk = view.walk(az, &crossings);
                let dir = DVec2::new(az.sin(), az.cos());
                for i in 1..300 {
                    let g = i as f64 * 10.0 + 0.37;
                    let p = origin + dir * g;
                    let got = walk.at(g);
                    assert_eq!(
                        got.map(|x| x.0),
                        land.polygon_at(p),
                        "from {origin} at {az} {g}"
                    );
                    if let Some((_, z)) = got {
                        assert!(
                            (z - land.height_at(p)).abs() < 1e-6 || land.polygons()[2].contains(p),
                            "{z} vs {}",
                            land.height_at(p)
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn beach_heights_follow_the_distance_to_the_coast_across_a_straight_shore() {
        // A shore along x = 1000 (land to the east): a ray at 60° from north meets it
        // obliquely; 100 m along the ray past the shore is 100·sin 60° from it.
        let land = Land::new(vec![poly(
            vec![rect(1000.0, -5000.0, 6000.0, 5000.0)],
            20.0,
            Edge::Beach { width_m: 200.0 },
        )]);
        let view = LandView::new(&land, DVec2::ZERO);
        let mut c = Vec::new();
        let az = 60f64.to_radians();
        view.crossings(az, &mut c);
        let shore = 1000.0 / az.sin();
        assert!((c[0].ground_m - shore).abs() < 1e-9);
        let mut walk = view.walk(az, &c);
        let (_, z) = walk.at(shore + 100.0).unwrap();
        assert!((z - 20.0 * 100.0 * az.sin() / 200.0).abs() < 1e-9);
        assert_eq!(walk.at(shore + 1000.0).unwrap().1, 20.0);
    }

    #[test]
    fn the_highest_land_elevation_is_the_cliff_top_it_should_be() {
        // Antenna 20 m up; an island 1000..1500 m north with a 30 m cliff top: the nearest
        // edge is the highest (H > h). A 10 m island: its far edge is (H < h), less the
        // earth's drop.
        let land = Land::new(vec![poly(
            vec![rect(-50.0, 1000.0, 50.0, 1500.0)],
            30.0,
            Edge::Cliff,
        )]);
        let view = LandView::new(&land, DVec2::ZERO);
        let mut s = Vec::new();
        let a = view
            .max_land_elevation_rad(0.0, 3000.0, 20.0, true, &mut s)
            .unwrap();
        assert!((a - elevation_rad(30.0, 1000.0, 20.0, true)).abs() < 1e-12);
        let low = Land::new(vec![poly(
            vec![rect(-50.0, 1000.0, 50.0, 1500.0)],
            10.0,
            Edge::Cliff,
        )]);
        let view = LandView::new(&low, DVec2::ZERO);
        let a = view
            .max_land_elevation_rad(0.0, 3000.0, 20.0, false, &mut s)
            .unwrap();
        assert!((a - elevation_rad(10.0, 1500.0, 20.0, false)).abs() < 1e-12);
        assert!(view
            .max_land_elevation_rad(0.0, 900.0, 20.0, true, &mut s)
            .is_none());
        assert!(view
            .max_land_elevation_rad(1.0, 3000.0, 20.0, true, &mut s)
            .is_none());
    }
}
