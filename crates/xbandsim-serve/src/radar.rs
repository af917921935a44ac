//! The radar (docs/live.md, "The radar API"): revolution after revolution of the scene,
//! rendered ahead on one thread, and sent on another as the antenna sweeps: at the
//! revolution's start (scenario time held there meanwhile) the calibrated record goes through
//! the video chain with the controls as they are then (docs/physics.md §12), and its video
//! spokes go out in `RadarMessage`s, each when scenario time reaches the last spoke it holds. With an NMEA feed, each
//! revolution's calibrated record also goes through the baseline plot extractor and ARPA
//! tracker at `xbandsim track`'s defaults (docs/tracking.md), and a `$RATTM` sentence for
//! every confirmed track follows the revolution's last spoke.

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
use xbandsim::processing::plots::{PlotExtractor, PlotScratch, PowerGrid};
use xbandsim::receiver::video_chain::{self, EchoHistory, PolarRecord, Video};
use xbandsim::Frame;
use xbandsim_nmea::sentence::{ttm, TrackedTarget};
use xbandsim_track::{Scan, Tracker, TrackerSettings};

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
    /// Whether the radar tracks its plots and sends TTM sentences (with an NMEA feed).
    pub arpa: bool,
    /// Whether its spokes carry the Doppler codes (a pulse-mode scene, video of 7 bits or
    /// fewer).
    pub doppler: bool,
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

/// The legend's Doppler codes for `bits`-bit video: closing (`2^bits`) and opening
/// (`2^bits + 1`); None for 8-bit video, which leaves no byte values for them.
pub fn doppler_codes(bits: u32) -> Option<(u8, u8)> {
    (bits <= 7).then(|| ((1u32 << bits) as u8, ((1u32 << bits) + 1) as u8))
}

/// Power over the noise a cell needs for its Doppler code, dB: a fixed level, whatever the
/// gain, so that noise shown at a high gain keeps its level (the pulse-pair estimate of a
/// noise cell is random).
pub const DOPPLER_THRESHOLD_DB: f64 = 10.0;

/// Marks `video`'s shown samples (level 1 or more) whose cell of the record closes or opens
/// at 3 kn or faster with power [`DOPPLER_THRESHOLD_DB`] over the noise with the Doppler
/// codes, as a target analyser colours them: each sample read at the record's spoke nearest
/// its own and the bin at its centre.
pub fn mark_doppler(
    video: &mut Video,
    rv: &xbandsim::products::RadialVelocity,
    range_bin_m: f64,
    codes: (u8, u8),
) {
    let (n, samples) = (video.spokes, video.samples);
    let threshold_db = DOPPLER_THRESHOLD_DB;
    for s in 0..n {
        let spoke = (s * rv.spokes + n / 2) / n % rv.spokes;
        for j in 0..samples {
            let k = s * samples + j;
            if video.levels[k] == 0 {
                continue;
            }
            let bin = (((j as f64 + 0.5) * video.sample_m / range_bin_m).round() as usize)
                .min(rv.range_bins - 1);
            let i = spoke * rv.range_bins + bin;
            if rv.approaching(i, threshold_db) {
                video.levels[k] = codes.0;
            } else if rv.receding(i, threshold_db) {
                video.levels[k] = codes.1;
            }
        }
    }
}

/// A rendered revolution on its way to the sender.
struct Rendered {
    generation: u64,
    frame: Frame,
    render_s: f64,
    tracker_s: f64,
    /// The TTM sentences of the tracks confirmed after this revolution.
    ttm: Vec<String>,
}

/// The radar's ARPA: the baseline extractor, a tracker, and the TTM target number (1–99)
/// each confirmed track holds while it lives.
struct Arpa {
    extractor: PlotExtractor,
    scratch: PlotScratch,
    tracker: Tracker,
    numbers: TargetNumbers,
}

/// TTM target numbers 1–99, each held by one live track: the lowest free number to a newly
/// confirmed track, freed when its track ends.
#[derive(Debug, Default)]
pub struct TargetNumbers {
    held: std::collections::BTreeMap<u32, u32>,
}

impl TargetNumbers {
    /// The numbers of `confirmed` tracks (None for one that finds all 99 taken), after
    /// freeing those of tracks not in `live`.
    pub fn assign(&mut self, live: &[u32], confirmed: &[u32]) -> Vec<Option<u32>> {
        self.held.retain(|id, _| live.contains(id));
        confirmed
            .iter()
            .map(|&id| {
                if let Some(&k) = self.held.get(&id) {
                    return Some(k);
                }
                let taken: std::collections::BTreeSet<u32> = self.held.values().copied().collect();
                let free = (1..=99).find(|k| !taken.contains(k))?;
                self.held.insert(id, free);
                Some(free)
            })
            .collect()
    }
}

impl Arpa {
    fn new(source: &RadarSource) -> xbandsim::Result<Arpa> {
        Ok(Arpa {
            extractor: xbandsim_track::baseline::extractor(source.sim.scene())?,
            scratch: PlotScratch::default(),
            tracker: Tracker::new(TrackerSettings::default())?,
            numbers: TargetNumbers::default(),
        })
    }

    /// Tracks `frame`'s plots; the TTM sentence of each confirmed track, its distance and
    /// bearing from the antenna at the track's time.
    fn ttm(&mut self, source: &RadarSource, frame: &Frame) -> Vec<String> {
        let grid = PowerGrid::from_record_db(
            &frame.polar_db,
            frame.spokes,
            frame.range_bins,
            frame.range_bin_m,
        );
        let plots = self.extractor.extract(&grid, &mut self.scratch);
        let (antenna, velocity) = match frame.own_ship {
            Some(s) => (s.antenna_position_m, [s.velocity_mps.x, s.velocity_mps.y]),
            None => (source.sim.scene().radar().position_m(), [0.0, 0.0]),
        };
        let scan = Scan {
            start_time_s: frame.start_time_s,
            period_s: source.period_s(),
            antenna_position_m: antenna.to_array(),
            antenna_velocity_mps: velocity,
            plots: &plots,
        };
        let report = self.tracker.step(&scan);
        let live: Vec<u32> = report.tracks.iter().map(|t| t.id).collect();
        let confirmed: Vec<&xbandsim_track::TrackReport> = report.confirmed().collect();
        let ids: Vec<u32> = confirmed.iter().map(|t| t.id).collect();
        let numbers = self.numbers.assign(&live, &ids);
        confirmed
            .into_iter()
            .zip(numbers)
            .filter_map(|(t, number)| {
                let number = number?;
                let own = source.antenna_m(t.time_s);
                let (east, north) = (t.position_m[0] - own.x, t.position_m[1] - own.y);
                ttm(
                    "RA",
                    &TrackedTarget {
                        number,
                        distance_m: east.hypot(north),
                        bearing_deg: east.atan2(north).to_degrees().rem_euclid(360.0),
                        speed_kn: t.speed_kn,
                        course_deg: t.course_deg,
                        cpa_m: t.cpa_m,
                        tcpa_s: t.tcpa_s,
                        name: String::new(),
                        status: 'T',
                        unix_s: source.start_unix_s + t.time_s,
                    },
                )
                .ok()
            })
            .collect()
    }
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
        let mut arpa = match source.arpa.then(|| Arpa::new(source)).transpose() {
            Ok(a) => a,
            Err(e) => {
                eprintln!("xbandsim serve: the radar's tracker: {e}");
                live.stop();
                return;
            }
        };
        for k in 0.. {
            if live.stopping() || live.generation() != generation {
                break;
            }
            let t0 = Instant::now();
            let outputs = xbandsim::engine::Outputs {
                radial_velocity: source.doppler,
                ..Default::default()
            };
            let request = Request::new(source.seed).frame(k).outputs(outputs);
            let frame = match source.sim.run(&request) {
                Ok(f) => f,
                Err(e) => {
                    eprintln!("xbandsim serve: revolution {k} failed: {e}");
                    live.stop();
                    return;
                }
            };
            let render_s = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let ttm = arpa
                .as_mut()
                .map_or_else(Vec::new, |a| a.ttm(source, &frame));
            let tracker_s = t1.elapsed().as_secs_f64();
            let mut item = Rendered {
                generation,
                frame,
                render_s,
                tracker_s,
                ttm,
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
    let n = source.spokes();
    let per_message = n.div_ceil(MESSAGES_PER_REVOLUTION).max(1);
    let period_s = source.period_s();
    let mut history = EchoHistory::default();
    let mut history_generation = live.generation();
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
        // The video with the controls as they are now, while scenario time waits at this
        // revolution's start (the last barrier).
        let t0 = Instant::now();
        let controls = live.controls();
        let mut video = video_of(source, &r.frame, &controls, &mut history);
        if let (Some(rv), Some(codes)) = (&r.frame.radial_velocity, doppler_codes(video.bits)) {
            mark_doppler(&mut video, rv, r.frame.range_bin_m, codes);
        }
        let video_s = t0.elapsed().as_secs_f64();
        let range_m = controls.range_m.min(source.max_range_m());
        // Scenario time may run to this revolution's end: it waits there for the next one,
        // so no spoke is skipped or sent in a burst, and nothing else runs ahead.
        live.set_barrier(r.generation, start_s + period_s);
        let mut last_due_s = start_s;
        for from in (0..n).step_by(per_message) {
            let to = (from + per_message).min(n);
            let due_s = start_s + (to - 1) as f64 / n as f64 * period_s;
            match live.wait_until(due_s, r.generation) {
                Wait::Due => {}
                Wait::Restarted => break,
                Wait::Stopping => return,
            }
            let m = spoke_message(source, &video, range_m, start_s, from, to);
            live.send_spokes(r.generation, due_s, Bytes::from(m.encode_to_vec()));
            last_due_s = due_s;
        }
        if !r.ttm.is_empty() {
            let text = Bytes::from(r.ttm.concat());
            live.send_nmea(r.generation, last_due_s, text, r.ttm.len() as u64);
        }
        if r.generation == live.generation() {
            let mut c = live.counters.lock().unwrap_or_else(|e| e.into_inner());
            c.revolutions += 1;
            c.last_render_s = r.render_s;
            c.last_video_s = video_s;
            c.last_tracker_s = r.tracker_s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use xbandsim::products::RadialVelocity;

    /// Numbers go to confirmed tracks lowest first, stay with them, and are freed when their
    /// track ends; a 100th track gets none.
    #[test]
    fn target_numbers_are_unique_and_reused() {
        let mut n = TargetNumbers::default();
        assert_eq!(n.assign(&[7, 9, 12], &[9, 12]), vec![Some(1), Some(2)]);
        assert_eq!(n.assign(&[9, 12, 205], &[205, 12]), vec![Some(3), Some(2)]);
        // Track 9 ends: its number goes to the next one confirmed.
        assert_eq!(
            n.assign(&[12, 205, 309], &[309, 205]),
            vec![Some(1), Some(3)]
        );
        let many: Vec<u32> = (1000..1100).collect();
        let got = n.assign(&many, &many);
        assert_eq!(got.iter().filter(|k| k.is_some()).count(), 99);
        assert_eq!(got[99], None);
    }

    /// A record of 4 spokes × 10 bins of 10 m: a closing echo in spoke 1, bins 4–5, an
    /// opening one in spoke 3, bin 9, a slow one in spoke 0; video of 8 spokes × 5 samples of
    /// 20 m, every sample shown. Each video sample takes its code from the cell nearest it:
    /// video spoke s reads record spoke `(4s + 4)/8 mod 4` (1 for s = 1, 2; 3 for s = 5, 6),
    /// sample j the bin at its centre `(j + ½)·20 m` (bin 5 for j = 2, bin 9 for j = 4).
    #[test]
    fn doppler_codes_mark_closing_and_opening_echoes() {
        let (spokes, bins) = (4, 10);
        let mut velocity = vec![0f32; spokes * bins];
        velocity[14] = -5.0;
        velocity[15] = -5.0;
        velocity[39] = 4.0;
        velocity[2] = -1.0;
        let rv = RadialVelocity {
            spokes,
            range_bins: bins,
            velocity_mps: velocity,
            estimated: vec![true; spokes * bins],
            power_db: vec![20.0; spokes * bins],
            unambiguous_mps: 10.0,
        };
        let mut video = Video {
            spokes: 8,
            samples: 5,
            bits: 4,
            sample_m: 20.0,
            threshold_db: 6.0,
            level_step_db: 2.0,
            levels: vec![3; 40],
        };
        video.levels[0] = 0;
        let codes = doppler_codes(4).unwrap();
        assert_eq!(codes, (16, 17));
        assert_eq!(doppler_codes(8), None);
        mark_doppler(&mut video, &rv, 10.0, codes);
        let marked: Vec<(usize, u8)> = video
            .levels
            .iter()
            .enumerate()
            .filter(|(_, &l)| l >= 16)
            .map(|(k, &l)| (k, l))
            .collect();
        assert_eq!(marked, vec![(7, 16), (12, 16), (29, 17), (34, 17)]);
        // Cells below 10 dB over the noise are not marked, whatever the video shows.
        let mut dim = video.clone();
        dim.levels = vec![3; 40];
        let faint = RadialVelocity {
            power_db: vec![9.0; spokes * bins],
            ..rv.clone()
        };
        mark_doppler(&mut dim, &faint, 10.0, codes);
        assert!(dim.levels.iter().all(|&l| l == 3));
    }
}
