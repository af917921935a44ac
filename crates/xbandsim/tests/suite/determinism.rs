//! Same seed, same output, whatever the thread count; another seed, other noise.

use super::common::*;
use xbandsim::engine::Simulation;

const SCENE: &str = include_str!("../../../../scenes/paper.toml");

fn render_with_threads(threads: usize, seed: u64) -> Vec<f32> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| Simulation::new(scene(SCENE)).render(seed).polar_db)
}

#[test]
fn same_seed_same_output_any_thread_count() {
    let one = render_with_threads(1, 42);
    let two = render_with_threads(2, 42);
    let four = render_with_threads(4, 42);
    assert!(
        one == two && two == four,
        "outputs differ between thread counts"
    );
    let other = render_with_threads(2, 43);
    assert!(one != other, "a different seed gave the same noise");
}
