//! Model: motion — how an object or the own ship moves with time (docs/formats.md, "Motion";
//! docs/physics.md, "Motion"). A path gives the reference point's horizontal position and
//! velocity; a heading rule turns the object; wave-induced motion adds heave, roll and pitch.
//!
//! - Steady path: a constant velocity whose horizontal part turns at a constant rate ω
//!   (nautical rate of turn, positive to starboard = clockwise from above). With course
//!   c(t) = c0 + ω·t and horizontal speed s the position is the closed-form circle
//!   `east = e0 + s·(cos c0 − cos c(t))/ω`, `north = n0 + s·(sin c(t) − sin c0)/ω`
//!   (straight `p0 + v·t` when ω = 0).
//! - Track: piecewise-linear waypoints `(t, east, north)`; the object rests at the first
//!   waypoint before its time and at the last after it.
//! - Wave-induced motion: `z += A_h·sin(2πt/T + φ)`, roll `A_r·sin(2πt/T + φ)`, pitch
//!   `A_p·cos(2πt/T + φ)` (pitch a quarter period ahead of roll), all about the object's own
//!   axes.

use super::checks::finite;
use crate::error::{Error, Problem, Result};
use crate::geometry::object_frame;
use glam::{DMat3, DVec3};
use std::f64::consts::TAU;

/// One international knot, m/s (1852 m per hour; BIPM SI brochure, 9th ed., Table 8).
pub const KNOT_M_PER_S: f64 = 1852.0 / 3600.0;

/// Fastest an object or the own ship may move, knots: above the water speed record (about
/// 276 kn, set in 1978), so any craft on the water and a helicopter low over it fit, and a
/// typo (`speed_kn = 1e9`) is refused.
pub const MAX_SPEED_KN: f64 = 300.0;

/// `speed_kn` if it is finite, 0 or more and at most [`MAX_SPEED_KN`]; else an error at
/// `field`.
pub fn check_speed_kn(field: &str, speed_kn: f64) -> Result<f64> {
    finite(field, speed_kn)?;
    if speed_kn < 0.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            field,
            speed_kn,
            "must be 0 or more (give the direction with course_deg)",
        ));
    }
    if speed_kn > MAX_SPEED_KN {
        return Err(Error::invalid(
            Problem::OutOfRange,
            field,
            speed_kn,
            format!(
                "must be at most {MAX_SPEED_KN} kn, above the water speed record (about 276 kn)"
            ),
        ));
    }
    Ok(speed_kn)
}

/// Horizontal speeds below this are "not moving": the course is undefined (null).
pub const STILL_SPEED_M_PER_S: f64 = 1e-9;

/// A waypoint of a track: time, east and north.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waypoint {
    /// Time, s.
    pub time_s: f64,
    /// East, m.
    pub east_m: f64,
    /// North, m.
    pub north_m: f64,
}

/// Where the reference point goes.
#[derive(Debug, Clone, PartialEq)]
pub enum Trajectory {
    /// From the object's position at t = 0 with `velocity_mps` (ENU), the horizontal part
    /// turning at `turn_rate_rad_per_s` (positive clockwise from above).
    Steady {
        /// Velocity at t = 0, ENU m/s.
        velocity_mps: DVec3,
        /// Rate of turn, rad/s.
        turn_rate_rad_per_s: f64,
    },
    /// Piecewise-linear through waypoints in strictly increasing time (at least two).
    Track {
        /// The waypoints.
        points: Vec<Waypoint>,
    },
}

/// Which way the object points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HeadingRule {
    /// The bow (the object's +y) follows the course over ground; while the object stands
    /// still it keeps the course of its nearest motion (0 = north if it never moves).
    AlongCourse,
    /// A fixed heading, rad (nautical), e.g. a vessel crabbing in a current.
    Fixed(f64),
}

/// Wave-induced motion about the object's own axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaveMotion {
    /// Heave amplitude, m.
    pub heave_amplitude_m: f64,
    /// Roll amplitude, rad.
    pub roll_amplitude_rad: f64,
    /// Pitch amplitude, rad.
    pub pitch_amplitude_rad: f64,
    /// Period, s.
    pub period_s: f64,
    /// Phase at t = 0, rad.
    pub phase_rad: f64,
}

impl WaveMotion {
    /// Checks the amplitudes (finite, ≥ 0, roll and pitch at most 60°), the phase (finite) and
    /// the period (finite, > 0); errors name `{prefix}.field`.
    fn check(&self, prefix: &str) -> Result<()> {
        let f = |name: &str| format!("{prefix}.{name}");
        for (name, v, max) in [
            ("heave_amplitude_m", self.heave_amplitude_m, f64::INFINITY),
            (
                "roll_amplitude_deg",
                self.roll_amplitude_rad.to_degrees(),
                60.0,
            ),
            (
                "pitch_amplitude_deg",
                self.pitch_amplitude_rad.to_degrees(),
                60.0,
            ),
        ] {
            finite(&f(name), v)?;
            if !(0.0..=max).contains(&v) {
                return Err(invalid(&f(name), v, format!("must be from 0 to {max}")));
            }
        }
        finite(&f("motion_phase_deg"), self.phase_rad)?;
        if !(self.period_s.is_finite() && self.period_s > 0.0) {
            return Err(invalid(
                &f("motion_period_s"),
                self.period_s,
                "wave-induced motion needs a period: a finite number of seconds above zero",
            ));
        }
        Ok(())
    }

    /// Roll `A_r·sin(2πt/T + φ)` and pitch `A_p·cos(2πt/T + φ)` at `t_s`, rad.
    pub fn roll_pitch_rad(&self, t_s: f64) -> (f64, f64) {
        let phase = TAU * t_s / self.period_s + self.phase_rad;
        (
            self.roll_amplitude_rad * phase.sin(),
            self.pitch_amplitude_rad * phase.cos(),
        )
    }
}

/// A validated motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    path: Trajectory,
    heading: HeadingRule,
    wave: Option<WaveMotion>,
}

/// Where a moving thing is at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// Reference point, ENU m.
    pub position_m: DVec3,
    /// Velocity of the reference point over ground, ENU m/s.
    pub velocity_mps: DVec3,
    /// Heading of the bow, rad (nautical: 0 = north, clockwise).
    pub heading_rad: f64,
    /// Object-to-world rotation.
    pub rotation: DMat3,
}

impl Kinematics {
    /// Horizontal speed over ground, m/s.
    pub fn speed_mps(&self) -> f64 {
        self.velocity_mps.x.hypot(self.velocity_mps.y)
    }

    /// Course over ground, rad in [0, 2π) (nautical); None when not moving horizontally.
    pub fn course_rad(&self) -> Option<f64> {
        course_of(self.velocity_mps)
    }
}

/// The course over ground of a velocity (ENU m/s), rad in [0, 2π) (nautical); None when its
/// horizontal speed is below [`STILL_SPEED_M_PER_S`].
pub fn course_of(velocity_mps: DVec3) -> Option<f64> {
    (velocity_mps.x.hypot(velocity_mps.y) > STILL_SPEED_M_PER_S)
        .then(|| velocity_mps.x.atan2(velocity_mps.y).rem_euclid(TAU))
}

fn invalid(field: &str, value: impl std::fmt::Display, why: impl Into<String>) -> Error {
    Error::invalid(Problem::OutOfRange, field, value, why.into())
}

impl Motion {
    /// A motion, checked: velocity and turn rate finite; a turn needs a horizontal speed;
    /// a track has at least two waypoints, finite, in strictly increasing time; wave
    /// amplitudes finite and ≥ 0 (roll and pitch at most 60°), the period finite and > 0.
    /// `field` prefixes the field names in errors (`object "ferry"`).
    pub fn new(
        field: &str,
        path: Trajectory,
        heading: HeadingRule,
        wave: Option<WaveMotion>,
    ) -> Result<Motion> {
        let f = |name: &str| format!("{field}.{name}");
        match &path {
            Trajectory::Steady {
                velocity_mps,
                turn_rate_rad_per_s,
            } => {
                if !velocity_mps.is_finite() {
                    return Err(Error::invalid(
                        Problem::NotFinite,
                        f("velocity_mps"),
                        format!("{velocity_mps:?}"),
                        "must be finite",
                    ));
                }
                finite(&f("turn_rate_deg_per_s"), *turn_rate_rad_per_s)?;
                if *turn_rate_rad_per_s != 0.0
                    && velocity_mps.x.hypot(velocity_mps.y) <= STILL_SPEED_M_PER_S
                {
                    return Err(Error::invalid(
                        Problem::Conflict,
                        f("turn_rate_deg_per_s"),
                        turn_rate_rad_per_s.to_degrees(),
                        "a turn needs a horizontal speed above zero (speed_kn or velocity_mps)",
                    ));
                }
            }
            Trajectory::Track { points } => {
                if points.len() < 2 {
                    return Err(invalid(
                        &f("track"),
                        format!("{} waypoint(s)", points.len()),
                        "a track needs at least two waypoints [t_s, east_m, north_m]",
                    ));
                }
                for (i, p) in points.iter().enumerate() {
                    for v in [p.time_s, p.east_m, p.north_m] {
                        if !v.is_finite() {
                            return Err(Error::invalid(
                                Problem::NotFinite,
                                format!("{field}.track[{i}]"),
                                format!("[{}, {}, {}]", p.time_s, p.east_m, p.north_m),
                                "every waypoint value must be a finite number",
                            ));
                        }
                    }
                    if i > 0 && p.time_s <= points[i - 1].time_s {
                        return Err(invalid(
                            &format!("{field}.track[{i}]"),
                            format!("[{}, {}, {}]", p.time_s, p.east_m, p.north_m),
                            format!(
                                "waypoints must be in strictly increasing time: t = {} s comes after track[{}] at t = {} s",
                                p.time_s,
                                i - 1,
                                points[i - 1].time_s
                            ),
                        ));
                    }
                }
            }
        }
        if let HeadingRule::Fixed(h) = heading {
            finite(&f("yaw_deg"), h)?;
        }
        if let Some(w) = &wave {
            w.check(field)?;
        }
        Ok(Motion {
            path,
            heading,
            wave,
        })
    }

    /// The path.
    pub fn path(&self) -> &Trajectory {
        &self.path
    }

    /// The heading rule.
    pub fn heading(&self) -> HeadingRule {
        self.heading
    }

    /// The wave-induced motion, if any.
    pub fn wave(&self) -> Option<&WaveMotion> {
        self.wave.as_ref()
    }

    /// Horizontal position (east, north), velocity (east, north) and the course the heading
    /// follows at time `t_s` for a path starting (steady) at `start_m`.
    fn horizontal(&self, start_m: DVec3, t_s: f64) -> (DVec3, DVec3, f64) {
        match &self.path {
            Trajectory::Steady {
                velocity_mps: v,
                turn_rate_rad_per_s: w,
            } => {
                let s = v.x.hypot(v.y);
                let c0 = v.x.atan2(v.y);
                if *w == 0.0 || s <= STILL_SPEED_M_PER_S {
                    let p = start_m + DVec3::new(v.x, v.y, 0.0) * t_s;
                    return (p, DVec3::new(v.x, v.y, 0.0), c0);
                }
                let c = c0 + w * t_s;
                let p = start_m
                    + DVec3::new(
                        s * (c0.cos() - c.cos()) / w,
                        s * (c.sin() - c0.sin()) / w,
                        0.0,
                    );
                (p, DVec3::new(s * c.sin(), s * c.cos(), 0.0), c)
            }
            Trajectory::Track { points } => track_at(points, start_m.z, t_s),
        }
    }

    /// Position, velocity, heading and rotation at time `t_s` of an object whose reference
    /// point is at `start_m` at t = 0 (the steady path's origin; a track sets its own
    /// horizontal position and keeps `start_m.z`), tilted at rest by `tilt` (its static
    /// pitch and roll, applied before the heading turns it).
    pub fn kinematics(&self, start_m: DVec3, tilt: DMat3, t_s: f64) -> Kinematics {
        let (mut position_m, mut velocity_mps, course) = self.horizontal(start_m, t_s);
        if let Trajectory::Steady {
            velocity_mps: v, ..
        } = &self.path
        {
            position_m.z = start_m.z + v.z * t_s;
            velocity_mps.z = v.z;
        }
        let heading_rad = match self.heading {
            HeadingRule::Fixed(h) => h,
            HeadingRule::AlongCourse => course,
        }
        .rem_euclid(TAU);
        let (mut roll, mut pitch) = (0.0, 0.0);
        if let Some(w) = &self.wave {
            let phase = TAU * t_s / w.period_s + w.phase_rad;
            let omega = TAU / w.period_s;
            position_m.z += w.heave_amplitude_m * phase.sin();
            velocity_mps.z += w.heave_amplitude_m * omega * phase.cos();
            roll = w.roll_amplitude_rad * phase.sin();
            pitch = w.pitch_amplitude_rad * phase.cos();
        }
        Kinematics {
            position_m,
            velocity_mps,
            heading_rad,
            rotation: object_frame(heading_rad, pitch, roll) * tilt,
        }
    }
}

/// Position, velocity and course on a track at `t_s` (height `z_m`).
fn track_at(points: &[Waypoint], z_m: f64, t_s: f64) -> (DVec3, DVec3, f64) {
    let at = |p: &Waypoint| DVec3::new(p.east_m, p.north_m, z_m);
    let course_of = |i: usize| {
        let (a, b) = (&points[i], &points[i + 1]);
        let (de, dn) = (b.east_m - a.east_m, b.north_m - a.north_m);
        (de.hypot(dn) > 0.0).then(|| de.atan2(dn))
    };
    let segments = points.len() - 1;
    // The segment that holds t (the last one at and after the last waypoint's time).
    let seg = points[1..]
        .iter()
        .position(|p| t_s < p.time_s)
        .unwrap_or(segments)
        .min(segments - 1);
    // Course: the segment's own, else the nearest moving segment's (earlier first).
    let course = course_of(seg)
        .or_else(|| (0..seg).rev().find_map(course_of))
        .or_else(|| (seg + 1..segments).find_map(course_of))
        .unwrap_or(0.0);
    let (a, b) = (&points[seg], &points[seg + 1]);
    if t_s <= points[0].time_s {
        return (at(&points[0]), DVec3::ZERO, course);
    }
    if t_s >= points[segments].time_s {
        return (at(&points[segments]), DVec3::ZERO, course);
    }
    let dt = b.time_s - a.time_s;
    let u = (t_s - a.time_s) / dt;
    let p = at(a) + (at(b) - at(a)) * u;
    let v = DVec3::new(
        (b.east_m - a.east_m) / dt,
        (b.north_m - a.north_m) / dt,
        0.0,
    );
    (p, v, course)
}

/// The heading of an object's bow (its +y axis) under `rotation`, rad (nautical); None when
/// the bow points straight up or down.
pub fn heading_of(rotation: DMat3) -> Option<f64> {
    let bow = rotation * DVec3::Y;
    (bow.x.hypot(bow.y) > 1e-9).then(|| bow.x.atan2(bow.y).rem_euclid(TAU))
}

/// The ship the radar rides on (`[own_ship]`): a straight course at a steady speed, with an
/// optional roll and pitch in the waves. The antenna's phase centre moves with it and, when
/// the ship rolls and pitches about a centre at the waterline under the mast, swings on its
/// mast height and tilts the beam (docs/physics.md §9); bearings in the record stay true
/// (north-referenced).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OwnShip {
    velocity_mps: DVec3,
    heading_rad: f64,
    /// Roll and pitch in the waves (heave 0).
    wave: Option<WaveMotion>,
    /// Height of the antenna's phase centre above the centre of roll and pitch, m.
    mast_height_m: f64,
}

impl OwnShip {
    /// A ship at `speed_kn` on `course_deg` with its bow on `heading_deg` (nautical degrees):
    /// all finite, the speed ≥ 0.
    pub fn new(speed_kn: f64, course_deg: f64, heading_deg: f64) -> Result<OwnShip> {
        check_speed_kn("own_ship.speed_kn", speed_kn)?;
        let course = finite("own_ship.course_deg", course_deg)?.to_radians();
        let heading = finite("own_ship.heading_deg", heading_deg)?.to_radians();
        let s = speed_kn * KNOT_M_PER_S;
        Ok(OwnShip {
            velocity_mps: DVec3::new(s * course.sin(), s * course.cos(), 0.0),
            heading_rad: heading.rem_euclid(TAU),
            wave: None,
            mast_height_m: 0.0,
        })
    }

    /// The same ship rolling `roll_amplitude_deg·sin(2πt/T + φ)` and pitching
    /// `pitch_amplitude_deg·cos(2πt/T + φ)` (T = `motion_period_s`, φ = `motion_phase_deg`)
    /// about a centre `mast_height_m` below the antenna; amplitudes 0–60°, errors name
    /// `own_ship.field`.
    pub fn rolling(
        self,
        roll_amplitude_deg: f64,
        pitch_amplitude_deg: f64,
        motion_period_s: f64,
        motion_phase_deg: f64,
        mast_height_m: f64,
    ) -> Result<OwnShip> {
        let wave = WaveMotion {
            heave_amplitude_m: 0.0,
            roll_amplitude_rad: roll_amplitude_deg.to_radians(),
            pitch_amplitude_rad: pitch_amplitude_deg.to_radians(),
            period_s: motion_period_s,
            phase_rad: motion_phase_deg.to_radians(),
        };
        wave.check("own_ship")?;
        Ok(OwnShip {
            wave: Some(wave),
            mast_height_m,
            ..self
        })
    }

    /// Roll and pitch at `t_s`, rad (0 without wave motion).
    pub fn roll_pitch_rad(&self, t_s: f64) -> (f64, f64) {
        self.wave.map_or((0.0, 0.0), |w| w.roll_pitch_rad(t_s))
    }

    /// Ship-to-world rotation at `t_s` (heading, pitch, roll as an object's:
    /// docs/formats.md, "Object frames").
    pub fn rotation(&self, t_s: f64) -> DMat3 {
        let (roll, pitch) = self.roll_pitch_rad(t_s);
        object_frame(self.heading_rad, pitch, roll)
    }

    /// Where the antenna's phase centre is at `t_s` relative to its place at t = 0, ENU m:
    /// the ship's run plus the mast's swing `R(t)·(0, 0, h) − (0, 0, h)`.
    pub fn antenna_offset_m(&self, t_s: f64) -> DVec3 {
        let run = self.displacement_m(t_s);
        if self.wave.is_none() {
            return run;
        }
        let mast = DVec3::new(0.0, 0.0, self.mast_height_m);
        run + self.rotation(t_s) * mast - mast
    }

    /// Velocity of the antenna's phase centre at `t_s`, ENU m/s: the ship's plus the mast's
    /// swing (its derivative by a central difference over a millionth of the wave period,
    /// relative error below 10⁻¹⁰).
    pub fn antenna_velocity_mps(&self, t_s: f64) -> DVec3 {
        match self.wave {
            None => self.velocity_mps,
            Some(w) => {
                let dt = w.period_s * 1e-6;
                let mast = DVec3::new(0.0, 0.0, self.mast_height_m);
                self.velocity_mps
                    + (self.rotation(t_s + dt) * mast - self.rotation(t_s - dt) * mast) / (2.0 * dt)
            }
        }
    }

    /// Elevation of the beam axis above the horizon when the antenna points at nautical
    /// azimuth `azimuth_rad` at `t_s`, from the deck's roll and pitch alone, rad: the
    /// boresight `(sin α, cos α, 0)` in the ship's frame (α = azimuth − heading) carried by
    /// [`OwnShip::rotation`], `asin(z)`; `sin p·cos α − cos p·sin r·sin α` (0 on a level deck).
    pub fn beam_tilt_rad(&self, t_s: f64, azimuth_rad: f64) -> f64 {
        if self.wave.is_none() {
            return 0.0;
        }
        let a = azimuth_rad - self.heading_rad;
        let boresight = self.rotation(t_s) * DVec3::new(a.sin(), a.cos(), 0.0);
        boresight.z.clamp(-1.0, 1.0).asin()
    }

    /// The wave motion, if the ship rolls or pitches.
    pub fn wave(&self) -> Option<&WaveMotion> {
        self.wave.as_ref()
    }

    /// Velocity over ground, ENU m/s.
    pub fn velocity_mps(&self) -> DVec3 {
        self.velocity_mps
    }

    /// Heading, rad (nautical).
    pub fn heading_rad(&self) -> f64 {
        self.heading_rad
    }

    /// How far the antenna has moved since t = 0 at time `t_s`, ENU m.
    pub fn displacement_m(&self, t_s: f64) -> DVec3 {
        self.velocity_mps * t_s
    }
}
