//! Same seed, same output, whatever the thread count; another seed, other noise.

use super::common::*;
use xbandsim::engine::Request;
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

/// Pulse mode with a moving target, sea clutter and the Doppler cube: the same bytes on 1
/// and 3 threads.
#[test]
fn pulse_mode_is_deterministic_across_thread_counts() {
    let text = "[radar]\nspokes = 90\nmax_range_m = 900.0\nprf_hz = 600.0\n[processing]\nmode = \"pulse\"\nintegration = \"coherent\"\n[environment]\nsea_state = 3\n[[object]]\nname = \"b\"\nshape = \"trihedral\"\nedge_m = 0.5\nposition_m = [200.0, 400.0, 2.0]\nspeed_kn = 20.0\ncourse_deg = 200.0\n";
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let f = Simulation::new(scene(text))
                .run(
                    &Request::new(5).frame(1).outputs(xbandsim::engine::Outputs {
                        doppler_cube: true,
                        iq: true,
                        ..Default::default()
                    }),
                )
                .expect("pulse mode gives a cube");
            (
                f.polar_db,
                f.doppler_cube.unwrap().values_db,
                f.iq.unwrap().values,
            )
        })
    };
    assert!(run(1) == run(3), "pulse mode differs between thread counts");
}
