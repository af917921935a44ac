//! The scenario's navigation feed (docs/live.md, "NMEA 0183 and AIS"): tick by tick, what the
//! own ship's GPS and compass and an AIS receiver would put on the ship's NMEA 0183 network —
//! GGA, RMC, VTG and HDT once a second, and the AIS reports of every object with an `mmsi` at
//! the reporting intervals of ITU-R M.1371-5 Tables 1 and 2, with static data every 6 minutes
//! — each group with the truth it was made from. `xbandsim nmea` writes a scenario's feed to a
//! log, `xbandsim serve` sends it live; both run [`NmeaFeed`], so the two agree line for line.

use crate::error::{Result, ServeError};
use serde::Serialize;
use xbandsim::land::projection::LocalProjection;
use xbandsim::model::motion::{course_of, KNOT_M_PER_S};
use xbandsim::model::Scene;
use xbandsim::scene::{AisClass, SceneSpec};
use xbandsim_nmea::ais;
use xbandsim_nmea::sentence::{gga, hdt, rmc, vtg, Fix};

/// The feed's tick, s: a third of a second, so that every reporting interval is a whole
/// number of ticks and times add up exactly.
pub const TICK_S: f64 = 1.0 / 3.0;

/// Ticks between the own ship's fixes (one a second).
pub const FIX_INTERVAL_TICKS: u64 = 3;

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

/// What one group of lines was made from: a line of the truth file (docs/formats.md,
/// "nmea truth").
#[derive(Debug, Clone, Serialize)]
pub struct FeedTruth {
    /// Scenario time, s.
    pub time_s: f64,
    /// UTC time, s after 1970-01-01T00:00:00Z.
    pub unix_s: f64,
    /// `own_ship`, or the object's name.
    pub source: String,
    /// The transponder's MMSI (None for the own ship).
    pub mmsi: Option<u32>,
    /// The AIS message ids sent (empty for the own ship).
    pub messages: Vec<u8>,
    /// ENU position, m.
    pub position_m: [f64; 2],
    /// Longitude, degrees.
    pub lon_deg: f64,
    /// Latitude, degrees.
    pub lat_deg: f64,
    /// ENU velocity, m/s.
    pub velocity_mps: [f64; 2],
    /// True heading, degrees.
    pub heading_deg: f64,
    /// Lines in the group.
    pub sentences: usize,
}

/// One source's lines at one tick.
#[derive(Debug, Clone)]
pub struct FeedGroup {
    /// The tick (`tick · TICK_S` is the scenario time).
    pub tick: u64,
    /// The sentences, each ending CR LF.
    pub lines: Vec<String>,
    /// What they were made from.
    pub truth: FeedTruth,
}

/// One AIS transponder and its schedule.
#[derive(Debug, Clone)]
struct Transponder {
    object: usize,
    mmsi: u32,
    class: AisClass,
    static_data: ais::StaticData,
    /// The tick of its last position report and the interval it promised then.
    last_report: Option<(u64, u64)>,
    next_static: u64,
}

/// The feed of one scenario: call [`NmeaFeed::tick`] with ticks 0, 1, 2, ... in turn.
#[derive(Debug, Clone)]
pub struct NmeaFeed {
    projection: LocalProjection,
    start_unix_s: f64,
    transponders: Vec<Transponder>,
    channel_b: bool,
    sequence: u8,
    next_tick: u64,
}

/// The `[geo]` origin of a scene spec, (longitude, latitude), degrees.
pub fn geo_origin(spec: &SceneSpec) -> Result<(f64, f64)> {
    let Some(geo) = spec.geo.as_ref() else {
        return Err(ServeError::NoGeoOrigin);
    };
    match (geo.origin_lon_deg, geo.origin_lat_deg) {
        (Some(lon), Some(lat)) => Ok((lon, lat)),
        _ => Err(ServeError::NoGeoOrigin),
    }
}

impl NmeaFeed {
    /// The feed of `scene` (built from `spec`), placed on the globe at `spec`'s `[geo]`
    /// origin, its t = 0 at `start_unix_s` (UTC, s after 1970).
    pub fn new(spec: &SceneSpec, scene: &Scene, start_unix_s: f64) -> Result<NmeaFeed> {
        let (lon0, lat0) = geo_origin(spec)?;
        let transponders = spec
            .objects
            .iter()
            .enumerate()
            .filter_map(|(i, o)| o.mmsi.map(|m| (i, m, o.ais_class.unwrap_or_default())))
            .map(|(i, mmsi, class)| {
                let o = &scene.objects()[i];
                let bounds = o.local_bounds();
                Transponder {
                    object: i,
                    mmsi,
                    class,
                    static_data: ais::StaticData {
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
                    },
                    last_report: None,
                    next_static: 0,
                }
            })
            .collect();
        Ok(NmeaFeed {
            projection: LocalProjection::new(lon0, lat0),
            start_unix_s,
            transponders,
            channel_b: false,
            sequence: 0,
            next_tick: 0,
        })
    }

    /// How many objects carry a transponder.
    pub fn transponders(&self) -> usize {
        self.transponders.len()
    }

    /// The next tick [`NmeaFeed::tick`] makes.
    pub fn next_tick(&self) -> u64 {
        self.next_tick
    }

    /// The groups of the next tick, in the log's order: the own ship first (on whole
    /// seconds), then the transponders that report, in scene order. AIS messages are framed
    /// in that order: radio channels alternate A, B, and a message of several fragments takes
    /// the next sequence number, 0–9.
    pub fn tick(&mut self, scene: &Scene) -> Result<Vec<FeedGroup>> {
        let tick = self.next_tick;
        self.next_tick += 1;
        let t = tick as f64 * TICK_S;
        let unix_s = self.start_unix_s + t;
        let mut groups = Vec::new();
        if tick.is_multiple_of(FIX_INTERVAL_TICKS) {
            groups.push(self.own_ship(scene, tick, t, unix_s)?);
        }
        for k in 0..self.transponders.len() {
            if let Some(g) = self.transponder(scene, k, tick, t, unix_s)? {
                groups.push(g);
            }
        }
        Ok(groups)
    }

    fn own_ship(&self, scene: &Scene, tick: u64, t: f64, unix_s: f64) -> Result<FeedGroup> {
        let radar_m = scene.radar().position_m();
        let (position, velocity, heading_rad) = match scene.own_ship() {
            Some(s) => (
                radar_m + s.displacement_m(t),
                s.velocity_mps(),
                s.heading_rad(),
            ),
            None => (radar_m, glam::DVec3::ZERO, 0.0),
        };
        let (lon, lat) = self.projection.to_lon_lat_deg(position.truncate());
        let fix = Fix {
            unix_s,
            lat_deg: lat,
            lon_deg: lon,
            altitude_m: position.z,
            sog_kn: velocity.x.hypot(velocity.y) / KNOT_M_PER_S,
            cog_deg: course_of(velocity).map(f64::to_degrees),
            heading_deg: heading_rad.to_degrees(),
        };
        let mut lines = vec![gga("GP", &fix)?, rmc("GP", &fix)?, vtg("GP", &fix)];
        if scene.own_ship().is_some() {
            lines.push(hdt("HE", &fix));
        }
        let truth = FeedTruth {
            time_s: t,
            unix_s,
            source: "own_ship".to_string(),
            mmsi: None,
            messages: Vec::new(),
            position_m: [position.x, position.y],
            lon_deg: lon,
            lat_deg: lat,
            velocity_mps: [velocity.x, velocity.y],
            heading_deg: fix.heading_deg,
            sentences: lines.len(),
        };
        Ok(FeedGroup { tick, lines, truth })
    }

    /// Transponder `k`'s group at `tick`, if it reports then. Every tick it takes the
    /// interval the object's state asks for now, or the one it had at its last report if
    /// that is shorter: a boat that gets under way is reported at once, not when its
    /// anchored interval runs out, and one that stops still makes the report its last state
    /// promised.
    fn transponder(
        &mut self,
        scene: &Scene,
        k: usize,
        tick: u64,
        t: f64,
        unix_s: f64,
    ) -> Result<Option<FeedGroup>> {
        let (object, mmsi, class) = {
            let x = &self.transponders[k];
            (x.object, x.mmsi, x.class)
        };
        let o = &scene.objects()[object];
        let mut kin = o.kinematics(t);
        if tick == 0 {
            // At t = 0 a track's object is at its first waypoint with no velocity yet: it
            // moves off along the first leg.
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
        let x = &mut self.transponders[k];
        if x.last_report
            .is_some_and(|(last, promised)| tick - last < interval.min(promised))
        {
            return Ok(None);
        }
        x.last_report = Some((tick, interval));
        let (lon, lat) = self.projection.to_lon_lat_deg(kin.position_m.truncate());
        let second = unix_s.rem_euclid(60.0).floor() as u32;
        let cog_deg = course_of(kin.velocity_mps).map(f64::to_degrees);
        let mut messages: Vec<(u8, ais::Bits)> = Vec::new();
        if tick >= x.next_static {
            match class {
                AisClass::A => messages.push((5, ais::static_and_voyage(&x.static_data)?)),
                AisClass::B => {
                    messages.push((24, ais::static_part_a(&x.static_data)?));
                    messages.push((24, ais::static_part_b(&x.static_data)?));
                }
            }
            x.next_static = tick + STATIC_INTERVAL_TICKS;
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
            AisClass::A => (
                1,
                ais::class_a_position(&ais::ClassAPosition {
                    message_type: 1,
                    mmsi,
                    nav_status: if speed_kn < 0.1 { 1 } else { 0 },
                    rot_deg_per_min: Some(rot_deg_per_min),
                    motion,
                    raim: false,
                    radio: 0,
                })?,
            ),
            AisClass::B => (
                18,
                ais::class_b_position(&ais::ClassBPosition { mmsi, motion })?,
            ),
        });
        let mut lines = Vec::new();
        for (_, bits) in &messages {
            let channel = if self.channel_b { 'B' } else { 'A' };
            self.channel_b = !self.channel_b;
            let framed = ais::sentences(bits, "AI", false, channel, self.sequence);
            if framed.len() > 1 {
                self.sequence = (self.sequence + 1) % 10;
            }
            lines.extend(framed);
        }
        let truth = FeedTruth {
            time_s: t,
            unix_s,
            source: o.name().to_string(),
            mmsi: Some(mmsi),
            messages: messages.iter().map(|m| m.0).collect(),
            position_m: [kin.position_m.x, kin.position_m.y],
            lon_deg: lon,
            lat_deg: lat,
            velocity_mps: [kin.velocity_mps.x, kin.velocity_mps.y],
            heading_deg,
            sentences: lines.len(),
        };
        Ok(Some(FeedGroup { tick, lines, truth }))
    }
}

/// Starts the feed's thread: each tick's groups when scenario time reaches it, to every NMEA
/// client, the UDP address and the recording. `fresh` is the feed at tick 0; a restart
/// starts from a copy of it.
pub fn spawn(
    live: std::sync::Arc<crate::live::Live>,
    source: std::sync::Arc<crate::radar::RadarSource>,
    fresh: NmeaFeed,
) -> std::thread::JoinHandle<()> {
    use crate::live::Wait;
    std::thread::Builder::new()
        .name("xbandsim-nmea".into())
        .spawn(move || {
            let scene = source.sim.scene();
            while !live.stopping() {
                let generation = live.generation();
                let mut feed = fresh.clone();
                loop {
                    let t_s = feed.next_tick() as f64 * TICK_S;
                    match live.wait_until(t_s, generation) {
                        Wait::Due => {}
                        Wait::Restarted => break,
                        Wait::Stopping => return,
                    }
                    let groups = match feed.tick(scene) {
                        Ok(g) => g,
                        Err(e) => {
                            eprintln!("xbandsim serve: the NMEA feed stopped at {t_s:.1} s: {e}");
                            return;
                        }
                    };
                    for g in groups {
                        let text: String = g.lines.concat();
                        live.send_nmea(
                            generation,
                            t_s,
                            bytes::Bytes::from(text),
                            g.lines.len() as u64,
                        );
                    }
                }
            }
        })
        .expect("a thread starts")
}
