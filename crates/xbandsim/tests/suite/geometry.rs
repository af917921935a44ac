//! Ray casting: BVH against brute force, and exact intersections against analytic distances.

use glam::DVec3;
use xbandsim::geometry::{
    closest_hit_brute_force, object_frame, Bvh, Primitive, PrimitiveKind, Ray, ShapeGeometry,
};

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = xbandsim::rng::splitmix64(self.0);
        xbandsim::rng::unit_f64(self.0)
    }
    fn vec(&mut self, scale: f64) -> DVec3 {
        DVec3::new(self.next() - 0.5, self.next() - 0.5, self.next() - 0.5) * 2.0 * scale
    }
}

fn random_scene(rng: &mut Lcg) -> Vec<Primitive> {
    let shapes = [
        ShapeGeometry::Sphere { radius_m: 1.5 },
        ShapeGeometry::Plate {
            width_m: 4.0,
            height_m: 2.0,
        },
        ShapeGeometry::Trihedral { edge_m: 2.0 },
        ShapeGeometry::Dihedral {
            width_m: 2.0,
            height_m: 3.0,
        },
        ShapeGeometry::Cylinder {
            radius_m: 0.7,
            height_m: 3.0,
        },
        ShapeGeometry::Box {
            size_m: DVec3::new(3.0, 1.0, 2.0),
        },
    ];
    let mut prims = Vec::new();
    for i in 0..60 {
        let shape = &shapes[i % shapes.len()];
        let rot = object_frame(rng.next() * 6.3, rng.next() * 3.0 - 1.5, rng.next() * 6.3);
        prims.extend(shape.primitives(rng.vec(30.0), rot, i as u32));
    }
    for _ in 0..300 {
        prims.push(Primitive {
            kind: PrimitiveKind::Triangle {
                v0: rng.vec(30.0),
                e1: rng.vec(2.0),
                e2: rng.vec(2.0),
            },
            object: 1000,
        });
    }
    prims
}

/// An object's primitives from the BVH's index are exactly those a scan of all primitives
/// finds for its tag, in the same order (tags 0–59 hold a few each, 1000 holds 300 triangles,
/// and absent tags hold none), and its bounds are theirs.
#[test]
fn object_primitives_are_the_scan_of_all() {
    let mut rng = Lcg(7);
    let bvh = Bvh::build(random_scene(&mut rng));
    for tag in (0..62).chain([999, 1000, 1001, u32::MAX]) {
        let scanned: Vec<&Primitive> = bvh
            .primitives()
            .iter()
            .filter(|p| p.object == tag)
            .collect();
        let indexed: Vec<&Primitive> = bvh.object_primitives(tag).collect();
        assert_eq!(indexed.len(), scanned.len(), "tag {tag}");
        for (a, b) in indexed.iter().zip(&scanned) {
            assert!(std::ptr::eq(*a, *b), "tag {tag}");
        }
        let bounds = scanned
            .iter()
            .fold(xbandsim::geometry::Aabb::EMPTY, |b, p| b.union(&p.bounds()));
        let object_bounds = bvh.object_bounds(tag);
        assert_eq!(
            (object_bounds.min, object_bounds.max),
            (bounds.min, bounds.max),
            "tag {tag}"
        );
    }
}

/// The BVH returns exactly the brute-force closest hit (distance, primitive) for random rays
/// into a random scene of every primitive kind, and the same any-hit answer.
#[test]
fn bvh_matches_brute_force() {
    let mut rng = Lcg(99);
    let prims = random_scene(&mut rng);
    let bvh = Bvh::build(prims);
    let ordered = bvh.primitives().to_vec();
    let mut hits = 0;
    for _ in 0..20_000 {
        let origin = rng.vec(60.0);
        let target = rng.vec(25.0);
        let ray = Ray::new(origin, target - origin);
        let a = bvh.closest_hit(&ray, f64::INFINITY);
        let b = closest_hit_brute_force(&ordered, &ray, f64::INFINITY);
        match (a, b) {
            (Some(x), Some(y)) => {
                hits += 1;
                // The same nearest hit: of equally near ones, the lowest index's.
                assert_eq!((x.t_m, x.primitive), (y.t_m, y.primitive), "{x:?} vs {y:?}");
            }
            (None, None) => {}
            (x, y) => panic!("bvh {x:?} vs brute force {y:?}"),
        }
        let t_max = rng.next() * 80.0;
        assert_eq!(
            bvh.any_hit(&ray, t_max),
            closest_hit_brute_force(&ordered, &ray, t_max).is_some()
        );
    }
    assert!(hits > 2_000, "too few hits to mean anything: {hits}");
}

/// A BVH of four 10 848-triangle vessels (43 392 primitives: its top nodes bin in parallel
/// chunks and build their subtrees in parallel) is the same tree on one thread as on four,
/// and returns the brute-force closest hit and any-hit answer.
#[test]
fn large_bvh_is_the_same_on_any_thread_count_and_matches_brute_force() {
    let vessel = ShapeGeometry::Mesh {
        mesh: std::sync::Arc::new(xbandsim::geometry::mesh::vessel(30.0, 128)),
    };
    let prims: Vec<Primitive> = (0..4u32)
        .flat_map(|i| {
            let at = DVec3::new(40.0 * f64::from(i), 15.0 * f64::from(i % 2), 0.0);
            vessel.primitives(at, object_frame(30.0 * f64::from(i), 0.0, 0.0), i)
        })
        .collect();
    assert!(prims.len() > 40_000);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
            .install(|| Bvh::build(prims.clone()))
    };
    let (one, four) = (on(1), on(4));
    assert_eq!(one.primitives(), four.primitives());
    assert_eq!(
        (one.num_nodes(), one.depth(), one.wide_depth(), one.bounds()),
        (
            four.num_nodes(),
            four.depth(),
            four.wide_depth(),
            four.bounds()
        )
    );
    let ordered = four.primitives().to_vec();
    let mut rng = Lcg(41);
    let mut hits = 0;
    for _ in 0..400 {
        let origin = DVec3::new(60.0, 0.0, 0.0) + rng.vec(150.0);
        let target = DVec3::new(60.0, 7.0, 3.0) + DVec3::new(70.0, 15.0, 4.0) * rng.vec(1.0);
        let ray = Ray::new(origin, target - origin);
        let a = four.closest_hit(&ray, f64::INFINITY);
        let b = closest_hit_brute_force(&ordered, &ray, f64::INFINITY);
        match (a, b) {
            (Some(x), Some(y)) => {
                hits += 1;
                assert!((x.t_m - y.t_m).abs() < 1e-9, "{x:?} vs {y:?}");
            }
            (None, None) => {}
            (x, y) => panic!("bvh {x:?} vs brute force {y:?}"),
        }
        let t_max = rng.next() * 200.0;
        assert_eq!(
            four.any_hit(&ray, t_max),
            closest_hit_brute_force(&ordered, &ray, t_max).is_some()
        );
    }
    assert!(hits > 100, "too few hits to mean anything: {hits}");
}

/// A two-level BVH (half the objects in a shared static level) returns the brute-force
/// closest hit of all the primitives (distance and object) and the same any-hit answer, and
/// finds each object's primitives and bounds in whichever level holds them.
#[test]
fn two_level_bvh_matches_brute_force() {
    let mut rng = Lcg(5);
    let prims = random_scene(&mut rng);
    let (fixed, moving): (Vec<Primitive>, Vec<Primitive>) =
        prims.iter().cloned().partition(|p| p.object % 2 == 0);
    let two = Bvh::over_static(std::sync::Arc::new(Bvh::build(fixed)), moving);
    assert!(two.static_level().is_some());
    let mut hits = 0;
    for _ in 0..20_000 {
        let origin = rng.vec(60.0);
        let target = rng.vec(25.0);
        let ray = Ray::new(origin, target - origin);
        let a = two.closest_hit(&ray, f64::INFINITY);
        let b = closest_hit_brute_force(&prims, &ray, f64::INFINITY);
        match (a, b) {
            (Some(x), Some(y)) => {
                hits += 1;
                assert!((x.t_m - y.t_m).abs() < 1e-9, "{x:?} vs {y:?}");
                assert!(x.object == y.object || (x.t_m - y.t_m).abs() < 1e-12);
            }
            (None, None) => {}
            (x, y) => panic!("two-level {x:?} vs brute force {y:?}"),
        }
        let t_max = rng.next() * 80.0;
        assert_eq!(
            two.any_hit(&ray, t_max),
            closest_hit_brute_force(&prims, &ray, t_max).is_some()
        );
    }
    assert!(hits > 2_000, "too few hits to mean anything: {hits}");
    for tag in [0u32, 1, 2, 7, 58, 1000, 1001] {
        let scanned = prims.iter().filter(|p| p.object == tag).count();
        assert_eq!(two.object_primitives(tag).count(), scanned, "tag {tag}");
        let bounds = prims
            .iter()
            .filter(|p| p.object == tag)
            .fold(xbandsim::geometry::Aabb::EMPTY, |b, p| b.union(&p.bounds()));
        assert_eq!(two.object_bounds(tag).min, bounds.min, "tag {tag}");
    }
}

/// A triangulated 12 × 12 m floor at z = 0 (2 × 144 triangles sharing every edge and vertex)
/// with a 10 m wall of 2 × 100 triangles standing on its x = 0 line, object 2000, and a copy
/// of the wall's lower half in the same place, object 2001 (every hit there a tie).
fn shared_vertex_scene() -> Vec<Primitive> {
    let mut prims = Vec::new();
    let mut quad = |p: DVec3, u: DVec3, v: DVec3, object: u32| {
        for (v0, e1, e2) in [(p, u, v), (p + u + v, -u, -v)] {
            prims.push(Primitive {
                kind: PrimitiveKind::Triangle { v0, e1, e2 },
                object,
            });
        }
    };
    for i in -6..6 {
        for j in -6..6 {
            let p = DVec3::new(f64::from(i), f64::from(j), 0.0);
            quad(p, DVec3::X, DVec3::Y, 2000);
        }
    }
    for j in -5..5 {
        for k in 0..10 {
            let p = DVec3::new(0.0, f64::from(j), f64::from(k));
            quad(p, DVec3::Y, DVec3::Z, 2000);
            if k < 5 {
                quad(p, DVec3::Y, DVec3::Z, 2001);
            }
        }
    }
    prims
}

/// Rays of packets: from one origin through the grid's vertices, edge midpoints and cell
/// centres (every shared vertex and edge of [`shared_vertex_scene`]), grazing along the
/// floor and the wall in their planes, coherent fans (a scan column's directions, from one
/// origin), random rays, directions with a negative zero, a zero direction (normalised to
/// NaN) and rays beyond the f32 test's reach among the others; with search distances
/// infinite, finite, zero, negative and NaN.
fn packet_rays(rng: &mut Lcg) -> (Vec<Ray>, Vec<f64>) {
    let mut rays = Vec::new();
    let origins = [
        DVec3::new(3.3, -2.7, 4.0),
        DVec3::new(-2.0, 1.5, 7.5),
        DVec3::new(0.0, 0.0, 12.0),
    ];
    for origin in origins {
        for i in -12..=12 {
            for j in -12..=12 {
                let at = DVec3::new(0.5 * f64::from(i), 0.5 * f64::from(j), 0.0);
                rays.push(Ray::new(origin, at - origin));
                let on_wall = DVec3::new(0.0, 0.5 * f64::from(i), 0.5 * f64::from(j + 12));
                rays.push(Ray::new(origin, on_wall - origin));
            }
        }
    }
    for k in 0..64 {
        let a = 0.1 * f64::from(k);
        // Grazing: in the floor's plane, and in the wall's.
        rays.push(Ray::new(
            DVec3::new(-8.0, 0.37 * f64::from(k % 9), 0.0),
            DVec3::new(1.0, a.sin(), 0.0),
        ));
        rays.push(Ray::new(
            DVec3::new(0.0, -7.0, 0.25 * f64::from(k % 13)),
            DVec3::new(0.0, 1.0, a.cos()),
        ));
    }
    for _ in 0..200 {
        let origin = rng.vec(40.0);
        let towards = rng.vec(20.0) - origin;
        for e in 0..8 {
            let dir = towards + DVec3::Z * (0.02 * f64::from(e) * towards.length());
            rays.push(Ray::new(origin, dir));
        }
    }
    for _ in 0..2000 {
        let origin = rng.vec(60.0);
        rays.push(Ray::new(origin, rng.vec(25.0) - origin));
    }
    // Directions with a negative zero (straight down onto the floor's vertices, and along
    // it), and, spread through the list so that they share packets with the others, rays
    // beyond the f32 test's reach: an origin past 10^36 m, a direction component of 10^-25.
    for k in 0..16 {
        let at = DVec3::new(f64::from(k % 4) - 1.5, f64::from(k / 4) - 1.5, 6.0);
        rays.push(Ray {
            origin_m: at,
            dir: DVec3::new(0.0, -0.0, -1.0),
        });
        rays.push(Ray {
            origin_m: at,
            dir: DVec3::new(-0.0, 0.6, -0.8),
        });
    }
    for k in 0..40u32 {
        let far = Ray {
            origin_m: DVec3::new(2e36, 0.0, 5.0),
            dir: DVec3::Z,
        };
        let faint = Ray::new(
            DVec3::new(3.3, -2.7 + 0.1 * f64::from(k), 4.0),
            DVec3::new(0.3, 1e-25, -1.0),
        );
        rays.insert(37 * k as usize + 5, far);
        rays.insert(53 * k as usize + 2, faint);
    }
    let t_max = (0..rays.len())
        .map(|i| match i % 11 {
            3 => rng.next() * 40.0,
            5 => 0.0,
            7 if i % 3 == 0 => f64::NAN,
            9 => -1.0,
            _ => f64::INFINITY,
        })
        .collect();
    (rays, t_max)
}

/// Packets of rays (`Bvh::closest_hits`) find exactly the single rays' hits, to the bit, and
/// the brute-force scan's (the nearest hit; of equally near ones, the primitive of the lowest
/// index): in a random scene of every kind with a triangulated floor and wall whose shared
/// vertices and edges the rays aim at or graze (so hits tie), in the same scene split into a
/// two-level hierarchy, and beyond the f32 boxes' reach (scaled by 10^35, where the packets
/// fall back to single rays). Every packet length from 1 to 8 is met.
#[test]
fn packets_match_single_rays_and_brute_force() {
    let mut rng = Lcg(2024);
    let mut prims = random_scene(&mut rng);
    prims.extend(shared_vertex_scene());
    let (rays, t_max) = packet_rays(&mut rng);
    let bvh = Bvh::build(prims.clone());
    let ordered = bvh.primitives().to_vec();
    let mut counted = [0usize; 2];
    let mut ties = 0;
    let mut start = 0;
    for len in (1..=8).cycle() {
        if start >= rays.len() {
            break;
        }
        let end = (start + len).min(rays.len());
        let mut hits = vec![None; end - start];
        bvh.closest_hits(&rays[start..end], &t_max[start..end], &mut hits);
        for (k, hit) in hits.iter().enumerate() {
            let (ray, t) = (&rays[start + k], t_max[start + k]);
            let single = bvh.closest_hit(ray, t);
            assert_eq!(*hit, single, "{ray:?} before {t}");
            let brute = closest_hit_brute_force(&ordered, ray, t);
            assert_eq!(
                hit.map(|h| (h.primitive, h.t_m.to_bits())),
                brute.map(|h| (h.primitive, h.t_m.to_bits())),
                "{ray:?} before {t}"
            );
            counted[usize::from(hit.is_some())] += 1;
            // A tie: another primitive met at the very same distance.
            if let Some(h) = hit {
                ties += usize::from(ordered.iter().enumerate().any(|(i, p)| {
                    i as u32 != h.primitive
                        && p.intersect(ray, h.t_m.next_up())
                            .is_some_and(|(u, _)| u == h.t_m)
                }));
            }
        }
        start = end;
    }
    assert!(
        counted[1] > 2500 && counted[0] > 1000,
        "hits and misses: {counted:?}"
    );
    assert!(ties > 500, "too few ties to mean anything: {ties}");

    // All at once (the whole set tested at the root first), and fans of 100 rays, some
    // missing everything (from far above, upward) and some not.
    let mut all = vec![None; rays.len()];
    bvh.closest_hits(&rays, &t_max, &mut all);
    for ((ray, &t), hit) in rays.iter().zip(&t_max).zip(&all) {
        assert_eq!(
            *hit,
            bvh.closest_hit(ray, t),
            "all at once, {ray:?} before {t}"
        );
    }
    let mut fans: Vec<Ray> = Vec::new();
    for f in 0..40 {
        let origin = DVec3::new(0.0, 0.0, 100.0 - 5.0 * f64::from(f));
        let up = if f % 2 == 0 { 1.0 } else { -1.0 };
        fans.extend((0..100).map(|e| {
            let el = up * (0.05 + 0.01 * f64::from(e));
            let az = 0.3 * f64::from(f);
            Ray::new(origin, DVec3::new(az.sin(), az.cos(), el.tan()))
        }));
    }
    let mut fan_hits = vec![None; fans.len()];
    for (chunk, out) in fans.chunks(100).zip(fan_hits.chunks_mut(100)) {
        bvh.closest_hits(chunk, &[f64::INFINITY; 100], out);
    }
    let fans_met = fan_hits.iter().filter(|h| h.is_some()).count();
    for (ray, hit) in fans.iter().zip(&fan_hits) {
        assert_eq!(*hit, bvh.closest_hit(ray, f64::INFINITY), "fan, {ray:?}");
    }
    assert!(
        fans_met > 50 && fans_met < 2000,
        "{fans_met} of the fans' rays hit"
    );

    // Two levels: the packets' hits are the single rays'.
    let (fixed, moving): (Vec<Primitive>, Vec<Primitive>) =
        prims.iter().cloned().partition(|p| p.object % 2 == 0);
    let two = Bvh::over_static(std::sync::Arc::new(Bvh::build(fixed)), moving);
    let mut hits = vec![None; rays.len()];
    two.closest_hits(&rays, &t_max, &mut hits);
    for ((ray, &t), hit) in rays.iter().zip(&t_max).zip(&hits) {
        assert_eq!(
            *hit,
            two.closest_hit(ray, t),
            "two levels, {ray:?} before {t}"
        );
    }

    // Beyond f32's reach: single rays behind the same call.
    let scale = 1e35;
    let far: Vec<Primitive> = prims
        .iter()
        .map(|p| Primitive {
            kind: match p.kind {
                PrimitiveKind::Triangle { v0, e1, e2 } => PrimitiveKind::Triangle {
                    v0: v0 * scale,
                    e1: e1 * scale,
                    e2: e2 * scale,
                },
                PrimitiveKind::Sphere { centre, radius_m } => PrimitiveKind::Sphere {
                    centre: centre * scale,
                    radius_m: radius_m * scale,
                },
                other => other,
            },
            object: p.object,
        })
        .filter(|p| {
            matches!(
                p.kind,
                PrimitiveKind::Triangle { .. } | PrimitiveKind::Sphere { .. }
            )
        })
        .collect();
    let far_bvh = Bvh::build(far);
    assert!(!far_bvh.boxes_in_f32());
    let far_rays: Vec<Ray> = rays
        .iter()
        .map(|r| Ray::new(r.origin_m * scale, r.dir))
        .collect();
    let far_t: Vec<f64> = t_max.iter().map(|t| t * scale).collect();
    let mut hits = vec![None; rays.len()];
    far_bvh.closest_hits(&far_rays, &far_t, &mut hits);
    let mut far_hits = 0;
    for ((ray, &t), hit) in far_rays.iter().zip(&far_t).zip(&hits) {
        assert_eq!(*hit, far_bvh.closest_hit(ray, t), "far, {ray:?} before {t}");
        far_hits += usize::from(hit.is_some());
    }
    assert!(far_hits > 1000, "{far_hits}");
}

/// Centre of sphere `i` of [`sphere_chain`] on the x axis, m.
fn centre_m(i: i32) -> f64 {
    17f64.powi(i)
}

/// The BVH of `n` spheres (object i the i-th) centred at `side`·17^i m on the x axis
/// (`side` ±1), radius 2 % of 17^i: spaced too far apart for the SAH's bins, so a chain one
/// level per sphere, the farthest sphere split off at each level.
fn sphere_chain(n: i32, side: f64) -> Bvh {
    sphere_chain_from(0, n, side)
}

/// [`sphere_chain`] of the spheres `first..first + n` (17^first m the nearest). Centres
/// within 10⁻¹² m of each other are not split (the SAH skips an axis of no extent), so the
/// spheres below that (17^-10 m and smaller) share one leaf.
fn sphere_chain_from(first: i32, n: i32, side: f64) -> Bvh {
    let prims: Vec<Primitive> = (first..first + n)
        .map(|i| Primitive {
            kind: PrimitiveKind::Sphere {
                centre: DVec3::new(side * centre_m(i), 0.0, 0.0),
                radius_m: 0.02 * centre_m(i),
            },
            object: (i - first) as u32,
        })
        .collect();
    Bvh::build(prims)
}

/// Primitives spaced geometrically by more than the SAH's 16 bins can split (each centre 17
/// times the last) leave it one plane, between the farthest primitive and the rest: a chain
/// one level per primitive, out to where the build's f32 coordinates stop (2^125 m), and
/// beyond the f32 boxes' reach, so the traversal takes the f64 boxes. A ray along the chain
/// meets both children's boxes at every level. The traversal must still find the nearest
/// sphere and the shadow test must still see it. (Trees deeper than the build makes from
/// these are tested by hand-made chains in `geometry::bvh`.)
#[test]
fn bvh_deep_chain_matches_brute_force() {
    let n = 100;
    let bvh = sphere_chain(n, 1.0);
    assert!(bvh.depth() >= 24, "depth {}: a chain", bvh.depth());
    // Spheres out to 17^99 m: beyond f32, so the f64 boxes.
    assert!(!bvh.boxes_in_f32() && bvh.wide_depth() >= 8);
    let ordered = bvh.primitives().to_vec();
    let mut rng = Lcg(7);
    let mut rays = vec![
        Ray::new(DVec3::new(-10.0, 0.0, 0.0), DVec3::X),
        Ray::new(DVec3::new(centre_m(n), 0.0, 0.0), -DVec3::X),
    ];
    for _ in 0..2_000 {
        // From halfway to sphere k, along +x or -x with a small tilt: the nearest hit is
        // sphere k or k - 1, deep in the chain or near its root.
        let k = (rng.next() * n as f64) as i32;
        let scale_m = centre_m(k);
        let origin = DVec3::new(0.5 * scale_m, 0.0, 0.0) + rng.vec(0.005 * scale_m);
        let sign = if rng.next() < 0.5 { 1.0 } else { -1.0 };
        rays.push(Ray::new(
            origin,
            DVec3::new(sign, 0.0, 0.0) + rng.vec(0.002),
        ));
    }
    let mut deep_hits = 0;
    for ray in &rays {
        let a = bvh.closest_hit(ray, f64::INFINITY);
        let b = closest_hit_brute_force(&ordered, ray, f64::INFINITY);
        match (a, b) {
            (Some(x), Some(y)) => {
                assert!(
                    x.object == y.object && (x.t_m - y.t_m).abs() <= 1e-9 * y.t_m,
                    "{ray:?}: bvh {x:?} vs brute force {y:?}"
                );
                deep_hits += usize::from(x.object < 30);
            }
            (None, None) => {}
            (x, y) => panic!("{ray:?}: bvh {x:?} vs brute force {y:?}"),
        }
    }
    assert!(deep_hits > 200, "too few hits below level 64: {deep_hits}");
    // The first sphere's near side is 10.98 m along the first ray.
    assert_eq!(bvh.closest_hit(&rays[0], f64::INFINITY).unwrap().object, 0);
    assert!(bvh.any_hit(&rays[0], 11.0));
    assert!(!bvh.any_hit(&rays[0], 10.9));
}

/// Chains ending at 17^30 m, beyond the f32 boxes' reach (10^36 m), of 12 to 39 spheres:
/// 4-wide trees of 2 to 10 levels with f64 boxes, on either side of the depth where traversal
/// switches from the short stack to the full one (9 and 10 levels). Every query finds what
/// brute force finds, toward the chain's root and away from it, and the shadow test answers
/// at the hit's distance to within 10^-9 of it. (A chain's nodes hold three leaves and one
/// node, so these queries keep few nodes pending; the row below fills the stack.)
#[test]
fn bvh_chains_around_the_short_stack_match_brute_force() {
    let mut depths = Vec::new();
    for first in -8..=19 {
        let n = 31 - first;
        for side in [1.0, -1.0] {
            let bvh = sphere_chain_from(first, n, side);
            assert!(!bvh.boxes_in_f32(), "spheres from 17^{first} m");
            depths.push(bvh.wide_depth());
            check_chain_queries(&bvh, first, n, side);
        }
    }
    for depth in [9, 10] {
        assert!(
            depths.contains(&depth),
            "4-wide depths {depths:?} should include {depth} (f64 boxes)"
        );
    }
}

/// Every query of the chain tests on the chain of spheres `first..first + n`: from halfway to
/// each sphere, toward it and away from it (the nearest hit is that sphere or the one
/// before), the closest hit is brute force's, and the shadow test answers at its distance to
/// within 10^-9 of it.
fn check_chain_queries(bvh: &Bvh, first: i32, n: i32, side: f64) {
    let ordered = bvh.primitives().to_vec();
    for k in first..first + n {
        let origin = DVec3::new(side * 0.5 * centre_m(k), 1e-3 * centre_m(k), 0.0);
        for dir in [DVec3::X, -DVec3::X] {
            let ray = Ray::new(origin, dir);
            let a = bvh.closest_hit(&ray, f64::INFINITY);
            let b = closest_hit_brute_force(&ordered, &ray, f64::INFINITY);
            assert_eq!(
                a.map(|h| h.object),
                b.map(|h| h.object),
                "spheres {first}..{}, 4-wide depth {}: {ray:?}",
                first + n,
                bvh.wide_depth()
            );
            if let Some(h) = b {
                assert!(bvh.any_hit(&ray, h.t_m * (1.0 + 1e-9)));
                assert!(!bvh.any_hit(&ray, h.t_m * (1.0 - 1e-9)));
            }
        }
    }
}

/// The short/full stack switch with f32 boxes: chains of 30 to 44 spheres starting at 17^-15 m
/// (3.5·10^-19 m) make 4-wide trees of 7 to 12 levels while their farthest sphere (17^28 m at
/// most) stays within the f32 boxes' reach, so both stacks run with f32 boxes (the chains from
/// 1 m get only 8 levels before leaving it); every query matches brute force as above.
#[test]
fn bvh_f32_chains_around_the_short_stack_match_brute_force() {
    let first = -15;
    let mut depths = Vec::new();
    for n in 30..=44 {
        for side in [1.0, -1.0] {
            let bvh = sphere_chain_from(first, n, side);
            assert!(bvh.boxes_in_f32(), "{n} spheres from 17^{first} m");
            depths.push(bvh.wide_depth());
            check_chain_queries(&bvh, first, n, side);
        }
    }
    for depth in [9, 10] {
        assert!(
            depths.contains(&depth),
            "4-wide depths {depths:?} should include {depth} (f32 boxes)"
        );
    }
}

/// A row of 4096 spheres along x, 1 m apart, and rays along the row: the ray meets every box
/// of the tree, so each node visited leaves three siblings pending and the closest-hit search
/// holds three entries a level (3·depth + 1) when it reaches the first leaf. Both it and the
/// shadow test find what brute force finds, from every 37th gap and beyond either end.
#[test]
fn bvh_row_met_by_every_box_matches_brute_force() {
    let prims: Vec<Primitive> = (0..4096)
        .map(|i| Primitive {
            kind: PrimitiveKind::Sphere {
                centre: DVec3::new(i as f64, 0.0, 0.0),
                radius_m: 0.3,
            },
            object: i,
        })
        .collect();
    let bvh = Bvh::build(prims);
    assert!(
        bvh.boxes_in_f32() && bvh.wide_depth() >= 4,
        "{}",
        bvh.wide_depth()
    );
    let ordered = bvh.primitives().to_vec();
    let mut checked = 0;
    for start in (-1..4097).step_by(37).chain([4097]) {
        let origin = DVec3::new(start as f64 + 0.5, 0.01, -0.02);
        for dir in [DVec3::X, -DVec3::X] {
            let ray = Ray::new(origin, dir);
            let a = bvh.closest_hit(&ray, f64::INFINITY);
            let b = closest_hit_brute_force(&ordered, &ray, f64::INFINITY);
            assert_eq!(a, b, "{ray:?}");
            for t_max_m in [0.1, 0.25, 1.0, 1e4] {
                assert_eq!(
                    bvh.any_hit(&ray, t_max_m),
                    closest_hit_brute_force(&ordered, &ray, t_max_m).is_some(),
                    "{ray:?} to {t_max_m} m"
                );
            }
            checked += usize::from(b.is_some());
        }
    }
    assert!(checked > 200, "too few hits: {checked}");
}

/// The f32 box test at a radar scene's scale: ship-sized boxes, plates and triangle fans
/// 1–20 km from a radar 15 m up, at coordinates that f32 cannot hold exactly. Rays from the
/// radar toward points on them, rays leaving their surfaces (the shadow rays of a return),
/// rays along the axes (direction components exactly zero) and rays lying in the planes of
/// the boxes' faces, which meet the boxes' slabs at their edges: the BVH (f32 boxes) and
/// brute force (no boxes) agree on every closest hit, and the shadow test on every segment.
#[test]
fn bvh_f32_boxes_match_brute_force_at_scene_scale() {
    let mut rng = Lcg(2026);
    let mut prims = Vec::new();
    let mut faces = Vec::new();
    let mut rays = Vec::new();
    for object in 0..24u32 {
        let range_m = 1_000.0 + 19_000.0 * rng.next();
        let az = rng.next() * std::f64::consts::TAU;
        let centre = DVec3::new(
            range_m * az.sin() + 0.123_456_789,
            range_m * az.cos() - 0.987_654_321,
            rng.next() * 8.0,
        );
        let size = DVec3::new(
            5.0 + 120.0 * rng.next(),
            3.0 + 20.0 * rng.next(),
            2.0 + 15.0 * rng.next(),
        );
        let shape = if object % 3 == 0 {
            // Axis-aligned: its faces are planes of its own boxes.
            faces.push((centre, size));
            ShapeGeometry::Box { size_m: size }.primitives(
                centre,
                object_frame(0.0, 0.0, 0.0),
                object,
            )
        } else {
            let rot = object_frame(
                rng.next() * 6.3,
                rng.next() * 0.2 - 0.1,
                rng.next() * 0.2 - 0.1,
            );
            ShapeGeometry::Box { size_m: size }.primitives(centre, rot, object)
        };
        prims.extend(shape);
        for _ in 0..40 {
            prims.push(Primitive {
                kind: PrimitiveKind::Triangle {
                    v0: centre + rng.vec(0.5) * size,
                    e1: rng.vec(3.0),
                    e2: rng.vec(3.0),
                },
                object,
            });
        }
    }
    // Plates whose corners f32 holds exactly (so their boxes gain nothing from rounding
    // outward), facing the radar along x or y, 5–15 km out.
    let mut plates = Vec::new();
    for i in 0..16u32 {
        let corner = DVec3::new(
            (5_000.0 + 10_000.0 * rng.next()).round(),
            (5_000.0 + 10_000.0 * rng.next()).round() * if i % 4 == 0 { -1.0 } else { 1.0 },
            1.0,
        );
        let along = if i % 2 == 0 { DVec3::X } else { DVec3::Y } * 8.0;
        let (edge_u, edge_v) = (along, DVec3::Z * 4.0);
        plates.push((corner, edge_u, edge_v));
        prims.push(Primitive {
            kind: PrimitiveKind::Parallelogram {
                corner,
                edge_u,
                edge_v,
            },
            object: 100 + i,
        });
    }
    let bvh = Bvh::build(prims);
    assert!(bvh.boxes_in_f32());
    let ordered = bvh.primitives().to_vec();
    let radar = DVec3::new(0.0, 0.0, 15.0);
    // Rays aimed at the plates' edges, where a ray meets the box's slabs at the same distance
    // to within rounding: from the radar (10 km: the products' rounding matters), and from
    // 1–3 m in front of the plate (the origin's rounding to f32, half a millimetre there,
    // matters), at origins f32 cannot hold.
    for &(corner, edge_u, edge_v) in &plates {
        let normal = edge_u.cross(edge_v).normalize();
        for _ in 0..40 {
            let (s, r) = (rng.next(), rng.next());
            let on_edge = match (rng.next() * 4.0) as u32 {
                0 => corner + edge_u * s,
                1 => corner + edge_v * s,
                2 => corner + edge_u + edge_v * s,
                _ => corner + edge_v + edge_u * s,
            };
            rays.push((Ray::new(radar, on_edge - radar), f64::INFINITY));
            let side = if normal.dot(radar - on_edge) > 0.0 {
                1.0
            } else {
                -1.0
            };
            let near = on_edge + (normal * side * (1.0 + 2.0 * r) + rng.vec(0.7)) * 1.000_000_1;
            rays.push((Ray::new(near, on_edge - near), f64::INFINITY));
        }
    }
    for p in ordered.iter().step_by(3) {
        let b = p.bounds();
        let target = b.min + (b.max - b.min) * DVec3::new(rng.next(), rng.next(), rng.next());
        rays.push((Ray::new(radar, target - radar), f64::INFINITY));
    }
    // Shadow rays: from just off a first hit, back toward the radar and toward its image
    // below the sea, as a return's are.
    for i in 0..rays.len() {
        let (ray, _) = rays[i];
        if let Some(h) = closest_hit_brute_force(&ordered, &ray, f64::INFINITY) {
            let p = ray.at(h.t_m) - ray.dir * 1e-4;
            rays.push((Ray::new(p, radar - p), (radar - p).length()));
            let image = DVec3::new(radar.x, radar.y, -radar.z);
            rays.push((
                Ray::new(p, image - p),
                p.z / (p.z + radar.z) * (image - p).length(),
            ));
        }
    }
    // Along the axes, through the axis-aligned boxes, and in the planes of their faces.
    for &(centre, size) in &faces {
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            for offset in [DVec3::ZERO, size * 0.5, -size * 0.5, size * 0.25] {
                let through = centre + offset - axis * offset.dot(axis);
                for sign in [1.0, -1.0] {
                    let origin = through - axis * sign * 300.0;
                    rays.push((
                        Ray {
                            origin_m: origin,
                            dir: axis * sign,
                        },
                        f64::INFINITY,
                    ));
                }
            }
        }
    }
    let mut hits = 0;
    for &(ray, t_max_m) in &rays {
        let a = bvh.closest_hit(&ray, t_max_m);
        let b = closest_hit_brute_force(&ordered, &ray, t_max_m);
        match (a, b) {
            (Some(x), Some(y)) => {
                hits += 1;
                assert!(
                    x.t_m == y.t_m && (x.primitive == y.primitive || x.normal == y.normal),
                    "{ray:?}: bvh {x:?} vs brute force {y:?}"
                );
            }
            (None, None) => {}
            (x, y) => panic!("{ray:?}: bvh {x:?} vs brute force {y:?}"),
        }
        let reach = b.map_or(t_max_m.min(3e4), |h| h.t_m);
        for t in [
            reach * (1.0 - 1e-12),
            reach * (1.0 + 1e-12),
            t_max_m.min(3e4),
        ] {
            assert_eq!(
                bvh.any_hit(&ray, t),
                closest_hit_brute_force(&ordered, &ray, t).is_some(),
                "{ray:?} to {t} m"
            );
        }
    }
    assert!(
        hits > 400,
        "too few hits to mean anything: {hits} of {}",
        rays.len()
    );
}

/// A ray with zero direction components, starting in the plane of its target's minimum face:
/// its slab distance there is 0·∞. Both box tests keep the box (the f64 one used to drop
/// it), so the BVH finds the tangent hit brute force finds, in f32 and, with a second sphere
/// beyond 10^36 m, in f64.
#[test]
fn bvh_keeps_a_box_whose_face_plane_holds_the_ray() {
    let sphere = |x: f64, radius_m: f64, object: u32| Primitive {
        kind: PrimitiveKind::Sphere {
            centre: DVec3::new(x, 0.0, 5.0),
            radius_m,
        },
        object,
    };
    let ray = Ray::new(DVec3::ZERO, DVec3::Z);
    for prims in [
        vec![sphere(1.0, 1.0, 0)],
        vec![sphere(1.0, 1.0, 0), sphere(1e37, 1.0, 1)],
    ] {
        let bvh = Bvh::build(prims.clone());
        assert_eq!(bvh.boxes_in_f32(), prims.len() == 1);
        let want = closest_hit_brute_force(&prims, &ray, f64::INFINITY).expect("tangent at t = 5");
        assert_eq!(want.t_m, 5.0);
        let got = bvh
            .closest_hit(&ray, f64::INFINITY)
            .map(|h| (h.t_m, h.object));
        assert_eq!(got, Some((5.0, 0)), "boxes in f32: {}", bvh.boxes_in_f32());
        assert!(bvh.any_hit(&ray, 6.0) && !bvh.any_hit(&ray, 4.0));
    }
}

/// Exact distances: sphere, plate, cylinder side and cap against closed forms.
#[test]
fn analytic_intersections() {
    let o = DVec3::new(0.0, -10.0, 0.0);
    let sphere = Primitive {
        kind: PrimitiveKind::Sphere {
            centre: DVec3::ZERO,
            radius_m: 2.0,
        },
        object: 0,
    };
    let (t, n) = sphere
        .intersect(&Ray::new(o, DVec3::Y), f64::INFINITY)
        .unwrap();
    assert!((t - 8.0).abs() < 1e-12 && (n + DVec3::Y).length() < 1e-12);
    // Off-centre ray at height h: t = 10 − sqrt(r² − h²).
    let h = 1.2;
    let (t, _) = sphere
        .intersect(&Ray::new(o + DVec3::Z * h, DVec3::Y), f64::INFINITY)
        .unwrap();
    assert!((t - (10.0 - (4.0f64 - h * h).sqrt())).abs() < 1e-12);
    let plate = ShapeGeometry::Plate {
        width_m: 2.0,
        height_m: 1.0,
    }
    .primitives(DVec3::ZERO, object_frame(0.0, 0.0, 0.0), 0);
    let (t, n) = plate[0]
        .intersect(&Ray::new(o, DVec3::Y), f64::INFINITY)
        .unwrap();
    assert!((t - 10.0).abs() < 1e-12 && (n.abs() - DVec3::Y).length() < 1e-12);
    assert!(plate[0]
        .intersect(&Ray::new(o + DVec3::X * 1.01, DVec3::Y), f64::INFINITY)
        .is_none());
    let cyl = ShapeGeometry::Cylinder {
        radius_m: 1.0,
        height_m: 2.0,
    }
    .primitives(DVec3::ZERO, object_frame(0.0, 0.0, 0.0), 0);
    let bvh = Bvh::build(cyl);
    let hit = bvh
        .closest_hit(&Ray::new(o + DVec3::X * 0.6, DVec3::Y), f64::INFINITY)
        .unwrap();
    assert!((hit.t_m - (10.0 - 0.8)).abs() < 1e-12);
    let hit = bvh
        .closest_hit(
            &Ray::new(DVec3::new(0.3, 0.2, 10.0), -DVec3::Z),
            f64::INFINITY,
        )
        .unwrap();
    assert!((hit.t_m - 9.0).abs() < 1e-12, "cap at {}", hit.t_m);
}

/// Object frames: at zero rotation a plate faces +y; yaw 90° turns it to face +x (east).
#[test]
fn yaw_turns_clockwise() {
    let plate = ShapeGeometry::Plate {
        width_m: 1.0,
        height_m: 1.0,
    };
    let p = plate.primitives(DVec3::ZERO, object_frame(90f64.to_radians(), 0.0, 0.0), 0);
    let (_, n) = p[0]
        .intersect(
            &Ray::new(DVec3::new(5.0, 0.0, 0.0), -DVec3::X),
            f64::INFINITY,
        )
        .unwrap();
    assert!((n - DVec3::X).length() < 1e-12, "normal {n}");
}

/// A mesh shared by several objects is built once and placed in each
/// (`scattering::scene_bvh_of`): the same primitives, hits and blocked rays as one build over
/// every object's primitives, whatever each copy's yaw, with triangles of no area in the mesh
/// (left out of the template as of the objects' primitives) and objects of other shapes.
#[test]
fn shared_mesh_copies_match_one_build_and_brute_force() {
    use glam::DMat3;
    use std::sync::Arc;
    use xbandsim::model::SceneObject;
    use xbandsim::scattering::{build_scene_bvh, scene_primitives_of};
    let mut mesh = xbandsim::geometry::mesh::vessel(24.0, 24);
    // Two triangles of no area: a repeated vertex, and three vertices on one line.
    mesh.triangles.push([0, 0, 1]);
    let n = mesh.vertices_m.len() as u32;
    mesh.vertices_m.extend([
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(0.0, 0.0, 2.0),
        DVec3::new(0.0, 0.0, 3.0),
    ]);
    mesh.triangles.push([n, n + 1, n + 2]);
    assert!(mesh.triangles.len() >= 256, "{}", mesh.triangles.len());
    let mesh = Arc::new(mesh);
    let mut rng = Lcg(17);
    let mut objects = Vec::new();
    for i in 0..9 {
        let shape = if i % 4 == 3 {
            ShapeGeometry::Sphere { radius_m: 3.0 }
        } else {
            ShapeGeometry::Mesh {
                mesh: Arc::clone(&mesh),
            }
        };
        let at = DVec3::new(rng.vec(60.0).x, rng.vec(60.0).y, 0.0);
        let yaw = DMat3::from_rotation_z(rng.next() * std::f64::consts::TAU);
        objects.push(SceneObject::new(format!("o{i}"), "ship", shape, at, yaw).unwrap());
    }
    let all = scene_primitives_of(&objects, |_, _| true);
    let copied = build_scene_bvh(&objects);
    let single = Bvh::build(all.clone());
    assert_eq!(copied.primitives().len(), all.len());
    for tag in 0..objects.len() as u32 {
        let mut a: Vec<String> = copied
            .object_primitives(tag)
            .map(|p| format!("{p:?}"))
            .collect();
        let mut b: Vec<String> = single
            .object_primitives(tag)
            .map(|p| format!("{p:?}"))
            .collect();
        a.sort();
        b.sort();
        assert_eq!(a, b, "object {tag}");
        assert_eq!(copied.object_bounds(tag), single.object_bounds(tag));
    }
    assert_eq!(copied.bounds(), single.bounds());
    let mut hits = 0;
    for _ in 0..20_000 {
        let origin = rng.vec(90.0) + DVec3::new(0.0, 0.0, 40.0);
        let aim =
            objects[(rng.next() * objects.len() as f64) as usize % objects.len()].position_m();
        let target = aim + rng.vec(12.0) * DVec3::new(1.0, 1.0, 0.3);
        let ray = Ray::new(origin, target - origin);
        let a = copied.closest_hit(&ray, f64::INFINITY);
        let b = closest_hit_brute_force(&all, &ray, f64::INFINITY);
        match (a, b) {
            (Some(x), Some(y)) => {
                hits += 1;
                // Exactly: the same primitives, each intersected by the same code (where two
                // meet the ray at one distance, either may be reported).
                assert_eq!(x.t_m, y.t_m, "{x:?} vs {y:?}");
            }
            (None, None) => {}
            (x, y) => panic!("shared-mesh BVH {x:?} vs brute force {y:?}"),
        }
        let t_max = rng.next() * 150.0;
        assert_eq!(
            copied.any_hit(&ray, t_max),
            closest_hit_brute_force(&all, &ray, t_max).is_some()
        );
    }
    assert!(hits > 5_000, "too few hits to mean anything: {hits}");
}
