//! Scattering checks: canonical RCS (plate, trihedral, dihedral, sphere, cylinder) from
//! `xbandsim rcs`'s code against Knott's closed forms, meshes against their primitives, and
//! ship-sized objects at the default ray budget (docs/validation.md).

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use glam::{DMat3, DVec3};
use std::f64::consts::PI;
use std::sync::Arc;
use xbandsim::constants::{linear_to_db, wavelength_m};
use xbandsim::geometry::{PrimitiveKind, ShapeGeometry, TriangleMesh};
use xbandsim::model::{Polarisation, Scene, SceneObject};
use xbandsim::scattering::rcs::{RcsSettings, RcsTarget};

/// A scene holding one object with the shape `fields` (TOML lines), and its RCS target.
fn shape_target(fields: &str) -> (Scene, RcsTarget) {
    let text = format!("[[object]]\nname = \"t\"\n{fields}\nposition_m = [0.0, 100.0, 0.0]\n");
    let scene = Scene::from_toml_str(&text, "validation").expect("validation shape is valid");
    let target = RcsTarget::new(&scene.objects()[0]);
    (scene, target)
}

/// RCS of a shape (TOML fields) at an aspect, m².
pub fn shape_rcs_m2(
    fields: &str,
    az_rad: f64,
    el_rad: f64,
    freq_hz: f64,
    pol: Polarisation,
) -> f64 {
    let (_, t) = shape_target(fields);
    t.rcs_m2(
        az_rad,
        el_rad,
        &RcsSettings {
            freq_hz,
            polarisation: pol,
            ray_spacing_wavelengths: 0.25,
            max_rays: 1 << 20,
            max_bounces: 3,
            edge_diffraction: false,
        },
    )
}

/// RCS of a shape (TOML fields) at an aspect with a scene's default PO settings (tube side
/// λ/2, `max_rays_per_object` 32768, 3 bounces), PO alone as the closed forms it is checked
/// against are (no edge diffraction): for ship-sized objects the ray budget binds and widens
/// the tubes, m².
pub fn shape_rcs_default_budget_m2(fields: &str, az_rad: f64, el_rad: f64) -> f64 {
    let (scene, t) = shape_target(fields);
    t.rcs_m2(
        az_rad,
        el_rad,
        &RcsSettings {
            freq_hz: scene.radar().carrier_freq_hz(),
            polarisation: scene.radar().polarisation(),
            ray_spacing_wavelengths: scene.scattering().ray_spacing_wavelengths(),
            max_rays: scene.scattering().max_rays_per_object(),
            max_bounces: scene.scattering().max_bounces(),
            edge_diffraction: false,
        },
    )
}

/// Mean RCS (m², linear mean) of the procedural 30 m vessel over aspects 0°…358° in 2° steps
/// at elevation 0, with tube side λ/2 and `max_rays` tubes per aspect.
pub fn vessel_mean_rcs_m2(max_rays: usize, segments: usize) -> f64 {
    let mesh = xbandsim::geometry::mesh::vessel(30.0, segments);
    let object = SceneObject::new(
        "vessel",
        "ship",
        ShapeGeometry::Mesh {
            mesh: Arc::new(mesh),
        },
        DVec3::ZERO,
        DMat3::IDENTITY,
    )
    .expect("a valid object");
    let aspects: Vec<(f64, f64)> = (0..180)
        .map(|i| ((2.0 * i as f64).to_radians(), 0.0))
        .collect();
    let rcs = RcsTarget::new(&object).sweep_m2(
        &aspects,
        &RcsSettings {
            freq_hz: 9.41e9,
            polarisation: Polarisation::Hh,
            ray_spacing_wavelengths: 0.5,
            max_rays,
            max_bounces: 3,
            edge_diffraction: false,
        },
    );
    rcs.iter().sum::<f64>() / rcs.len() as f64
}

/// Broadside RCS of a `width_m` × `height_m` flat plate lit by a spherical wave from
/// `range_m` (the near-field loss of PO, independent of the ray tubes): the PO integral
/// `S = (√(4π)/λ)·∫∫exp(−jk(x² + y²)/R) dx dy` (two-way path 2R + (x² + y²)/R), evaluated
/// by the midpoint rule, m². Tends to 4πA²/λ² far away.
pub fn plate_near_field_rcs_m2(width_m: f64, height_m: f64, range_m: f64, freq_hz: f64) -> f64 {
    let lambda = wavelength_m(freq_hz);
    let k = 2.0 * PI / lambda;
    let line = |len: f64| {
        let n = 20_000;
        let dx = len / n as f64;
        (0..n)
            .map(|i| {
                let x = -0.5 * len + (i as f64 + 0.5) * dx;
                num_complex::Complex64::from_polar(dx, -k * x * x / range_m)
            })
            .sum::<num_complex::Complex64>()
    };
    4.0 * PI / (lambda * lambda) * (line(width_m) * line(height_m)).norm_sqr()
}

/// A ship-sized plate (`width_m` × `height_m`, broadside, due north at the range of output
/// bin `bin` so that the peak is sampled without straddle loss, radar and plate 4 m up,
/// noise off) rendered with the default ray budget (which binds): the
/// (expected SNR from the radar equation with the plate's near-field PO RCS, measured peak,
/// truth's RCS in dBsm, that RCS in dBsm).
pub fn ship_plate_render_db(width_m: f64, height_m: f64, bin: usize) -> (f64, f64, f64, f64) {
    let range_m = bin_range_m(bin as f64, 100e6);
    let text = format!(
        "{}[[object]]\nname = \"hull\"\nshape = \"plate\"\nwidth_m = {width_m}\nheight_m = {height_m}\nposition_m = [0.0, {range_m}, 4.0]\nyaw_deg = 180.0\n",
        radar_block_no_noise(&format!("max_range_m = {}", range_m + 300.0))
    );
    let (sim, frame) = render_text(&text, 1);
    let radar = sim.scene().radar();
    let rcs = plate_near_field_rcs_m2(width_m, height_m, range_m, radar.carrier_freq_hz());
    let expected = linear_to_db(radar.point_target_snr(rcs, range_m));
    let j = (range_m / radar.range_bin_m()).round() as usize;
    let measured = spoke(&frame, 0)[j - 3..j + 4]
        .iter()
        .cloned()
        .fold(f32::MIN, f32::max) as f64;
    let truth = frame.truth[0].rcs_dbsm.unwrap_or(f64::NAN);
    (expected, measured, truth, linear_to_db(rcs))
}

/// RCS of a shape built as a triangle mesh (the same surfaces as the primitive), m².
pub fn mesh_rcs_m2(triangles: &[[DVec3; 3]], az_rad: f64, freq_hz: f64) -> f64 {
    let mesh = TriangleMesh {
        vertices_m: triangles.iter().flatten().copied().collect(),
        triangles: (0..triangles.len() as u32)
            .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
            .collect(),
    };
    let object = SceneObject::new(
        "mesh",
        "mesh",
        ShapeGeometry::Mesh {
            mesh: Arc::new(mesh),
        },
        DVec3::new(0.0, 100.0, 0.0),
        DMat3::IDENTITY,
    )
    .expect("a valid object");
    RcsTarget::new(&object).rcs_m2(
        az_rad,
        0.0,
        &RcsSettings {
            freq_hz,
            polarisation: Polarisation::Hh,
            ray_spacing_wavelengths: 0.25,
            max_rays: 1 << 20,
            max_bounces: 3,
            edge_diffraction: false,
        },
    )
}

/// The triangles of a primitive shape (plates split in two), in its object frame.
pub fn shape_triangles(shape: &ShapeGeometry) -> Vec<[DVec3; 3]> {
    shape
        .primitives(DVec3::ZERO, DMat3::IDENTITY, 0)
        .iter()
        .flat_map(|p| match p.kind {
            PrimitiveKind::Triangle { v0, e1, e2 } => vec![[v0, v0 + e1, v0 + e2]],
            PrimitiveKind::Parallelogram {
                corner,
                edge_u,
                edge_v,
            } => vec![
                [corner, corner + edge_u, corner + edge_u + edge_v],
                [corner, corner + edge_u + edge_v, corner + edge_v],
            ],
            _ => Vec::new(),
        })
        .collect()
}

/// The checks of this area, in the order `xbandsim validate` prints them.
pub(crate) fn checks(out: &mut Checks) {
    let f0 = 9.41e9;
    let lambda = wavelength_m(f0);
    const SKOLNIK: &str = "Skolnik, Introduction to Radar Systems, 3rd ed., eq. 2.51";
    const KNOTT: &str = "Knott, Shaeffer & Tuley, Radar Cross Section, 2nd ed., Table 5.1";

    // Canonical RCS at 9.41 GHz.
    let hh = Polarisation::Hh;
    let r = 20.0 / (2.0 * PI / lambda);
    out.push(check(
        "sphere πr² (ka = 20)",
        linear_to_db(PI * r * r),
        linear_to_db(shape_rcs_m2(
            &format!("shape = \"sphere\"\nradius_m = {r}"),
            0.3,
            0.2,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.3),
        KNOTT,
    ));
    out.push(check(
        "sphere πr² (r = 1 m)",
        linear_to_db(PI),
        linear_to_db(shape_rcs_m2(
            "shape = \"sphere\"\nradius_m = 1.0",
            0.3,
            0.2,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.3),
        KNOTT,
    ));
    let a = 0.5;
    out.push(check(
        "plate 4πA²/λ², 1 m × 0.5 m, normal",
        linear_to_db(4.0 * PI * a * a / (lambda * lambda)),
        linear_to_db(shape_rcs_m2(
            "shape = \"plate\"\nwidth_m = 1.0\nheight_m = 0.5",
            0.0,
            0.0,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.1),
        KNOTT,
    ));
    let null1 = (lambda / 2.0).asin();
    let (mut best, mut best_v) = (0.0, f64::MAX);
    for i in 0..=80 {
        let ang = null1 * (0.8 + 0.4 * i as f64 / 80.0);
        let v = shape_rcs_m2(
            "shape = \"plate\"\nwidth_m = 1.0\nheight_m = 0.5",
            ang,
            0.0,
            f0,
            hh,
        );
        if v < best_v {
            best = ang;
            best_v = v;
        }
    }
    out.push(check(
        "plate first null at sin θ = λ/2W (W = 1 m)",
        null1.to_degrees(),
        best.to_degrees(),
        "deg",
        Tolerance::Relative(0.10),
        KNOTT,
    ));
    out.push(check(
        "dihedral 8πa²b²/λ², 0.5 m × 0.5 m",
        linear_to_db(8.0 * PI * 0.0625 / (lambda * lambda)),
        linear_to_db(shape_rcs_m2(
            "shape = \"dihedral\"\nwidth_m = 0.5\nheight_m = 0.5",
            0.0,
            0.0,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.3),
        KNOTT,
    ));
    out.push(check(
        "trihedral 4πa⁴/(3λ²), a = 0.5 m",
        linear_to_db(4.0 * PI * 0.0625 / (3.0 * lambda * lambda)),
        linear_to_db(shape_rcs_m2(
            "shape = \"trihedral\"\nedge_m = 0.5",
            0.0,
            0.0,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.1),
        KNOTT,
    ));
    for (name, shape, fields, az_deg) in [
        (
            "mesh plate (2 triangles) = primitive, 2° off normal",
            ShapeGeometry::Plate {
                width_m: 0.8,
                height_m: 0.5,
            },
            "shape = \"plate\"\nwidth_m = 0.8\nheight_m = 0.5",
            2.0f64,
        ),
        (
            "mesh trihedral (3 triangles) = primitive, 20° off axis",
            ShapeGeometry::Trihedral { edge_m: 0.5 },
            "shape = \"trihedral\"\nedge_m = 0.5",
            20.0,
        ),
    ] {
        let az = az_deg.to_radians();
        out.push(check(
            name,
            linear_to_db(shape_rcs_m2(fields, az, 0.0, f0, hh)),
            linear_to_db(mesh_rcs_m2(&shape_triangles(&shape), az, f0)),
            "dBsm",
            Tolerance::Absolute(0.25),
            "same PO surfaces, meshed",
        ));
    }
    out.push(check(
        "cylinder broadside 2πrh²/λ, r = 0.3 m, h = 1 m",
        linear_to_db(2.0 * PI * 0.3 / lambda),
        linear_to_db(shape_rcs_m2(
            "shape = \"cylinder\"\nradius_m = 0.3\nheight_m = 1.0",
            0.7,
            0.0,
            f0,
            hh,
        )),
        "dBsm",
        Tolerance::Absolute(0.25),
        KNOTT,
    ));
    // Ship-sized objects at the default ray budget (the cap binds and widens the tubes).
    let (w, h) = (8.0, 3.0);
    out.push(check(
        "plate 4πA²/λ², 8 m × 3 m, normal, default ray budget",
        linear_to_db(4.0 * PI * (w * h) * (w * h) / (lambda * lambda)),
        linear_to_db(shape_rcs_default_budget_m2(
            &format!("shape = \"plate\"\nwidth_m = {w}\nheight_m = {h}"),
            0.0,
            0.0,
        )),
        "dBsm",
        // Tubes are counted by their centre ray: the lit area is known to ±δ per edge
        // (δ = 4.2 cm here), 2·(δ/W + δ/H) = 3.9 % of σ at worst.
        Tolerance::Absolute(0.2),
        KNOTT,
    ));
    out.push(check(
        "dihedral 8πa²b²/λ², 3 m × 2 m, default ray budget",
        linear_to_db(8.0 * PI * 9.0 * 4.0 / (lambda * lambda)),
        linear_to_db(shape_rcs_default_budget_m2(
            "shape = \"dihedral\"\nwidth_m = 3.0\nheight_m = 2.0",
            0.0,
            0.0,
        )),
        "dBsm",
        Tolerance::Absolute(0.3),
        KNOTT,
    ));
    out.push(check(
        "trihedral 4πa⁴/(3λ²), a = 2 m, default ray budget",
        linear_to_db(4.0 * PI * 16.0 / (3.0 * lambda * lambda)),
        linear_to_db(shape_rcs_default_budget_m2(
            "shape = \"trihedral\"\nedge_m = 2.0",
            0.0,
            0.0,
        )),
        "dBsm",
        Tolerance::Absolute(0.2),
        KNOTT,
    ));
    let (e, m, truth, rcs_db) = ship_plate_render_db(8.0, 3.0, 600);
    out.push(check(
        "8 m × 3 m plate at 899 m rendered: SNR = radar equation with its near-field PO RCS",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.15),
        SKOLNIK,
    ));
    out.push(check(
        "8 m × 3 m plate at 899 m: truth RCS = near-field PO integral",
        rcs_db,
        truth,
        "dBsm",
        Tolerance::Absolute(0.1),
        "PO surface integral with the two-way Fresnel phase, by quadrature",
    ));
    let base = vessel_mean_rcs_m2(32_768, 128);
    let doubled = vessel_mean_rcs_m2(65_536, 128);
    out.push(check(
        "30 m vessel mesh: mean RCS over aspect, ray budget 32768 → 65536",
        linear_to_db(base),
        linear_to_db(doubled),
        "dBsm",
        Tolerance::Absolute(0.5),
        "convergence criterion (docs/validation.md)",
    ));
}
