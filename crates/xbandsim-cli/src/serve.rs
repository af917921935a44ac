//! `xbandsim serve` and `xbandsim replay`: the scene's scenario as a live radar — the page,
//! the mayara radar API's spoke and control streams, NMEA 0183 over UDP and TCP, and a
//! recording of what was sent — and a recording served again (docs/live.md).

use anyhow::{Context, Result};
use clap::Args;
use std::net::SocketAddr;
use std::path::PathBuf;
use xbandsim_nmea::sentence::UtcTime;
use xbandsim_serve::{Bound, ServeOptions, Summary};

/// The options both commands take.
#[derive(Args, Debug, Clone)]
pub struct Listen {
    /// Address of the page and the radar API (loopback unless given; port 0 takes a free
    /// port, printed at the start).
    #[arg(long, default_value = "127.0.0.1:6502", value_name = "ADDR:PORT")]
    pub listen: SocketAddr,
    /// Run the scenario this many times faster than real time (0.01 to 100).
    #[arg(long, default_value_t = 1.0, value_name = "X")]
    pub speed: f64,
    /// Send the NMEA 0183 feed to this address as UDP datagrams (one a sentence group).
    #[arg(long, value_name = "ADDR:PORT")]
    pub nmea_udp: Option<SocketAddr>,
    /// Serve the NMEA 0183 feed to TCP clients on this address.
    #[arg(long, value_name = "ADDR:PORT")]
    pub nmea_tcp: Option<SocketAddr>,
    /// Record the spoke stream and the NMEA lines with their times to this file.
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
    /// Stop once the scenario reaches this time, s (default: run until Ctrl-C).
    #[arg(long, value_name = "S")]
    pub duration_s: Option<f64>,
}

impl Listen {
    fn options(&self) -> ServeOptions {
        ServeOptions {
            listen: self.listen,
            speed: self.speed,
            nmea_udp: self.nmea_udp,
            nmea_tcp: self.nmea_tcp,
            record: self.record.clone(),
            duration_s: self.duration_s,
        }
    }
}

/// Arguments of `xbandsim serve`.
#[derive(Args, Debug, Clone)]
pub struct ServeArgs {
    /// Scene file (TOML). With a `[geo]` origin it also has an NMEA feed and positions.
    pub scene: PathBuf,
    #[command(flatten)]
    pub listen: Listen,
    /// Random seed of the renders.
    #[arg(long, default_value_t = 1, value_parser = crate::whole_number)]
    pub seed: u64,
    /// UTC time of the scenario's t = 0, as YYYY-MM-DDTHH:MM:SSZ.
    #[arg(long, default_value = "2026-01-01T00:00:00Z")]
    pub start_utc: String,
    /// Override any scene field: FIELD=VALUE (repeatable), as for render.
    #[arg(long, value_name = "FIELD=VALUE")]
    pub set: Vec<String>,
}

/// Arguments of `xbandsim replay`.
#[derive(Args, Debug, Clone)]
pub struct ReplayArgs {
    /// A recording made by `xbandsim serve --record FILE`.
    pub recording: PathBuf,
    #[command(flatten)]
    pub listen: Listen,
}

fn announce(what: &str, bound: Bound, o: &ServeOptions) {
    crate::say!(
        "{what} on http://{}/ (radar API http://{}/v1/api/radars), {}x real time",
        bound.http,
        bound.http,
        o.speed
    );
    if let Some(addr) = o.nmea_udp {
        crate::say!("NMEA 0183 to udp {addr}");
    }
    if let Some(addr) = bound.nmea_tcp {
        crate::say!("NMEA 0183 on tcp {addr}");
    }
    if let Some(path) = &o.record {
        crate::say!("recording to {}", path.display());
    }
    crate::say!("Ctrl-C stops");
}

fn report(s: &Summary, o: &ServeOptions) {
    crate::say!(
        "stopped at {:.1} s: {} revolutions, {} spoke messages, {} NMEA sentences, {} clients dropped",
        s.time_s,
        s.counters.revolutions,
        s.counters.spoke_messages,
        s.counters.nmea_sentences,
        s.counters.clients_dropped
    );
    if let (Some(n), Some(path)) = (s.recorded, &o.record) {
        crate::say!("recorded {n} records -> {}", path.display());
    }
}

/// Runs `xbandsim serve`.
pub fn run(a: &ServeArgs) -> Result<()> {
    let Some(start_unix_s) = UtcTime::parse_unix_s(&a.start_utc) else {
        anyhow::bail!(
            "invalid --start-utc {:?}: must be YYYY-MM-DDTHH:MM:SSZ, e.g. 2026-01-01T00:00:00Z",
            a.start_utc
        );
    };
    let spec = crate::render::load_spec(&a.scene, &a.set)?;
    let o = a.listen.options();
    let name = a
        .scene
        .file_stem()
        .map_or_else(|| "scene".to_string(), |s| s.to_string_lossy().into_owned());
    let summary = xbandsim_serve::serve(&spec, &name, a.seed, start_unix_s, &o, |bound| {
        announce(&format!("serving {}", a.scene.display()), bound, &o)
    })
    .with_context(|| format!("serving {}", a.scene.display()))?;
    report(&summary, &o);
    Ok(())
}

/// Runs `xbandsim replay`.
pub fn replay(a: &ReplayArgs) -> Result<()> {
    if let Some(out) = &a.listen.record {
        let same = match (a.recording.canonicalize(), out.canonicalize()) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        };
        if same {
            anyhow::bail!(
                "invalid --record {}: it is the recording being replayed; record to another file",
                out.display()
            );
        }
    }
    let recording = xbandsim_serve::record::read(&a.recording)?;
    if !recording.complete {
        eprintln!(
            "warning: {} has no end record (its server did not stop cleanly): replaying its {} whole records",
            a.recording.display(),
            recording.records.len()
        );
    }
    let o = a.listen.options();
    let summary = xbandsim_serve::replay(recording, &o, |bound| {
        announce(&format!("replaying {}", a.recording.display()), bound, &o)
    })
    .with_context(|| format!("replaying {}", a.recording.display()))?;
    report(&summary, &o);
    Ok(())
}
