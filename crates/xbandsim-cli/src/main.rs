//! `xbandsim`: the command-line front end. It parses arguments, calls the library and turns
//! library errors into messages; the physics lives in the `xbandsim` crate.

/// `println!` that ends the program quietly when stdout is closed (`xbandsim ... | head`).
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut out = std::io::stdout().lock();
        if let Err(e) = writeln!(out, $($arg)*) {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                std::process::exit(0);
            }
        }
    }};
}

mod bench;
mod dataset;
mod detect;
mod figures;
mod nmea;
mod progress;
mod rcs;
mod render;
mod serve;
mod track;
mod validate;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "xbandsim",
    version,
    about = "Physics-based X-band marine radar simulator"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render one antenna revolution of a scene: ppi.png, ppi_gray.png, polar.npy, truth.json.
    Render(render::RenderArgs),
    /// Render revolutions of a scene and extract plots with a CFAR detector along range,
    /// each plot scored against the truth (its object, an artefact, land, or false): plots.json.
    Detect(detect::DetectArgs),
    /// Render revolutions of a scene, extract their plots and track them with the ARPA-class
    /// tracker (IMM of constant-velocity and turn models, M-of-N initiation, global nearest
    /// neighbour), each confirmed track scored against the truth: tracks.json.
    Track(track::TrackArgs),
    /// Write what the scenario's navigation network carries as an NMEA 0183 log: the own
    /// ship's GPS fix and heading once a second (GGA, RMC, VTG, HDT) and the AIS reports of
    /// every object with an `mmsi` (messages 1, 5, 18, 24); the scene needs a [geo] origin.
    Nmea(nmea::NmeaArgs),
    /// Run the scene's scenario as a live radar: a PPI page at /, the mayara radar API (spoke
    /// stream of protobuf RadarMessages, controls), NMEA 0183 and AIS over UDP and TCP, and
    /// a recording of what was sent (docs/live.md).
    Serve(serve::ServeArgs),
    /// Serve a recording made by `serve --record` again, byte for byte.
    Replay(serve::ReplayArgs),
    /// Make a labelled dataset from a dataset spec: every sample's scene drawn from (spec,
    /// seed, index), rendered and written atomically; run again to resume.
    Dataset(dataset::DatasetArgs),
    /// Print the JSON Schema of the scene file format.
    Schema,
    /// Draw the figures as PNGs: fig2_antenna_pattern.png (the paper's Fig. 2, antenna
    /// pattern), fig3_signal_chain.png (Fig. 3, chirp, echoes, received and compressed
    /// signals), fig4_ppi_pulse_widths.png (Fig. 4, PPIs for 1, 20 and 50 us),
    /// fig5_sea_clutter_rain.png (PPIs without and with sea clutter and rain),
    /// object_frames.png (each shape's object frame and aspect convention) and
    /// fig6_receiver_video.png (calibrated and receiver-video PPIs, one panel per artefact).
    Figures {
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Scene of Figs. 2-4; Fig. 5 uses sea-state-4-rain.toml and harbour-calm.toml from
        /// the same folder.
        #[arg(long, default_value = "scenes/paper.toml")]
        scene: PathBuf,
        /// Random seed for the noise.
        #[arg(long, default_value_t = 1, value_parser = crate::whole_number)]
        seed: u64,
    },
    /// Measure ray-casting throughput, frame time and peak memory.
    Bench(bench::BenchArgs),
    /// Monostatic RCS of one object versus aspect, alone in free space.
    Rcs(rcs::RcsArgs),
    /// Write the procedurally generated vessel mesh as an OBJ file.
    MakeVessel {
        /// Output .obj file.
        #[arg(long)]
        out: PathBuf,
        /// Overall length, m.
        #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
        length_m: f64,
        /// Resolution: segments along the hull (128 gives about 10 800 triangles).
        #[arg(long, default_value_t = 128)]
        segments: usize,
    },
    /// Run the physics checks against closed forms and print expected, measured, tolerance.
    Validate {
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn make_vessel(out: &std::path::Path, length_m: f64, segments: usize) -> anyhow::Result<()> {
    if !(length_m.is_finite() && length_m > 0.0) {
        anyhow::bail!("invalid --length-m {length_m}: must be a positive number");
    }
    if !(8..=10_000).contains(&segments) {
        anyhow::bail!("invalid --segments {segments}: must be between 8 and 10000");
    }
    let mesh = xbandsim::geometry::mesh::vessel(length_m, segments);
    let text = mesh.to_obj(&format!("xbandsim procedural vessel: length {length_m} m, {segments} segments, {} triangles\nframe: bow +y, up +z, waterline z = 0; units m\nregenerate: xbandsim make-vessel --length-m {length_m} --segments {segments} --out FILE", mesh.triangles.len()));
    xbandsim::products::output::write_atomic(out, text.as_bytes())?;
    say!(
        "wrote {} ({} vertices, {} triangles)",
        out.display(),
        mesh.vertices_m.len(),
        mesh.triangles.len()
    );
    Ok(())
}

/// Reads a whole number of 0 or more (seeds, counts): a clear message for `-1` or `2.5`.
pub fn whole_number(text: &str) -> Result<u64, String> {
    text.trim()
        .parse()
        .map_err(|_| format!("{text:?} must be a whole number of 0 or more"))
}

/// The command line, with negative numbers taken as values wherever an option takes one
/// (`--el-deg -5`, `--spokes -1`, which then gets the option's own message), not as flags.
fn command_line() -> Cli {
    use clap::{CommandFactory, FromArgMatches};
    fn negatives(cmd: clap::Command) -> clap::Command {
        let names: Vec<String> = cmd
            .get_subcommands()
            .map(|s| s.get_name().to_string())
            .collect();
        let mut cmd = cmd.allow_negative_numbers(true);
        for name in names {
            cmd = cmd.mut_subcommand(name, negatives);
        }
        cmd
    }
    let mut cmd = negatives(Cli::command());
    let matches = cmd.clone().get_matches();
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.format(&mut cmd).exit())
}

/// The message of `e` and its causes (the library's errors carry their own cause in their
/// text, not as a source: each is printed once), with a path said once where the CLI's
/// context ends with it and the library's message starts with it.
fn message(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let cause = cause.to_string();
        // `making the dataset in DIR` then `DIR: Not a directory`: the path once.
        let rest = match cause.split_once(": ") {
            Some((head, rest)) if !head.is_empty() && text.ends_with(head) => rest,
            _ => cause.as_str(),
        };
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(rest);
    }
    text
}

fn main() -> ExitCode {
    let cli = command_line();
    let result = match cli.command {
        Command::Render(args) => render::run(&args),
        Command::Detect(args) => detect::run(&args),
        Command::Track(args) => track::run(&args),
        Command::Nmea(args) => nmea::run(&args),
        Command::Serve(args) => serve::run(&args),
        Command::Replay(args) => serve::replay(&args),
        Command::Schema => {
            let schema = schemars::schema_for!(xbandsim::scene::SceneSpec);
            say!(
                "{}",
                serde_json::to_string_pretty(&schema).unwrap_or_default()
            );
            Ok(())
        }
        Command::Figures { out, scene, seed } => figures::run(&out, &scene, seed),
        Command::Bench(args) => bench::run(&args),
        Command::Rcs(args) => rcs::run(&args),
        Command::Dataset(args) => dataset::run(&args),
        Command::MakeVessel {
            out,
            length_m,
            segments,
        } => make_vessel(&out, length_m, segments),
        Command::Validate { json } => validate::run(json),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", message(&e));
            ExitCode::FAILURE
        }
    }
}
