//! Ray casting: BVH against brute force, and exact intersections against analytic distances.

use glam::DVec3;
use xbandsim::geometry::{
    closest_hit_brute_force, object_frame, Bvh, Primitive, PrimitiveKind, Ray, ShapeGeometry,
};

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = xbandsim::rng::splitmix64(self.0);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
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
                assert!((x.t_m - y.t_m).abs() < 1e-9, "{x:?} vs {y:?}");
                assert!(x.primitive == y.primitive || (x.t_m - y.t_m).abs() < 1e-12);
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

/// Centre of sphere `i` of [`sphere_chain`] on the x axis, m.
fn centre_m(i: i32) -> f64 {
    17f64.powi(i)
}

/// The BVH of `n` spheres (object i the i-th) centred at `side`·17^i m on the x axis
/// (`side` ±1), radius 2 % of 17^i: spaced too far apart for the SAH's bins, so a chain one
/// level per sphere, the farthest sphere split off at each level.
fn sphere_chain(n: i32, side: f64) -> Bvh {
    let prims: Vec<Primitive> = (0..n)
        .map(|i| Primitive {
            kind: PrimitiveKind::Sphere {
                centre: DVec3::new(side * centre_m(i), 0.0, 0.0),
                radius_m: 0.02 * centre_m(i),
            },
            object: i as u32,
        })
        .collect();
    Bvh::build(prims)
}

/// Primitives spaced geometrically by more than the SAH's 16 bins can split (each centre 17
/// times the last) leave it one plane, between the farthest primitive and the rest: a chain
/// one level per primitive. A ray along the chain meets both children's boxes at every level.
/// The traversal must still find the nearest sphere (it used to drop the near subtree once its
/// 64-entry stack filled, and missed it) and the shadow test must still see it.
#[test]
fn bvh_deep_chain_matches_brute_force() {
    let n = 100;
    let bvh = sphere_chain(n, 1.0);
    assert!(
        (65..=72).contains(&bvh.depth()),
        "depth {}: the SAH's chain should be cut to medians below level 64",
        bvh.depth()
    );
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

/// Trees on either side of the depth where traversal switches from the short stack to the
/// full one (31 and 32 levels), with the stack filled to depth + 1 by the closest-hit search
/// and by the shadow test: every one finds what brute force finds, at every depth.
#[test]
fn bvh_chains_around_the_short_stack_match_brute_force() {
    let mut depths = Vec::new();
    for n in 24..=44 {
        let bvh = sphere_chain(n, 1.0);
        depths.push(bvh.depth());
        let ordered = bvh.primitives().to_vec();
        for k in 0..n {
            // From halfway to sphere k, toward it and away from it: the nearest hit is
            // sphere k or k - 1.
            let origin = DVec3::new(0.5 * centre_m(k), 1e-3 * centre_m(k), 0.0);
            for dir in [DVec3::X, -DVec3::X] {
                let ray = Ray::new(origin, dir);
                let a = bvh.closest_hit(&ray, f64::INFINITY);
                let b = closest_hit_brute_force(&ordered, &ray, f64::INFINITY);
                assert_eq!(
                    a.map(|h| h.object),
                    b.map(|h| h.object),
                    "{n} spheres, depth {}: {ray:?}",
                    bvh.depth()
                );
                if let Some(h) = b {
                    assert!(bvh.any_hit(&ray, h.t_m * (1.0 + 1e-9)));
                    assert!(!bvh.any_hit(&ray, h.t_m * (1.0 - 1e-9)));
                }
            }
        }
    }
    assert!(
        depths.contains(&31) && depths.contains(&32),
        "depths {depths:?} should reach both sides of the switch"
    );
    // The shadow test pushes both children and visits the right one first. On the chain along
    // −x the right child is the deep subtree and the left one the farthest sphere, so a ray
    // that meets every subtree's box leaves one sphere pending per level: the stack fills to
    // depth + 1. Along −x at y = 3 cm it passes sphere 0 (radius 2 cm) and meets sphere 1
    // (radius 34 cm, at x = −17 m) at 16.66 m.
    let mut mirrored_depths = Vec::new();
    for n in 24..=44 {
        let bvh = sphere_chain(n, -1.0);
        mirrored_depths.push(bvh.depth());
        let ordered = bvh.primitives().to_vec();
        let ray = Ray::new(DVec3::new(0.0, 0.03, 0.0), -DVec3::X);
        for t_max_m in [16.0, 17.0] {
            assert_eq!(
                bvh.any_hit(&ray, t_max_m),
                closest_hit_brute_force(&ordered, &ray, t_max_m).is_some(),
                "{n} spheres along -x, depth {}, t_max {t_max_m}",
                bvh.depth()
            );
        }
        assert!(!bvh.any_hit(&ray, 16.0) && bvh.any_hit(&ray, 17.0));
    }
    assert!(
        mirrored_depths.contains(&31) && mirrored_depths.contains(&32),
        "depths {mirrored_depths:?} should reach both sides of the switch"
    );
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
