//! `xbandsim nmea`: what the scenario's navigation network would carry (docs/live.md): the
//! own ship's GPS fix and true heading once a second (GGA, RMC, VTG, HDT) and the AIS
//! reports of every object with an `mmsi` at the ITU-R M.1371 reporting intervals, as an NMEA
//! 0183 log in time order, with a truth file saying what each report was made from.

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use xbandsim::land::projection::LocalProjection;
use xbandsim::model::motion::{course_of, KNOT_M_PER_S};
use xbandsim::scene::AisClass;
use xbandsim_nmea::ais;
use xbandsim_nmea::sentence::{gga, hdt, rmc, vtg, Fix};

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

/// Seconds after 1970-01-01T00:00:00Z of `YYYY-MM-DDTHH:MM:SSZ`.
fn parse_utc(text: &str) -> Option<f64> {
    let t = text.trim().strip_suffix('Z')?;
    let (date, time) = t.split_once('T')?;
    let mut d = date.split('-').map(|x| x.parse::<i64>().ok());
    let (y, m, day) = (d.next()??, d.next()??, d.next()??);
    let mut h = time.split(':').map(|x| x.parse::<f64>().ok());
    let (hh, mm, ss) = (h.next()??, h.next()??, h.next()??);
    if d.next().is_some() || h.next().is_some() {
        return None;
    }
    let ok = (1..=12).contains(&m)
        && (1..=31).contains(&day)
        && (0.0..24.0).contains(&hh)
        && (0.0..60.0).contains(&mm)
        && (0.0..60.0).contains(&ss)
        && hh.fract() == 0.0
        && mm.fract() == 0.0
        && ss.fract() == 0.0;
    if !ok {
        return None;
    }
    // Days from 1970-01-01 of the proleptic Gregorian date (years counted from March).
    let (y, m) = if m <= 2 { (y - 1, m + 9) } else { (y, m - 3) };
    let era = y.div_euclid(400);
    let year_of_era = y.rem_euclid(400);
    let day_of_year = (153 * m + 2) / 5 + day - 1;
    let day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
    let days = era * 146_097 + day_of_era - 719_468;
    let unix_s = days as f64 * 86_400.0 + hh * 3600.0 + mm * 60.0 + ss;
    // A day past its month's end (2026-02-31) comes back as another date: refused.
    let back = xbandsim_nmea::sentence::UtcTime::from_unix_s(unix_s);
    let (year, month) = if m >= 10 { (y + 1, m - 9) } else { (y, m + 3) };
    (back.year == year && i64::from(back.month) == month && i64::from(back.day) == day)
        .then_some(unix_s)
}

/// AIS ship and cargo type of an object class of the target library (ITU-R M.1371 Table
/// 53; 0: not available).
fn ship_type(class: &str) -> u8 {
    match class {
        "container_ship" | "bulk_carrier" | "cargo_ship" | "cargo" | "ship" => 70,
        "tanker" => 80,
        "ferry" | "passenger" => 60,
        "fishing_vessel" | "trawler" => 30,
        "sailing_yacht" | "yacht" => 36,
        "pilot_boat" => 50,
        "tug" => 52,
        "motorboat" | "rib" | "pleasure_craft" | "boat" => 37,
        _ => 0,
    }
}

/// `text` in the characters AIS text carries, at most `chars` of them (others become
/// spaces).
fn ais_text(text: &str, chars: usize) -> String {
    text.to_ascii_uppercase()
        .chars()
        .map(|c| if (' '..='_').contains(&c) { c } else { ' ' })
        .take(chars)
        .collect()
}

/// The schedule's tick, s: a third of a second, so that every reporting interval is a
/// whole number of ticks and times add up exactly.
const TICK_S: f64 = 1.0 / 3.0;

/// A class A ship's reporting interval (ITU-R M.1371-5 Table 1), ticks: by speed, shorter
/// while changing course; 3 minutes at anchor (below 0.1 kn here).
fn class_a_interval_ticks(speed_kn: f64, turning: bool) -> u64 {
    match (speed_kn, turning) {
        (s, _) if s < 0.1 => 540,      // 3 min
        (s, false) if s <= 14.0 => 30, // 10 s
        (s, true) if s <= 14.0 => 10,  // 3⅓ s
        (s, false) if s <= 23.0 => 18, // 6 s
        _ => 6,                        // 2 s
    }
}

/// A class B CS unit's reporting interval (ITU-R M.1371-5 Table 2), ticks: 30 s above 2 kn,
/// 3 minutes below.
fn class_b_interval_ticks(speed_kn: f64) -> u64 {
    if speed_kn <= 2.0 {
        540
    } else {
        90
    }
}

/// Static data go out at the start and every 6 minutes, ticks.
const STATIC_INTERVAL_TICKS: u64 = 1080;

/// A ship is changing course while its heading turns 5° in 30 s or faster (10°/min): the
/// rule of thumb of class A test standards for Table 1's "changing course".
const TURNING_DEG_PER_MIN: f64 = 10.0;

/// One AIS message to send, framed into sentences once the log is in time order.
struct Message {
    id: u8,
    bits: ais::Bits,
}

/// One moment of one source: its tick, its place in the log's order at that tick (0 the own
/// ship, then the transponders in scene order), its NMEA sentences, its AIS messages and
/// its truth.
struct Event<'a> {
    tick: u64,
    order: usize,
    sentences: Vec<String>,
    messages: Vec<Message>,
    truth: TruthLine<'a>,
}

#[derive(Serialize)]
struct TruthLine<'a> {
    time_s: f64,
    unix_s: f64,
    source: &'a str,
    mmsi: Option<u32>,
    messages: Vec<u8>,
    position_m: [f64; 2],
    lon_deg: f64,
    lat_deg: f64,
    velocity_mps: [f64; 2],
    heading_deg: f64,
    sentences: usize,
}

/// Runs `xbandsim nmea`.
pub fn run(a: &NmeaArgs) -> Result<()> {
    if !(a.duration_s.is_finite() && a.duration_s > 0.0) {
        bail!(
            "invalid --duration-s {}: must be a positive number of seconds",
            a.duration_s
        );
    }
    let Some(start_unix_s) = parse_utc(&a.start_utc) else {
        bail!(
            "invalid --start-utc {:?}: must be YYYY-MM-DDTHH:MM:SSZ, e.g. 2026-01-01T00:00:00Z",
            a.start_utc
        );
    };
    let spec = crate::render::load_spec(&a.scene, &a.set)?;
    let Some(geo) = spec.spec().geo.as_ref() else {
        bail!(
            "{}: the scene has no [geo] origin, so its positions have no latitude and longitude: add one (docs/formats.md, \"[[land]] and [geo]\"), e.g. --set geo.origin_lat_deg=50.36 --set geo.origin_lon_deg=-4.14",
            a.scene.display()
        );
    };
    let (Some(lon0), Some(lat0)) = (geo.origin_lon_deg, geo.origin_lat_deg) else {
        bail!(
            "{}: [geo] needs origin_lon_deg and origin_lat_deg",
            a.scene.display()
        );
    };
    let scene = spec.build()?;
    let projection = LocalProjection::new(lon0, lat0);
    let radar_m = scene.radar().position_m();
    // The transponders: (object index, MMSI, class), in scene order.
    let transponders: Vec<(usize, u32, AisClass)> = spec
        .spec()
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| o.mmsi.map(|m| (i, m, o.ais_class.unwrap_or_default())))
        .collect();
    // Events: (tick, order, own-ship sentences or AIS messages, truth): the own ship at
    // every whole second, each transponder when its interval has passed; in time order, the
    // own ship first, then the transponders in scene order.
    let last_tick = (a.duration_s / TICK_S + 1e-9).floor() as u64;
    let mut events: Vec<Event> = Vec::new();
    for tick in (0..=last_tick).step_by(3) {
        let t = tick as f64 * TICK_S;
        let (position, velocity, heading_rad) = match scene.own_ship() {
            Some(s) => (
                radar_m + s.displacement_m(t),
                s.velocity_mps(),
                s.heading_rad(),
            ),
            None => (radar_m, glam::DVec3::ZERO, 0.0),
        };
        let (lon, lat) = projection.to_lon_lat_deg(position.truncate());
        let fix = Fix {
            unix_s: start_unix_s + t,
            lat_deg: lat,
            lon_deg: lon,
            altitude_m: position.z,
            sog_kn: velocity.x.hypot(velocity.y) / KNOT_M_PER_S,
            cog_deg: course_of(velocity).map(f64::to_degrees),
            heading_deg: heading_rad.to_degrees(),
        };
        let mut group = vec![gga("GP", &fix)?, rmc("GP", &fix)?, vtg("GP", &fix)];
        if scene.own_ship().is_some() {
            group.push(hdt("HE", &fix));
        }
        let truth = TruthLine {
            time_s: t,
            unix_s: fix.unix_s,
            source: "own_ship",
            mmsi: None,
            messages: Vec::new(),
            position_m: [position.x, position.y],
            lon_deg: lon,
            lat_deg: lat,
            velocity_mps: [velocity.x, velocity.y],
            heading_deg: fix.heading_deg,
            sentences: group.len(),
        };
        events.push(Event {
            tick,
            order: 0,
            sentences: group,
            messages: Vec::new(),
            truth,
        });
    }
    for (order, &(i, mmsi, class)) in transponders.iter().enumerate() {
        let o = &scene.objects()[i];
        let bounds = o.local_bounds();
        let static_data = ais::StaticData {
            mmsi,
            imo: 0,
            call_sign: String::new(),
            name: ais_text(o.name(), 20),
            ship_type: ship_type(o.class()),
            to_bow_m: bounds.max.y.max(0.0).round() as u32,
            to_stern_m: (-bounds.min.y).max(0.0).round() as u32,
            to_port_m: (-bounds.min.x).max(0.0).round() as u32,
            to_starboard_m: bounds.max.x.max(0.0).round() as u32,
            draught_m: 0.0,
            destination: String::new(),
        };
        // Every tick, the interval the object's state asks for now, or the one it had at its
        // last report if that is shorter: a boat that gets under way is reported at once, not
        // when its anchored interval runs out, and one that stops still makes the report its
        // last state promised.
        let mut last_report: Option<(u64, u64)> = None;
        let mut next_static = 0u64;
        for tick in 0..=last_tick {
            let t = tick as f64 * TICK_S;
            let mut kin = o.kinematics(t);
            if tick == 0 {
                // At t = 0 a track's object is at its first waypoint with no velocity yet:
                // it moves off along the first leg.
                kin.velocity_mps = o.kinematics(1e-3).velocity_mps;
            }
            let heading_deg = kin.heading_rad.to_degrees();
            // Rate of turn from the heading a second either side, °/min.
            let ahead = o.kinematics(t + 1.0).heading_rad.to_degrees();
            let behind = o.kinematics((t - 1.0).max(0.0)).heading_rad.to_degrees();
            let span_s = t + 1.0 - (t - 1.0).max(0.0);
            let turn = (ahead - behind + 540.0).rem_euclid(360.0) - 180.0;
            let rot_deg_per_min = turn / span_s * 60.0;
            let speed_kn = kin.speed_mps() / KNOT_M_PER_S;
            let turning = rot_deg_per_min.abs() >= TURNING_DEG_PER_MIN;
            let interval = match class {
                AisClass::A => class_a_interval_ticks(speed_kn, turning),
                AisClass::B => class_b_interval_ticks(speed_kn),
            };
            if last_report.is_some_and(|(last, promised)| tick - last < interval.min(promised)) {
                continue;
            }
            last_report = Some((tick, interval));
            let (lon, lat) = projection.to_lon_lat_deg(kin.position_m.truncate());
            let unix_s = start_unix_s + t;
            let second = unix_s.rem_euclid(60.0).floor() as u32;
            let cog_deg = course_of(kin.velocity_mps).map(f64::to_degrees);
            let mut messages = Vec::new();
            if tick >= next_static {
                match class {
                    AisClass::A => messages.push(Message {
                        id: 5,
                        bits: ais::static_and_voyage(&static_data)?,
                    }),
                    AisClass::B => {
                        messages.push(Message {
                            id: 24,
                            bits: ais::static_part_a(&static_data)?,
                        });
                        messages.push(Message {
                            id: 24,
                            bits: ais::static_part_b(&static_data)?,
                        });
                    }
                }
                next_static = tick + STATIC_INTERVAL_TICKS;
            }
            let motion = ais::ReportedMotion {
                sog_kn: Some(speed_kn),
                high_accuracy: false,
                lon_deg: Some(lon),
                lat_deg: Some(lat),
                cog_deg,
                heading_deg: Some(heading_deg),
                second: Some(second),
            };
            messages.push(match class {
                AisClass::A => Message {
                    id: 1,
                    bits: ais::class_a_position(&ais::ClassAPosition {
                        message_type: 1,
                        mmsi,
                        nav_status: if speed_kn < 0.1 { 1 } else { 0 },
                        rot_deg_per_min: Some(rot_deg_per_min),
                        motion,
                        raim: false,
                        radio: 0,
                    })?,
                },
                AisClass::B => Message {
                    id: 18,
                    bits: ais::class_b_position(&ais::ClassBPosition { mmsi, motion })?,
                },
            });
            let truth = TruthLine {
                time_s: t,
                unix_s,
                source: o.name(),
                mmsi: Some(mmsi),
                messages: messages.iter().map(|m| m.id).collect(),
                position_m: [kin.position_m.x, kin.position_m.y],
                lon_deg: lon,
                lat_deg: lat,
                velocity_mps: [kin.velocity_mps.x, kin.velocity_mps.y],
                heading_deg,
                sentences: 0,
            };
            events.push(Event {
                tick,
                order: order + 1,
                sentences: Vec::new(),
                messages,
                truth,
            });
        }
    }
    events.sort_by_key(|e| (e.tick, e.order));
    // Frame the AIS messages in log order: radio channels alternate A, B; a message of
    // several fragments takes the next sequence number, 0–9.
    let (mut channel_b, mut sequence) = (false, 0u8);
    let mut log = String::new();
    let mut truths = Vec::with_capacity(events.len());
    for event in events {
        let (mut group, mut truth) = (event.sentences, event.truth);
        for m in &event.messages {
            let channel = if channel_b { 'B' } else { 'A' };
            channel_b = !channel_b;
            let framed = ais::sentences(&m.bits, "AI", false, channel, sequence);
            if framed.len() > 1 {
                sequence = (sequence + 1) % 10;
            }
            group.extend(framed);
        }
        truth.sentences = group.len();
        log.extend(group);
        truths.push(truth);
    }
    let truth_text = match &a.truth {
        Some(_) => {
            let mut s = String::new();
            for t in &truths {
                s.push_str(&serde_json::to_string(t)?);
                s.push('\n');
            }
            Some(s)
        }
        None => None,
    };
    // Both are made before either is written; each is replaced whole.
    xbandsim::products::output::write_atomic(&a.out, log.as_bytes())
        .with_context(|| format!("writing {}", a.out.display()))?;
    if let (Some(path), Some(text)) = (&a.truth, truth_text) {
        xbandsim::products::output::write_atomic(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    crate::say!(
        "nmea {}: {:.0} s from {}, own ship and {} AIS transponders, {} sentences -> {}",
        a.scene.display(),
        a.duration_s,
        a.start_utc,
        transponders.len(),
        log.lines().count(),
        a.out.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_times_read_as_posix_seconds() {
        assert_eq!(parse_utc("1970-01-01T00:00:00Z"), Some(0.0));
        assert_eq!(parse_utc("2000-03-01T00:00:00Z"), Some(11_017.0 * 86_400.0));
        assert_eq!(
            parse_utc("2026-12-07T12:34:56Z"),
            Some(20_794.0 * 86_400.0 + 45_296.0)
        );
        assert_eq!(parse_utc("2026-13-01T00:00:00Z"), None);
        assert_eq!(parse_utc("2026-02-31T00:00:00Z"), None);
        assert_eq!(parse_utc("2024-02-29T00:00:00Z"), Some(19_782.0 * 86_400.0));
        assert_eq!(parse_utc("2026-01-01T00:00:00.5Z"), None);
        assert_eq!(parse_utc("2026-01-01 00:00:00"), None);
    }
}
