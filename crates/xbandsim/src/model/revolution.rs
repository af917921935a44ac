//! Model: one revolution of the antenna as the spoke-mode scan sees it. The antenna turns
//! clockwise from north at Ω = 2π/T, so it points at nautical bearing β at
//! `t = t_start + β/Ω`; each object is placed where it is when the beam crosses it, found by
//! solving `Ω·(t − t_start) = β(t)` with β(t) the object's bearing from the (moving) antenna
//! (docs/physics.md, "Motion"). The scene seen by the one trace of the revolution holds every
//! object at its own beam-crossing time, displaced so that its position relative to the
//! antenna is the one at that time, with the antenna where it is at the start of the
//! revolution.

use super::motion::Kinematics;
use super::{Scene, SceneObject};
use glam::DVec3;
use std::f64::consts::{PI, TAU};
use std::sync::Arc;

/// Where the own ship (the antenna) is at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShipState {
    /// Antenna phase centre, ENU m.
    pub antenna_position_m: DVec3,
    /// Velocity over ground, ENU m/s.
    pub velocity_mps: DVec3,
    /// Heading, rad (nautical).
    pub heading_rad: f64,
    /// Roll, rad (starboard down positive; 0 without `roll_amplitude_deg`).
    pub roll_rad: f64,
    /// Pitch, rad (bow up positive).
    pub pitch_rad: f64,
}

/// An object when the beam crosses it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectState {
    /// Time the beam's axis crossed its reference point, s from the start of the run.
    pub beam_time_s: f64,
    /// Its position, velocity, heading and rotation then (true, ENU).
    pub kinematics: Kinematics,
    /// The antenna's phase centre then, ENU m.
    pub antenna_position_m: DVec3,
    /// The antenna's velocity then, ENU m/s.
    pub antenna_velocity_mps: DVec3,
    /// How far the own ship's roll and pitch raised the beam axis toward it then, rad (0 on
    /// a level deck): the antenna's elevation pattern is centred at `tilt + this`.
    pub beam_tilt_rad: f64,
}

impl ShipState {
    /// Course over ground, rad (nautical); None while the ship stands still.
    pub fn course_rad(&self) -> Option<f64> {
        super::motion::course_of(self.velocity_mps)
    }
}

impl ObjectState {
    /// Its velocity relative to the antenna, ENU m/s: what its range rate and Doppler come
    /// from.
    pub fn relative_velocity_mps(&self) -> DVec3 {
        self.kinematics.velocity_mps - self.antenna_velocity_mps
    }
}

/// One revolution: its start time, the still scene its trace sees, and every object's state.
#[derive(Debug, Clone)]
pub struct Revolution {
    start_time_s: f64,
    scene: Arc<Scene>,
    objects: Vec<ObjectState>,
    own_ship: Option<ShipState>,
    ship: Option<super::motion::OwnShip>,
}

impl Revolution {
    /// The revolution of `scene` that starts at `start_time_s`. A still scene is used as it is.
    pub fn of(scene: &Arc<Scene>, start_time_s: f64) -> Revolution {
        Revolution::with_lead(scene, start_time_s, 0.0)
    }

    /// As [`Revolution::of`], with the beam crossings sought from `lead_s` before the start
    /// (the antenna `Ω·lead_s` short of north) to one period later: pulse mode's spoke 0
    /// takes its first pulses half a spoke before north.
    pub fn with_lead(scene: &Arc<Scene>, start_time_s: f64, lead_s: f64) -> Revolution {
        let period_s = scene.radar().scan().period_s();
        let radar_at = |t: f64| {
            scene.radar().position_m()
                + scene
                    .own_ship()
                    .map_or(DVec3::ZERO, |s| s.antenna_offset_m(t))
        };
        let radar_velocity = |t: f64| {
            scene
                .own_ship()
                .map_or(DVec3::ZERO, |s| s.antenna_velocity_mps(t))
        };
        let (sin_lead, cos_lead) = (TAU * lead_s / period_s).sin_cos();
        let objects: Vec<ObjectState> = scene
            .objects()
            .iter()
            .map(|o| {
                let beam_time_s = if lead_s == 0.0 {
                    beam_crossing_time_s(start_time_s, period_s, |t| {
                        o.kinematics(t).position_m - radar_at(t)
                    })
                } else {
                    // Bearings measured from the antenna's azimuth at start − lead.
                    beam_crossing_time_s(start_time_s - lead_s, period_s, |t| {
                        let r = o.kinematics(t).position_m - radar_at(t);
                        DVec3::new(
                            r.x * cos_lead + r.y * sin_lead,
                            r.y * cos_lead - r.x * sin_lead,
                            r.z,
                        )
                    })
                };
                let kinematics = o.kinematics(beam_time_s);
                let antenna_position_m = radar_at(beam_time_s);
                let r = kinematics.position_m - antenna_position_m;
                ObjectState {
                    beam_time_s,
                    kinematics,
                    antenna_position_m,
                    antenna_velocity_mps: radar_velocity(beam_time_s),
                    beam_tilt_rad: scene
                        .own_ship()
                        .map_or(0.0, |s| s.beam_tilt_rad(beam_time_s, r.x.atan2(r.y))),
                }
            })
            .collect();
        let own_ship = scene.own_ship().map(|s| {
            let (roll_rad, pitch_rad) = s.roll_pitch_rad(start_time_s);
            ShipState {
                antenna_position_m: radar_at(start_time_s),
                velocity_mps: s.velocity_mps(),
                heading_rad: s.heading_rad(),
                roll_rad,
                pitch_rad,
            }
        });
        let seen = if scene.is_still() {
            Arc::clone(scene)
        } else {
            let start_radar = radar_at(start_time_s);
            let posed: Vec<SceneObject> = scene
                .objects()
                .iter()
                .zip(&objects)
                .map(|(o, s)| {
                    // Horizontal only: objects keep their heights over the sea (the multipath
                    // reflector); the mast top's height change between the revolution's start
                    // and the crossing (cm for a rolling ship) is left to the antenna.
                    let d = start_radar - s.antenna_position_m;
                    o.posed_at(s.beam_time_s, DVec3::new(d.x, d.y, 0.0))
                })
                .collect();
            Arc::new(Scene {
                radar: scene.radar().moved_to(start_radar),
                environment: scene.environment().clone(),
                scattering: scene.scattering().clone(),
                objects: posed,
                own_ship: None,
                processing: scene.processing().clone(),
                receiver: scene.receiver().copied(),
                artefacts: scene.artefacts().clone(),
            })
        };
        Revolution {
            start_time_s,
            scene: seen,
            objects,
            own_ship,
            ship: scene.own_ship().copied(),
        }
    }

    /// How far the own ship's roll and pitch raise the beam axis at `t_s` when the antenna
    /// points at `azimuth_rad`, rad (0 on a level deck or without an own ship).
    pub fn beam_tilt_rad(&self, t_s: f64, azimuth_rad: f64) -> f64 {
        self.ship.map_or(0.0, |s| s.beam_tilt_rad(t_s, azimuth_rad))
    }

    /// Whether the own ship rolls or pitches (the beam tilts with time and azimuth).
    pub fn deck_moves(&self) -> bool {
        self.ship.is_some_and(|s| s.wave().is_some())
    }

    /// Start of the revolution, s.
    pub fn start_time_s(&self) -> f64 {
        self.start_time_s
    }

    /// The still scene the revolution's trace sees.
    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// Every object's state when the beam crosses it, in scene order.
    pub fn objects(&self) -> &[ObjectState] {
        &self.objects
    }

    /// The own ship at the start of the revolution (None without `[own_ship]`).
    pub fn own_ship(&self) -> Option<&ShipState> {
        self.own_ship.as_ref()
    }
}

/// The time in `[start, start + period]` at which a beam turning clockwise from north at
/// start, at 2π/period, crosses the bearing of `relative_position(t)` (target minus antenna,
/// ENU). Solved by bisection on `g(t) = Ω·(t − start) − β(t)`, β unwrapped from its value at
/// the start (g(start) = −β(start) ≤ 0). When the object runs ahead of the beam across north
/// (g(end) < 0) the beam meets it at the end of the revolution, which is returned. A still
/// geometry gives `start + β/Ω` exactly.
pub fn beam_crossing_time_s(
    start_s: f64,
    period_s: f64,
    relative_position: impl Fn(f64) -> DVec3,
) -> f64 {
    let omega = TAU / period_s;
    let bearing = |t: f64| {
        let r = relative_position(t);
        r.x.atan2(r.y).rem_euclid(TAU)
    };
    let b0 = bearing(start_s);
    let first = start_s + b0 / omega;
    if relative_position(first) == relative_position(start_s) {
        return first;
    }
    let g = |t: f64| {
        let d = (bearing(t) - b0 + PI).rem_euclid(TAU) - PI;
        omega * (t - start_s) - (b0 + d)
    };
    let end_s = start_s + period_s;
    if g(end_s) < 0.0 {
        return end_s;
    }
    let (mut lo, mut hi) = (start_s, end_s);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if g(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}
