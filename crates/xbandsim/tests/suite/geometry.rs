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
