//! `xbandsim nmea`: what the scenario's navigation network would carry (docs/live.md): the
//! own ship's GPS fix and true heading once a second (GGA, RMC, VTG, HDT) and the AIS
//! reports of every object with an `mmsi` at the ITU-R M.1371 reporting intervals, as an NMEA
//! 0183 log in time order, with a truth file saying what each report was made from.

use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use xbandsim_nmea::sentence::UtcTime;
use xbandsim_serve::feed::{NmeaFeed, TICK_S};

/// Arguments of `xbandsim nmea`.
#[derive(Args, Debug, Clone)]
pub struct NmeaArgs {
    /// Scene file (TOML); it needs a `[geo]` origin to put the scene on the globe.
    pub scene: PathBuf,
    /// The NMEA 0183 log: one sentence a line, in time order.
    #[arg(long, default_value = "nmea.log")]
    pub out: PathBuf,
    /// What each line was made from (JSON Lines, one object per sentence group): the
    /// scenario time, the source (own ship or object), its ENU position and velocity.
    #[arg(long, value_name = "FILE.jsonl")]
    pub truth: Option<PathBuf>,
    /// Length of the scenario to write, s.
    #[arg(long, default_value_t = 60.0)]
    pub duration_s: f64,
    /// UTC time of the scenario's t = 0, as YYYY-MM-DDTHH:MM:SSZ.
    #[arg(long, default_value = "2026-01-01T00:00:00Z")]
    pub start_utc: String,
    /// Override any scene field: FIELD=VALUE (repeatable), as for render.
    #[arg(long, value_name = "FIELD=VALUE")]
    pub set: Vec<String>,
}

/// Runs `xbandsim nmea`.
pub fn run(a: &NmeaArgs) -> Result<()> {
    if !(a.duration_s.is_finite() && a.duration_s > 0.0) {
        bail!(
            "invalid --duration-s {}: must be a positive number of seconds",
            a.duration_s
        );
    }
    let Some(start_unix_s) = UtcTime::parse_unix_s(&a.start_utc) else {
        bail!(
            "invalid --start-utc {:?}: must be YYYY-MM-DDTHH:MM:SSZ, e.g. 2026-01-01T00:00:00Z",
            a.start_utc
        );
    };
    let spec = crate::render::load_spec(&a.scene, &a.set)?;
    let scene = spec.build()?;
    let mut feed = NmeaFeed::new(spec.spec(), &scene, start_unix_s)
        .with_context(|| a.scene.display().to_string())?;
    let last_tick = (a.duration_s / TICK_S + 1e-9).floor() as u64;
    let mut log = String::new();
    let mut truth_text = String::new();
    while feed.next_tick() <= last_tick {
        for group in feed.tick(&scene)? {
            for line in &group.lines {
                log.push_str(line);
            }
            if a.truth.is_some() {
                truth_text.push_str(&serde_json::to_string(&group.truth)?);
                truth_text.push('\n');
            }
        }
    }
    // Both are made before either is written; each is replaced whole.
    xbandsim::products::output::write_atomic(&a.out, log.as_bytes())
        .with_context(|| format!("writing {}", a.out.display()))?;
    if let Some(path) = &a.truth {
        xbandsim::products::output::write_atomic(path, truth_text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    crate::say!(
        "nmea {}: {:.0} s from {}, own ship and {} AIS transponders, {} sentences -> {}",
        a.scene.display(),
        a.duration_s,
        a.start_utc,
        feed.transponders(),
        log.lines().count(),
        a.out.display()
    );
    Ok(())
}
