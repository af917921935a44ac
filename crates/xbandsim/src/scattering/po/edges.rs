//! Edge diffraction: the physical theory of diffraction's fringe returns of an object's wedge
//! edges ([`crate::geometry::WedgeEdge`]), piece by piece, added to the tubes' PO.
//!
//! PO's current stops abruptly at an edge, so PO gets an edge's far field wrong away from
//! the specular directions. Ufimtsev's PTD adds the fringe field: the exact wedge's
//! diffraction coefficient less PO's own (Ufimtsev, *Fundamentals of the Physical Theory of
//! Diffraction*, 2007, ch. 2–4; Knott, Shaeffer & Tuley, *Radar Cross Section*, 2nd ed., §5.4,
//! §6). In the plane across an edge of exterior angle nπ, with φ′ the direction toward the
//! source and φ toward the receiver, measured from face 0 through the exterior, Keller's
//! coefficients of the soft (E along the edge) and hard (H along it) cases are, with
//! `C = exp(−jπ/4)/√(2πk)`,
//!
//! `D_s,h = C·(sin(π/n)/n)·[1/(cos(π/n) − cos((φ−φ′)/n)) ∓ 1/(cos(π/n) − cos((φ+φ′)/n))]`,
//!
//! and PO's, of each face lit and seen (face 0 when φ′ < π and φ < π; face n, with φ and φ′
//! measured from it, when both exceed (n−1)π: the faces whose current the tubes radiate),
//! `C·sin φ′/(cos φ + cos φ′)` and `−C·sin φ/(cos φ + cos φ′)`. The fringe
//! coefficient is their difference; it stays finite where each is infinite (the faces'
//! specular directions).
//!
//! A piece of length ℓ radiates as an incremental length of the edge (Mitzner's ILDC at
//! incidence across the edge, where a straight edge returns):
//!
//! `S = (−j/√π) · ℓ · sinc(q_∥ℓ/2) · [f_s (E·t̂)(p̂·t̂) + f_h (E·û_i)(p̂·û_s)] · exp(−j2πL/λ)`
//!
//! with `f = D/C` the fringe coefficients, t̂ along the edge, `û_i = t̂ × k̂_i` and
//! `û_s = t̂ × ŝ` (normalised), `q_∥ = k(ŝ − k̂_i)·t̂` and L the path through the piece's
//! centre. It has the units and phase of a tube's S (the PO edge terms of a plate's tubes are
//! this formula with PO's coefficients). Pieces are cut as a rod's ([`super::ROD_PIECE_M`]);
//! over the sea each returns along the four paths of the two-ray model, with shadow rays on
//! every leg, as a rod's piece does. A piece whose `|q_∥ℓ/2|` exceeds [`MAX_SINC_ARGUMENT`]
//! (its sinc's envelope under 1 %) is skipped before any ray is cast.

use super::rods::{arrivals_at, leg_pair_return, legs_to, segment_pieces, Leg};
use super::tube::{sea_mirror, ComplexVec3, Illumination, RaySink, SbrSettings, TubeReturn};
use crate::geometry::{Bvh, WedgeEdge};
use glam::DVec3;
use num_complex::Complex64;
use std::f64::consts::PI;

/// Pieces whose `|q_∥ℓ/2|` exceeds this return nothing (the sinc's envelope is under 1 %).
pub const MAX_SINC_ARGUMENT: f64 = 100.0;

/// How far off the edge, along its exterior's bisector, the legs start, m.
const EDGE_OFFSET_M: f64 = 1e-4;

fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-9 {
        1.0
    } else {
        x.sin() / x
    }
}

/// Keller's wedge coefficients over C (soft, hard), for receiver φ and source φ′ (rad, from
/// face 0 through the exterior) on a wedge of exterior angle nπ.
pub fn keller_coefficients(phi: f64, phi_source: f64, wedge_n: f64) -> (f64, f64) {
    let n = wedge_n;
    let cos_pi_n = (PI / n).cos();
    let scale = (PI / n).sin() / n;
    let minus = 1.0 / (cos_pi_n - ((phi - phi_source) / n).cos());
    let plus = 1.0 / (cos_pi_n - ((phi + phi_source) / n).cos());
    (scale * (minus - plus), scale * (minus + plus))
}

/// PO's edge coefficients over C (soft, hard) of the faces that are lit and seen (the faces
/// whose PO current the tubes radiate toward the receiver: a tube returns only from a face
/// whose front the receiver sees), for the same angles.
pub fn po_coefficients(phi: f64, phi_source: f64, wedge_n: f64) -> (f64, f64) {
    let face = |phi: f64, phi_source: f64| {
        let denominator = phi.cos() + phi_source.cos();
        (phi_source.sin() / denominator, -phi.sin() / denominator)
    };
    let (mut soft, mut hard) = (0.0, 0.0);
    if phi_source < PI && phi < PI {
        let (s, h) = face(phi, phi_source);
        soft += s;
        hard += h;
    }
    let far = wedge_n * PI;
    if phi_source > far - PI && phi > far - PI {
        let (s, h) = face(far - phi, far - phi_source);
        soft += s;
        hard += h;
    }
    (soft, hard)
}

/// The fringe coefficients over C (soft, hard): Keller's less PO's. Near a face's specular
/// direction both are large and cancel: within 10⁻⁴ of it (in `cos φ + cos φ′`, where the
/// cancellation would lose more than 10⁻⁸) the fringe is the mean of its values 2·10⁻⁴ rad
/// to either side (the fringe is smooth there; the mean's error is of order 10⁻⁸).
pub fn fringe_coefficients(phi: f64, phi_source: f64, wedge_n: f64) -> (f64, f64) {
    let far = wedge_n * PI;
    let near_specular = (phi.cos() + phi_source.cos()).abs() < 1e-4
        || ((far - phi).cos() + (far - phi_source).cos()).abs() < 1e-4;
    let difference = |phi: f64| {
        let (ks, kh) = keller_coefficients(phi, phi_source, wedge_n);
        let (ps, ph) = po_coefficients(phi, phi_source, wedge_n);
        (ks - ps, kh - ph)
    };
    if near_specular {
        let (s1, h1) = difference(phi - 2e-4);
        let (s2, h2) = difference(phi + 2e-4);
        (0.5 * (s1 + s2), 0.5 * (h1 + h2))
    } else {
        difference(phi)
    }
}

/// The PTD fringe returns of `edges` lit by `illumination` (the plane wave's path reference
/// at `plane_origin_m`, as the tube grid's), each scaled by `reflectivity`, appended to `out`;
/// the rays cast.
#[allow(clippy::too_many_arguments)]
pub fn edge_returns(
    bvh: &Bvh,
    illumination: Illumination,
    plane_origin_m: DVec3,
    edges: &[WedgeEdge],
    reflectivity: f64,
    s: &SbrSettings,
    out: &mut Vec<TubeReturn>,
    rays_met: &mut impl RaySink,
) -> u64 {
    let settings = s.seen_from(illumination);
    let sea = settings.sea;
    let wavenumber = std::f64::consts::TAU / s.wavelength_m;
    let minus_j_over_root_pi = Complex64::new(0.0, -1.0 / PI.sqrt());
    let mut rays = 0u64;
    let mut legs: Vec<Leg> = Vec::with_capacity(2);
    for edge in edges {
        let length = edge.length_m();
        if length.is_nan() || length <= 0.0 {
            continue;
        }
        let along = (edge.b_m - edge.a_m) / length;
        let (pieces, piece_m) =
            segment_pieces(edge.a_m, along, length, illumination, s.wavelength_m);
        let half_exterior = 0.5 * edge.wedge_n * PI;
        let bisector =
            edge.face0_dir * half_exterior.cos() + edge.face0_normal * half_exterior.sin();
        for p in 0..pieces {
            let centre = edge.a_m + along * (piece_m * (p as f64 + 0.5));
            // Before any ray: can some pair of arrivals (straight from the radar, and up from
            // the sea) light the piece, be seen from it, and fall within the sinc's reach?
            // (A vertical edge's mixed pairs are its dihedral with the sea, which can return
            // where the direct pair's sinc has long died.)
            let arrivals = arrivals_at(centre, illumination, sea.as_ref());
            let exterior = edge.wedge_n * PI;
            let outside = |d: DVec3| {
                let phi = edge.angle_of(d);
                phi > 0.0 && phi < exterior
            };
            let may_return = arrivals.iter().flatten().any(|&k_tx| {
                arrivals.iter().flatten().any(|&k_rx| {
                    outside(-k_tx)
                        && outside(-k_rx)
                        && (0.5 * wavenumber * (k_tx + k_rx).dot(along) * piece_m).abs()
                            <= MAX_SINC_ARGUMENT
                })
            });
            if !may_return {
                continue;
            }
            let point = centre + bisector * EDGE_OFFSET_M;
            rays += legs_to(
                bvh,
                illumination,
                plane_origin_m,
                point,
                &settings,
                &mut legs,
                rays_met,
            );
            for leg_tx in &legs {
                for leg_rx in &legs {
                    let arrival = |leg: &Leg| {
                        if leg.via_sea {
                            sea_mirror(leg.from_radar)
                        } else {
                            leg.from_radar
                        }
                    };
                    let k_i = arrival(leg_tx);
                    let s_hat = -arrival(leg_rx);
                    if !(outside(-k_i) && outside(s_hat)) {
                        continue;
                    }
                    let phi_source = edge.angle_of(-k_i);
                    let phi = edge.angle_of(s_hat);
                    let q_along = wavenumber * (s_hat - k_i).dot(along);
                    let length_factor = piece_m * sinc(0.5 * q_along * piece_m);
                    let (Some(u_i), Some(u_s)) = (
                        along.cross(k_i).try_normalize(),
                        along.cross(s_hat).try_normalize(),
                    ) else {
                        continue;
                    };
                    let (f_soft, f_hard) = fringe_coefficients(phi, phi_source, edge.wedge_n);
                    let e = leg_tx.field_at_end(s, sea.as_ref());
                    let diffracted = ComplexVec3::scaled(along, e.dot(along) * f_soft)
                        .plus(ComplexVec3::scaled(u_s, e.dot(u_i) * f_hard));
                    let pol = leg_rx.received(diffracted, s_hat, s, sea.as_ref());
                    let amplitude = pol * minus_j_over_root_pi * (reflectivity * length_factor);
                    if amplitude.norm_sqr() == 0.0 {
                        continue;
                    }
                    out.push(leg_pair_return(
                        leg_tx,
                        leg_rx,
                        Complex64::new(1.0, 0.0),
                        amplitude,
                        s.wavelength_m,
                    ));
                }
            }
        }
    }
    rays
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a half-plane (n = 2) in backscatter Keller's coefficients are
    /// `½(−1 ± 1/cos φ)` (soft +, hard −), PO's `±½ tan φ`, and the fringe at normal
    /// incidence to the face is −½ in both cases (Knott et al. §6).
    #[test]
    fn half_plane_backscatter_coefficients() {
        for phi in [0.3f64, 0.9, 1.2, 2.0] {
            let (ks, kh) = keller_coefficients(phi, phi, 2.0);
            assert!((ks - 0.5 * (-1.0 + 1.0 / phi.cos())).abs() < 1e-12);
            assert!((kh - 0.5 * (-1.0 - 1.0 / phi.cos())).abs() < 1e-12);
            let (ps, ph) = po_coefficients(phi, phi, 2.0);
            assert!((ps - 0.5 * phi.tan()).abs() < 1e-12, "{phi}");
            assert!((ph + 0.5 * phi.tan()).abs() < 1e-12, "{phi}");
        }
        let (fs, fh) = fringe_coefficients(PI / 2.0, PI / 2.0, 2.0);
        assert!(
            (fs + 0.5).abs() < 1e-7 && (fh + 0.5).abs() < 1e-7,
            "{fs} {fh}"
        );
    }

    /// Keller's, PO's and the fringe coefficients are the same seen from either face
    /// (φ → nπ − φ, φ′ → nπ − φ′): face n's PO term is face 0's mirrored, for a wedge lit on
    /// face n alone and on both faces.
    #[test]
    fn coefficients_are_symmetric_between_the_faces() {
        for n in [1.3f64, 1.5, 1.8, 2.0] {
            let far = n * PI;
            for (phi, source) in [
                (0.4, 0.5),
                (far - 0.6, far - 0.5),
                (0.5 * far, 0.5 * far + 0.05),
            ] {
                for f in [keller_coefficients, po_coefficients, fringe_coefficients] {
                    let (s1, h1) = f(phi, source, n);
                    let (s2, h2) = f(far - phi, far - source, n);
                    assert!(
                        (s1 - s2).abs() < 1e-9 && (h1 - h2).abs() < 1e-9,
                        "n {n} φ {phi} φ′ {source}: ({s1}, {h1}) vs ({s2}, {h2})"
                    );
                }
            }
        }
    }

    /// The fringe is finite and continuous through a face's specular direction, where
    /// Keller's and PO's coefficients are each infinite: a right-angled wedge, bistatic.
    #[test]
    fn fringe_is_continuous_through_the_specular_direction() {
        let n = 1.5;
        let source = 0.7;
        let specular = PI - source;
        let at = |phi: f64| fringe_coefficients(phi, source, n);
        let (s0, h0) = at(specular);
        for d in [1e-3, -1e-3] {
            let (s, h) = at(specular + d);
            assert!(
                (s - s0).abs() < 1e-2 && (h - h0).abs() < 1e-2,
                "{s} {s0} {h} {h0}"
            );
        }
        assert!(s0.is_finite() && h0.is_finite());
    }
}
