//! `xbandsim bench`: ray-casting throughput, frame times and peak memory, printed so anyone
//! can reproduce the figures in docs/performance.md.

use anyhow::Result;
use clap::Args;
use glam::DVec3;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;
use xbandsim::engine::Request;
use xbandsim::engine::Simulation;
use xbandsim::geometry::{Bvh, Ray};
use xbandsim::products::ppi::PpiSettings;
use xbandsim::scattering::{build_scene_bvh, paper};
use xbandsim::scene::LoadedSpec;
use xbandsim::Scene;

/// The paper's scene, built into the binary so that `xbandsim bench` runs from any folder.
const PAPER_SCENE: &str = include_str!("../../../scenes/paper.toml");

/// Arguments of `xbandsim bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scene to measure (default: the paper's 5-target scene, scenes/paper.toml, built in).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Timed repetitions of each measurement (the median is printed); at least 1.
    #[arg(long, default_value_t = 5)]
    pub repeats: usize,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
}

/// One revolution traced afresh — trace, echo groups, clutter, every spoke, labels — as a
/// `Simulation`'s first frame is; later frames of the same static scene reuse the trace cache.
fn traced_frame(sim: &Simulation, seed: u64) -> (Vec<f32>, usize) {
    let set = sim.trace();
    let groups = sim.echo_groups(&set);
    let clutter = sim.clutter_map(xbandsim::rng::FrameKey::new(seed, 0));
    let polar = sim
        .synthesize(&groups, clutter.as_ref(), &Request::new(seed))
        .expect("the frozen scan of this radar");
    let truth = sim.truth(&set);
    (polar, truth.len())
}

fn median_s(repeats: usize, mut f: impl FnMut()) -> f64 {
    f(); // warm-up
    let mut t: Vec<f64> = (0..repeats.max(1))
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

/// Peak resident set size of this process, MB (Linux `VmHWM`), if known.
pub fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Casts the paper's uniform scan grid (closest hit) and returns the number of hits: column by
/// column (one azimuth, every elevation), each column's rays made from its azimuth's and the
/// elevations' sines and cosines and traced as packets ([`Bvh::closest_hits`]). With `sea`,
/// the sea is the plane z = 0 outside the BVH, as in the PO trace: a ray that reaches it
/// before any object hits it, and its distance bounds the search.
fn cast_scan_grid(scene: &Scene, bvh: &Bvh, sea: bool) -> usize {
    let (settings, antenna) = (scene.scattering(), scene.radar().antenna());
    let n_el = settings.paper_rays_elevation();
    let n_az = paper::grid_size(settings) / n_el;
    let origin = scene.radar().position_m();
    let elevations: Vec<(f64, f64)> = (0..n_el)
        .map(|ie| paper::grid_direction(settings, antenna, ie).1.sin_cos())
        .collect();
    (0..n_az)
        .into_par_iter()
        .with_min_len(64)
        .map_init(
            || {
                (
                    Vec::with_capacity(n_el),
                    Vec::with_capacity(n_el),
                    vec![None; n_el],
                )
            },
            |(rays, t_max, hits), ia| {
                let (sin_az, cos_az) = paper::grid_direction(settings, antenna, ia * n_el)
                    .0
                    .sin_cos();
                rays.clear();
                t_max.clear();
                for &(sin_el, cos_el) in &elevations {
                    let dir = DVec3::new(sin_az * cos_el, cos_az * cos_el, sin_el);
                    rays.push(Ray {
                        origin_m: origin,
                        dir,
                    });
                    t_max.push(if sea && dir.z < 0.0 && origin.z > 0.0 {
                        -origin.z / dir.z
                    } else {
                        f64::INFINITY
                    });
                }
                bvh.closest_hits(rays, t_max, hits);
                hits.iter()
                    .zip(t_max.iter())
                    .filter(|(hit, t)| hit.is_some() || t.is_finite())
                    .count()
            },
        )
        .sum()
}

#[derive(serde::Serialize)]
struct Row {
    name: String,
    value: f64,
    unit: String,
}

/// Runs `xbandsim bench`.
pub fn run(a: &BenchArgs) -> Result<()> {
    if a.repeats == 0 {
        anyhow::bail!("invalid --repeats 0: at least one timed run is needed");
    }
    let loaded = match &a.scene {
        Some(path) => LoadedSpec::read(path)?,
        None => LoadedSpec::from_toml(PAPER_SCENE, "paper (built in)", Path::new("."))?,
    };
    let scene = loaded.build()?;
    let (spec, base) = (loaded.spec(), loaded.base_dir());
    let progress = crate::progress::spinner("bench: measurements");
    let mut rows: Vec<Row> = Vec::new();
    let mut put = |name: &str, value: f64, unit: &str| {
        progress.inc(1);
        progress.set_message(name.to_string());
        if !a.json {
            progress.suspend(|| crate::say!("{name:<62} {value:>12.3} {unit}"));
        }
        rows.push(Row {
            name: name.into(),
            value,
            unit: unit.into(),
        });
    };
    let threads = rayon::current_num_threads();
    if !a.json {
        crate::say!(
            "xbandsim bench: scene {}, {threads} threads, median of {} runs",
            loaded.origin(),
            a.repeats
        );
    }

    // 1. Ray casting, the paper's radar-scan pattern (360 x 100 az x 100 el = 3.6 M rays).
    let bvh = build_scene_bvh(scene.objects());
    let n_rays = paper::grid_size(scene.scattering()) as f64;
    let t = median_s(a.repeats, || {
        std::hint::black_box(cast_scan_grid(&scene, &bvh, false));
    });
    put(
        "scan-pattern rays, paper scene (closest hit)",
        n_rays / t / 1e6,
        "M rays/s",
    );
    // The same with the sea plane z = 0 (outside the BVH, as in the PO trace), so that rays
    // below the horizon hit something too.
    let t = median_s(a.repeats, || {
        std::hint::black_box(cast_scan_grid(&scene, &bvh, true));
    });
    put(
        "scan-pattern rays, paper scene + sea plane (closest hit)",
        n_rays / t / 1e6,
        "M rays/s",
    );

    // 2. Full frames with the calibrated PO model.
    let sim = Simulation::new(scene.clone());
    let mut rays = 0;
    let t_trace = median_s(a.repeats, || {
        rays = std::hint::black_box(sim.trace()).rays_cast;
    });
    put(
        "SBR/PO tracing, paper scene (targeted + bounce rays)",
        rays as f64 / t_trace / 1e6,
        "M rays/s",
    );
    let t = median_s(a.repeats, || {
        std::hint::black_box(traced_frame(&sim, 1));
    });
    put(
        &format!(
            "PO frame, paper scene, {} spokes x {} bins",
            scene.radar().spokes(),
            scene.radar().num_range_bins()
        ),
        t * 1e3,
        "ms",
    );
    let mut next = 0;
    let t = median_s(a.repeats, || {
        next += 1;
        std::hint::black_box(
            sim.run(&Request::new(1).frame(next))
                .expect("the scene's own scan runs"),
        );
    });
    put(
        "PO frame, next revolution of the same scene (trace cached)",
        t * 1e3,
        "ms",
    );

    let mut big = spec.clone();
    big.radar.max_range_m = Some(3100.0);
    let big_scene = Scene::from_spec_in(&big, base)?;
    let bins = big_scene.radar().num_range_bins();
    let sim_big = Simulation::new(big_scene);
    let t = median_s(a.repeats, || {
        std::hint::black_box(traced_frame(&sim_big, 1));
    });
    put(
        &format!("PO frame, paper scene, 360 spokes x {bins} bins (1 us)"),
        t * 1e3,
        "ms",
    );

    // 2b. Sea clutter (K, NRL, sea state 4) and a rain cell on a 360 x 2048 frame: the added
    //     cost over the same frame without them (target: under 50 ms).
    let mut sea = spec.clone();
    sea.radar.max_range_m = Some(2048.0 * 1.499);
    sea.environment.clutter = Some(false);
    sea.environment.rain = Some(false);
    let plain = Simulation::new(Scene::from_spec_in(&sea, base)?);
    sea.environment.clutter = Some(true);
    sea.environment.rain = Some(true);
    sea.environment.sea_state = Some(4.0);
    sea.environment.rain_cells = vec![xbandsim::scene::RainCellSpec {
        centre_m: Some([1500.0, 500.0]),
        radius_m: Some(600.0),
        rate_mm_per_h: Some(16.0),
    }];
    let cluttered = Simulation::new(Scene::from_spec_in(&sea, base)?);
    let groups_plain = plain.echo_groups(&plain.trace());
    let groups_sea = cluttered.echo_groups(&cluttered.trace());
    let t_plain = median_s(a.repeats, || {
        let clutter = plain.clutter_map(xbandsim::rng::FrameKey::new(1, 0));
        std::hint::black_box(plain.synthesize(&groups_plain, clutter.as_ref(), &Request::new(1)))
            .expect("the frozen scan of this radar");
    });
    // Each map made whole, as a new scene's first revolution makes it ...
    let t_sea = median_s(a.repeats, || {
        let clutter = xbandsim::signal::clutter_map::ClutterMap::new(
            cluttered.scene().radar(),
            cluttered.scene().environment(),
            xbandsim::rng::FrameKey::new(1, 0),
            cluttered.compressor().record_len(),
        );
        std::hint::black_box(cluttered.synthesize(&groups_sea, clutter.as_ref(), &Request::new(1)))
            .expect("the frozen scan of this radar");
    });
    // ... and the next revolutions of a radar that stands still: the clutter surface kept,
    // the texture drawn for each.
    let mut next_map = 0;
    let t_sea_kept = median_s(a.repeats, || {
        next_map += 1;
        let clutter = cluttered.clutter_map(xbandsim::rng::FrameKey::new(1, next_map));
        std::hint::black_box(cluttered.synthesize(&groups_sea, clutter.as_ref(), &Request::new(1)))
            .expect("the frozen scan of this radar");
    });
    put(
        &format!(
            "echoes + filter, 360 x {} bins, no clutter",
            plain.compressor().num_bins()
        ),
        t_plain * 1e3,
        "ms",
    );
    put(
        "  + sea clutter (K, SS 4) and a rain cell: added time",
        (t_sea - t_plain) * 1e3,
        "ms",
    );
    put(
        "  the same, next revolutions (radar still, clutter surface kept)",
        (t_sea_kept - t_plain) * 1e3,
        "ms",
    );

    // 2b'. The receiver's video chain at its defaults (2048 x 512, 4 bits) with auto STC,
    //      FTC and interference rejection on that sea-clutter frame (trace cached): its cost
    //      over the frame, in the same run (target: under 10 %). Each frame has a seed of its
    //      own, so that it makes its whole clutter map as a dataset sample does.
    let mut with_video = sea.clone();
    with_video.receiver = Some(toml::from_str(
        "stc = \"auto\"\nftc_time_constant_us = 0.5\ninterference_rejection = \"medium\"\n",
    )?);
    let video_sim = Simulation::new(Scene::from_spec_in(&with_video, base)?);
    let (mut next_plain, mut next_video) = (1000, 1000);
    let t_frame = median_s(a.repeats, || {
        next_plain += 1;
        std::hint::black_box(
            cluttered
                .run(&Request::new(next_plain))
                .expect("the scene's own scan runs"),
        );
    });
    let t_video = median_s(a.repeats, || {
        next_video += 1;
        std::hint::black_box(
            video_sim
                .run(&Request::new(next_video))
                .expect("the scene's own scan runs"),
        );
    });
    put(
        "sea-clutter frame (K, SS 4, rain cell), trace cached, its map made whole",
        t_frame * 1e3,
        "ms",
    );
    put(
        "  + receiver video (2048 x 512, auto STC, FTC, IR)",
        t_video * 1e3,
        "ms",
    );
    put(
        "  receiver video's cost over that frame (same run)",
        100.0 * (t_video / t_frame - 1.0),
        "%",
    );

    // 2c. A pulse-by-pulse revolution (target: faster than the radar turns): 24 rpm at a
    //     2 kHz PRF (5000 pulses), 2048+ range samples, K sea clutter with Doppler, a target
    //     moving, the Doppler cube; against the 2.5 s the antenna takes for it.
    let mut pulse = spec.clone();
    pulse.radar.max_range_m = Some(3100.0);
    pulse.radar.prf_hz = Some(2000.0);
    pulse.radar.rotation_rpm = Some(24.0);
    pulse.environment.clutter = Some(true);
    pulse.environment.sea_state = Some(3.0);
    pulse.processing.mode = Some(xbandsim::model::ProcessingMode::Pulse);
    if let Some(o) = pulse.objects.first_mut() {
        o.speed_kn = Some(15.0);
        o.course_deg = Some(200.0);
    }
    let pulse_scene = Scene::from_spec_in(&pulse, base)?;
    let (pulses, pulse_bins, period_s) = (
        pulse_scene.radar().scan().pulses_per_revolution(),
        pulse_scene.radar().num_range_bins(),
        pulse_scene.radar().scan().period_s(),
    );
    let pulse_sim = Simulation::new(pulse_scene);
    let mut next = 0;
    let t = median_s(a.repeats, || {
        next += 1;
        std::hint::black_box(pulse_sim.run(&Request::new(1).frame(next).outputs(
            xbandsim::engine::Outputs {
                doppler_cube: true,
                ..Default::default()
            },
        )))
        .expect("the bench's pulse-mode scene gives a cube");
    });
    put(
        &format!(
            "pulse-mode revolution: {pulses} pulses x {pulse_bins} bins, K clutter + Doppler, cube"
        ),
        t * 1e3,
        "ms",
    );
    put(
        "  that revolution's time / the antenna's rotation period",
        t / period_s,
        "x real time",
    );

    // 2d. The same revolution with everything pulse mode offers on top: combined pulses (a short
    //     pulse inside the long one's eclipse), a 4:5 staggered PRF, the own ship under way
    //     and rolling, and every cell's pulse-pair velocity.
    let mut full = pulse.clone();
    full.radar.pulse_mode = Some(xbandsim::scene::PulseModeName::Combined);
    full.radar.prf_stagger = Some(vec![4.0, 5.0]);
    full.own_ship = Some(xbandsim::scene::OwnShipSpec {
        speed_kn: Some(8.0),
        course_deg: Some(30.0),
        roll_amplitude_deg: Some(8.0),
        pitch_amplitude_deg: Some(3.0),
        motion_period_s: Some(7.0),
        ..Default::default()
    });
    let full_sim = Simulation::new(Scene::from_spec_in(&full, base)?);
    let mut next = 0;
    let t_full = median_s(a.repeats, || {
        next += 1;
        std::hint::black_box(full_sim.run(&Request::new(1).frame(next).outputs(
            xbandsim::engine::Outputs {
                doppler_cube: true,
                radial_velocity: true,
                ..Default::default()
            },
        )))
        .expect("the bench's pulse-mode scene gives a cube");
    });
    put(
        "  + combined pulses, 4:5 PRF stagger, own ship rolling, pulse-pair velocities",
        t_full * 1e3,
        "ms",
    );
    put(
        "  that revolution's time / the antenna's rotation period",
        t_full / period_s,
        "x real time",
    );

    // 3. Paper-equivalent frames: 3.6 M-ray grid, paper amplitude law, 360 beams, matched
    //    filter and a 512 x 512 PPI, for 1, 20 and 50 us (compare with the NumPy version).
    for pw in [1.0, 20.0, 50.0] {
        let mut p = spec.clone();
        p.scattering.model = Some(xbandsim::model::ScatteringModel::Paper);
        p.radar.pulse_width_us = Some(pw);
        p.display.image_size_px = Some(512);
        let ps = Scene::from_spec_in(&p, base)?;
        let conv = PpiSettings::from_spec(&p.display)?.scan_converter(ps.radar());
        let psim = Simulation::new(ps);
        let mut ppi = vec![0f32; 512 * 512];
        let t = median_s(a.repeats, || {
            let (polar_db, _) = traced_frame(&psim, 1);
            conv.convert(&polar_db, f32::NAN, &mut ppi);
            std::hint::black_box(&ppi);
        });
        put(
            &format!("paper-equivalent frame (3.6 M-ray grid, bounding-sphere prefilter, 512^2 PPI), {pw} us"),
            t * 1e3,
            "ms",
        );
    }
    // 4. RCS of the ~10 k-triangle vessel mesh over 360 aspects (target: under 10 s).
    let vessel = xbandsim::geometry::mesh::vessel(30.0, 128);
    let triangles = vessel.triangles.len();
    let object = xbandsim::model::SceneObject::new(
        "vessel",
        "ship",
        xbandsim::geometry::ShapeGeometry::Mesh {
            mesh: std::sync::Arc::new(vessel),
        },
        DVec3::ZERO,
        glam::DMat3::IDENTITY,
    )
    .expect("a valid object");
    let target = xbandsim::scattering::rcs::RcsTarget::new(&object);
    let settings = xbandsim::scattering::rcs::RcsSettings {
        freq_hz: 9.41e9,
        polarisation: xbandsim::model::Polarisation::Hh,
        ray_spacing_wavelengths: 0.25,
        max_rays: 262_144,
        max_bounces: 3,
        edge_diffraction: true,
    };
    let aspects: Vec<(f64, f64)> = (0..360).map(|d| ((d as f64).to_radians(), 0.0)).collect();
    let t = median_s(a.repeats.min(3), || {
        std::hint::black_box(target.sweep_m2(&aspects, &settings));
    });
    put(
        &format!("RCS of a {triangles}-triangle mesh, 360 aspects (xbandsim rcs defaults)"),
        t,
        "s",
    );
    // 5. Labelled dataset frames: datasets/detection.toml (512 x 512 gray PPI, 0-10
    //    library targets, sea clutter, rain in a third), written with labels and manifests;
    //    then the same with 1-10 targets (no empty frames).
    dataset_rows(a.repeats.min(3), &mut put)?;
    // 6. A coastal scene of 10^5 and 10^6 triangles: the harbour with 10 or 92 moored
    //    10.8 k-triangle vessels; BVH build, a still revolution and one with a ship under way.
    coastal_rows(a.repeats.min(3), &mut put)?;
    // 7. Plots and tracks: extraction and tracking of a 2048-spoke revolution with 50 moving
    //    targets in sea clutter, against the revolution's render (target: under 10 %).
    tracking_rows(&mut put)?;
    if let Some(mb) = peak_rss_mb() {
        put("peak resident memory (whole bench process)", mb, "MB");
    }

    progress.finish_and_clear();
    if a.json {
        crate::say!("{}", serde_json::to_string_pretty(&rows)?);
    }
    Ok(())
}

/// The detection spec the dataset rows measure.
const DETECTION_SPEC: &str = include_str!("../../../datasets/detection.toml");

/// The ship-heavy spec: ten detailed vessels in every sample.
const SHIPS_SPEC: &str = include_str!("../../../datasets/ships.toml");

/// Samples per dataset measurement.
const DATASET_BENCH_SAMPLES: u64 = 24;

/// Dataset rows: labelled frames per second of a whole run (every core), and where one
/// sample's time goes, stage by stage on one thread (mean over the same samples).
fn dataset_rows(repeats: usize, put: &mut dyn FnMut(&str, f64, &str)) -> Result<()> {
    use xbandsim_dataset::{generate, DatasetSpec, Format, Request, Shard};
    let spec = DatasetSpec::parse(DETECTION_SPEC, Path::new("."))?;
    // The 1-10-target row draws at least one target; the shipped spec 0-10 (empty frames are
    // training data too, and cheaper). The same spec with the count's lower end at 1.
    let mut one_to_ten: toml::Table = toml::from_str(DETECTION_SPEC)?;
    let targets = one_to_ten
        .get_mut("targets")
        .and_then(toml::Value::as_table_mut)
        .ok_or_else(|| anyhow::anyhow!("datasets/detection.toml has no [targets] table"))?;
    let mut count = toml::Table::new();
    count.insert("uniform_int".into(), toml::Value::try_from([1i64, 10])?);
    targets.insert("count".into(), toml::Value::Table(count));
    let one_to_ten = DatasetSpec::parse(&toml::to_string(&one_to_ten)?, Path::new("."))?;
    // The shipped spec with the receiver's video chain at its defaults in every sample.
    let with_video = DatasetSpec::parse(
        &DETECTION_SPEC.replace("[scene.radar]", "[scene.receiver]\n\n[scene.radar]"),
        Path::new("."),
    )?;
    // The shipped spec with a procedural coast (any layout) in every sample.
    let with_coast = DatasetSpec::parse(
        &format!("{DETECTION_SPEC}\n[coast]\nprobability = 1.0\n"),
        Path::new("."),
    )?;
    // The same with hills and a harbour town as datasets/coastal.toml draws them.
    let with_town = DatasetSpec::parse(
        &format!(
            "{DETECTION_SPEC}\n[coast]\nprobability = 1.0\nhills = {{ uniform_int = [0, 3] }}\nbuildings = {{ uniform_int = [0, 6] }}\n"
        ),
        Path::new("."),
    )?;
    let ships_spec = DatasetSpec::parse(SHIPS_SPEC, Path::new("."))?;
    let n = DATASET_BENCH_SAMPLES;
    // Each run writes a fresh folder, and all are removed at the end: on ext4, files made
    // just after many were deleted cost the inode allocator a search past them
    // (docs/performance.md, "Measuring"), which is not the generator's time.
    let mut dirs = Vec::new();
    let mut rate = |spec: &DatasetSpec| {
        let t = median_s(repeats, || {
            let dir = tempfile_dir();
            let request = Request {
                count: n,
                seed: 0,
                shard: Shard::ALL,
                jobs: 0,
                format: Format::Dir,
                assemble: true,
            };
            let _ = generate(spec, &dir, &request, &|| {});
            dirs.push(dir);
        });
        n as f64 / t
    };
    let (all, at_least_one, video) = (rate(&spec), rate(&one_to_ten), rate(&with_video));
    let coast = rate(&with_coast);
    let town = rate(&with_town);
    let ships = rate(&ships_spec);
    for dir in dirs {
        let _ = std::fs::remove_dir_all(&dir);
    }
    put(
        &format!("labelled 512^2 frames/s, datasets/detection.toml ({n} samples, all cores)"),
        all,
        "frames/s",
    );
    put(
        &format!(
            "labelled 512^2 frames/s, the same with 1-10 targets (no empty frames, {n} samples)"
        ),
        at_least_one,
        "frames/s",
    );
    put(
        &format!("labelled 512^2 frames/s, detection.toml with [scene.receiver] ({n} samples)"),
        video,
        "frames/s",
    );
    put(
        &format!(
            "labelled 512^2 frames/s, datasets/ships.toml (10 detailed vessels each, {n} samples)"
        ),
        ships,
        "frames/s",
    );
    put(
        "  that rate / detection.toml's (same run)",
        ships / all,
        "x",
    );
    put(
        "receiver video's cost over the dataset rate (same run)",
        100.0 * (all / video - 1.0),
        "%",
    );
    put(
        &format!(
            "labelled 512^2 frames/s, detection.toml with [coast] in every sample ({n} samples)"
        ),
        coast,
        "frames/s",
    );
    put(
        "  that rate / the open-sea rate (same run)",
        coast / all,
        "x",
    );
    put(
        &format!(
            "labelled 512^2 frames/s, the same with hills 0-3 and a town of 0-6 buildings ({n} samples)"
        ),
        town,
        "frames/s",
    );
    put(
        "  that rate / the open-sea rate (same run)",
        town / all,
        "x",
    );
    // One core, stage by stage (a one-thread pool: the stages' own parallel loops too).
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let stages = one.install(|| dataset_stages(&spec, n))?;
    let town_stages = one.install(|| dataset_stages(&with_town, n))?;
    let names = [
        "draw the sample, build the scene and its BVH",
        "PO trace of the targets, their echo groups",
        "frame: clutter map, echoes, noise, matched filter",
        "target-only render of the boxes' spokes (masks)",
        "scan conversion, PNG, truth.json",
        "masks",
    ];
    for (name, ms) in names.iter().zip(stages) {
        put(
            &format!("dataset sample, {name} (one core, mean)"),
            ms,
            "ms",
        );
    }
    for (name, ms) in names.iter().zip(town_stages) {
        put(
            &format!("  with coast, hills and town: {name} (one core, mean)"),
            ms,
            "ms",
        );
    }
    Ok(())
}

/// Mean milliseconds of each stage of a sample over samples 0..n.
fn dataset_stages(spec: &xbandsim_dataset::DatasetSpec, n: u64) -> Result<[f64; 6]> {
    use std::time::Instant;
    let mut stages = [0f64; 6];
    for i in 0..n {
        let t0 = Instant::now();
        let sample = spec.sample(0, i)?;
        let loaded = LoadedSpec::from_toml(&sample.scene_toml, "scene.toml", Path::new("."))?;
        let display = loaded.ppi_settings()?;
        let sim = Simulation::new(loaded.build()?);
        let t1 = Instant::now();
        let _ = sim.traced(0.0);
        let t2 = Instant::now();
        let frame = sim.run(&Request::new(sample.render_seed))?;
        let t3 = Instant::now();
        // As the dataset does: only the spokes of the objects' polar boxes.
        let quiet = sim
            .targets_only()
            .only_spokes(&xbandsim_dataset::labels::mask_spokes(
                &frame.truth,
                frame.spokes,
            ))
            .run(&Request::new(sample.render_seed))?;
        let t4 = Instant::now();
        let encoded = xbandsim::products::frame_files::encode_frame_files(
            sim.scene().radar(),
            &display,
            &frame,
            Path::new("."),
            "bench",
            sample.render_seed,
            spec.image.images(),
        )?;
        let t5 = Instant::now();
        let masks = xbandsim_dataset::labels::object_masks(
            &encoded.objects,
            &quiet.polar_db,
            frame.spokes,
            frame.range_bins,
            &encoded.converter,
            0.0,
            None,
        );
        std::hint::black_box(&masks);
        let t6 = Instant::now();
        for (k, (a, b)) in [(t0, t1), (t1, t2), (t2, t3), (t3, t4), (t4, t5), (t5, t6)]
            .into_iter()
            .enumerate()
        {
            stages[k] += (b - a).as_secs_f64() * 1e3 / n as f64;
        }
    }
    Ok(stages)
}

/// The harbour scene the coastal rows extend.
const HARBOUR_SCENE: &str = include_str!("../../../scenes/harbour-calm.toml");

/// The harbour scene at 3 km (720 spokes x 2049 bins, sea clutter, land and structures) with
/// `moored` copies of the 10.8 k-triangle vessel mesh (`mesh_file`) moored in rows to the
/// west, and its ship under way or not.
/// What moves in a coastal scene of the bench.
#[derive(Clone, Copy, PartialEq)]
enum CoastalMotion {
    /// Nothing.
    Still,
    /// The harbour's ship, at 8 kn.
    Ship,
    /// The ship and the radar's own ship, at 6 kn.
    ShipAndOwnShip,
}

fn coastal_scene(mesh_file: &Path, moored: usize, motion: CoastalMotion) -> Result<Scene> {
    let mesh = mesh_file.display().to_string().replace('\\', "/");
    let mut text = HARBOUR_SCENE
        .replace("max_range_m = 1500.0", "max_range_m = 3070.0")
        .replace("\"meshes/vessel.obj\"", &format!("{mesh:?}"));
    if motion != CoastalMotion::Still {
        text = text.replace(
            "position_m = [350.0, 700.0, 0.0]\nyaw_deg = 30.0",
            "position_m = [350.0, 700.0, 0.0]\nspeed_kn = 8.0\ncourse_deg = 30.0",
        );
    }
    if motion == CoastalMotion::ShipAndOwnShip {
        text.push_str("\n[own_ship]\nspeed_kn = 6.0\ncourse_deg = 10.0\n");
    }
    for i in 0..moored {
        let (x, y) = (
            -2640.0 + (i / 40) as f64 * 100.0,
            -500.0 + (i % 40) as f64 * 32.0,
        );
        text.push_str(&format!(
            "\n[[object]]\nname = \"moored-{i}\"\nclass = \"ship\"\nshape = \"mesh\"\nmesh_file = {mesh:?}\nposition_m = [{x}, {y}, 0.0]\nyaw_deg = 90.0\n"
        ));
    }
    Ok(LoadedSpec::from_toml(&text, "coastal (built in)", Path::new("."))?.build()?)
}

/// Coastal rows: BVH build of 10^5 and 10^6 triangles (one level, all cores; the moored
/// vessels share one mesh, built once, and the same without that sharing), a revolution
/// of the still scene (trace cached) and of the scene with a ship under way (every object
/// retraced, its BVH one moving level over the static one), and the peak memory.
fn coastal_rows(repeats: usize, put: &mut dyn FnMut(&str, f64, &str)) -> Result<()> {
    let dir = tempfile_dir();
    std::fs::create_dir_all(&dir)?;
    let mesh_file = dir.join("vessel.obj");
    let vessel = xbandsim::geometry::mesh::vessel(30.0, 128);
    std::fs::write(&mesh_file, vessel.to_obj("bench vessel"))?;
    let triangles_of = |scene: &Scene| -> usize {
        scene
            .objects()
            .iter()
            .map(|o| match o.shape() {
                xbandsim::geometry::ShapeGeometry::Mesh { mesh } => mesh.triangles.len(),
                _ => 0,
            })
            .sum()
    };
    let harbour = Simulation::new(coastal_scene(&mesh_file, 0, CoastalMotion::Still)?);
    let mut frame = 0;
    let t_harbour = median_s(repeats, || {
        frame += 1;
        std::hint::black_box(harbour.run(&Request::new(1).frame(frame)))
            .expect("the harbour renders");
    });
    put(
        "coastal: harbour revolution, 720 x 2049, clutter, land, structures (cached)",
        t_harbour * 1e3,
        "ms",
    );
    // Its clutter map made whole (a new scene, or a radar that moves) and drawn on the
    // surface kept from the revolution before (a radar that stands still).
    let t_map_whole = median_s(repeats, || {
        std::hint::black_box(xbandsim::signal::clutter_map::ClutterMap::new(
            harbour.scene().radar(),
            harbour.scene().environment(),
            xbandsim::rng::FrameKey::new(1, 0),
            harbour.compressor().record_len(),
        ));
    });
    let t_map_kept = median_s(repeats, || {
        frame += 1;
        std::hint::black_box(harbour.clutter_map(xbandsim::rng::FrameKey::new(1, frame)));
    });
    put(
        "coastal: the harbour's clutter map, made whole",
        t_map_whole * 1e3,
        "ms",
    );
    put(
        "  on the surface kept from the revolution before (radar still)",
        t_map_kept * 1e3,
        "ms",
    );
    for moored in [10usize, 92] {
        let scene = coastal_scene(&mesh_file, moored, CoastalMotion::Still)?;
        let triangles = triangles_of(&scene);
        let t_build = median_s(repeats, || {
            std::hint::black_box(build_scene_bvh(scene.objects()));
        });
        put(
            &format!("coastal: BVH build, {triangles} triangles (harbour + {moored} moored)"),
            t_build * 1e3,
            "ms",
        );
        // The same triangles as if every vessel were a mesh of its own.
        let t_unshared = median_s(repeats, || {
            std::hint::black_box(Bvh::build(xbandsim::scattering::scene_primitives_of(
                scene.objects(),
                |_, _| true,
            )));
        });
        put(
            "  the same, every object's triangles built as its own (no shared mesh)",
            t_unshared * 1e3,
            "ms",
        );
        let sim = Simulation::new(scene);
        let mut frame = 0;
        let t_still = median_s(repeats, || {
            frame += 1;
            std::hint::black_box(sim.run(&Request::new(1).frame(frame)))
                .expect("the coastal scene renders");
        });
        put(
            &format!("coastal: revolution, {triangles} triangles, still (trace cached)"),
            t_still * 1e3,
            "ms",
        );
        put(
            "  that revolution / the harbour's alone (same run)",
            t_still / t_harbour,
            "x",
        );
    }
    let moving = coastal_scene(&mesh_file, 10, CoastalMotion::Ship)?;
    let triangles = triangles_of(&moving);
    let dynamic =
        xbandsim::scattering::scene_primitives_of(moving.objects(), |_, o| o.motion().is_some());
    let fixed = std::sync::Arc::new(Bvh::build(xbandsim::scattering::scene_primitives_of(
        moving.objects(),
        |_, o| o.motion().is_none(),
    )));
    let t_dynamic = median_s(repeats, || {
        std::hint::black_box(Bvh::over_static(
            std::sync::Arc::clone(&fixed),
            dynamic.clone(),
        ));
    });
    put(
        &format!(
            "coastal: a revolution's moving BVH level ({} primitives) over the static one",
            dynamic.len()
        ),
        t_dynamic * 1e3,
        "ms",
    );
    let sim = Simulation::new(moving);
    let mut frame = 0;
    let t_moving = median_s(repeats, || {
        frame += 1;
        std::hint::black_box(sim.run(&Request::new(1).frame(frame)))
            .expect("the coastal scene renders");
    });
    put(
        &format!("coastal: revolution, {triangles} triangles, a ship under way (retraced)"),
        t_moving * 1e3,
        "ms",
    );
    // The radar itself under way: every object is traced anew and the clutter surface made
    // each revolution.
    let sailing = Simulation::new(coastal_scene(
        &mesh_file,
        10,
        CoastalMotion::ShipAndOwnShip,
    )?);
    let mut frame = 0;
    let t_sailing = median_s(repeats, || {
        frame += 1;
        std::hint::black_box(sailing.run(&Request::new(1).frame(frame)))
            .expect("the coastal scene renders");
    });
    put(
        &format!(
            "coastal: revolution, {triangles} triangles, the ship and the own ship (6 kn) under way"
        ),
        t_sailing * 1e3,
        "ms",
    );
    if let Some(mb) = peak_rss_mb() {
        put(
            "coastal: peak resident memory after the coastal rows",
            mb,
            "MB",
        );
    }
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}

/// A fresh folder under the system's temporary directory.
fn tempfile_dir() -> std::path::PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(0);
    std::env::temp_dir().join(format!(
        "xbandsim-bench-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ))
}

/// The tracking rows' scene: a 2048-spoke revolution out to 3 km at sea state 3, with 50
/// boats and ships on a ring of courses between 500 m and 2.8 km.
fn tracking_scene() -> Result<Scene> {
    let mut text = String::from(
        "[radar]\npreset = \"drs4d-nxt\"\nspokes = 2048\nmax_range_m = 3000.0\n\
         rotation_rpm = 24.0\n\n[environment]\nsea_state = 3\nwind_direction_deg = 45.0\n",
    );
    for i in 0..TRACKING_TARGETS {
        let bearing = (i as f64 * 137.5_f64).to_radians();
        let range = 500.0 + 2300.0 * ((i * 7) % TRACKING_TARGETS) as f64 / TRACKING_TARGETS as f64;
        let (x, y) = (range * bearing.sin(), range * bearing.cos());
        let course = (i * 53 % 360) as f64;
        let speed = 4.0 + (i % 5) as f64 * 3.0;
        text.push_str(&format!(
            "\n[[object]]\nname = \"target-{i}\"\nclass = \"boat\"\nshape = \"box\"\n\
             size_m = [4.0, 12.0, 3.0]\nposition_m = [{x:.1}, {y:.1}, 1.5]\n\
             speed_kn = {speed}\ncourse_deg = {course}\n"
        ));
    }
    Ok(LoadedSpec::from_toml(&text, "tracking (built in)", Path::new("."))?.build()?)
}

/// Targets of the tracking rows' scene.
const TRACKING_TARGETS: usize = 50;

/// Revolutions the tracking rows render and track (the tracker holds its tracks by the
/// fourth).
const TRACKING_SCANS: u64 = 8;

/// Tracking rows: a revolution's render, its plot extraction (the `xbandsim track`
/// extractor: CA-CFAR at 10⁻⁸, plots of 3 cells or more, sidelobe editing) and the tracker's
/// step on its plots, each the median over the scans after the third, and their share.
fn tracking_rows(put: &mut dyn FnMut(&str, f64, &str)) -> Result<()> {
    use xbandsim::processing::cfar::{Cfar, CfarKind};
    use xbandsim::processing::plots::{PlotExtractor, PlotScratch, SidelobeEditor};
    use xbandsim_track::{Scan, Tracker, TrackerSettings};
    let scene = tracking_scene()?;
    let editor = SidelobeEditor::new(&scene.radar().antenna().azimuth(), 6.0)?;
    let extractor = PlotExtractor::new(Cfar::new(CfarKind::CellAveraging, 4, 16, 1e-8)?, 3)?
        .with_sidelobe_editing(editor);
    let sim = Simulation::new(scene);
    let radar = sim.scene().radar();
    let (period_s, antenna) = (radar.scan().period_s(), radar.position_m());
    let mut tracker = Tracker::new(TrackerSettings::default())?;
    let mut scratch = PlotScratch::default();
    let (mut render, mut extract, mut track) = (Vec::new(), Vec::new(), Vec::new());
    let (mut plots_seen, mut confirmed) = (0usize, 0usize);
    for k in 0..TRACKING_SCANS {
        let t0 = Instant::now();
        let frame = sim.run(&Request::new(0).frame(k))?;
        let t1 = Instant::now();
        let plots = extractor.extract(&crate::detect::grid_of(&frame, false), &mut scratch);
        let t2 = Instant::now();
        let report = tracker.step(&Scan {
            start_time_s: frame.start_time_s,
            period_s,
            antenna_position_m: [antenna.x, antenna.y, antenna.z],
            antenna_velocity_mps: [0.0, 0.0],
            plots: &plots,
        });
        let t3 = Instant::now();
        if k >= 3 {
            render.push((t1 - t0).as_secs_f64());
            extract.push((t2 - t1).as_secs_f64());
            track.push((t3 - t2).as_secs_f64());
            plots_seen += plots.len();
            confirmed = report.confirmed().count();
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (render_s, extract_s, track_s) = (
        median(&mut render),
        median(&mut extract),
        median(&mut track),
    );
    let scans = (TRACKING_SCANS - 3) as f64;
    put(
        &format!("revolution, 2048 spokes, {TRACKING_TARGETS} moving boats, sea state 3"),
        render_s * 1e3,
        "ms",
    );
    put(
        &format!(
            "plot extraction of it ({:.0} plots a scan)",
            plots_seen as f64 / scans
        ),
        extract_s * 1e3,
        "ms",
    );
    put(
        &format!("tracking its plots ({confirmed} confirmed tracks)"),
        track_s * 1e3,
        "ms",
    );
    put(
        "plot extraction + tracking, share of the revolution's render",
        100.0 * (extract_s + track_s) / render_s,
        "%",
    );
    Ok(())
}
