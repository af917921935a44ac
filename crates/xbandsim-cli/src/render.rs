//! `xbandsim render`.

use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;
use xbandsim::engine::{Outputs, Simulation};
use xbandsim::model::ProcessingMode;
use xbandsim::products::frame_files::write_frame_files;
use xbandsim::products::labels::ObjectTruth;
use xbandsim::scene::LoadedSpec;

/// Arguments of `xbandsim render`.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Random seed: the same seed gives the same output.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Override radar.pulse_width_us.
    #[arg(long, allow_negative_numbers = true)]
    pub pulse_width_us: Option<f64>,
    /// Override radar.spokes.
    #[arg(long, allow_negative_numbers = true)]
    pub spokes: Option<i64>,
    /// Override radar.max_range_m.
    #[arg(long, allow_negative_numbers = true)]
    pub max_range_m: Option<f64>,
    /// Override scattering.model ("po" or "paper").
    #[arg(long)]
    pub model: Option<String>,
    /// Override radar.window ("none", "hamming", "taylor").
    #[arg(long)]
    pub window: Option<String>,
    /// Override display.image_size_px.
    #[arg(long, allow_negative_numbers = true)]
    pub image_size_px: Option<i64>,
    /// Turn receiver noise off.
    #[arg(long)]
    pub no_noise: bool,
    /// Render N consecutive revolutions (everything moving) into OUT/frame_0000/,
    /// OUT/frame_0001/, ... (without it: one revolution, its files straight in OUT).
    #[arg(long, value_name = "N")]
    pub frames: Option<u64>,
    /// Also write each frame's range-Doppler-azimuth cube, doppler_cube.npy (needs
    /// [processing] mode = "pulse").
    #[arg(long)]
    pub datacube: bool,
    /// Also write each frame's raw received I/Q of every pulse before the matched filter,
    /// iq.npy (complex64, pulses x samples) with iq_pulses.npy (time, azimuth, spoke per
    /// pulse): for short runs (a pulse-mode revolution is pulses x samples x 8 bytes).
    #[arg(long)]
    pub iq: bool,
    /// Override any scene field: FIELD=VALUE with FIELD a dotted path and VALUE a TOML value,
    /// e.g. --set radar.pulse_width_us=2 --set object[0].yaw_deg=45 (repeatable).
    #[arg(long, value_name = "FIELD=VALUE")]
    pub set: Vec<String>,
}

/// Reads a scene file and applies `--set FIELD=VALUE` overrides (the library's one loader).
pub fn load_spec(path: &Path, sets: &[String]) -> Result<LoadedSpec> {
    Ok(LoadedSpec::read(path)?.with_overrides(sets)?)
}

/// The overrides of `xbandsim render`: its named flags are shorthands for `--set`, applied
/// first, then every `--set` in order.
pub fn overrides(a: &RenderArgs) -> Result<Vec<String>> {
    let count = |flag: &str, field: &str, v: i64| -> Result<String> {
        if v < 0 {
            bail!("invalid {flag} {v} (overrides {field}): must be a whole number of 0 or more");
        }
        Ok(format!("{field}={v}"))
    };
    let mut sets = Vec::new();
    if let Some(v) = a.pulse_width_us {
        sets.push(format!("radar.pulse_width_us={v:?}"));
    }
    if let Some(v) = a.spokes {
        sets.push(count("--spokes", "radar.spokes", v)?);
    }
    if let Some(v) = a.max_range_m {
        sets.push(format!("radar.max_range_m={v:?}"));
    }
    if let Some(v) = &a.model {
        sets.push(format!("scattering.model={}", toml_string(v)));
    }
    if let Some(v) = &a.window {
        sets.push(format!("radar.window={}", toml_string(v)));
    }
    if let Some(v) = a.image_size_px {
        sets.push(count("--image-size-px", "display.image_size_px", v)?);
    }
    if a.no_noise {
        sets.push("environment.noise=false".into());
    }
    sets.extend(a.set.iter().cloned());
    Ok(sets)
}

/// A TOML basic string holding `text`.
fn toml_string(text: &str) -> String {
    toml::Value::String(text.to_string()).to_string()
}

/// Tells on stderr which objects had their PO tubes widened by the ray budget (truth.json
/// says the same in `po_tubes.capped`).
pub fn warn_ray_caps(truth: &[ObjectTruth]) {
    for o in truth {
        if let Some(b) = o.po_tubes.filter(|b| b.capped) {
            eprintln!(
                "warning: object \"{}\": scattering.max_rays_per_object bound ({} tubes); tube side widened from {:.4} m to {:.4} m. The RCS stays calibrated, but fine detail (off-specular lobes) may change with the budget; raise max_rays_per_object to refine.",
                o.name, b.tubes, b.requested_spacing_m, b.spacing_m
            );
        }
    }
}

/// Runs `xbandsim render`.
pub fn run(a: &RenderArgs) -> Result<()> {
    let t0 = Instant::now();
    if a.frames == Some(0) {
        bail!("invalid --frames 0: must be 1 or more");
    }
    let spec = load_spec(&a.scene, &overrides(a)?)?;
    let scene = spec.build()?;
    let display = spec.ppi_settings()?;
    if a.datacube && scene.processing().mode() != ProcessingMode::Pulse {
        bail!("--datacube needs processing.mode = \"pulse\" (the scene fires one pulse per spoke; add [processing] mode = \"pulse\" or --set processing.mode=pulse)");
    }
    let outputs = Outputs {
        doppler_cube: a.datacube,
        iq: a.iq,
        radial_velocity: display.doppler_colour,
    };
    let sim = Simulation::new(scene);
    sim.check_outputs(outputs)?;
    let radar = sim.scene().radar();
    let scene_name = a.scene.display().to_string();
    let Some(count) = a.frames else {
        // A bar for renders of more than a few million cells (a second or more).
        let big = radar.spokes() * radar.num_range_bins() > 2_000_000;
        let progress = if big {
            crate::progress::bar(radar.spokes() as u64, "render: spokes")
        } else {
            indicatif::ProgressBar::hidden()
        };
        let frame = sim.render_frame_outputs(a.seed, 0, outputs, &|| progress.inc(1))?;
        progress.finish_and_clear();
        warn_ray_caps(&frame.truth);
        write_frame_files(radar, &display, &frame, &a.out, &scene_name, a.seed)
            .with_context(|| format!("writing the outputs into {}", a.out.display()))?;
        let s = &frame.stats;
        crate::say!(
            "rendered {}: {} objects, {} rays, {} contributions, {} spokes x {} bins, trace {:.1} ms, echoes+filter {:.1} ms, total {:.2} s -> {}",
            a.scene.display(),
            sim.scene().objects().len(),
            s.rays_cast,
            s.contributions,
            frame.spokes,
            frame.range_bins,
            s.trace_s * 1e3,
            s.synthesis_s * 1e3,
            t0.elapsed().as_secs_f64(),
            a.out.display()
        );
        return Ok(());
    };
    let progress = crate::progress::bar(count, "render: frames");
    let (mut trace_s, mut synthesis_s) = (0.0, 0.0);
    for k in 0..count {
        let frame = sim.render_frame_outputs(a.seed, k, outputs, &|| {})?;
        if k == 0 {
            warn_ray_caps(&frame.truth);
        }
        let dir = a.out.join(frame_dir_name(k));
        write_frame_files(radar, &display, &frame, &dir, &scene_name, a.seed)
            .with_context(|| format!("writing frame {k} into {}", dir.display()))?;
        trace_s += frame.stats.trace_s;
        synthesis_s += frame.stats.synthesis_s;
        progress.inc(1);
    }
    progress.finish_and_clear();
    crate::say!(
        "rendered {}: {} frames of {:.2} s ({} objects, {} spokes, {}), trace {:.1} ms, echoes+filter {:.1} ms, total {:.2} s -> {}",
        a.scene.display(),
        count,
        radar.scan().period_s(),
        sim.scene().objects().len(),
        radar.spokes(),
        if sim.scene().is_still() { "still scene, traced once" } else { "moving" },
        trace_s * 1e3,
        synthesis_s * 1e3,
        t0.elapsed().as_secs_f64(),
        a.out.display()
    );
    Ok(())
}

/// The directory of frame `k` of a multi-frame render: `frame_0000`, `frame_0001`, ...
pub fn frame_dir_name(k: u64) -> String {
    format!("frame_{k:04}")
}
