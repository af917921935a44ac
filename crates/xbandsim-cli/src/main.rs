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
mod figures;
mod rcs;
mod render;
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
    /// Print the JSON Schema of the scene file format.
    Schema,
    /// Reproduce the seed paper's Figs. 2, 3 and 4 as PNGs.
    Figures {
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Scene used for Fig. 4.
        #[arg(long, default_value = "scenes/paper.toml")]
        scene: PathBuf,
        /// Random seed for the noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Measure ray-casting throughput, frame time and peak memory.
    Bench(bench::BenchArgs),
    /// Monostatic RCS of one object versus aspect, alone in free space.
    Rcs(rcs::RcsArgs),
    /// Run the physics checks against closed forms and print expected, measured, tolerance.
    Validate {
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => render::run(&args),
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
        Command::Validate { json } => validate::run(json),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
