//! Ray casting: BVH closest hit over the paper scene in the radar-scan pattern, the SBR trace,
//! and the BVH against brute force on a many-primitive scene (why we use a BVH at all).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::DVec3;
use xbandsim::engine::Simulation;
use xbandsim::geometry::{
    closest_hit_brute_force, object_frame, Bvh, Primitive, Ray, ShapeGeometry,
};
use xbandsim::model::Scene;
use xbandsim::scattering::{build_scene_bvh, direction_from_az_el, paper};

const PAPER: &str = include_str!("../../../scenes/paper.toml");

fn scan_rays(c: &mut Criterion) {
    let scene = Scene::from_toml_str(PAPER, "paper").unwrap();
    let bvh = build_scene_bvh(scene.objects());
    // One degree of the paper's scan grid: 100 az x 100 el rays, single thread.
    let n = 100 * scene.scattering().paper_rays_elevation();
    let mut g = c.benchmark_group("raycast");
    g.throughput(Throughput::Elements(n as u64));
    let origin = scene.radar().position_m();
    // The degree's rays made once: both searches below cast the same ones.
    let rays: Vec<Ray> = ((36 * n)..(37 * n))
        .map(|i| {
            let (az, el) = paper::grid_direction(scene.scattering(), scene.radar().antenna(), i);
            Ray {
                origin_m: origin,
                dir: direction_from_az_el(az, el),
            }
        })
        .collect();
    g.bench_function("paper_scene_scan_grid_1deg", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|ray| bvh.closest_hit(ray, f64::INFINITY).is_some())
                .count()
        })
    });
    // The same as packets, a column (one azimuth, every elevation) at a time.
    let n_el = scene.scattering().paper_rays_elevation();
    let t_max = vec![f64::INFINITY; n_el];
    let mut hits = vec![None; n_el];
    g.bench_function("paper_scene_scan_grid_1deg_packets", |b| {
        b.iter(|| {
            let mut met = 0;
            for column in rays.chunks(n_el) {
                bvh.closest_hits(column, &t_max, &mut hits);
                met += hits.iter().filter(|h| h.is_some()).count();
            }
            met
        })
    });
    let sim = Simulation::new(scene.clone());
    let rays = sim.trace().rays_cast;
    g.throughput(Throughput::Elements(rays));
    g.sample_size(20);
    g.bench_function("paper_scene_sbr_po_trace", |b| b.iter(|| sim.trace()));
    g.finish();
}

fn bvh_vs_brute_force(c: &mut Criterion) {
    // 2000 boxes (12 000 parallelograms) on a grid: brute force tests all, the BVH a few.
    let mut prims: Vec<Primitive> = Vec::new();
    for i in 0..2000u32 {
        let p = DVec3::new((i % 50) as f64 * 4.0, (i / 50) as f64 * 4.0 + 100.0, 0.0);
        prims.extend(
            ShapeGeometry::Box {
                size_m: DVec3::splat(2.0),
            }
            .primitives(p, object_frame(0.3, 0.0, 0.0), i),
        );
    }
    let bvh = Bvh::build(prims.clone());
    let rays: Vec<Ray> = (0..256)
        .map(|k| {
            Ray::new(
                DVec3::new(100.0, 0.0, 0.5),
                DVec3::new((k as f64 - 128.0) / 200.0, 1.0, 0.0),
            )
        })
        .collect();
    let mut g = c.benchmark_group("bvh_vs_brute_force_12k_prims");
    g.throughput(Throughput::Elements(rays.len() as u64));
    g.bench_function("bvh", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| bvh.closest_hit(r, f64::INFINITY).is_some())
                .count()
        })
    });
    g.sample_size(10);
    g.bench_function("brute_force", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| closest_hit_brute_force(&prims, r, f64::INFINITY).is_some())
                .count()
        })
    });
    g.finish();
}

criterion_group!(benches, scan_rays, bvh_vs_brute_force);
criterion_main!(benches);
