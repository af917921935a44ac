//! Shooting-and-bouncing rays with physical-optics ray tubes (the default model).
//!
//! For each object that is not a point, square ray tubes of side δ (`ray_spacing_wavelengths`·λ,
//! grown if the object would need more than `max_rays_per_object`) are launched from the radar
//! phase centre toward a grid over the disk that covers the object's bounding sphere, seen
//! from the radar. A tube whose first hit is on another object is shadowed and dropped (that
//! object has tubes of its own). At every hit the tube's PO integral toward the radar gives
//! (docs/physics.md §2.2; Ling, Chou & Lee 1989; Knott, Shaeffer & Tuley, *Radar Cross Section*,
//! 2nd ed., ch. 5):
//!
//! `S = (√(4π)/λ) · A⊥ · P · F · exp(−j2πℓ/λ)`
//!
//! - `A⊥` the tube's cross-section (δ² scaled by (ℓ₁/R)² for the spherical spread to the object),
//! - `P = p̂_rx · (−[(n̂·E_i)k̂_i − (n̂·k̂_i)E_i]⊥)`, the received part of the far field of the
//!   PO current `2n̂ × H_i` at the hit (its part across `ŝ`, times n̂·ŝ; Knott et al. eq. 5.37),
//!   with the incident field `E_i` starting from the transmit polarisation `p̂_tx` and reflected
//!   at each perfect-conductor hit as `E_r = 2(n̂·E_i)n̂ − E_i`, and at the sea by the Fresnel
//!   coefficients Γ_H, Γ_V (complex) in the local plane of incidence. In the specular direction
//!   `P = (n̂·ŝ)·E_r·p̂_rx`; off it, PO's polarisation independence holds (a plate's `cos θ` in
//!   both planes),
//! - `F = sinc(q·e₁/2)·sinc(q·e₂/2)/|n̂·k̂_i|`, `q = k(ŝ − k̂_r)`: with the n̂·ŝ in `P`, the exact
//!   PO integral over the tube's parallelogram footprint `e₁, e₂` on its facet (sinc x = sin x / x),
//! - `ℓ` the whole path radar → hits → radar (f64).
//!
//! **The sea (multipath).** With the sea on, the plane z = 0 reflects (`propagation::sea_reflection`).
//! Each object gets a second tube grid aimed at its mirror image below the sea: those tubes
//! reach it after a sea reflection. Every hit on an object radiates back both directly and via
//! the sea (toward the radar's image), so the four paths direct–direct, direct–sea, sea–direct
//! and sea–sea of the two-ray model all arise, with shadowing by other objects. The sea's own
//! backscatter (clutter) is not a PO return here.
//!
//! Return paths other than the way a tube came in are checked with shadow rays.
//! Ideal `point` objects give `S = √σ·exp(−j2πℓ/λ)` per path (four paths over the sea).

mod edges;
mod rods;
mod still;
mod tube;

pub use edges::{
    edge_returns, fringe_coefficients, keller_coefficients, po_coefficients, MAX_SINC_ARGUMENT,
};
pub use rods::{rod_returns, ROD_PIECE_M};

pub use still::{KeptTrace, ObjectReach, StillTraces};
pub use tube::{
    polarisation_vector, sea_mirror, sea_reflect, trace_tube, trace_tube_with, ComplexVec3,
    Illumination, RaySink, SbrSettings, TubeCoverage, TubeGrid, TubeReturn,
};

use super::{azimuth_elevation_rad, carrier_phase, vector_bits, Contribution, ScatterSet};
use crate::geometry::{wedge_edges, Bvh, Ray, Rod, ShapeGeometry};
use crate::model::{Polarisation, Scene, SceneObject};
use crate::propagation::SeaSurface;
use crate::special::LastCall;
use glam::DVec3;
use num_complex::Complex64;
use rayon::prelude::*;

/// What of an object scatters besides its traced primitives, and how they reflect: its rods
/// (world frame, [`rod_returns`]) and the amplitude reflectivity of its traced surfaces,
/// applied at each reflection a return makes (on a return that also bounced off another
/// object, at that bounce too: the rare cross-object paths take the traced object's
/// material).
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectOptics {
    /// Rods, m.
    pub rods: Vec<Rod>,
    /// Amplitude reflectivity of the traced surfaces (1: a conductor).
    pub reflectivity: f64,
    /// The widest tube side its detail allows, m: the ray budget rises above
    /// `max_rays_per_object` until the tubes are no wider (None: the budget as set).
    pub max_tube_side_m: Option<f64>,
}

impl ObjectOptics {
    /// A conductor without rods.
    pub fn conductor() -> ObjectOptics {
        ObjectOptics {
            rods: Vec::new(),
            reflectivity: 1.0,
            max_tube_side_m: None,
        }
    }

    /// Those of a scene object, placed in the world.
    pub fn of(object: &SceneObject) -> ObjectOptics {
        ObjectOptics {
            rods: object.rods_m(),
            reflectivity: object.shape().surface_reflectivity(),
            max_tube_side_m: object.shape().max_tube_side_m(),
        }
    }
}

/// The tube grid an object was traced with, against what was asked for.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TubeBudget {
    /// Requested tube side (`ray_spacing_wavelengths`·λ), m.
    pub requested_spacing_m: f64,
    /// Tube side used at the grid plane through the object's centre, m.
    pub spacing_m: f64,
    /// Tubes in the direct grid's disk (about π/4 of `cells_per_side²`).
    pub tubes: usize,
    /// `max_rays_per_object` bound, so `spacing_m > requested_spacing_m`.
    pub capped: bool,
}

/// What tracing one object gave.
#[derive(Debug, Clone)]
pub struct ObjectTrace {
    /// Returns of every tube, in a deterministic order.
    pub returns: Vec<TubeReturn>,
    /// Rays cast (including bounce and shadow rays).
    pub rays: u64,
    /// The direct grid's tube budget.
    pub budget: TubeBudget,
}

/// [`ObjectTrace`] with the returns as the runs of rows the parallel trace made, in order
/// (their concatenation is `ObjectTrace::returns`), not copied into one vector.
struct ObjectRuns {
    runs: Vec<Vec<TubeReturn>>,
    rays: u64,
    budget: TubeBudget,
}

/// All returns of one object lit by `illumination` (rows traced in parallel, collected in
/// order so the result does not depend on the thread count). With the sea on (and a radar
/// at a point), a second grid aimed at the object's mirror image adds the paths that reach
/// it via the sea.
pub fn trace_object(
    bvh: &Bvh,
    illumination: Illumination,
    centre_m: DVec3,
    radius_m: f64,
    index: u32,
    optics: &ObjectOptics,
    s: &SbrSettings,
) -> ObjectTrace {
    let traced = trace_object_runs(bvh, illumination, centre_m, radius_m, index, optics, s);
    let total: usize = traced.runs.iter().map(Vec::len).sum();
    let mut runs = traced.runs.into_iter();
    let mut returns = runs.next().unwrap_or_default();
    returns.reserve(total - returns.len());
    for run in runs {
        returns.extend(run);
    }
    ObjectTrace {
        returns,
        rays: traced.rays,
        budget: traced.budget,
    }
}

/// [`trace_object`] without joining the runs.
fn trace_object_runs(
    bvh: &Bvh,
    illumination: Illumination,
    centre_m: DVec3,
    radius_m: f64,
    index: u32,
    optics: &ObjectOptics,
    s: &SbrSettings,
) -> ObjectRuns {
    trace_object_runs_with(
        bvh,
        illumination,
        centre_m,
        radius_m,
        index,
        optics,
        s,
        || (),
    )
    .0
}

/// [`trace_object_runs`], handing every ray cast to a sink `new_sink` makes (one per run of
/// rows traced together, and one for the rods): the runs and their sinks, in order.
#[allow(clippy::too_many_arguments)]
fn trace_object_runs_with<R: RaySink + Send>(
    bvh: &Bvh,
    illumination: Illumination,
    centre_m: DVec3,
    radius_m: f64,
    index: u32,
    optics: &ObjectOptics,
    s: &SbrSettings,
    new_sink: impl Fn() -> R + Sync + Send,
) -> (ObjectRuns, Vec<R>) {
    // A detailed object's budget grows until its tubes are no wider than its detail allows.
    let max_rays = crate::model::object_max_rays(s.max_rays, radius_m, optics.max_tube_side_m);
    let s = &SbrSettings { max_rays, ..*s };
    let mut grids = vec![TubeGrid::new(
        illumination,
        centre_m,
        radius_m,
        s.spacing_m,
        s.max_rays,
        false,
    )];
    if let (Some(_), Illumination::FromPoint { radar_m }) = (s.sea, illumination) {
        if radar_m.z > 0.0 && centre_m.z + radius_m > 0.0 {
            let image = sea_mirror(centre_m);
            grids.push(TubeGrid::new(
                illumination,
                image,
                radius_m,
                s.spacing_m,
                s.max_rays,
                true,
            ));
        }
    }
    let direct = &grids[0];
    let budget = TubeBudget {
        requested_spacing_m: s.spacing_m,
        spacing_m: direct.spacing_m,
        tubes: (0..direct.cells_per_side)
            .map(|j| {
                (0..direct.cells_per_side)
                    .filter(|&i| direct.point(i, j).is_some())
                    .count()
            })
            .sum(),
        capped: direct.capped,
    };
    let mut returns: Vec<Vec<TubeReturn>> = Vec::new();
    let mut sinks = Vec::new();
    let mut rays = 0;
    let bounds = bvh.object_bounds(index);
    for grid in &grids {
        // Only the tubes that can meet one of the object's primitives: the rest
        // return nothing.
        let coverage = grid.coverage(&bounds, object_parts(bvh, index));
        let (columns, rows) = (coverage.columns.clone(), coverage.rows.clone());
        // Rows in runs of at least four per task, each run's returns in one vector; the runs
        // are contiguous and collected in order, so the returns keep the row order whatever
        // the thread count.
        let runs: Vec<(Vec<TubeReturn>, u64, R)> = rows
            .into_par_iter()
            .with_min_len(4)
            .fold(
                || (Vec::new(), 0u64, new_sink()),
                |(mut out, mut rays, mut sink), j| {
                    for i in columns.clone() {
                        if coverage.covers(i, j) {
                            rays += trace_tube_with(bvh, grid, i, j, index, s, &mut out, &mut sink);
                        }
                    }
                    (out, rays, sink)
                },
            )
            .collect();
        for (run, n, sink) in runs {
            rays += n;
            sinks.push(sink);
            if !run.is_empty() {
                returns.push(run);
            }
        }
    }
    if optics.reflectivity != 1.0 {
        // A plastic surface scales the field at every reflection on it.
        for run in &mut returns {
            for r in run.iter_mut() {
                r.root_rcs_m *= optics.reflectivity.powi(i32::from(r.bounces));
            }
        }
    }
    let rods = &optics.rods;
    if !rods.is_empty() {
        // The rods' returns after the tubes', their paths measured as the direct grid's.
        let mut sink = new_sink();
        let mut run = Vec::new();
        rays += rod_returns(
            bvh,
            illumination,
            direct.plane_origin_m(),
            rods,
            s,
            &mut run,
            &mut sink,
        );
        sinks.push(sink);
        if !run.is_empty() {
            returns.push(run);
        }
    }
    if s.edge_diffraction {
        // The fringe returns of its wedge edges after the rods', their paths measured alike.
        let edges = wedge_edges(bvh.object_primitives(index));
        let mut sink = new_sink();
        let mut run = Vec::new();
        rays += edge_returns(
            bvh,
            illumination,
            direct.plane_origin_m(),
            &edges,
            optics.reflectivity,
            s,
            &mut run,
            &mut sink,
        );
        sinks.push(sink);
        if !run.is_empty() {
            returns.push(run);
        }
    }
    let runs = ObjectRuns {
        runs: returns,
        rays,
        budget,
    };
    (runs, sinks)
}

/// The hull points of the primitives of object `index` in `bvh`, for
/// [`TubeGrid::coverage`] (made as they are read: a mesh's would be 200 bytes a triangle).
pub fn object_parts(bvh: &Bvh, index: u32) -> impl Iterator<Item = ([DVec3; 8], usize)> + '_ {
    bvh.object_primitives(index).map(|p| p.hull_points())
}

/// Monostatic RCS of everything in `bvh` tagged `index`, lit by a plane wave from
/// `toward_radar` (unit, object → radar): `σ = |Σ S|²`, m².
pub fn plane_wave_rcs_m2(
    bvh: &Bvh,
    toward_radar: DVec3,
    centre_m: DVec3,
    radius_m: f64,
    index: u32,
    optics: &ObjectOptics,
    s: &SbrSettings,
) -> f64 {
    trace_object(
        bvh,
        Illumination::PlaneWave { toward_radar },
        centre_m,
        radius_m,
        index,
        optics,
        s,
    )
    .returns
    .iter()
    .map(|r| r.root_rcs_m)
    .sum::<Complex64>()
    .norm_sqr()
}

/// SBR settings of a scene.
/// Whether `obj` of `scene` cannot be seen and is not traced: wholly beyond the recorded
/// range (max range + c·T/2, where the last echo tail ends: it depends on the pulse) or below
/// the radar horizon.
pub fn out_of_sight(scene: &Scene, obj: &SceneObject) -> bool {
    let radar = scene.radar();
    let centre = obj.bounding_centre_m();
    let radius = obj.shape().bounding_radius_m();
    let nearest_m = (centre - radar.position_m()).length() - radius;
    let ground_m = ((centre - radar.position_m()).truncate().length() - radius).max(0.0);
    // With second-trace echoes an object up to one pulse interval beyond the record still
    // echoes (in the next pulse's record).
    let reach_m = radar.max_range_m()
        + radar.eclipse_range_m()
        + if scene.artefacts().second_trace {
            let stagger = radar.scan().stagger();
            if stagger.is_staggered() {
                // The longest interval folds the farthest.
                let longest_s = stagger.intervals_s().iter().fold(0f64, |a, &t| a.max(t));
                crate::constants::SPEED_OF_LIGHT_M_PER_S * longest_s / 2.0
            } else {
                crate::constants::SPEED_OF_LIGHT_M_PER_S / (2.0 * radar.prf_hz())
            }
        } else {
            0.0
        };
    nearest_m > reach_m
        || (scene.environment().earth_curvature()
            && !crate::propagation::above_horizon(
                radar.position_m().z,
                ground_m,
                centre.z + radius,
            ))
}

pub fn settings_for(scene: &Scene) -> SbrSettings {
    let lambda = scene.radar().wavelength_m();
    SbrSettings {
        wavelength_m: lambda,
        polarisation: scene.radar().polarisation(),
        max_bounces: scene.scattering().max_bounces(),
        spacing_m: scene.scattering().ray_spacing_wavelengths() * lambda,
        max_rays: scene.scattering().max_rays_per_object(),
        sea: scene.environment().sea().copied(),
        earth_curvature: scene.environment().earth_curvature(),
        edge_diffraction: scene.scattering().edge_diffraction(),
    }
}

/// One leg between the radar and a point target: path length, direction from the radar, and
/// the sea's reflection coefficient along it (1 for the direct leg); None if blocked.
fn point_leg(
    bvh: &Bvh,
    radar_m: DVec3,
    target_m: DVec3,
    via_sea: Option<&SeaSurface>,
    s: &SbrSettings,
) -> Option<(f64, DVec3, Complex64)> {
    match via_sea {
        None => {
            let v = target_m - radar_m;
            let len = v.length();
            let dir = v / len;
            (!bvh.any_hit(
                &Ray {
                    origin_m: radar_m,
                    dir,
                },
                len,
            ))
            .then_some((len, dir, Complex64::new(1.0, 0.0)))
        }
        Some(sea) => {
            if radar_m.z <= 0.0 || target_m.z <= 0.0 {
                return None;
            }
            let image = sea_mirror(target_m);
            let v = image - radar_m;
            let len = v.length();
            let dir = v / len;
            let t_sea = radar_m.z / -dir.z;
            let sea_pt = radar_m + dir * t_sea;
            let up = target_m - sea_pt;
            let up_len = up.length();
            if bvh.any_hit(
                &Ray {
                    origin_m: radar_m,
                    dir,
                },
                t_sea,
            ) || bvh.any_hit(
                &Ray {
                    origin_m: sea_pt,
                    dir: up / up_len,
                },
                up_len,
            ) {
                return None;
            }
            let (gh, gv) = sea.reflection_sin((-dir.z).clamp(-1.0, 1.0), s.wavelength_m);
            Some((
                len,
                dir,
                if s.polarisation == Polarisation::Hh {
                    gh
                } else {
                    gv
                },
            ))
        }
    }
}

/// Traces every object of the scene with SBR/PO and converts to volts.
pub fn trace(scene: &Scene, bvh: &Bvh) -> ScatterSet {
    let all = vec![Selection::Trace; scene.objects().len()];
    trace_selected(scene, bvh, &all).0
}

/// What [`trace_selected`] does with an object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Selection {
    /// Leaves it out (its returns are known already).
    Skip,
    /// Traces it.
    Trace,
    /// Traces it and records where its rays went.
    TraceRecording,
}

/// What [`trace_selected`] gives beside the contributions, per object: the rays its trace
/// cast and, for [`Selection::TraceRecording`], where they went.
#[derive(Debug, Default)]
pub struct ObjectRays {
    pub rays: u64,
    pub reach: Option<ObjectReach>,
}

/// [`trace`] of the objects `select` picks (a point is traced unless skipped), in object
/// order: each object's contributions are one run of the set's.
pub fn trace_selected(
    scene: &Scene,
    bvh: &Bvh,
    select: &[Selection],
) -> (ScatterSet, Vec<ObjectRays>) {
    let radar = scene.radar();
    let s = settings_for(scene);
    let volts = |r_tx: f64, r_rx: f64| {
        super::path_volts_per_root_m2(scene.radar(), scene.environment(), r_tx, r_rx)
    };
    let mut set = ScatterSet {
        tube_budgets: vec![None; scene.objects().len()],
        ..ScatterSet::default()
    };
    let selection = |idx: usize| select.get(idx).copied().unwrap_or(Selection::Trace);
    let mut per_object: Vec<ObjectRays> = (0..scene.objects().len())
        .map(|_| ObjectRays::default())
        .collect();
    // Every extended object's tubes first (None for a point, an object left out or one
    // that cannot be seen), so that the contributions are reserved once, not moved as each
    // object adds its own; then the contributions in object order.
    let traces: Vec<Option<ObjectRuns>> = scene
        .objects()
        .iter()
        .enumerate()
        .map(|(idx, obj)| {
            if let ShapeGeometry::Point { .. } = obj.shape() {
                return None;
            }
            if selection(idx) == Selection::Skip || out_of_sight(scene, obj) {
                return None;
            }
            let centre = obj.bounding_centre_m();
            let radius = obj.shape().bounding_radius_m();
            let illumination = Illumination::FromPoint {
                radar_m: radar.position_m(),
            };
            let optics = ObjectOptics::of(obj);
            if selection(idx) == Selection::Trace {
                return Some(trace_object_runs(
                    bvh,
                    illumination,
                    centre,
                    radius,
                    idx as u32,
                    &optics,
                    &s,
                ));
            }
            let cones = ObjectReach::new(radar.position_m(), centre, radius, s.sea.is_some());
            let (runs, sinks) = trace_object_runs_with(
                bvh,
                illumination,
                centre,
                radius,
                idx as u32,
                &optics,
                &s,
                || cones.same_cones(),
            );
            let mut reach = cones;
            reach.absorb(sinks);
            per_object[idx].reach = Some(reach);
            Some(runs)
        })
        .collect();
    let points = scene
        .objects()
        .iter()
        .filter(|o| matches!(o.shape(), ShapeGeometry::Point { .. }))
        .count();
    // A point's legs: direct and via the sea, each way.
    set.contributions.reserve(
        traces
            .iter()
            .flatten()
            .flat_map(|t| &t.runs)
            .map(Vec::len)
            .sum::<usize>()
            + 4 * points,
    );
    for (idx, obj) in scene.objects().iter().enumerate() {
        let index = idx as u32;
        if selection(idx) == Selection::Skip {
            continue;
        }
        if let ShapeGeometry::Point { rcs_m2 } = obj.shape() {
            let ground = (obj.position_m() - radar.position_m()).truncate().length();
            if s.earth_curvature
                && !crate::propagation::above_horizon(
                    radar.position_m().z,
                    ground,
                    obj.position_m().z,
                )
            {
                continue;
            }
            let mut routes: Vec<Option<&SeaSurface>> = vec![None];
            if let Some(sea) = s.sea.as_ref() {
                routes.push(Some(sea));
            }
            let legs: Vec<(f64, DVec3, Complex64, u8)> = routes
                .into_iter()
                .filter_map(|via| {
                    point_leg(bvh, radar.position_m(), obj.position_m(), via, &s)
                        .map(|(len, dir, g)| (len, dir, g, u8::from(via.is_some())))
                })
                .collect();
            set.rays_cast += 2 * legs.len() as u64;
            per_object[idx].rays = 2 * legs.len() as u64;
            for &(len_tx, dir_tx, g_tx, sea_tx) in &legs {
                for &(len_rx, dir_rx, g_rx, sea_rx) in &legs {
                    let path_m = len_tx + len_rx;
                    let root = carrier_phase(path_m, s.wavelength_m) * g_tx * g_rx * rcs_m2.sqrt();
                    let (az_tx, el_tx) = azimuth_elevation_rad(dir_tx);
                    let (az_rx, el_rx) = azimuth_elevation_rad(dir_rx);
                    set.contributions.push(Contribution {
                        amplitude_v: root * volts(len_tx, len_rx),
                        root_rcs_m: root,
                        path_m,
                        az_tx_rad: az_tx,
                        el_tx_rad: el_tx,
                        az_rx_rad: az_rx,
                        el_rx_rad: el_rx,
                        object: index,
                        bounces: 0,
                        sea_reflections: sea_tx + sea_rx,
                    });
                }
            }
            continue;
        }
        let Some(traced) = &traces[idx] else {
            continue;
        };
        set.rays_cast += traced.rays;
        per_object[idx].rays = traced.rays;
        set.tube_budgets[idx] = Some(traced.budget);
        // A tube's returns share its launch direction (about half of all returns follow
        // another of the same tube): its angles are computed once, the same values.
        let mut tx_angles = LastCall::new();
        set.contributions
            .extend(traced.runs.iter().flatten().map(|r| {
                let (az_tx, el_tx) =
                    tx_angles.get_or(vector_bits(r.tx_dir), || azimuth_elevation_rad(r.tx_dir));
                let (az_rx, el_rx) = if vector_bits(r.rx_dir) == vector_bits(r.tx_dir) {
                    (az_tx, el_tx)
                } else {
                    azimuth_elevation_rad(r.rx_dir)
                };
                Contribution {
                    amplitude_v: r.root_rcs_m * volts(r.range_tx_m, r.range_rx_m),
                    root_rcs_m: r.root_rcs_m,
                    path_m: r.path_m,
                    az_tx_rad: az_tx,
                    el_tx_rad: el_tx,
                    az_rx_rad: az_rx,
                    el_rx_rad: el_rx,
                    object: index,
                    bounces: r.bounces,
                    sea_reflections: r.sea_reflections,
                }
            }));
    }
    (set, per_object)
}
