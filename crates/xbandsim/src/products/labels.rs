//! Stage: labels. Ground truth for every object, from the scene and the traced physics, not
//! from detection: position, range, azimuth, aspect RCS, every loss its echo suffers, the
//! expected SNR, a visibility flag that names the physical reason, the box in polar
//! (spoke, bin) coordinates and the echo region from which products draw their own boxes
//! (the PPI's pixel box: [`crate::products::ppi::PpiGeometry::label`]; docs/formats.md,
//! "truth.json").
//!
//! No sentinel numbers: a value that does not exist (the RCS of an object that returns no
//! echo, a box around nothing) is `None` (JSON `null`).

use crate::constants::{linear_to_db, SPEED_OF_LIGHT_M_PER_S};
use crate::geometry::{Bvh, Ray};
use crate::model::motion::{heading_of, KNOT_M_PER_S};
use crate::model::revolution::Revolution;
use crate::model::{Environment, Polarisation, Radar, ScatteringModel, Scene};
use crate::scattering::po::TubeBudget;
use crate::scattering::{azimuth_elevation_rad, ScatterSet};
use glam::DVec3;
use num_complex::Complex64;
use serde::Serialize;

/// Why an object can or cannot be seen in this frame; the first reason that applies, in
/// this order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Visibility {
    /// Wholly below the radar horizon of the 4/3 earth: no echo.
    BeyondHorizon,
    /// Its nearest point is farther than the radar's maximum range: not recorded.
    BeyondMaxRange,
    /// No echo: land hides it (the line of sight passes below the land between, and any
    /// path via the sea meets land); `shadowed_by_land` is true.
    ShadowedByLand,
    /// No echo, and the line of sight to it is blocked by another object.
    Shadowed,
    /// No echo although the line of sight is clear: nothing on it scatters back toward the
    /// radar (physical optics), e.g. a flat plate seen exactly edge-on.
    NoReturn,
    /// `paper` model only: the model's uniform ray grid passes around it (a small object
    /// between two elevation rows, or a `point`, which has no geometry to hit), so that
    /// model gives it no echo. Not a physical effect.
    MissedByRayGrid,
    /// Inside c·T/2 while the receiver is blanked, and the echo is lost to it: nothing of
    /// the pulse is received, or the eclipse loss alone takes its SNR below 0 dB.
    Eclipsed,
    /// Its expected single-pulse SNR is below 0 dB.
    BelowNoise,
    /// Seen, but inside c·T/2: only the tail of the pulse is received
    /// (`eclipse_received_fraction` < 1, `losses_db.eclipse` > 0).
    PartiallyEclipsed,
    /// Returns an echo above the noise.
    Visible,
}

impl Visibility {
    /// Whether the object leaves an echo in the recorded data (so it gets boxes).
    pub fn has_echo(&self) -> bool {
        !matches!(
            self,
            Visibility::BeyondHorizon
                | Visibility::BeyondMaxRange
                | Visibility::ShadowedByLand
                | Visibility::Shadowed
                | Visibility::NoReturn
                | Visibility::MissedByRayGrid
        )
    }
}

/// A box in polar coordinates; `spoke_min > spoke_max` means it wraps through north.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PolarBox {
    /// First spoke.
    pub spoke_min: usize,
    /// Last spoke (inclusive).
    pub spoke_max: usize,
    /// First range bin.
    pub bin_min: usize,
    /// Last range bin (inclusive).
    pub bin_max: usize,
}

impl PolarBox {
    /// Number of spokes the box spans out of `spokes`, counting across north.
    pub fn spoke_count(&self, spokes: usize) -> usize {
        (self.spoke_max + spokes - self.spoke_min) % spokes + 1
    }

    /// The box's spokes from `spoke_min` to `spoke_max`, across north if it wraps.
    pub fn spoke_indices(&self, spokes: usize) -> impl Iterator<Item = usize> {
        let first = self.spoke_min;
        (0..self.spoke_count(spokes)).map(move |s| (first + s) % spokes)
    }
}

/// The losses of an object's echo against the free-space radar equation on the beam axis,
/// dB (each ≥ 0; subtract them all, and add the multipath gain, to get the expected SNR).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EchoLosses {
    /// Matched-filter window loss `(Σw)²/(N·Σw²)`.
    pub window: f64,
    /// Two-way elevation pattern at the object's elevation, `−20·log10 Gn_el`.
    pub elevation_pattern: f64,
    /// Two-way atmospheric attenuation.
    pub atmosphere: f64,
    /// Two-way rain attenuation along the path (ITU-R P.838-3 through the rain cells).
    pub rain: f64,
    /// Eclipsing: `−20·log10(received fraction)` of the matched-filter peak; null when
    /// nothing is received (total eclipse).
    pub eclipse: Option<f64>,
    /// The own ship's structure in the beam: the two-way loss of the blind sectors
    /// (`[[own_ship.structure]]`) its bearing lies in (0 in none).
    pub blind_sector: f64,
}

/// Radial speeds below this, either way, class an object as stationary: 3 knots, about
/// the radial speed below which marine radars' target analysers leave a target uncoloured
/// (docs/formats.md, "truth.json").
pub const RADIAL_CLASS_THRESHOLD_MPS: f64 = 3.0 * KNOT_M_PER_S;

/// Which pulse's channel an object's echo is recorded on (docs/physics.md §11).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PulseChannel {
    /// Single pulse mode: the one pulse.
    Single,
    /// Combined pulse mode, inside the join range: the short pulse.
    Short,
    /// Combined pulse mode, from the join range on: the long pulse.
    Long,
}

/// Which way an object moves along the line of sight, against
/// [`RADIAL_CLASS_THRESHOLD_MPS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RadialMotion {
    /// Closing faster than the threshold.
    Approaching,
    /// Opening faster than the threshold.
    Receding,
    /// Slower than the threshold either way.
    Stationary,
}

impl RadialMotion {
    /// The class of a range rate, m/s (negative: closing).
    pub fn of(radial_velocity_mps: f64) -> RadialMotion {
        if radial_velocity_mps <= -RADIAL_CLASS_THRESHOLD_MPS {
            RadialMotion::Approaching
        } else if radial_velocity_mps >= RADIAL_CLASS_THRESHOLD_MPS {
            RadialMotion::Receding
        } else {
            RadialMotion::Stationary
        }
    }
}

/// Ground truth of one object in one frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObjectTruth {
    /// Index in the scene.
    pub id: u32,
    /// Track identity, the same in every frame of a run (the object's index in the scene).
    pub track_id: u32,
    /// Time the beam's axis crossed the object's reference point, s from the start of the
    /// run; the object's position, velocity and the geometry below are those of that time.
    pub beam_time_s: f64,
    /// Name.
    pub name: String,
    /// Class label.
    pub class: String,
    /// Shape name.
    pub shape: String,
    /// Position, ENU m.
    pub position_m: [f64; 3],
    /// Velocity over ground, ENU m/s.
    pub velocity_mps: [f64; 3],
    /// Speed over ground, knots.
    pub speed_kn: f64,
    /// Course over ground, nautical degrees; null when it is not moving horizontally.
    pub course_deg: Option<f64>,
    /// Heading of its bow (its +y axis), nautical degrees; null when the bow points
    /// straight up or down.
    pub heading_deg: Option<f64>,
    /// Range rate relative to the antenna (the own ship's velocity taken off), m/s:
    /// positive opening, negative closing.
    pub radial_velocity_mps: f64,
    /// Two-way Doppler shift of its reference point, `−2·radial_velocity/λ`, Hz (positive
    /// approaching).
    pub doppler_hz: f64,
    /// Approaching, receding or stationary at [`RADIAL_CLASS_THRESHOLD_MPS`].
    pub radial_motion: RadialMotion,
    /// Slant range from the antenna phase centre, m.
    pub range_m: f64,
    /// Horizontal range, m.
    pub ground_range_m: f64,
    /// Nautical azimuth from the radar, degrees (0 = north, clockwise).
    pub azimuth_deg: f64,
    /// Elevation from the radar, degrees.
    pub elevation_deg: f64,
    /// Where the radar lies seen from the object, in the object's own frame, degrees: the
    /// azimuth from its bow (+y) toward its starboard side (+x), 0–360 (0 bow-on, 90 the
    /// starboard beam, 180 stern-on), turning with its heading, roll and pitch. The aspect of
    /// `rcs_m2`.
    pub aspect_azimuth_deg: f64,
    /// The radar's elevation above the object's deck plane (its x–y plane), degrees.
    pub aspect_elevation_deg: f64,
    /// Monostatic free-space RCS at this aspect from the scattering model, m²; null for the
    /// `paper` model and for objects with no free-space return.
    pub rcs_m2: Option<f64>,
    /// The same in dBsm.
    pub rcs_dbsm: Option<f64>,
    /// Power gain of the sea paths over free space, `|Σ all paths|²/|Σ direct|²`, dB
    /// (0 without multipath; null for `paper` and when there is no free-space return).
    pub multipath_gain_db: Option<f64>,
    /// Every loss on the echo's way, dB.
    pub losses_db: EchoLosses,
    /// Part of the matched-filter peak amplitude received while the receiver is blanked:
    /// 1 outside c·T/2, the window-weighted fraction of the pulse's tail inside it, 0 at
    /// the radar.
    pub eclipse_received_fraction: f64,
    /// The pulse whose channel records its echo: "single", or in combined pulse mode "short"
    /// (peak bin inside the join range) or "long". Eclipse, window loss and expected SNR are
    /// that pulse's.
    pub pulse: PulseChannel,
    /// Expected matched-filter peak with that RCS on the beam axis, dB over the mean noise:
    /// the radar equation's single-pulse SNR plus the multipath gain minus `losses_db`
    /// (null when `rcs_m2` is null).
    pub expected_snr_db: Option<f64>,
    /// Its expected SNR before the eclipse, dB (None where `expected_snr_db` has no
    /// calibrated value): what its echoes shown elsewhere (second-trace, indirect, multiple;
    /// `products::artefacts`) start from. Not written.
    #[serde(skip)]
    pub snr_before_eclipse_db: Option<f64>,
    /// Whether and why it is or is not seen.
    pub visibility: Visibility,
    /// Whether land hides all of its echo (visibility `shadowed_by_land`); false in open
    /// sea. Land that hides part of it takes that part out of `rcs_m2` and the SNR.
    pub shadowed_by_land: bool,
    /// Horizontal distance from its reference point to the nearest coast, m; null without
    /// land in the scene.
    pub distance_to_coast_m: Option<f64>,
    /// The PO tube grid it was traced with (null for points, the `paper` model and objects
    /// not traced); `capped` says the ray budget widened the tubes.
    pub po_tubes: Option<TubeBudget>,
    /// Box in polar coordinates; null when the object leaves no echo in the record.
    pub polar_box: Option<PolarBox>,
    /// Box in PPI pixels `[x_min, y_min, x_max, y_max]`, clipped to the image; null when the
    /// object leaves no echo in the image. Set by the PPI product
    /// ([`crate::products::ppi::PpiGeometry::label`], which `write_frame_files` applies for
    /// its image): a frame's truth from the engine has none, since the image size is a
    /// display setting and not part of the scene.
    pub ppi_box_px: Option<[f64; 4]>,
    /// Edges of its bounding box in its own frame, m: across (x, to starboard), along (y, to
    /// the bow) and height (z); zeros for a `point`.
    pub size_m: [f64; 3],
    /// The horizontal corners of that box at the beam crossing, ENU `[east, north]` m, in
    /// the order bow-starboard, bow-port, stern-port, stern-starboard: the object's true
    /// extent and heading on the sea (the oriented box of the dataset's YOLO-OBB labels).
    pub footprint_m: [[f64; 2]; 4],
    /// The same corners in PPI pixels `[x, y]` (not clipped); null when `ppi_box_px` is
    /// null. Set with `ppi_box_px`.
    pub ppi_footprint_px: Option<[[f64; 2]; 4]>,
    /// Where its echo can lie (None when it leaves no echo); products draw boxes from it.
    #[serde(skip)]
    pub echo_region: Option<EchoRegion>,
    /// Where its echo would lie were the record long enough (objects beyond the recorded
    /// range only): second-trace echoes are drawn from it.
    #[serde(skip)]
    pub far_region: Option<EchoRegion>,
    /// Where its echo lies whether or not the record shows it (blanked, say): its echoes
    /// shown elsewhere (indirect, multiple) are drawn from it.
    #[serde(skip)]
    pub region: EchoRegion,
    /// `footprint_m` from the antenna, `[east, north]` m (for products' pixel coordinates).
    #[serde(skip)]
    pub footprint_from_radar_m: [[f64; 2]; 4],
}

/// The bounding box `bounds` (object frame) of an object at `position_m` turned by
/// `rotation`: its edges and its four horizontal corners in ENU (bow-starboard, bow-port,
/// stern-port, stern-starboard), taken at the box's mid height. A point (empty box) has
/// zero size and all four corners at its position.
pub fn footprint_of(
    bounds: &crate::geometry::Aabb,
    position_m: DVec3,
    rotation: glam::DMat3,
) -> ([f64; 3], [[f64; 2]; 4]) {
    if !(bounds.min.is_finite() && bounds.max.is_finite()) {
        let p = [position_m.x, position_m.y];
        return ([0.0; 3], [p; 4]);
    }
    let (lo, hi) = (bounds.min, bounds.max);
    let z = 0.5 * (lo.z + hi.z);
    let corner = |x: f64, y: f64| {
        let w = position_m + rotation * DVec3::new(x, y, z);
        [w.x, w.y]
    };
    (
        (hi - lo).to_array(),
        [
            corner(hi.x, hi.y),
            corner(lo.x, hi.y),
            corner(lo.x, lo.y),
            corner(hi.x, lo.y),
        ],
    )
}

/// The eclipse loss, dB, of a point echo at slant range `range_m` for `radar` (0 without
/// blanking; None when none of it is received), in the pulse channel that records that
/// range: what `losses_db.eclipse` is for an object there.
pub fn eclipse_loss_db_at(radar: &Radar, range_m: f64) -> Option<f64> {
    if !radar.receiver_blanking() {
        return Some(0.0);
    }
    let delay_samples = 2.0 * range_m / SPEED_OF_LIGHT_M_PER_S * radar.sample_rate_hz();
    let (chirp, window) = match radar.short_pulse() {
        Some(p) if (delay_samples.round() as usize) < radar.join_bin() => (&p.chirp, p.window),
        _ => (radar.chirp(), radar.window()),
    };
    let fraction = eclipse_received_fraction(
        delay_samples,
        &chirp.samples(),
        &window.coefficients(chirp.num_samples()),
    );
    (fraction > 0.0).then(|| loss_db(fraction.powi(2)))
}

/// Fraction of the matched-filter peak amplitude received from an echo at `delay_samples`
/// when the receiver is blanked for the pulse's `chirp.len()` samples: the echo's samples
/// before the end of transmission are lost, so only the chirp's last `delay_samples`
/// samples are correlated with the reference `w·chirp`. The fraction is the largest
/// correlation magnitude of that tail over lags, over the full pulse's `Σw` (exactly `τ/T`
/// without a window, where the peak stays at zero lag; with a window the tail meets larger
/// weights a few lags off, so the peak moves and is searched). Fractional delays
/// interpolate between whole samples.
pub fn eclipse_received_fraction(delay_samples: f64, chirp: &[Complex64], weights: &[f64]) -> f64 {
    let n = chirp.len();
    if delay_samples >= n as f64 {
        return 1.0;
    }
    let d = delay_samples.max(0.0);
    let lo = d.floor() as usize;
    let f = d - lo as f64;
    let at = |m: usize| tail_peak_fraction(m.min(n), chirp, weights);
    let a = at(lo);
    if f > 0.0 {
        a * (1.0 - f) + at(lo + 1) * f
    } else {
        a
    }
}

/// Peak correlation magnitude of the chirp's last `m` samples against the windowed
/// reference, over `Σw`.
fn tail_peak_fraction(m: usize, chirp: &[Complex64], weights: &[f64]) -> f64 {
    let n = chirp.len();
    if m == 0 {
        return 0.0;
    }
    let total: f64 = weights.iter().sum();
    let start = n - m;
    // The tail's own bandwidth is m/n of the chirp's: its peak lies within a few of its
    // (wider) resolution cells of zero lag.
    let span = (4 * n / m).clamp(4, 4096) as isize;
    let mut best = 0.0f64;
    for lag in -span..=span {
        let mut acc = Complex64::new(0.0, 0.0);
        for i in start..n {
            let r = i as isize - lag;
            if r < 0 || r >= n as isize {
                continue;
            }
            let r = r as usize;
            acc += chirp[i] * chirp[r].conj() * weights[r];
        }
        best = best.max(acc.norm());
    }
    (best / total).min(1.0)
}

/// A power factor ≤ 1 as a loss in dB (≥ 0, never −0).
fn loss_db(power_factor: f64) -> f64 {
    let db = -linear_to_db(power_factor);
    if db > 0.0 {
        db
    } else {
        0.0
    }
}

/// Two-way rain attenuation along the straight path from the radar to `target_m`, dB: its
/// slant length through the rain columns below the rain top, as the echo loses it
/// (docs/physics.md §2.7).
pub fn rain_two_way_loss_db(radar: &Radar, environment: &Environment, target_m: DVec3) -> f64 {
    let Some(rain) = environment.rain() else {
        return 0.0;
    };
    let slant = (target_m - radar.position_m()).length();
    let rel = (target_m - radar.position_m()).truncate();
    let ground = rel.length();
    let dir = if ground > 0.0 { rel / ground } else { rel };
    let attenuator = rain.attenuator(
        radar.carrier_freq_hz() / 1e9,
        radar.polarisation() == Polarisation::Hh,
    );
    2.0 * attenuator.one_way_db_path(
        radar.position_m().truncate(),
        dir,
        ground,
        slant,
        radar.position_m().z,
        target_m.z,
    )
}

/// Whether the straight line from the radar to `p` meets another object than `object`
/// before reaching `p`.
fn line_of_sight_blocked(bvh: &Bvh, radar_m: DVec3, p: DVec3, object: u32) -> bool {
    let v = p - radar_m;
    let len = v.length();
    if len <= 0.0 {
        return false;
    }
    bvh.closest_hit(
        &Ray {
            origin_m: radar_m,
            dir: v / len,
        },
        len,
    )
    .is_some_and(|h| h.object != object)
}

/// Whether land hides both the centre `centre_m` and the top (`radius_m` above it) of an
/// object from the antenna: its line of sight passes below the land's highest elevation on
/// its bearing ([`crate::land::profile`]).
fn land_hides(scene: &Scene, centre_m: DVec3, radius_m: f64) -> bool {
    let land = scene.environment().land();
    if land.is_empty() {
        return false;
    }
    let antenna = scene.radar().position_m();
    let curvature = scene.environment().earth_curvature();
    let view = crate::land::profile::LandView::new(land, antenna.truncate());
    let mut scratch = Vec::new();
    [centre_m, centre_m + DVec3::Z * radius_m].iter().all(|p| {
        let rel = *p - antenna;
        let ground = rel.truncate().length();
        let az = rel.x.atan2(rel.y);
        let seen_at = crate::land::profile::elevation_rad(p.z, ground, antenna.z, curvature);
        view.max_land_elevation_rad(az, ground, antenna.z, curvature, &mut scratch)
            .is_some_and(|top| top > seen_at)
    })
}

/// Builds the truth of every object from a revolution's traced scene state.
pub fn object_truth(revolution: &Revolution, set: &ScatterSet, bvh: &Bvh) -> Vec<ObjectTruth> {
    let scene: &Scene = revolution.scene();
    let radar = scene.radar();
    let ant = &radar.antenna();
    let n_objects = scene.objects().len();
    let calibrated = scene.scattering().model() == ScatteringModel::PhysicalOptics;
    // Each object's RCS, multipath gain and whether it returns anything: one pass.
    let sums = set.object_sums(n_objects);
    // The long (or single) pulse and, in combined mode, the short one: samples, window
    // weights, window loss and width.
    let pulse_of = |chirp: &crate::waveform::LfmChirp, window: crate::waveform::Window| {
        let n = chirp.num_samples();
        (
            chirp.samples(),
            window.coefficients(n),
            window.snr_loss_linear(n),
            chirp.pulse_width_s,
        )
    };
    let long_pulse = pulse_of(radar.chirp(), radar.window());
    let short_pulse = radar.short_pulse().map(|p| pulse_of(&p.chirp, p.window));
    let bin_m = radar.range_bin_m();
    let spokes = radar.spokes();
    let resolution_m = radar.range_resolution_m();
    scene
        .objects()
        .iter()
        .enumerate()
        .map(|(i, o)| {
            let rel = o.position_m() - radar.position_m();
            let range_m = rel.length();
            let state = &revolution.objects()[i];
            let k = &state.kinematics;
            let radial_velocity_mps = if range_m > 0.0 {
                state.relative_velocity_mps().dot(rel / range_m)
            } else {
                0.0
            };
            let ground_range_m = rel.x.hypot(rel.y);
            let (az, el) = azimuth_elevation_rad(rel);
            // The radar in the object's frame (the rotation's transpose is its inverse).
            let to_radar = k.rotation.transpose() * -rel;
            let aspect_azimuth_deg = to_radar
                .x
                .atan2(to_radar.y)
                .rem_euclid(std::f64::consts::TAU)
                .to_degrees();
            let aspect_elevation_deg = to_radar.z.atan2(to_radar.x.hypot(to_radar.y)).to_degrees();
            // RCS and gain exist only where the model is calibrated and a free-space path
            // returned something.
            let rcs_m2 = sums[i].rcs_m2();
            let rcs = (calibrated && sums[i].returns > 0 && rcs_m2 > 0.0).then_some(rcs_m2);
            let gain = rcs.map(|_| sums[i].multipath_gain());
            let delay_samples = 2.0 * range_m / SPEED_OF_LIGHT_M_PER_S * radar.sample_rate_hz();
            let (channel, (chirp, weights, window_loss, pulse_width_s)) = match &short_pulse {
                None => (PulseChannel::Single, &long_pulse),
                Some(p) if (delay_samples.round() as usize) < radar.join_bin() => {
                    (PulseChannel::Short, p)
                }
                Some(_) => (PulseChannel::Long, &long_pulse),
            };
            let eclipse_fraction = if radar.receiver_blanking() {
                eclipse_received_fraction(delay_samples, chirp, weights)
            } else {
                1.0
            };
            let losses = EchoLosses {
                window: loss_db(*window_loss),
                elevation_pattern: loss_db(
                    ant.tilted_by(state.beam_tilt_rad)
                        .elevation_pattern(el)
                        .powi(2)
                        .max(1e-300),
                ),
                atmosphere: loss_db(scene.environment().attenuation_power(range_m)),
                rain: rain_two_way_loss_db(radar, scene.environment(), o.position_m()),
                eclipse: (eclipse_fraction > 0.0).then(|| loss_db(eclipse_fraction.powi(2))),
                blind_sector: crate::model::artefacts::blind_loss_db(
                    &scene.artefacts().blind_sectors,
                    az,
                    revolution.own_ship().map_or(0.0, |s| s.heading_rad),
                ),
            };
            let snr_unclipped_db = rcs.map(|s| {
                linear_to_db(radar.point_target_snr_for_pulse(s, range_m, *pulse_width_s))
                    + linear_to_db(gain.unwrap_or(1.0))
                    - losses.window
                    - losses.elevation_pattern
                    - losses.atmosphere
                    - losses.rain
                    - losses.blind_sector
            });
            let snr_db =
                snr_unclipped_db.and_then(|s| losses.eclipse.map(|eclipse_db| s - eclipse_db));
            let r_b = o.shape().bounding_radius_m();
            let centre_range = (o.bounding_centre_m() - radar.position_m()).length();
            let top_m = o.bounding_centre_m().z + r_b;
            let beyond_horizon = scene.environment().earth_curvature()
                && !crate::propagation::above_horizon(radar.position_m().z, ground_range_m, top_m);
            let visibility = if beyond_horizon {
                Visibility::BeyondHorizon
            } else if centre_range - r_b > radar.max_range_m() {
                Visibility::BeyondMaxRange
            } else if sums[i].returns == 0
                && (set.land_shadowed.get(i).is_some_and(|&n| n > 0)
                    || land_hides(scene, o.bounding_centre_m(), r_b))
            {
                Visibility::ShadowedByLand
            } else if sums[i].returns == 0 {
                let idx = i as u32;
                let blocked = [
                    o.bounding_centre_m(),
                    o.bounding_centre_m() + DVec3::Z * r_b,
                ]
                .iter()
                .all(|&p| line_of_sight_blocked(bvh, radar.position_m(), p, idx));
                if blocked {
                    Visibility::Shadowed
                } else if calibrated {
                    Visibility::NoReturn
                } else {
                    Visibility::MissedByRayGrid
                }
            } else if eclipse_fraction == 0.0
                || (snr_db.is_some_and(|s| s < 0.0) && snr_unclipped_db.is_some_and(|s| s >= 0.0))
            {
                Visibility::Eclipsed
            } else if snr_db.is_some_and(|s| s < 0.0) {
                Visibility::BelowNoise
            } else if eclipse_fraction < 1.0 {
                Visibility::PartiallyEclipsed
            } else {
                Visibility::Visible
            };
            // The compressed echo's extent beyond the object: one range resolution on the far
            // side for the LFM pulse; the short pulse's response on both sides (c·τ/2 for an
            // unmodulated pulse: its triangle's half-base).
            let (near_m, far_m) = match (channel, radar.short_pulse()) {
                (PulseChannel::Short, Some(p)) => {
                    let half = if p.chirp.bandwidth_hz > 0.0 {
                        SPEED_OF_LIGHT_M_PER_S / (2.0 * p.chirp.bandwidth_hz)
                    } else {
                        SPEED_OF_LIGHT_M_PER_S * p.chirp.pulse_width_s / 2.0
                    };
                    (half, half)
                }
                _ => (0.0, resolution_m),
            };
            let region = || {
                EchoRegion::new(
                    rel,
                    az,
                    centre_range,
                    r_b,
                    ground_range_m,
                    (near_m, far_m),
                    ant.az_beamwidth_rad,
                )
            };
            let echo_region = visibility.has_echo().then(region);
            let far_region = (visibility == Visibility::BeyondMaxRange).then(region);
            let polar_box =
                echo_region.and_then(|e| e.polar_box(bin_m, radar.num_range_bins(), spokes));
            let (size_m, footprint_m) =
                footprint_of(&o.local_bounds(), o.position_m(), o.rotation());
            let antenna = radar.position_m();
            let footprint_from_radar_m = footprint_m.map(|[e, n]| [e - antenna.x, n - antenna.y]);
            ObjectTruth {
                id: i as u32,
                track_id: i as u32,
                beam_time_s: state.beam_time_s,
                name: o.name().to_string(),
                class: o.class().to_string(),
                shape: o.shape_name().to_string(),
                position_m: k.position_m.to_array(),
                velocity_mps: k.velocity_mps.to_array(),
                speed_kn: k.speed_mps() / KNOT_M_PER_S,
                course_deg: k.course_rad().map(f64::to_degrees),
                heading_deg: heading_of(k.rotation).map(f64::to_degrees),
                radial_velocity_mps,
                doppler_hz: -2.0 * radial_velocity_mps / radar.wavelength_m(),
                radial_motion: RadialMotion::of(radial_velocity_mps),
                range_m,
                ground_range_m,
                azimuth_deg: az.to_degrees(),
                elevation_deg: el.to_degrees(),
                aspect_azimuth_deg,
                aspect_elevation_deg,
                rcs_m2: rcs,
                rcs_dbsm: rcs.map(linear_to_db),
                multipath_gain_db: gain.filter(|g| *g > 0.0).map(linear_to_db),
                losses_db: losses,
                eclipse_received_fraction: eclipse_fraction,
                pulse: channel,
                expected_snr_db: snr_db,
                snr_before_eclipse_db: snr_unclipped_db,
                visibility,
                shadowed_by_land: visibility == Visibility::ShadowedByLand,
                distance_to_coast_m: scene
                    .environment()
                    .land()
                    .distance_to_coast_m(o.position_m().truncate()),
                po_tubes: set.tube_budgets.get(i).copied().flatten(),
                polar_box,
                ppi_box_px: None,
                size_m,
                footprint_m,
                ppi_footprint_px: None,
                echo_region,
                far_region,
                region: region(),
                footprint_from_radar_m,
            }
        })
        .collect()
}

/// Where an object's echo can lie: its bounding sphere's slant-range extent plus one range
/// resolution, and its azimuth extent plus half the beamwidth each side. The polar box is
/// drawn from it here; products draw their own boxes from it (the PPI's pixel box, in
/// [`crate::products::ppi::PpiGeometry::pixel_box`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EchoRegion {
    /// Nearest slant range, m.
    pub range_min_m: f64,
    /// Farthest slant range, m.
    pub range_max_m: f64,
    /// Height of the object's reference point above the antenna, m.
    pub height_above_radar_m: f64,
    /// Nautical azimuth of the centre, rad.
    pub azimuth_rad: f64,
    /// Half the azimuth extent, rad (≤ π).
    pub half_width_rad: f64,
}

impl EchoRegion {
    #[allow(clippy::too_many_arguments)]
    fn new(
        rel: DVec3,
        az: f64,
        centre_range_m: f64,
        radius_m: f64,
        ground_range_m: f64,
        (near_m, far_m): (f64, f64),
        az_beamwidth_rad: f64,
    ) -> EchoRegion {
        let half_az = (radius_m / ground_range_m.max(1e-9)).atan() + az_beamwidth_rad / 2.0;
        EchoRegion {
            range_min_m: (centre_range_m - radius_m - near_m).max(0.0),
            range_max_m: centre_range_m + radius_m + far_m,
            height_above_radar_m: rel.z,
            azimuth_rad: az,
            half_width_rad: half_az.min(std::f64::consts::PI),
        }
    }

    /// The box in (spoke, bin) of the record; None when the region starts beyond its last bin.
    pub fn polar_box(&self, bin_m: f64, num_bins: usize, spokes: usize) -> Option<PolarBox> {
        if num_bins == 0 || spokes == 0 {
            return None;
        }
        let spoke_rad = std::f64::consts::TAU / spokes as f64;
        let (az, half_az) = (self.azimuth_rad, self.half_width_rad);
        let max_bin = num_bins - 1;
        let first_bin = (self.range_min_m / bin_m).floor();
        (first_bin <= max_bin as f64).then(|| {
            let bin_min = first_bin as usize;
            let bin_max = ((self.range_max_m / bin_m).ceil() as usize).min(max_bin);
            let s_lo = ((az - half_az) / spoke_rad).round() as i64;
            let s_hi = ((az + half_az) / spoke_rad).round() as i64;
            let (spoke_min, spoke_max) = if s_hi - s_lo + 1 >= spokes as i64 {
                (0, spokes - 1)
            } else {
                (
                    s_lo.rem_euclid(spokes as i64) as usize,
                    s_hi.rem_euclid(spokes as i64) as usize,
                )
            };
            PolarBox {
                spoke_min,
                spoke_max,
                bin_min,
                bin_max,
            }
        })
    }
}
