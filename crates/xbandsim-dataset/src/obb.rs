//! Oriented boxes of echoes: the smallest-area rectangle around a mask's set pixels
//! (docs/formats.md, "Dataset labels"), the extent a detector sees.
//!
//! The rectangle is found the standard way (Freeman & Shapira, "Determining the
//! minimum-area encasing rectangle for an arbitrary closed curve", Comm. ACM 18(7), 1975:
//! one side of a minimum-area enclosing rectangle lies along an edge of the convex hull):
//! the convex hull of the set pixels' corners (only each row's first and last pixel can
//! contribute), by Andrew's monotone chain, then one candidate rectangle per hull edge.

/// A point in pixel coordinates, `[x, y]` (x right, y down; pixel (i, j) covers
/// `[i, i + 1] × [j, j + 1]`).
pub type Point = [f64; 2];

/// The convex hull of `points` (counter-clockwise in a y-up frame, without collinear
/// points), by Andrew's monotone chain. Fewer than three distinct points come back as they
/// are (sorted, deduplicated).
pub fn convex_hull(mut points: Vec<Point>) -> Vec<Point> {
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let cross = |o: Point, a: Point, b: Point| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<Point> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let push = |p: Point, hull: &mut Vec<Point>| {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        };
        if pass == 0 {
            for &p in &points {
                push(p, &mut hull);
            }
        } else {
            for &p in points.iter().rev() {
                push(p, &mut hull);
            }
        }
        hull.pop(); // the last point of each chain starts the other
    }
    hull
}

/// The smallest-area rectangle enclosing the convex polygon `hull` (at least one point): its
/// four corners in order around it, starting from the one at the least coordinates along and
/// across the hull edge chosen. Ties keep the first edge (the same input gives the same
/// bytes).
pub fn min_area_rectangle(hull: &[Point]) -> [Point; 4] {
    if hull.len() == 1 {
        return [hull[0]; 4];
    }
    let mut best: Option<(f64, [Point; 4])> = None;
    for i in 0..hull.len() {
        let [ax, ay] = hull[i];
        let [bx, by] = hull[(i + 1) % hull.len()];
        let len = (bx - ax).hypot(by - ay);
        if len == 0.0 {
            continue;
        }
        let (ux, uy) = ((bx - ax) / len, (by - ay) / len); // along the edge
        let (vx, vy) = (-uy, ux); // across it
        let (mut u0, mut u1, mut v0, mut v1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &[x, y] in hull {
            let u = x * ux + y * uy;
            let v = x * vx + y * vy;
            u0 = u0.min(u);
            u1 = u1.max(u);
            v0 = v0.min(v);
            v1 = v1.max(v);
        }
        let area = (u1 - u0) * (v1 - v0);
        // A clearly smaller area only: near-equal ones keep the first edge, so rounding in
        // the last bits does not pick another (equally small) rectangle on another machine.
        if best.as_ref().is_none_or(|(a, _)| area < *a * (1.0 - 1e-12)) {
            let corner = |u: f64, v: f64| [u * ux + v * vx, u * uy + v * vy];
            best = Some((
                area,
                [
                    corner(u0, v0),
                    corner(u1, v0),
                    corner(u1, v1),
                    corner(u0, v1),
                ],
            ));
        }
    }
    best.map_or([hull[0]; 4], |(_, r)| r)
}

/// The corners of the pixels that can be on the hull of a set of pixels given row by row as
/// `(y, first x, last x)`: each row's outer corners.
pub fn row_extreme_corners(rows: impl Iterator<Item = (usize, usize, usize)>) -> Vec<Point> {
    let mut points = Vec::new();
    for (y, first, last) in rows {
        let (y0, y1) = (y as f64, (y + 1) as f64);
        let (x0, x1) = (first as f64, (last + 1) as f64);
        points.extend([[x0, y0], [x0, y1], [x1, y0], [x1, y1]]);
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Area of a polygon (shoelace).
    fn area(p: &[Point]) -> f64 {
        let mut twice = 0.0;
        for i in 0..p.len() {
            let [x0, y0] = p[i];
            let [x1, y1] = p[(i + 1) % p.len()];
            twice += x0 * y1 - x1 * y0;
        }
        0.5 * twice.abs()
    }

    /// The smallest area over rectangles at 0.01° steps of orientation enclosing `points`:
    /// the naive reference (never below the true minimum; within a hair above it).
    fn brute_force_area(points: &[Point]) -> f64 {
        (0..18_000)
            .map(|k| {
                let t = (k as f64 * 0.01).to_radians();
                let (c, s) = (t.cos(), t.sin());
                let (mut u0, mut u1, mut v0, mut v1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
                for &[x, y] in points {
                    let (u, v) = (x * c + y * s, -x * s + y * c);
                    u0 = u0.min(u);
                    u1 = u1.max(u);
                    v0 = v0.min(v);
                    v1 = v1.max(v);
                }
                (u1 - u0) * (v1 - v0)
            })
            .fold(f64::MAX, f64::min)
    }

    /// Whether `p` lies in the convex quadrilateral `r` (within `eps`).
    fn inside(r: &[Point; 4], p: Point, eps: f64) -> bool {
        let mut sign = 0.0;
        for i in 0..4 {
            let [ax, ay] = r[i];
            let [bx, by] = r[(i + 1) % 4];
            let c = (bx - ax) * (p[1] - ay) - (by - ay) * (p[0] - ax);
            let len = (bx - ax).hypot(by - ay).max(1e-12);
            if c.abs() / len <= eps {
                continue;
            }
            if sign == 0.0 {
                sign = c.signum();
            } else if c.signum() != sign {
                return false;
            }
        }
        true
    }

    /// Pseudo-random blobs of pixels (ellipses at random angles, with holes and spurs): the
    /// rectangle encloses every pixel corner, is a rectangle, and its area is the brute-force
    /// minimum over orientations (to the 0.01° step's slack).
    #[test]
    fn min_area_rectangle_matches_a_brute_force_search() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            xbandsim::rng::unit_f64(state)
        };
        for case in 0..200 {
            let (a, b) = (1.0 + 20.0 * next(), 0.5 + 6.0 * next());
            let t = std::f64::consts::PI * next();
            let (cx, cy) = (30.0 + 5.0 * next(), 30.0 + 5.0 * next());
            let mut pixels = Vec::new();
            for y in 0..64usize {
                for x in 0..64usize {
                    let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
                    let (u, v) = (dx * t.cos() + dy * t.sin(), -dx * t.sin() + dy * t.cos());
                    let hole = next() < 0.1;
                    if (u / a).powi(2) + (v / b).powi(2) <= 1.0 && !hole
                        || (case % 7 == 0 && next() < 0.002)
                    {
                        pixels.push((x, y));
                    }
                }
            }
            if pixels.is_empty() {
                continue;
            }
            let corners: Vec<Point> = pixels
                .iter()
                .flat_map(|&(x, y)| {
                    let (x, y) = (x as f64, y as f64);
                    [[x, y], [x + 1.0, y], [x, y + 1.0], [x + 1.0, y + 1.0]]
                })
                .collect();
            // The rows' extreme corners give the same hull as every corner.
            let mut rows: std::collections::BTreeMap<usize, (usize, usize)> = Default::default();
            for &(x, y) in &pixels {
                let e = rows.entry(y).or_insert((x, x));
                e.0 = e.0.min(x);
                e.1 = e.1.max(x);
            }
            let hull = convex_hull(row_extreme_corners(
                rows.iter().map(|(&y, &(f, l))| (y, f, l)),
            ));
            assert_eq!(hull, convex_hull(corners.clone()), "case {case}");
            let r = min_area_rectangle(&hull);
            for &p in &corners {
                assert!(inside(&r, p, 1e-9), "case {case}: {p:?} outside {r:?}");
            }
            // A rectangle: opposite sides equal, adjacent sides perpendicular.
            let side = |i: usize| [r[(i + 1) % 4][0] - r[i][0], r[(i + 1) % 4][1] - r[i][1]];
            let dot = side(0)[0] * side(1)[0] + side(0)[1] * side(1)[1];
            assert!(dot.abs() < 1e-9, "case {case}: {r:?}");
            let brute = brute_force_area(&hull);
            let got = area(&r);
            assert!(
                got <= brute * (1.0 + 1e-9) + 1e-9,
                "case {case}: {got} > {brute}"
            );
            assert!(
                got >= brute * (1.0 - 1e-2) - 1e-9,
                "case {case}: {got} << {brute}"
            );
        }
    }

    #[test]
    fn single_pixels_and_lines() {
        let one = convex_hull(row_extreme_corners([(3, 5, 5)].into_iter()));
        let r = min_area_rectangle(&one);
        assert!((area(&r) - 1.0).abs() < 1e-12, "{r:?}");
        let line = convex_hull(row_extreme_corners([(3, 5, 14)].into_iter()));
        let r = min_area_rectangle(&line);
        assert!((area(&r) - 10.0).abs() < 1e-12, "{r:?}");
        // A diagonal staircase: the rectangle turns with it (smaller than its axis box).
        let stairs: Vec<(usize, usize, usize)> = (0..20).map(|k| (k, k, k + 1)).collect();
        let r = min_area_rectangle(&convex_hull(row_extreme_corners(stairs.into_iter())));
        assert!(area(&r) < 0.5 * 21.0 * 20.0, "{}", area(&r));
    }
}
