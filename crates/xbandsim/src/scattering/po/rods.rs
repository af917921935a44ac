//! Rods ([`crate::geometry::Rod`]): the physical-optics return of a finite circular cylinder
//! in closed form, piece by piece along its axis.
//!
//! For incidence along `k̂_i` and scattering toward `ŝ`, with `q = k(ŝ − k̂_i)` split into
//! its part `q_∥` along the axis and `q_⊥` across it, the PO integral over the lit side of a
//! piece of length ℓ is, by stationary phase around the circumference (Knott, Shaeffer &
//! Tuley, *Radar Cross Section*, 2nd ed., §5.2; docs/physics.md §2.2),
//!
//! `S = (√(4π)/λ) · P · w · ℓ · sinc(q_∥ℓ/2) · exp(−j2πL/λ − jπ/4)`
//! (pieces of [`ROD_PIECE_M`], longer the farther the radar),
//!
//! times the rod's reflectivity (1 for a conductor), with `n̂ = q_⊥/|q_⊥|` the normal at the
//! specular line, `w = √(2πa/|q_⊥|)` the width of the first Fresnel zone around it (capped at
//! the diameter 2a where the stationary phase fails, `|q_⊥|a < π/2`),
//! `P = p̂_rx·(−[(n̂·E)k̂_i − (n̂·k̂_i)E]⊥)` the received part of the field the PO current there
//! radiates, as for a facet (it carries the factor n̂·ŝ), and L the path through the specular
//! point `c + a·n̂` of the piece's centre c. Monostatic (`ŝ = −k̂_i`, tilt ψ from broadside) the
//! pieces add up to Knott's `σ = k·a·L²·cos ψ·sinc²(kL sin ψ)` (Table 5.1) for a plane wave;
//! from a point source each piece has its own path, so the rod is focused exactly as the
//! wave front curves.
//!
//! Over the sea each piece returns along the four paths of the two-ray model (radar or its
//! image in z = 0, each way, with the sea's Fresnel reflection and shadow rays on each leg);
//! a vertical rod's direct–sea paths are the rod–sea dihedral that makes masts bright at low
//! grazing. A piece under the sea or below the radar horizon returns nothing, as a tube's
//! hit there would not. Rods neither shadow nor bounce (they are not in the BVH); PO holds for `ka ≳ 1`
//! (radius ≳ 5 mm at X band).

use super::tube::{
    polarisation_vector, sea_mirror, sea_reflect, ComplexVec3, Illumination, RaySink, SbrSettings,
    TubeReturn,
};
use crate::geometry::{Bvh, Ray, Rod};
use crate::propagation::SeaSurface;
use crate::scattering::carrier_phase;
use glam::DVec3;
use num_complex::Complex64;

/// Shortest and longest piece a rod is cut into, m. Between them a piece is as long as
/// keeps the wave front's bend over it, `ℓ²/(8R)` from the radar R away, under λ/10
/// (`ℓ = √(0.8·λ·R)`: 1.6 m at 100 m, 5 m at 1 km at X band), so a piece's closed form holds
/// as for a plane wave; the longest also bounds how coarsely a piece's shadow ray samples
/// what hides the rod.
pub const ROD_PIECE_M: (f64, f64) = (0.5, 4.0);

/// The piece length for a rod whose nearest point lies `range_m` from the radar (infinite
/// for a plane wave), m.
fn piece_length_m(range_m: f64, wavelength_m: f64) -> f64 {
    (0.8 * wavelength_m * range_m)
        .sqrt()
        .clamp(ROD_PIECE_M.0, ROD_PIECE_M.1)
}

/// How many pieces a segment from `a_m` along unit `along` for `length_m` is cut into under
/// `illumination`, and their length, m ([`piece_length_m`] at the segment's nearest point to
/// the radar).
pub(super) fn segment_pieces(
    a_m: DVec3,
    along: DVec3,
    length_m: f64,
    illumination: Illumination,
    wavelength_m: f64,
) -> (usize, f64) {
    let range_m = match illumination {
        Illumination::PlaneWave { .. } => f64::INFINITY,
        Illumination::FromPoint { radar_m } => {
            // The nearest point of the segment to the radar.
            let t = (radar_m - a_m).dot(along).clamp(0.0, length_m);
            (a_m + along * t - radar_m).length()
        }
    };
    let pieces = (length_m / piece_length_m(range_m, wavelength_m))
        .ceil()
        .max(1.0) as usize;
    (pieces, length_m / pieces as f64)
}

/// The directions of travel at `point`: straight from the radar, and with the sea on, up
/// from the sea toward it (on the line from the radar to its image).
pub(super) fn arrivals_at(
    point: DVec3,
    illumination: Illumination,
    sea: Option<&SeaSurface>,
) -> [Option<DVec3>; 2] {
    let mut arrivals = [None, None];
    match illumination {
        Illumination::PlaneWave { toward_radar } => arrivals[0] = Some(-toward_radar),
        Illumination::FromPoint { radar_m } => {
            arrivals[0] = Some((point - radar_m).normalize());
            if sea.is_some() && radar_m.z > 0.0 && point.z > 0.0 {
                arrivals[1] = Some(sea_mirror((sea_mirror(point) - radar_m).normalize()));
            }
        }
    }
    arrivals
}

/// Lift of a shadow ray's end off the rod's surface, m.
const SURFACE_OFFSET_M: f64 = 1e-6;

/// One clear leg between the radar and a point: the direction from the radar along its
/// first segment, its length, and whether it goes via the sea.
pub(super) struct Leg {
    /// Direction from the radar along the leg's first segment.
    pub(super) from_radar: DVec3,
    /// Length, m.
    pub(super) length_m: f64,
    /// Via the sea.
    pub(super) via_sea: bool,
}

impl Leg {
    /// The field this leg brings from the radar to its end: the transmit polarisation,
    /// reflected by the sea on a leg via it.
    pub(super) fn field_at_end(&self, s: &SbrSettings, sea: Option<&SeaSurface>) -> ComplexVec3 {
        let e = ComplexVec3::real(polarisation_vector(self.from_radar, s.polarisation));
        match (self.via_sea, sea) {
            (true, Some(sea)) => sea_reflect(e, self.from_radar, sea, s.wavelength_m).0,
            _ => e,
        }
    }

    /// What the radar receives of `field` leaving this leg's end toward it along `s_hat`:
    /// reflected by the sea on a leg via it, projected on the receive polarisation.
    pub(super) fn received(
        &self,
        field: ComplexVec3,
        s_hat: DVec3,
        s: &SbrSettings,
        sea: Option<&SeaSurface>,
    ) -> Complex64 {
        let field = match (self.via_sea, sea) {
            (true, Some(sea)) => sea_reflect(field, s_hat, sea, s.wavelength_m).0,
            _ => field,
        };
        field.dot(polarisation_vector(self.from_radar, s.polarisation))
    }
}

/// The return of a point scatterer lit along `leg_tx` and heard along `leg_rx`, of amplitude
/// `phase_factor · amplitude` before the path's carrier phase.
pub(super) fn leg_pair_return(
    leg_tx: &Leg,
    leg_rx: &Leg,
    phase_factor: Complex64,
    amplitude: Complex64,
    wavelength_m: f64,
) -> TubeReturn {
    let path_m = leg_tx.length_m + leg_rx.length_m;
    TubeReturn {
        root_rcs_m: carrier_phase(path_m, wavelength_m) * phase_factor * amplitude,
        path_m,
        tx_dir: leg_tx.from_radar,
        rx_dir: leg_rx.from_radar,
        range_tx_m: leg_tx.length_m,
        range_rx_m: leg_rx.length_m,
        bounces: 1,
        sea_reflections: u8::from(leg_tx.via_sea) + u8::from(leg_rx.via_sea),
    }
}

fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-9 {
        1.0
    } else {
        x.sin() / x
    }
}

/// The legs from the radar to `p` that nothing blocks: the direct one, and with the sea on
/// the one reflected at z = 0. Each ray cast goes to `rays_met`; returns the rays cast.
pub(super) fn legs_to(
    bvh: &Bvh,
    illumination: Illumination,
    plane_origin_m: DVec3,
    p: DVec3,
    s: &SbrSettings,
    legs: &mut Vec<Leg>,
    rays_met: &mut impl RaySink,
) -> u64 {
    legs.clear();
    match illumination {
        Illumination::PlaneWave { toward_radar } => {
            let origin = p + toward_radar * SURFACE_OFFSET_M;
            rays_met.segment(origin, toward_radar, f64::INFINITY);
            if !bvh.any_hit(
                &Ray {
                    origin_m: origin,
                    dir: toward_radar,
                },
                f64::INFINITY,
            ) {
                legs.push(Leg {
                    from_radar: -toward_radar,
                    length_m: (plane_origin_m - p).dot(toward_radar),
                    via_sea: false,
                });
            }
            1
        }
        Illumination::FromPoint { radar_m } => {
            // Under the sea, or below the radar horizon, as a tube's hit would be.
            let hidden = (s.sea.is_some() && p.z <= 0.0)
                || (s.earth_curvature
                    && !crate::propagation::above_horizon(
                        radar_m.z,
                        (p - radar_m).truncate().length(),
                        p.z,
                    ));
            if hidden {
                return 0;
            }
            let mut rays = 1;
            let v = p - radar_m;
            let len = v.length();
            let dir = v / len;
            rays_met.segment(radar_m, dir, len - SURFACE_OFFSET_M);
            if !bvh.any_hit(
                &Ray {
                    origin_m: radar_m,
                    dir,
                },
                len - SURFACE_OFFSET_M,
            ) {
                legs.push(Leg {
                    from_radar: dir,
                    length_m: len,
                    via_sea: false,
                });
            }
            if s.sea.is_some() && radar_m.z > 0.0 && p.z > 0.0 {
                let image = sea_mirror(p);
                let v = image - radar_m;
                let len = v.length();
                let dir = v / len;
                let t_sea = radar_m.z / -dir.z;
                let sea_pt = radar_m + dir * t_sea;
                let up = p - sea_pt;
                let up_len = up.length();
                rays += 2;
                rays_met.segment(radar_m, dir, t_sea);
                rays_met.segment(sea_pt, up / up_len, up_len - SURFACE_OFFSET_M);
                let clear = !bvh.any_hit(
                    &Ray {
                        origin_m: radar_m,
                        dir,
                    },
                    t_sea,
                ) && !bvh.any_hit(
                    &Ray {
                        origin_m: sea_pt,
                        dir: up / up_len,
                    },
                    up_len - SURFACE_OFFSET_M,
                );
                if clear {
                    legs.push(Leg {
                        from_radar: dir,
                        length_m: len,
                        via_sea: true,
                    });
                }
            }
            rays
        }
    }
}

/// The PO returns of `rods` lit by `illumination` (the plane wave's path reference at
/// `plane_origin_m`, as the tube grid's), appended to `out`; the rays cast.
pub fn rod_returns(
    bvh: &Bvh,
    illumination: Illumination,
    plane_origin_m: DVec3,
    rods: &[Rod],
    s: &SbrSettings,
    out: &mut Vec<TubeReturn>,
    rays_met: &mut impl RaySink,
) -> u64 {
    let settings = s.seen_from(illumination);
    let sea = settings.sea;
    let wavenumber = std::f64::consts::TAU / s.wavelength_m;
    let root_4pi_over_lambda = (4.0 * std::f64::consts::PI).sqrt() / s.wavelength_m;
    let quarter_turn_back = Complex64::from_polar(1.0, -std::f64::consts::FRAC_PI_4);
    let mut rays = 0u64;
    let mut legs_at_point = Vec::with_capacity(2);
    for rod in rods {
        let length = rod.length_m();
        if length.is_nan() || length <= 0.0 || rod.radius_m.is_nan() || rod.radius_m <= 0.0 {
            continue;
        }
        let axis = (rod.b_m - rod.a_m) / length;
        let (pieces, piece_m) = segment_pieces(rod.a_m, axis, length, illumination, s.wavelength_m);
        for n in 0..pieces {
            let centre = rod.a_m + axis * (piece_m * (n as f64 + 0.5));
            // The directions of travel at the piece: straight from the radar, and up from
            // the sea toward it (on the line from the radar to its image).
            let arrivals = arrivals_at(centre, illumination, sea.as_ref());
            // Pairs (transmit route, receive route); the two mixed pairs share their
            // specular point and its legs.
            let mut mixed_legs_found = false;
            for (tx, rx) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                let (Some(k_i), Some(k_back)) = (arrivals[tx], arrivals[rx]) else {
                    continue;
                };
                let s_hat = -k_back;
                let q = (s_hat - k_i) * wavenumber;
                let q_par = q.dot(axis);
                let q_perp = q - axis * q_par;
                let q_perp_len = q_perp.length();
                if q_perp_len * rod.radius_m < 1e-9 {
                    continue;
                }
                let normal = q_perp / q_perp_len;
                let seen = normal.dot(s_hat);
                if -normal.dot(k_i) <= 0.0 || seen <= 0.0 {
                    continue;
                }
                if (tx, rx) != (1, 0) || !mixed_legs_found {
                    mixed_legs_found = (tx, rx) == (0, 1);
                    let point = centre + normal * (rod.radius_m + SURFACE_OFFSET_M);
                    rays += legs_to(
                        bvh,
                        illumination,
                        plane_origin_m,
                        point,
                        &settings,
                        &mut legs_at_point,
                        rays_met,
                    );
                }
                let find = |via_sea: bool| legs_at_point.iter().find(|l| l.via_sea == via_sea);
                let (Some(leg_tx), Some(leg_rx)) = (find(tx == 1), find(rx == 1)) else {
                    continue;
                };
                let e = leg_tx.field_at_end(s, sea.as_ref());
                // The field radiated toward ŝ, times n̂·ŝ.
                let radiated = e.po_radiated(normal, k_i, s_hat);
                let pol = leg_rx.received(radiated, s_hat, s, sea.as_ref());
                let width_m = (std::f64::consts::TAU * rod.radius_m / q_perp_len)
                    .sqrt()
                    .min(2.0 * rod.radius_m);
                let along_m = piece_m * sinc(0.5 * q_par * piece_m);
                let amplitude = pol * (root_4pi_over_lambda * rod.reflectivity * width_m * along_m);
                if amplitude.norm_sqr() == 0.0 {
                    continue;
                }
                out.push(leg_pair_return(
                    leg_tx,
                    leg_rx,
                    quarter_turn_back,
                    amplitude,
                    s.wavelength_m,
                ));
            }
        }
    }
    rays
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Polarisation;

    fn settings(polarisation: Polarisation) -> SbrSettings {
        SbrSettings {
            wavelength_m: 0.0319,
            polarisation,
            max_bounces: 3,
            edge_diffraction: false,
            spacing_m: 0.016,
            max_rays: 1 << 16,
            sea: None,
            earth_curvature: false,
        }
    }

    /// Plane-wave RCS of `rods` seen from `toward_radar`, m².
    fn rcs_m2(rods: &[Rod], toward_radar: DVec3, s: &SbrSettings) -> f64 {
        let bvh = Bvh::build(Vec::new());
        let mut out = Vec::new();
        rod_returns(
            &bvh,
            Illumination::PlaneWave { toward_radar },
            toward_radar * 100.0,
            rods,
            s,
            &mut out,
            &mut (),
        );
        out.iter()
            .map(|r| r.root_rcs_m)
            .sum::<Complex64>()
            .norm_sqr()
    }

    /// Knott et al., Table 5.1: a cylinder of radius a and length L seen at ψ from
    /// broadside, `σ = k·a·L²·cos ψ·sinc²(kL sin ψ)`, to 0.01 dB at broadside and wherever
    /// the pattern is within 20 dB of it, for a rod cut into many pieces (3.7 m) or one
    /// (0.4 m), in both polarisations alike, as PO has it (docs/physics.md §2.2).
    #[test]
    fn a_rod_has_knotts_cylinder_rcs() {
        for pol in [Polarisation::Hh, Polarisation::Vv] {
            let s = settings(pol);
            let k = std::f64::consts::TAU / s.wavelength_m;
            for (a, length) in [(0.05, 3.7), (0.3, 0.4)] {
                let rod = Rod::new(
                    DVec3::new(0.3, 0.2, 1.0),
                    DVec3::new(0.3, 0.2, 1.0 + length),
                    a,
                );
                let peak = k * a * length * length;
                for psi_deg in [0.0f64, 0.05, 0.1, 0.2, 0.3, 3.0] {
                    let psi = psi_deg.to_radians();
                    let toward = DVec3::new(0.6 * psi.cos(), -0.8 * psi.cos(), psi.sin());
                    let x = k * length * psi.sin();
                    let sinc = if x == 0.0 { 1.0 } else { x.sin() / x };
                    let expected = peak * psi.cos() * sinc * sinc;
                    if expected < 0.01 * peak {
                        continue;
                    }
                    let got = rcs_m2(&[rod], toward, &s);
                    let err_db = 10.0 * (got / expected).log10();
                    assert!(
                        err_db.abs() < 0.01,
                        "{pol:?} a {a} L {length} psi {psi_deg}: {got} vs {expected}"
                    );
                }
            }
        }
    }

    /// Over the sea, a rod above it returns along all four paths; one under the water, or
    /// beyond the radar horizon, returns nothing (as a tube's hit there would not).
    #[test]
    fn a_rod_in_the_water_or_past_the_horizon_is_silent() {
        use crate::propagation::{SeaRoughness, SeaSurface};
        let mut s = settings(Polarisation::Hh);
        s.sea = Some(SeaSurface {
            permittivity: Complex64::new(55.0, -35.0),
            rms_height_m: 0.0,
            roughness: SeaRoughness::Ament,
        });
        s.earth_curvature = true;
        let bvh = Bvh::build(Vec::new());
        let count = |rod: Rod, radar_m: DVec3| {
            let mut out = Vec::new();
            rod_returns(
                &bvh,
                Illumination::FromPoint { radar_m },
                DVec3::ZERO,
                &[rod],
                &s,
                &mut out,
                &mut (),
            );
            out.len()
        };
        let near = DVec3::new(0.0, -300.0, 15.0);
        let above = Rod::new(DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 0.0, 1.4), 0.05);
        let under = Rod::new(DVec3::new(0.0, 0.0, -1.0), DVec3::new(0.0, 0.0, -0.6), 0.05);
        assert_eq!(count(above, near), 4);
        assert_eq!(count(under, near), 0);
        // 40 km away from a 15 m antenna, a point 1.4 m up is below the horizon (about
        // 16 km for the antenna plus 4.9 km for the point on the 4/3 earth).
        assert_eq!(count(above, DVec3::new(0.0, -40_000.0, 15.0)), 0);
    }

    /// A rod hidden behind a plate returns nothing; in front of it, its one piece.
    #[test]
    fn a_rod_behind_a_plate_is_shadowed() {
        use crate::geometry::{Primitive, PrimitiveKind};
        let s = settings(Polarisation::Hh);
        let rod = Rod::new(DVec3::ZERO, DVec3::Z * 2.0, 0.05);
        let plate = |y: f64| {
            Bvh::build(vec![Primitive {
                kind: PrimitiveKind::Parallelogram {
                    corner: DVec3::new(-1.0, y, -1.0),
                    edge_u: DVec3::X * 2.0,
                    edge_v: DVec3::Z * 4.0,
                },
                object: 1,
            }])
        };
        let count = |bvh: &Bvh| {
            let mut out = Vec::new();
            rod_returns(
                bvh,
                Illumination::PlaneWave {
                    toward_radar: DVec3::Y,
                },
                DVec3::Y * 100.0,
                &[rod],
                &s,
                &mut out,
                &mut (),
            );
            out.len()
        };
        assert_eq!(count(&plate(5.0)), 0);
        // One piece: under a plane wave the 2 m rod is shorter than the longest piece.
        assert_eq!(count(&plate(-5.0)), 1);
    }
}
