//! Times environment steps on one core: `cargo run --release -p xbandsim-rl --example steps
//! -- [task] [level] [steps]` prints milliseconds per step (a profiling harness; the
//! benchmark with its reference is bench/env_steps.py).

use std::time::Instant;
use xbandsim_rl::{Action, Episode, EpisodeConfig, Task};

fn main() -> Result<(), xbandsim::Error> {
    let args: Vec<String> = std::env::args().collect();
    let task = match args.get(1).map(String::as_str) {
        Some("tracking") => Task::Tracking,
        _ => Task::Detection,
    };
    let level = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2);
    let steps: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(200);
    let mut config = EpisodeConfig::new(task, level);
    config.max_steps = steps + 1;
    let mut e = Episode::new(config)?;
    e.reset(1)?;
    let action = Action::default();
    let start = Instant::now();
    let mut bytes = 0usize;
    for _ in 0..steps {
        e.step(&action)?;
        bytes += e.observation().len();
    }
    let dt = start.elapsed().as_secs_f64() / steps as f64;
    println!(
        "{task:?} level {level}: {:.2} ms/step, {:.0} steps/s ({bytes} observation bytes)",
        dt * 1e3,
        1.0 / dt
    );
    Ok(())
}
