//! `xbandsim render`.

use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;
use xbandsim::engine::Request;
use xbandsim::engine::{Outputs, Simulation};
use xbandsim::model::ProcessingMode;
use xbandsim::products::frame_files::{encode_frame_files, Images};
use xbandsim::products::labels::ObjectTruth;
use xbandsim::products::output::write_set;
use xbandsim::products::spokes::{self, SpokePacking, SweepTiming};
use xbandsim::receiver::video_chain::EchoHistory;
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
    #[arg(long, default_value_t = 0, value_parser = crate::whole_number)]
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
    #[arg(long, value_name = "N", value_parser = crate::whole_number)]
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
    /// Also write each frame's receiver video as a stream of spoke records, spokes.bin
    /// (needs a [receiver] table; docs/formats.md): "bytes" (a byte a sample) or "packed"
    /// (video_bits a sample, low bits first, as networked radars send them).
    #[arg(long, value_name = "FORMAT")]
    pub spoke_format: Option<String>,
}

/// Reads a scene file and applies `--set FIELD=VALUE` overrides and the options that stand
/// for them (the library's one loader); errors in their values are said to come from the
/// command line.
pub fn load_spec(path: &Path, sets: &[String]) -> Result<LoadedSpec> {
    Ok(LoadedSpec::read(path)?.with_overrides_named("the command line", sets)?)
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
        sets.push(format!("radar.pulse_width_us={}", toml_float(v)));
    }
    if let Some(v) = a.spokes {
        sets.push(count("--spokes", "radar.spokes", v)?);
    }
    if let Some(v) = a.max_range_m {
        sets.push(format!("radar.max_range_m={}", toml_float(v)));
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

/// `x` as a TOML float: `nan` and `inf` as TOML writes them, so that the scene's own check
/// names the field (`must be finite`) rather than the override failing to parse.
fn toml_float(x: f64) -> String {
    toml::Value::Float(x).to_string()
}

/// A TOML basic string holding `text`.
fn toml_string(text: &str) -> String {
    toml::Value::String(text.to_string()).to_string()
}

/// Says on stderr, in one line, which objects were traced with tubes wider than the
/// requested spacing to keep within the ray budget. That is the normal case for objects
/// larger than a few metres at the default budget, not a fault: every tube is sized with
/// the wider side, so the RCS stays calibrated (docs/physics.md, "Ray budget";
/// truth.json's `po_tubes` gives each object's sides).
pub fn note_ray_caps(truth: &[ObjectTruth]) {
    if let Some(note) = ray_cap_note(truth) {
        eprintln!("{note}");
    }
}

/// The line [`note_ray_caps`] prints, if any object's tubes were widened.
pub fn ray_cap_note(truth: &[ObjectTruth]) -> Option<String> {
    let capped: Vec<String> = truth
        .iter()
        .filter_map(|o| {
            let b = o.po_tubes.filter(|b| b.capped)?;
            Some(format!("\"{}\" {:.3} m", o.name, b.spacing_m))
        })
        .collect();
    if capped.is_empty() {
        return None;
    }
    Some(format!(
        "note: ray tubes widened to keep within scattering.max_rays_per_object: {} (normal for objects over a few metres, not a fault: the RCS stays calibrated within the 0.2-0.5 dB that docs/validation.md tests; docs/physics.md \"Ray budget\")",
        capped.join(", ")
    ))
}

/// Adds `spokes.bin`, the frame's video as spoke records, when `packing` asks for it.
fn add_spoke_stream(
    files: &mut Vec<(&'static str, Vec<u8>)>,
    frame: &xbandsim::Frame,
    radar: &xbandsim::model::Radar,
    packing: Option<SpokePacking>,
) {
    if let (Some(packing), Some(video)) = (packing, &frame.video) {
        let timing = SweepTiming {
            start_time_s: frame.start_time_s,
            period_s: radar.scan().period_s(),
            heading_deg: frame.own_ship.map(|s| s.heading_rad.to_degrees()),
        };
        files.push(("spokes.bin", spokes::encode(video, timing, packing)));
    }
}

/// Runs `xbandsim render`.
pub fn run(a: &RenderArgs) -> Result<()> {
    let t0 = Instant::now();
    if a.frames == Some(0) {
        bail!("invalid --frames 0: must be 1 or more");
    }
    check_out_folder(&a.out)?;
    let spec = load_spec(&a.scene, &overrides(a)?)?;
    let scene = spec.build()?;
    let display = spec.ppi_settings()?;
    let spoke_packing = match a.spoke_format.as_deref() {
        None => None,
        Some(name) => {
            let Some(p) = SpokePacking::from_name(name) else {
                bail!("invalid --spoke-format {name:?}: must be \"bytes\" or \"packed\"");
            };
            if scene.receiver().is_none() {
                bail!("--spoke-format writes the receiver's video: the scene needs a [receiver] table (docs/formats.md, \"[receiver]\"), e.g. --set receiver.gain_db=0");
            }
            Some(p)
        }
    };
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
        let frame = sim.run(
            &Request::new(a.seed)
                .outputs(outputs)
                .progress(&|| progress.inc(1)),
        )?;
        progress.finish_and_clear();
        note_ray_caps(&frame.truth);
        let mut encoded = encode_frame_files(
            radar,
            &display,
            &frame,
            &a.out,
            &scene_name,
            a.seed,
            Images::BOTH,
        )?;
        add_spoke_stream(&mut encoded.files, &frame, radar, spoke_packing);
        write_set(&a.out, &encoded.files)
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
    // The receiver's echo averaging runs on from frame to frame.
    let echo_history = std::sync::Mutex::new(EchoHistory::default());
    for k in 0..count {
        let frame = sim.run(
            &Request::new(a.seed)
                .frame(k)
                .outputs(outputs)
                .echo_history(&echo_history),
        )?;
        let dir = a.out.join(frame_dir_name(k));
        let mut encoded = encode_frame_files(
            radar,
            &display,
            &frame,
            &dir,
            &scene_name,
            a.seed,
            Images::BOTH,
        )
        .with_context(|| format!("encoding frame {k}"))?;
        add_spoke_stream(&mut encoded.files, &frame, radar, spoke_packing);
        if k == 0 {
            note_ray_caps(&frame.truth);
            let frame_bytes: usize = encoded.files.iter().map(|(_, b)| b.len()).sum();
            check_disk_space(&a.out, count, frame_bytes as u64)?;
        }
        write_set(&dir, &encoded.files)
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

/// Refuses an `--out` that cannot be a folder (it, or the nearest part of its path that
/// exists, is a file) before anything is rendered; nothing is created here.
fn check_out_folder(out: &Path) -> Result<()> {
    if let Some(existing) = out.ancestors().find(|p| p.exists()) {
        if !existing.is_dir() {
            bail!(
                "invalid --out {}: {} is a file, not a folder",
                out.display(),
                existing.display()
            );
        }
    }
    Ok(())
}

/// Refuses `--frames count` when frames of `frame_bytes` (the first frame's files; the
/// others differ by their images' compression) would not fit in the space left where `out`
/// is, with a tenth to spare: before anything is written, not part-way by a full disk.
fn check_disk_space(out: &Path, count: u64, frame_bytes: u64) -> Result<()> {
    let needed = count as f64 * frame_bytes as f64 * 1.1;
    // The nearest folder that exists: `out` is made when the first frame is written.
    let mut probe = out.to_path_buf();
    while !probe.is_dir() {
        match probe.parent() {
            Some(p) if !p.as_os_str().is_empty() => probe = p.to_path_buf(),
            _ => {
                probe = PathBuf::from(".");
                break;
            }
        }
    }
    let Ok(free) = fs4::available_space(&probe) else {
        return Ok(()); // a file system that cannot tell: write and see
    };
    if needed > free as f64 {
        bail!(
            "invalid --frames {count}: {count} frames of about {} each need about {}, and {} has {} free; lower --frames or write elsewhere (--out)",
            human_bytes(frame_bytes as f64),
            human_bytes(needed),
            probe.display(),
            human_bytes(free as f64)
        );
    }
    Ok(())
}

/// `bytes` in kB, MB or GB (powers of 1000), three significant figures (more above 999 GB).
fn human_bytes(bytes: f64) -> String {
    let (value, unit) = if bytes >= 1e9 {
        (bytes / 1e9, "GB")
    } else if bytes >= 1e6 {
        (bytes / 1e6, "MB")
    } else {
        (bytes / 1e3, "kB")
    };
    // Three significant figures below 1000, whole numbers above.
    let decimals = if value >= 1000.0 {
        0
    } else {
        2 - (value.max(1.0).log10().floor() as usize).min(2)
    };
    format!("{value:.decimals$} {unit}")
}

/// The directory of frame `k` of a multi-frame render: `frame_0000`, `frame_0001`, ...
pub fn frame_dir_name(k: u64) -> String {
    format!("frame_{k:04}")
}
