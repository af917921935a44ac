//! Sea clutter and rain for one revolution: building the clutter map (texture, σ0, rain)
//! and the whole synthesis with and without it, 360 spokes × 2049 bins.

use criterion::{criterion_group, criterion_main, Criterion};
use xbandsim::engine::Request;
use xbandsim::engine::Simulation;
use xbandsim::model::Scene;
use xbandsim::rng::FrameKey;

fn scene(clutter: bool) -> Scene {
    let text = format!(
        "[environment]\nclutter = {clutter}\nrain = {clutter}\nsea_state = 4.0\nmultipath = false\n[[environment.rain_cell]]\ncentre_m = [1500.0, 500.0]\nradius_m = 600.0\nrate_mm_per_h = 16.0\n[radar]\nposition_m = [0.0, 0.0, 10.0]\nmax_range_m = 3070.0\n"
    );
    Scene::from_toml_str(&text, "bench").unwrap()
}

fn clutter(c: &mut Criterion) {
    let with = Simulation::new(scene(true));
    let without = Simulation::new(scene(false));
    let groups = with.echo_groups(&with.trace());
    let mut g = c.benchmark_group("clutter_360x2049");
    g.sample_size(20);
    g.bench_function("clutter_map", |b| {
        b.iter(|| with.clutter_map(FrameKey::new(1, 0)))
    });
    g.bench_function("synthesis_with_clutter_and_rain", |b| {
        b.iter(|| {
            let map = with.clutter_map(FrameKey::new(1, 0));
            with.synthesize(&groups, map.as_ref(), &Request::new(1))
        })
    });
    g.bench_function("synthesis_without", |b| {
        b.iter(|| without.synthesize(&groups, None, &Request::new(1)))
    });
    g.finish();
}

criterion_group!(benches, clutter);
criterion_main!(benches);
