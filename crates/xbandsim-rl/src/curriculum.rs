//! Episode scenes drawn from a curriculum level (docs/rl.md, "Episodes"): the radar the
//! environments use, the sea, rain and wind, the own ship and the moving targets, as a scene
//! file (TOML) that the library validates like any other.
//!
//! Targets are point scatterers (`shape = "point"`) of a class-typical RCS: an episode
//! re-traces its moving scene every revolution, and a point costs nothing to trace where a
//! ship mesh costs tens of milliseconds. Their echoes still go through everything else — the
//! radar equation, multipath over the sea, rain attenuation, eclipsing, the antenna pattern,
//! clutter and noise.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::fmt::Write;

/// What an episode asks of the agent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Task {
    /// Find every target in few revolutions (`xbandsim/Detection-v0`).
    Detection,
    /// Keep moving targets in track (`xbandsim/Tracking-v0`).
    Tracking,
}

impl Task {
    /// Revolutions after which an episode is truncated.
    pub fn max_steps(self) -> usize {
        match self {
            Task::Detection => 12,
            Task::Tracking => 30,
        }
    }
}

/// Curriculum levels: 0 (calm sea, one large target) … 3 (heavy clutter, rain, many small
/// targets).
pub const LEVELS: usize = 4;

/// Instrumented range of the environments' radar, m.
pub const MAX_RANGE_M: f64 = 1500.0;

/// Spokes per revolution of the environments' radar (2°: two per 3.9° beamwidth).
pub const SPOKES: usize = 180;

/// One level's draws.
#[derive(Debug, Clone, Copy)]
struct Level {
    sea_state: (f64, f64),
    rain_cells: (usize, usize),
    rain_rate_mm_per_h: (f64, f64),
    targets: (usize, usize),
    rcs_m2: (f64, f64),
    speed_kn: (f64, f64),
    own_ship_kn: (f64, f64),
}

const LEVEL_TABLE: [Level; LEVELS] = [
    Level {
        sea_state: (0.0, 1.0),
        rain_cells: (0, 0),
        rain_rate_mm_per_h: (0.0, 0.0),
        targets: (1, 1),
        rcs_m2: (100.0, 1000.0),
        speed_kn: (0.0, 8.0),
        own_ship_kn: (0.0, 0.0),
    },
    Level {
        sea_state: (2.0, 3.0),
        rain_cells: (0, 0),
        rain_rate_mm_per_h: (0.0, 0.0),
        targets: (1, 3),
        rcs_m2: (5.0, 100.0),
        speed_kn: (0.0, 15.0),
        own_ship_kn: (0.0, 6.0),
    },
    Level {
        sea_state: (3.0, 4.0),
        rain_cells: (0, 1),
        rain_rate_mm_per_h: (2.0, 8.0),
        targets: (2, 5),
        rcs_m2: (2.0, 50.0),
        speed_kn: (0.0, 20.0),
        own_ship_kn: (0.0, 8.0),
    },
    Level {
        sea_state: (4.0, 5.0),
        rain_cells: (1, 2),
        rain_rate_mm_per_h: (4.0, 16.0),
        targets: (3, 8),
        rcs_m2: (0.5, 20.0),
        speed_kn: (0.0, 25.0),
        own_ship_kn: (0.0, 10.0),
    },
];

/// Classes by RCS: under 5 m² a buoy, under 100 m² a boat, a ship above.
fn class_of(rcs_m2: f64) -> &'static str {
    if rcs_m2 < 5.0 {
        "buoy"
    } else if rcs_m2 < 100.0 {
        "boat"
    } else {
        "ship"
    }
}

/// The own ship an episode sails (the Tracking task's own ship moves from level 1 up; the
/// Detection task's stands still).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OwnShip {
    /// Speed through the water, kn.
    pub speed_kn: f64,
    /// Course, degrees from north.
    pub course_deg: f64,
}

/// An episode's scene: its text and what was drawn.
#[derive(Debug, Clone)]
pub struct EpisodeScene {
    /// The scene file, without the pulse (the action sets it).
    pub toml: String,
    /// Targets placed.
    pub targets: usize,
    /// Sea state drawn.
    pub sea_state: f64,
    /// Rain cells drawn.
    pub rain_cells: usize,
    /// The own ship.
    pub own_ship: OwnShip,
}

fn uniform(rng: &mut Pcg64Mcg, (lo, hi): (f64, f64)) -> f64 {
    if hi > lo {
        rng.random_range(lo..hi)
    } else {
        lo
    }
}

fn uniform_count(rng: &mut Pcg64Mcg, (lo, hi): (usize, usize)) -> usize {
    rng.random_range(lo..=hi)
}

/// Draws the scene of an episode of `task` at `level` (< [`LEVELS`]) from `seed`, for
/// images of `image_size_px`: the same arguments give the same text.
pub fn draw_scene(task: Task, level: usize, seed: u64, image_size_px: u32) -> EpisodeScene {
    let l = LEVEL_TABLE[level.min(LEVELS - 1)];
    let mut rng = Pcg64Mcg::seed_from_u64(xbandsim::rng::splitmix64(seed ^ 0x5eed_e915));
    let sea_state = uniform(&mut rng, l.sea_state);
    let wind_deg = rng.random_range(0.0..360.0);
    let mut t = String::new();
    // Writing into a String cannot fail.
    let _ = write!(
        t,
        "# xbandsim RL episode: {task:?}, level {level}, seed {seed}\n\
         [radar]\npreset = \"drs4d-nxt\"\nposition_m = [0.0, 0.0, 8.0]\nspokes = {SPOKES}\n\
         max_range_m = {MAX_RANGE_M:.1}\nsample_rate_mhz = 20.0\nbandwidth_mhz = 20.0\n\
         window = \"hamming\"\npulse_width_us = 0.5\n\n\
         [environment]\nsea_state = {sea_state}\nwind_direction_deg = {wind_deg}\n"
    );
    let rain_cells = uniform_count(&mut rng, l.rain_cells);
    for _ in 0..rain_cells {
        let r = rng.random_range(0.3..0.9) * MAX_RANGE_M;
        let b: f64 = rng.random_range(0.0..std::f64::consts::TAU);
        let radius = rng.random_range(250.0..600.0);
        let rate = uniform(&mut rng, l.rain_rate_mm_per_h);
        let _ = write!(
            t,
            "[[environment.rain_cell]]\ncentre_m = [{}, {}]\nradius_m = {radius}\nrate_mm_per_h = {rate}\n",
            r * b.sin(),
            r * b.cos()
        );
    }
    let own_ship = match task {
        Task::Tracking => OwnShip {
            speed_kn: uniform(&mut rng, l.own_ship_kn),
            course_deg: rng.random_range(0.0..360.0),
        },
        Task::Detection => OwnShip {
            speed_kn: 0.0,
            course_deg: 0.0,
        },
    };
    if own_ship.speed_kn > 0.0 {
        let _ = write!(
            t,
            "\n[own_ship]\nspeed_kn = {}\ncourse_deg = {}\n",
            own_ship.speed_kn, own_ship.course_deg
        );
    }
    let _ = write!(t, "\n[display]\nimage_size_px = {image_size_px}\n");
    let targets = uniform_count(&mut rng, l.targets);
    let mut placed: Vec<(f64, f64)> = Vec::new();
    for i in 0..targets {
        // Range 250 m … 90 % of the scale, at least 80 m from the others.
        let (mut e, mut n) = (0.0, 0.0);
        for _ in 0..64 {
            let r = rng.random_range(250.0..0.9 * MAX_RANGE_M);
            let b: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            (e, n) = (r * b.sin(), r * b.cos());
            if placed
                .iter()
                .all(|&(pe, pn)| (pe - e).hypot(pn - n) >= 80.0)
            {
                break;
            }
        }
        placed.push((e, n));
        let (lo, hi) = l.rcs_m2;
        let rcs = (lo.ln() + rng.random::<f64>() * (hi.ln() - lo.ln())).exp();
        let speed = uniform(&mut rng, l.speed_kn);
        let course = rng.random_range(0.0..360.0);
        // The scatterer's height over the sea, 1–4 m: with the antenna at 8 m the four-path
        // multipath nulls (R = 2·h_r·h_t/λ) fall at 0.5–2 km, so targets fade in and out as
        // real small craft do, each at its own ranges.
        let height = rng.random_range(1.0..4.0);
        let _ = write!(
            t,
            "\n[[object]]\nname = \"target-{i}\"\nclass = \"{}\"\nshape = \"point\"\n\
             rcs_m2 = {rcs}\nposition_m = [{e}, {n}, {height}]\nspeed_kn = {speed}\ncourse_deg = {course}\n",
            class_of(rcs)
        );
    }
    EpisodeScene {
        toml: t,
        targets,
        sea_state,
        rain_cells,
        own_ship,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_level_draws_a_valid_scene_deterministically() {
        for task in [Task::Detection, Task::Tracking] {
            for level in 0..LEVELS {
                for seed in 0..20 {
                    let s = draw_scene(task, level, seed, 256);
                    assert_eq!(s.toml, draw_scene(task, level, seed, 256).toml);
                    let l = LEVEL_TABLE[level];
                    assert!((l.targets.0..=l.targets.1).contains(&s.targets));
                    let spec = xbandsim::LoadedSpec::from_toml(
                        &s.toml,
                        "episode",
                        std::path::Path::new("."),
                    )
                    .unwrap();
                    let scene = spec.build().unwrap_or_else(|e| panic!("{e}\n{}", s.toml));
                    assert_eq!(scene.objects().len(), s.targets);
                }
            }
        }
        assert_ne!(
            draw_scene(Task::Detection, 2, 1, 256).toml,
            draw_scene(Task::Detection, 2, 2, 256).toml
        );
    }
}
