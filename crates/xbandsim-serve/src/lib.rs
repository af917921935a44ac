//! # xbandsim-serve
//!
//! xbandsim as a live radar (docs/live.md): a scene's scenario run in real time (or faster),
//! revolution after revolution, served to the software a ship's radar feeds —
//!
//! - the **spoke stream** of the mayara radar server's v1 API: a REST description of the
//!   radar and a WebSocket of protobuf `RadarMessage`s ([`proto`], [`radar`], [`server`]);
//! - the operator's **controls** (range scale, gain, sea, rain, interference rejection) over
//!   the same API ([`controls`]);
//! - the own ship's GPS and compass and the AIS of every object with an `mmsi` as **NMEA
//!   0183**, over UDP and TCP ([`feed`]);
//! - a **browser PPI** at `/`, shipped in the binary;
//! - the **scenario** — clock, pause, resume, restart, speed — and the truth of every object
//!   at any moment ([`clock`], [`live`]);
//! - **recordings** of what was sent, which `xbandsim replay` sends again byte for byte
//!   ([`record`]).

pub mod clock;
pub mod controls;
pub mod error;
pub mod feed;
pub mod live;
pub mod proto;
pub mod radar;
pub mod record;
pub mod server;

pub use error::{Result, ServeError};

use crate::controls::{range_scales_m, Controls};
use crate::live::{Live, Wait, CLIENT_SEND_TIMEOUT};
use crate::radar::RadarSource;
use crate::record::{RecordKind, Recorder, Recording};
use serde_json::{json, Value};
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;
use tokio::io::AsyncWriteExt;
use tokio::sync::broadcast::error::RecvError;
use xbandsim::land::projection::LocalProjection;
use xbandsim::{LoadedSpec, Simulation};

/// The fastest a scenario may run, times the wall.
pub const MAX_SPEED: f64 = 100.0;

/// The slowest a scenario may run, times the wall.
pub const MIN_SPEED: f64 = 0.01;

/// How the server runs.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The address of the page and the radar API.
    pub listen: SocketAddr,
    /// Times faster than the wall.
    pub speed: f64,
    /// Where to send the NMEA feed as UDP datagrams.
    pub nmea_udp: Option<SocketAddr>,
    /// Where to serve the NMEA feed over TCP.
    pub nmea_tcp: Option<SocketAddr>,
    /// Where to record what is sent.
    pub record: Option<PathBuf>,
    /// Stop once scenario time reaches this, s (None: run until stopped).
    pub duration_s: Option<f64>,
}

/// What the server did, once stopped.
#[derive(Debug, Clone)]
pub struct Summary {
    /// Scenario time reached, s.
    pub time_s: f64,
    /// What it sent.
    pub counters: live::Counters,
    /// Records written to the recording (None: no recording).
    pub recorded: Option<u64>,
}

/// Where the server listens, once it does.
#[derive(Debug, Clone, Copy)]
pub struct Bound {
    /// The page and API.
    pub http: SocketAddr,
    /// The NMEA TCP feed.
    pub nmea_tcp: Option<SocketAddr>,
}

/// Checks a speed factor.
pub fn check_speed(speed: f64) -> Result<()> {
    if (MIN_SPEED..=MAX_SPEED).contains(&speed) {
        Ok(())
    } else {
        Err(ServeError::setting(
            "speed",
            speed,
            &format!("must be {MIN_SPEED} to {MAX_SPEED} times real time"),
        ))
    }
}

fn check_options(o: &ServeOptions) -> Result<()> {
    check_speed(o.speed)?;
    if let Some(d) = o.duration_s {
        if !(d.is_finite() && d > 0.0) {
            return Err(ServeError::setting(
                "--duration-s",
                d,
                "must be a positive number of seconds",
            ));
        }
    }
    Ok(())
}

/// The legend: level k of `bits`-bit video to a colour, black through green and yellow to
/// red, as mayara's `legend.pixels`; then (video of 7 bits or fewer) the Doppler codes,
/// `2^bits` closing (magenta) and `2^bits + 1` opening (blue).
pub fn legend(bits: u32) -> Value {
    let levels = 1u32 << bits;
    let pixels: Vec<Value> = (0..levels)
        .map(|k| {
            let x = k as f64 / (levels - 1).max(1) as f64;
            let (r, g, b) = if k == 0 {
                (0.0, 0.0, 0.0)
            } else if x < 0.5 {
                (0.0, 0.35 + 1.3 * x, 0.0)
            } else {
                (2.0 * (x - 0.5) + 0.5, 1.0 - 1.6 * (x - 0.5), 0.0)
            };
            let c = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
            json!({"type": "normal", "color": format!("#{:02x}{:02x}{:02x}ff", c(r), c(g), c(b))})
        })
        .collect();
    let mut legend = json!({"pixels": pixels, "lowNormal": 1, "mediumNormal": levels / 2, "strongReturn": levels - 1});
    if let Some((closing, opening)) = radar::doppler_codes(bits) {
        let pixels = legend["pixels"].as_array_mut().expect("an array");
        pixels.push(json!({"type": "dopplerApproaching", "color": "#ff40ffff"}));
        pixels.push(json!({"type": "dopplerReceding", "color": "#40a0ffff"}));
        legend["dopplerApproaching"] = json!(closing);
        legend["dopplerReceding"] = json!(opening);
    }
    legend
}

/// The radar's description, as `/v1/api/radars` lists it (without its stream addresses).
fn describe(name: &str, source: &RadarSource, scales_m: &[f64]) -> Value {
    json!({
        "id": "1",
        "name": name,
        "brand": "xbandsim",
        "model": "simulated X-band radar",
        "spokesPerRevolution": source.spokes(),
        "maxSpokeLen": source.samples(),
        "rotationPeriodS": source.period_s(),
        "bits": source.base.video_bits,
        "startUnixS": source.start_unix_s,
        "legend": legend(source.base.video_bits),
        "controls": Controls::describe(scales_m),
    })
}

/// The radar of `spec` (its video chain run here, with the controls), ready to serve.
pub fn radar_source(spec: &LoadedSpec, seed: u64, start_unix_s: f64) -> Result<RadarSource> {
    let scene = spec.build()?;
    let base = scene.receiver().copied().unwrap_or_default();
    let projection = feed::geo_origin(spec.spec())
        .ok()
        .map(|(lon, lat)| LocalProjection::new(lon, lat));
    let sim = Simulation::new(scene.with_receiver(None));
    let doppler = radar::doppler_codes(base.video_bits).is_some()
        && sim
            .check_outputs(xbandsim::engine::Outputs {
                radial_velocity: true,
                ..Default::default()
            })
            .is_ok();
    Ok(RadarSource {
        sim,
        base,
        seed,
        start_unix_s,
        projection,
        mmsi: spec.spec().objects.iter().map(|o| o.mmsi).collect(),
        arpa: false,
        doppler,
    })
}

/// `live` sending its NMEA groups to `--nmea-udp`, if given.
fn with_udp(live: Live, options: &ServeOptions) -> Result<Live> {
    match options.nmea_udp {
        Some(to) => {
            let any = if to.is_ipv4() { "0.0.0.0:0" } else { "[::]:0" };
            let socket =
                std::net::UdpSocket::bind(any).map_err(|e| bind_error("--nmea-udp", to, e))?;
            Ok(live.with_udp(socket, to))
        }
        None => Ok(live),
    }
}

fn bind_error(what: &str, addr: SocketAddr, source: std::io::Error) -> ServeError {
    ServeError::Network {
        what: what.to_string(),
        addr: addr.to_string(),
        source,
    }
}

/// Serves the scenario of `spec` until Ctrl-C, SIGTERM or `duration_s`; `ready` is told
/// where it listens once it does.
pub fn serve(
    spec: &LoadedSpec,
    name: &str,
    seed: u64,
    start_unix_s: f64,
    options: &ServeOptions,
    ready: impl FnOnce(Bound),
) -> Result<Summary> {
    check_options(options)?;
    let mut source = radar_source(spec, seed, start_unix_s)?;
    let feed = match feed::NmeaFeed::new(spec.spec(), source.sim.scene(), start_unix_s) {
        Ok(f) => Some(f),
        Err(ServeError::NoGeoOrigin)
            if options.nmea_udp.is_none() && options.nmea_tcp.is_none() =>
        {
            None
        }
        Err(e) => return Err(e),
    };
    source.arpa = feed.is_some();
    let source = Arc::new(source);
    let scales = range_scales_m(source.max_range_m());
    let description = describe(name, &source, &scales);
    let recorder = match &options.record {
        Some(path) => Some(Recorder::create(
            path,
            &json!({
                "radar": description,
                "scene": name,
                "seed": seed,
                "speed": options.speed,
                "controls": Controls::of_settings(&source.base, source.max_range_m()),
            }),
        )?),
        None => None,
    };
    let controls = Controls::of_settings(&source.base, source.max_range_m());
    let live = Arc::new(with_udp(
        Live::new(options.speed, controls, scales, recorder),
        options,
    )?);
    let app = Arc::new(server::App {
        live: live.clone(),
        source: Some(source.clone()),
        description,
    });
    run(app, options, ready, move |live| {
        let mut threads = radar::spawn(live.clone(), source.clone());
        if let Some(f) = feed {
            threads.push(feed::spawn(live, source, f));
        }
        threads
    })
}

/// Serves `recording` again: its spoke messages and NMEA groups at their scenario times,
/// until it ends, Ctrl-C or SIGTERM.
pub fn replay(
    recording: Recording,
    options: &ServeOptions,
    ready: impl FnOnce(Bound),
) -> Result<Summary> {
    check_options(options)?;
    let description = recording.header["radar"].clone();
    let recording_path = recording.path.clone();
    let whole = |key: &str| description[key].as_u64().is_some_and(|v| v > 0);
    if !(whole("spokesPerRevolution")
        && whole("maxSpokeLen")
        && description["legend"].is_object()
        && description["controls"].is_object())
    {
        return Err(ServeError::Recording {
            path: recording_path,
            message: "its header has no radar description (radar.spokesPerRevolution, maxSpokeLen, legend, controls)".into(),
        });
    }
    let max_range = description["controls"][controls::RANGE]["validValues"]
        .as_array()
        .and_then(|v| v.last())
        .and_then(Value::as_f64)
        .unwrap_or(0.0);
    let scales = range_scales_m(max_range.max(1.0));
    let controls = serde_json::from_value(recording.header["controls"].clone())
        .unwrap_or_else(|_| Controls::of_settings(&Default::default(), max_range.max(1.0)));
    let recorder = match &options.record {
        Some(path) => Some(Recorder::create_raw(path, &recording.header_raw)?),
        None => None,
    };
    let live = Arc::new(with_udp(
        Live::new(options.speed, controls, scales, recorder).for_replay(),
        options,
    )?);
    let app = Arc::new(server::App {
        live: live.clone(),
        source: None,
        description,
    });
    let recording = Arc::new(recording);
    run(app, options, ready, move |live| {
        let thread = std::thread::Builder::new()
            .name("xbandsim-replay".into())
            .spawn(move || {
                while !live.stopping() {
                    let generation = live.generation();
                    let mut ended = true;
                    for r in &recording.records {
                        match live.wait_until(r.time_s, generation) {
                            Wait::Due => {}
                            Wait::Restarted => {
                                ended = false;
                                break;
                            }
                            Wait::Stopping => return,
                        }
                        match r.kind {
                            RecordKind::Spokes => {
                                live.send_spokes(generation, r.time_s, r.payload.clone())
                            }
                            RecordKind::Nmea => {
                                let lines = r.payload.iter().filter(|&&b| b == b'\n').count();
                                live.send_nmea(
                                    generation,
                                    r.time_s,
                                    r.payload.clone(),
                                    lines as u64,
                                );
                            }
                            RecordKind::Restart => live.rewind(generation, r.time_s),
                        }
                    }
                    if ended {
                        live.stop();
                    }
                }
            })
            .expect("a thread starts");
        vec![thread]
    })
}

/// Runs the server: binds, starts the stream threads, serves until a stop, then stops the
/// threads and ends the recording.
fn run(
    app: Arc<server::App>,
    options: &ServeOptions,
    ready: impl FnOnce(Bound),
    start: impl FnOnce(Arc<Live>) -> Vec<std::thread::JoinHandle<()>>,
) -> Result<Summary> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .thread_name("xbandsim-http")
        .enable_all()
        .build()
        .map_err(|e| bind_error("the server's runtime on", options.listen, e))?;
    let live = app.live.clone();
    let result = runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind(options.listen)
            .await
            .map_err(|e| bind_error("--listen", options.listen, e))?;
        let http = listener
            .local_addr()
            .map_err(|e| bind_error("--listen", options.listen, e))?;
        let nmea_tcp = match options.nmea_tcp {
            Some(addr) => {
                let l = tokio::net::TcpListener::bind(addr)
                    .await
                    .map_err(|e| bind_error("--nmea-tcp", addr, e))?;
                let bound = l
                    .local_addr()
                    .map_err(|e| bind_error("--nmea-tcp", addr, e))?;
                tokio::spawn(nmea_tcp_server(l, live.clone()));
                Some(bound)
            }
            None => None,
        };
        let threads = start(live.clone());
        ready(Bound { http, nmea_tcp });
        // The shutdown: a stop, then the stream threads finished, then the clients told the
        // streams have ended (each sends what it still holds, then closes), then the server.
        let shutdown = {
            let live = live.clone();
            let duration_s = options.duration_s;
            async move {
                stop_when(live.clone(), duration_s).await;
                live.stop();
                let _ = tokio::task::spawn_blocking(move || {
                    for t in threads {
                        let _ = t.join();
                    }
                })
                .await;
                live.end_streams();
            }
        };
        let served = axum::serve(listener, server::router(app.clone()))
            .with_graceful_shutdown(shutdown)
            .await;
        live.stop();
        live.end_streams();
        Ok::<_, ServeError>(served)
    });
    let served = match result {
        Ok(x) => x,
        Err(e) => {
            live.stop();
            let _ = live.finish_recording();
            return Err(e);
        }
    };
    // Clients draining what they hold get a moment, at most the time one send may take.
    runtime.block_on(async {
        let deadline = tokio::time::Instant::now() + live::CLIENT_SEND_TIMEOUT;
        while live.spoke_clients.load(std::sync::atomic::Ordering::SeqCst) > 0
            && tokio::time::Instant::now() < deadline
        {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    });
    runtime.shutdown_timeout(Duration::from_secs(1));
    let recorded = live.finish_recording()?;
    served.map_err(|e| bind_error("serving on", options.listen, e))?;
    Ok(Summary {
        time_s: live.time_s(),
        counters: live.counters(),
        recorded,
    })
}

/// Resolves on Ctrl-C, SIGTERM, at `duration_s` of scenario time, or when a stream thread
/// stops the server.
async fn stop_when(live: Arc<Live>, duration_s: Option<f64>) {
    let mut stopped = live.stop_signal();
    let mut tick = tokio::time::interval(Duration::from_millis(50));
    let ctrl_c = tokio::signal::ctrl_c();
    tokio::pin!(ctrl_c);
    #[cfg(unix)]
    let mut term = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()).ok();
    loop {
        #[cfg(unix)]
        let sigterm = async {
            match term.as_mut() {
                Some(t) => {
                    t.recv().await;
                }
                None => std::future::pending::<()>().await,
            }
        };
        #[cfg(not(unix))]
        let sigterm = std::future::pending::<()>();
        tokio::select! {
            _ = &mut ctrl_c => break,
            _ = sigterm => break,
            _ = stopped.changed() => break,
            _ = tick.tick() => {
                if live.stopping() || duration_s.is_some_and(|d| live.time_s() >= d) {
                    break;
                }
            }
        }
    }
    live.stop();
}

/// The NMEA feed over TCP: every connection gets every group from when it connects; one
/// that falls behind or stalls is closed.
async fn nmea_tcp_server(listener: tokio::net::TcpListener, live: Arc<Live>) {
    let mut stop = live.stop_signal();
    loop {
        let accepted = tokio::select! {
            _ = stop.changed() => return,
            a = listener.accept() => a,
        };
        let Ok((mut socket, _)) = accepted else {
            // Out of descriptors, say: wait before trying again.
            tokio::time::sleep(Duration::from_millis(100)).await;
            continue;
        };
        let live = live.clone();
        tokio::spawn(async move {
            let mut rx = live.nmea.subscribe();
            let mut ended = live.ended_signal();
            loop {
                let m = tokio::select! {
                    _ = ended.changed() => {
                        // What was sent before the streams ended still goes out.
                        while let Ok(bytes) = rx.try_recv() {
                            let sent = tokio::time::timeout(CLIENT_SEND_TIMEOUT, socket.write_all(&bytes)).await;
                            if !matches!(sent, Ok(Ok(()))) {
                                break;
                            }
                        }
                        break;
                    }
                    m = rx.recv() => m,
                };
                match m {
                    Ok(bytes) => {
                        let sent =
                            tokio::time::timeout(CLIENT_SEND_TIMEOUT, socket.write_all(&bytes))
                                .await;
                        if !matches!(sent, Ok(Ok(()))) {
                            live.client_dropped();
                            break;
                        }
                    }
                    Err(RecvError::Lagged(_)) => {
                        live.client_dropped();
                        break;
                    }
                    Err(RecvError::Closed) => break,
                }
            }
            let _ = socket.shutdown().await;
        });
    }
}
