//! The radar (docs/live.md, "The spoke stream"): revolution after revolution of the scene,
//! rendered one ahead on one thread, and sent on another as the antenna sweeps: the
//! calibrated record through the video chain with the controls as they are at the
//! revolution's start (docs/physics.md §12), then its video spokes in `RadarMessage`s, each
//! sent when scenario time reaches the last spoke it holds.

use crate::controls::Controls;
use crate::live::{Live, Wait, POLL};
use crate::proto::{to_e16, RadarMessage, Spoke};
use bytes::Bytes;
use prost::Message;
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError, SyncSender, TrySendError};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;
use xbandsim::engine::{Request, Simulation};
use xbandsim::land::projection::LocalProjection;
use xbandsim::model::receiver::VideoSettings;
use xbandsim::receiver::video_chain::{self, EchoHistory, PolarRecord, Video};
use xbandsim::Frame;

/// The radar's number in the API.
pub const RADAR_NUMBER: u32 = 1;

/// Spoke messages a revolution is cut into (at most): 128, so 16 spokes a message at 2048
/// spokes, about 20 ms of sweep at 24 rpm.
pub const MESSAGES_PER_REVOLUTION: usize = 128;

/// What the radar is made of.
pub struct RadarSource {
    /// The scene, without its own video chain (the radar runs it with the controls).
    pub sim: Simulation,
    /// The scene's receiver (or the default one): the controls adjust it.
    pub base: VideoSettings,
    /// The render seed.
    pub seed: u64,
    /// UTC of scenario time 0, s after 1970.
    pub start_unix_s: f64,
    /// The scene's place on the globe (None without `[geo]`: spokes carry no position).
    pub projection: Option<LocalProjection>,
    /// Each object's MMSI, in scene order (None: no transponder).
    pub mmsi: Vec<Option<u32>>,
}

impl RadarSource {
    /// Spokes a revolution sends.
    pub fn spokes(&self) -> usize {
        self.base.video_spokes
    }

    /// Samples a spoke.
    pub fn samples(&self) -> usize {
        self.base.video_samples
    }

    /// Antenna rotation period, s.
    pub fn period_s(&self) -> f64 {
        self.sim.scene().radar().scan().period_s()
    }

    /// The recorded range, m.
    pub fn max_range_m(&self) -> f64 {
        self.sim.scene().radar().max_range_m()
    }

    /// The antenna's ENU position at scenario time `t_s`, m.
    pub fn antenna_m(&self, t_s: f64) -> glam::DVec3 {
        let radar = self.sim.scene().radar().position_m();
        match self.sim.scene().own_ship() {
            Some(s) => radar + s.displacement_m(t_s),
            None => radar,
        }
    }

    /// The own ship's heading, degrees (0 without an own ship).
    pub fn heading_deg(&self) -> f64 {
        self.sim
            .scene()
            .own_ship()
            .map_or(0.0, |s| s.heading_rad().to_degrees())
    }
}

/// A rendered revolution on its way to the sender.
struct Rendered {
    generation: u64,
    frame: Frame,
    render_s: f64,
}

/// The spokes of revolution `video` starting at `start_time_s`, spoke numbers `from..to`,
/// as one message.
pub fn spoke_message(
    source: &RadarSource,
    video: &Video,
    range_m: f64,
    start_time_s: f64,
    from: usize,
    to: usize,
) -> RadarMessage {
    let n = video.spokes;
    let heading_spokes = (source.heading_deg() / 360.0 * n as f64).round() as i64;
    let spokes = (from..to)
        .map(|s| {
            let t_s = start_time_s + s as f64 / n as f64 * source.period_s();
            let (lat, lon) = match &source.projection {
                Some(p) => {
                    let (lon, lat) = p.to_lon_lat_deg(source.antenna_m(t_s).truncate());
                    (Some(to_e16(lat)), Some(to_e16(lon)))
                }
                None => (None, None),
            };
            Spoke {
                angle: (s as i64 - heading_spokes).rem_euclid(n as i64) as u32,
                bearing: Some(s as u32),
                range: range_m.round() as u32,
                time: Some(((source.start_unix_s + t_s) * 1000.0).round() as u64),
                data: video.levels[s * video.samples..(s + 1) * video.samples].to_vec(),
                lat,
                lon,
            }
        })
        .collect();
    RadarMessage {
        radar: RADAR_NUMBER,
        spokes,
    }
}

/// The video of `frame` with `controls`.
pub fn video_of(
    source: &RadarSource,
    frame: &Frame,
    controls: &Controls,
    history: &mut EchoHistory,
) -> Video {
    let settings = controls.apply(&source.base);
    let record = PolarRecord {
        db: &frame.polar_db,
        spokes: frame.spokes,
        bins: frame.range_bins,
        bin_m: frame.range_bin_m,
        range_m: controls.range_m.min(source.max_range_m()),
    };
    video_chain::run(&settings, &record, Some(history))
}

/// Starts the radar's two threads.
pub fn spawn(live: Arc<Live>, source: Arc<RadarSource>) -> Vec<JoinHandle<()>> {
    let (tx, rx) = sync_channel::<Rendered>(1);
    let (l, s) = (live.clone(), source.clone());
    let render = std::thread::Builder::new()
        .name("xbandsim-render".into())
        .spawn(move || render_loop(&l, &s, tx))
        .expect("a thread starts");
    let send = std::thread::Builder::new()
        .name("xbandsim-spokes".into())
        .spawn(move || send_loop(&live, &source, rx))
        .expect("a thread starts");
    vec![render, send]
}

fn render_loop(live: &Live, source: &RadarSource, tx: SyncSender<Rendered>) {
    while !live.stopping() {
        let generation = live.generation();
        for k in 0.. {
            if live.stopping() || live.generation() != generation {
                break;
            }
            let t0 = Instant::now();
            let frame = match source.sim.run(&Request::new(source.seed).frame(k)) {
                Ok(f) => f,
                Err(e) => {
                    eprintln!("xbandsim serve: revolution {k} failed: {e}");
                    live.stop();
                    return;
                }
            };
            let mut item = Rendered {
                generation,
                frame,
                render_s: t0.elapsed().as_secs_f64(),
            };
            loop {
                match tx.try_send(item) {
                    Ok(()) => break,
                    Err(TrySendError::Full(back)) => {
                        if live.stopping() || live.generation() != generation {
                            break;
                        }
                        item = back;
                        std::thread::sleep(POLL);
                    }
                    Err(TrySendError::Disconnected(_)) => return,
                }
            }
        }
    }
}

fn send_loop(live: &Live, source: &RadarSource, rx: Receiver<Rendered>) {
    let mut history = EchoHistory::default();
    let mut history_generation = live.generation();
    let n = source.spokes();
    let per_message = n.div_ceil(MESSAGES_PER_REVOLUTION).max(1);
    let period_s = source.period_s();
    loop {
        let r = match rx.recv_timeout(POLL) {
            Ok(r) => r,
            Err(RecvTimeoutError::Timeout) if live.stopping() => return,
            Err(RecvTimeoutError::Timeout) => continue,
            Err(RecvTimeoutError::Disconnected) => return,
        };
        if r.generation != live.generation() {
            continue;
        }
        if r.generation != history_generation {
            history = EchoHistory::default();
            history_generation = r.generation;
        }
        let start_s = r.frame.start_time_s;
        // A revolution later than a message's worth of sweep holds the scenario clock at
        // its start: no spoke is skipped or sent in a burst.
        if live.time_s() > start_s + period_s / MESSAGES_PER_REVOLUTION as f64 {
            live.hold_at(start_s);
        }
        let controls = live.controls();
        let t0 = Instant::now();
        let video = video_of(source, &r.frame, &controls, &mut history);
        let video_s = t0.elapsed().as_secs_f64();
        let range_m = controls.range_m.min(source.max_range_m());
        for from in (0..n).step_by(per_message) {
            let to = (from + per_message).min(n);
            let due_s = start_s + (to - 1) as f64 / n as f64 * period_s;
            match live.wait_until(due_s, r.generation) {
                Wait::Due => {}
                Wait::Restarted => break,
                Wait::Stopping => return,
            }
            let m = spoke_message(source, &video, range_m, start_s, from, to);
            live.send_spokes(due_s, Bytes::from(m.encode_to_vec()));
        }
        if r.generation == live.generation() {
            let mut c = live.counters.lock().unwrap_or_else(|e| e.into_inner());
            c.revolutions += 1;
            c.last_render_s = r.render_s;
            c.last_video_s = video_s;
        }
    }
}
