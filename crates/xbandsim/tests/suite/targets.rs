//! The target catalogue (`xbandsim::targets`): every class builds an ordinary scene object
//! that survives a TOML round trip bit for bit, bad sizes and draws are refused by field, the
//! `vessel` and `buoy` shapes check their fields, and each class's RCS at X band is
//! plausible (docs/targets.md, docs/validation.md).

use std::f64::consts::PI;
use xbandsim::constants::{linear_to_db, wavelength_m};
use xbandsim::geometry::{Outfit, ShapeGeometry};
use xbandsim::model::{Polarisation, Scene};
use xbandsim::scattering::rcs::{RcsSettings, RcsTarget};
use xbandsim::targets::{
    skolnik_ship_above_grazing_m2, skolnik_ship_median_m2, ReferenceRcs, TargetClass,
    REFERENCE_FREQ_HZ, SHIP_GRAZING_MAX_ELEVATION_DEG,
};
use xbandsim::SceneSpec;

fn spec_of(class: TargetClass, size_m: f64, draws: &[f64; 3]) -> SceneSpec {
    let mut o = class.object_spec(size_m, draws).unwrap();
    o.name = Some("t".into());
    let z = o.position_m.unwrap()[2];
    o.position_m = Some([0.0, 500.0, z]);
    o.yaw_deg = Some(30.0);
    SceneSpec {
        objects: vec![o],
        ..SceneSpec::default()
    }
}

#[test]
fn classes_have_stable_names_ids_and_ranges() {
    let names: Vec<&str> = TargetClass::all().iter().map(|c| c.name()).collect();
    assert_eq!(
        names,
        [
            "navigation_buoy",
            "lobster_pot",
            "kayak",
            "rib",
            "sailing_yacht",
            "fishing_vessel",
            "pilot_boat",
            "ferry",
            "cargo_ship",
            "tanker",
            "corner_reflector",
            "channel_marker"
        ]
    );
    for (i, c) in TargetClass::all().iter().enumerate() {
        assert_eq!(c.category_id(), i as u32 + 1);
        assert_eq!(TargetClass::from_name(c.name()), Some(*c));
        assert_eq!(c.name().parse::<TargetClass>().unwrap(), *c);
        assert_eq!(
            serde_json::to_string(c).unwrap(),
            format!("\"{}\"", c.name())
        );
        let (lo, hi) = c.size_range_m();
        assert!(0.0 < lo && lo < hi, "{c}");
        let (s0, s1) = c.speed_range_kn();
        assert!(s0 == 0.0 && (0.0..=40.0).contains(&s1), "{c}");
    }
    let e = "submarine".parse::<TargetClass>().unwrap_err().to_string();
    assert!(e.contains("submarine") && e.contains("kayak"), "{e}");
}

/// Every class at its extreme and middle sizes and draws is a valid scene object, labelled
/// with its class, standing on the sea (its lowest point at or just below z = 0, never
/// wholly under), and the scene written as TOML reads back to the same primitives, bit for
/// bit.
#[test]
fn every_class_builds_and_round_trips_through_toml() {
    for c in TargetClass::all() {
        let (lo, hi) = c.size_range_m();
        for size in [lo, 0.5 * (lo + hi), hi] {
            for d in [0.0, 0.5, 0.999] {
                let spec = spec_of(*c, size, &[d, 1.0 - d - 0.0005, d]);
                let scene = Scene::from_spec(&spec).unwrap_or_else(|e| panic!("{c} {size}: {e}"));
                let text = toml::to_string(&spec).unwrap();
                let again = Scene::from_toml_str(&text, "round-trip.toml").unwrap();
                let (a, b) = (&scene.objects()[0], &again.objects()[0]);
                assert_eq!(a.class(), c.name());
                assert_eq!(b.class(), c.name());
                let pa = a.shape().primitives(a.position_m(), a.rotation(), 0);
                let pb = b.shape().primitives(b.position_m(), b.rotation(), 0);
                assert_eq!(pa, pb, "{c} {size}: TOML round trip changed the geometry");
                assert!(!pa.is_empty());
                let bottom = pa
                    .iter()
                    .map(|p| p.bounds().min.z)
                    .fold(f64::INFINITY, f64::min);
                assert!(a.top_m() > 0.0, "{c} {size}: under the sea");
                assert!(
                    bottom < 1e-9 || c.is_moored(),
                    "{c} {size}: afloat at {bottom}"
                );
            }
        }
    }
}

#[test]
fn bad_sizes_and_draws_are_refused_by_field() {
    let k = TargetClass::Kayak;
    for (size, draws, needle) in [
        (2.0, [0.5; 3], "kayak.size_m"),
        (f64::NAN, [0.5; 3], "kayak.size_m"),
        (4.0, [0.5, 1.0, 0.5], "kayak.draws[1]"),
        (4.0, [0.5, 0.5, -0.1], "kayak.draws[2]"),
        (4.0, [f64::NAN, 0.5, 0.5], "kayak.draws[0]"),
    ] {
        let e = k.object_spec(size, &draws).unwrap_err().to_string();
        assert!(e.contains(needle), "{e:?} does not name {needle}");
    }
}

fn error_of(fields: &str) -> String {
    let text = format!("[[object]]\nname = \"v\"\n{fields}\nposition_m = [0.0, 300.0, 0.0]\n");
    match Scene::from_toml_str(&text, "scene.toml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// The `vessel` and `buoy` shapes: each field finite, positive and in proportion, named
/// with its line when refused; fields of other shapes and a choice that is not one are
/// refused too.
#[test]
fn vessel_and_buoy_fields_are_checked_by_name() {
    let cases: &[(&str, &[&str])] = &[
        ("shape = \"vessel\"", &["object \"v\".length_m", "missing"]),
        ("shape = \"vessel\"\nlength_m = 0.5", &["object \"v\".length_m", "0.5", "between 1"]),
        ("shape = \"vessel\"\nlength_m = nan", &["object \"v\".length_m"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nbeam_m = 7.0", &["object \"v\".beam_m", "scene.toml:5", "0.6 times"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nbeam_m = -1.0", &["object \"v\".beam_m"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nfreeboard_m = 3.0", &["object \"v\".freeboard_m", "0.25 times"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nsuperstructure_height_m = 1.0", &["object \"v\".superstructure_height_m", "needs a superstructure"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nsuperstructure = \"cabin\"\nsuperstructure_height_m = 6.0", &["object \"v\".superstructure_height_m", "half"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nsuperstructure = \"cabin\"\nmast_height_m = 1.5", &["object \"v\".mast_height_m", "above"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nmast_height_m = 40.0", &["object \"v\".mast_height_m"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nsuperstructure = \"castle\"", &["castle", "bridge-aft", "wheelhouse"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nedge_m = 1.0", &["object \"v\".edge_m", "does not use"]),
        ("shape = \"vessel\"\nlength_m = 10.0\nreflector_edge_m = 1.0", &["object \"v\".reflector_edge_m", "does not use"]),
        ("shape = \"sphere\"\nradius_m = 1.0\nbeam_m = 1.0", &["object \"v\".beam_m", "does not use"]),
        ("shape = \"buoy\"\nradius_m = 1.0", &["object \"v\".height_m", "missing"]),
        ("shape = \"buoy\"\nradius_m = 1.0\nheight_m = 1.0\nreflector_edge_m = 3.0", &["object \"v\".reflector_edge_m", "twice"]),
        ("shape = \"buoy\"\nradius_m = 1.0\nheight_m = 1.0\nreflector_edge_m = 0.3\nmast_height_m = 1.5", &["object \"v\".mast_height_m", "reflector"]),
        ("shape = \"buoy\"\nradius_m = 1.0\nheight_m = 1.0\nmast_height_m = 0.5", &["object \"v\".mast_height_m"]),
        ("shape = \"buoy\"\nradius_m = 20.0\nheight_m = 1.0", &["object \"v\".radius_m"]),
        ("shape = \"buoy\"\nradius_m = 1.0\nheight_m = 1.0\nlength_m = 3.0", &["object \"v\".length_m", "does not use"]),
        ("shape = \"vessel\"\nlength_m = 30.0\noutfit = \"trawler\"\nsuperstructure = \"cabin\"", &["object \"v\".superstructure", "outfit \"trawler\""]),
        ("shape = \"vessel\"\nlength_m = 30.0\noutfit_seed = 4", &["object \"v\".outfit_seed", "needs an outfit"]),
        ("shape = \"vessel\"\nlength_m = 6.0\noutfit = \"rib\"\nmast_height_m = 5.0", &["object \"v\".mast_height_m", "\"rib\" has no mast"]),
        ("shape = \"vessel\"\nlength_m = 30.0\noutfit = \"container-ship\"", &["object \"v\".length_m", "\"container-ship\" is built for"]),
        ("shape = \"vessel\"\nlength_m = 30.0\noutfit = \"submarine\"", &["submarine", "container-ship"]),
        ("shape = \"buoy\"\nradius_m = 1.0\nheight_m = 1.0\noutfit = \"ferry\"", &["object \"v\".outfit", "does not use"]),
    ];
    for (fields, needles) in cases {
        let e = error_of(fields);
        for n in *needles {
            assert!(
                e.contains(n),
                "{fields:?}: error {e:?} does not mention {n:?}"
            );
        }
    }
}

/// Triangles grow with √L (the segment rule in docs/formats.md): modest at every size.
#[test]
fn vessel_triangle_counts_follow_the_length_rule() {
    let count = |fields: &str| {
        let text = format!("[[object]]\nname = \"v\"\nshape = \"vessel\"\n{fields}\nposition_m = [0.0, 300.0, 0.0]\n");
        let scene = Scene::from_toml_str(&text, "t").unwrap();
        match scene.objects()[0].shape() {
            ShapeGeometry::Vessel { parts, .. } => parts.mesh.triangles.len(),
            other => panic!("{other:?}"),
        }
    };
    let (k, y, t) = (
        count("length_m = 5.0"),
        count("length_m = 12.0\nsuperstructure = \"cabin\"\nmast_height_m = 16.0"),
        count("length_m = 250.0\nbeam_m = 44.0\nfreeboard_m = 12.0\nsuperstructure = \"bridge-aft\"\nmast_height_m = 60.0"),
    );
    eprintln!("triangles: 5 m kayak {k}, 12 m yacht {y}, 250 m tanker {t}");
    assert!(k < y && y < t, "{k} {y} {t}");
    assert!(t < 2500, "{t}");
    // The make-vessel mesh of the same 30 m is far finer (10 800 at 128 segments).
    assert!(count("length_m = 30.0") < 1000);
}

fn rcs_settings(spacing_wavelengths: f64, max_rays: usize) -> RcsSettings {
    RcsSettings {
        freq_hz: 9.41e9,
        polarisation: Polarisation::Hh,
        ray_spacing_wavelengths: spacing_wavelengths,
        max_rays,
        max_bounces: 3,
        edge_diffraction: true,
    }
}

/// The corner-reflector class is the trihedral: its peak on the axis equals 4πa⁴/(3λ²)
/// within the ±0.25 dB of `rcs::trihedral_axis_and_wide_response` (same tube side λ/4).
#[test]
fn corner_reflector_class_peak_matches_the_closed_form() {
    let (lo, hi) = TargetClass::CornerReflector.size_range_m();
    let a = 0.5 * (lo + hi);
    let spec = spec_of(TargetClass::CornerReflector, a, &[0.5; 3]);
    let scene = Scene::from_spec(&spec).unwrap();
    let t = RcsTarget::new(&scene.objects()[0]);
    let lambda = wavelength_m(9.41e9);
    let peak = t.rcs_m2(0.0, 0.0, &rcs_settings(0.25, 1 << 20));
    let e = linear_to_db(peak) - linear_to_db(4.0 * PI * a.powi(4) / (3.0 * lambda * lambda));
    assert!(e.abs() < 0.25, "corner reflector a = {a}: {e:.2} dB");
}

/// Percentile `p` (0 … 1) of `v` (sorted here), nearest rank.
fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

/// The elevations of the RCS sweeps, degrees: a ship's radar sees targets from these.
const SWEEP_ELEVATIONS_DEG: [f64; 4] = [0.5, 1.0, 2.0, 3.0];
/// Azimuths of the RCS sweeps at each elevation: every 10° from 5°.
const SWEEP_AZIMUTHS: usize = 36;

/// (10th percentile, median, 90th percentile) of `v`, m².
fn spread(v: &[f64]) -> [f64; 3] {
    let mut v = v.to_vec();
    [
        percentile(&mut v, 0.1),
        percentile(&mut v, 0.5),
        percentile(&mut v, 0.9),
    ]
}

/// A class's RCS over the aspects a ship's radar sees it from (azimuth every 10° from 5° at
/// each of [`SWEEP_ELEVATIONS_DEG`], elevation by elevation), HH, 9.41 GHz, tubes λ/2 up to
/// 32 768 per aspect: free space (plane wave) and over the sea (the default environment's
/// sea, radar 15 m up, ground range `15 m / tan el`, every path), m².
fn aspect_rcs(scene: &Scene) -> (Vec<f64>, Vec<f64>) {
    let target = RcsTarget::new(&scene.objects()[0]);
    let aspects: Vec<(f64, f64)> = SWEEP_ELEVATIONS_DEG
        .iter()
        .flat_map(|el| {
            (0..SWEEP_AZIMUTHS)
                .map(move |i| ((10.0 * i as f64 + 5.0).to_radians(), el.to_radians()))
        })
        .collect();
    let settings = rcs_settings(0.5, 32_768);
    let sea = *Scene::from_spec(&SceneSpec::default())
        .unwrap()
        .environment()
        .sea()
        .unwrap();
    (
        target.sweep_m2(&aspects, &settings),
        target.over_sea_sweep_m2(&aspects, 15.0, &sea, &settings),
    )
}

/// The values of an [`aspect_rcs`] sweep at elevations within `range` (degrees).
/// Pooled sweeps (one after another) are taken alike.
fn at_elevations(v: &[f64], range: std::ops::RangeInclusive<f64>) -> Vec<f64> {
    assert_eq!(v.len() % (SWEEP_AZIMUTHS * SWEEP_ELEVATIONS_DEG.len()), 0);
    v.chunks(SWEEP_AZIMUTHS)
        .zip(SWEEP_ELEVATIONS_DEG.iter().cycle())
        .filter(|(_, el)| range.contains(el))
        .flat_map(|(values, _)| values.iter().copied())
        .collect()
}

/// The ships whose grazing median lies outside ±6 dB of Skolnik's median, with how far it
/// may lie, dB, signed (docs/targets.md, "RCS at X band", says why): the test fails if one
/// moves further out, or comes within ±6 dB (then it leaves this list).
const OUTSIDE_REFERENCE_DB: [(&str, f64); 2] = [("pilot_boat", 9.0), ("tanker", -10.0)];

/// Each class at its middle size (the cargo class's container ships and bulk carriers apart)
/// against its published reference (`TargetClass::reference_rcs`), as the reference was
/// measured:
/// - the ships of Skolnik's references (`TargetClass::reference_is_over_sea`), three vessels
///   each, over the sea: their median at grazing incidence (0.5° and 1°) within ±6 dB of
///   Skolnik's median (or as `OUTSIDE_REFERENCE_DB` lists), and their median above it (2°
///   and 3°) no more than 6 dB under his higher-angle rule (displacement in tons as m²) and
///   not above his grazing median;
/// - the others, at draws 0.5, in free space over 0.5–3°: within ±6 dB of a median
///   reference, inside a band reference, within 0.3 dB of the lobster-pot float's πr².
///
/// docs/targets.md gives the measured figures.
#[test]
fn class_rcs_matches_published_references() {
    let t0 = std::time::Instant::now();
    let mut report = String::new();
    let mut failures = Vec::new();
    let db = linear_to_db;
    // Each class at its middle size; a ship (whose structures the draws vary) as three
    // vessels, all draws 0.2, 0.5 and 0.8, its aspects pooled; the others at draws 0.5.
    let specs = |c: TargetClass, outfit: Option<Outfit>| -> Vec<SceneSpec> {
        let (lo, hi) = c.size_range_m();
        let draws: &[f64] = if c.reference_is_over_sea() {
            &[0.2, 0.5, 0.8]
        } else {
            &[0.5]
        };
        draws
            .iter()
            .map(|&d| {
                let mut spec = spec_of(c, 0.5 * (lo + hi), &[d; 3]);
                if outfit.is_some() {
                    spec.objects[0].outfit = outfit;
                }
                spec
            })
            .collect()
    };
    let mut rows: Vec<(TargetClass, String, Vec<SceneSpec>)> = TargetClass::all()
        .iter()
        .filter(|c| **c != TargetClass::CornerReflector)
        .map(|c| (*c, c.name().to_string(), specs(*c, None)))
        .collect();
    // The cargo class's two ships apart: container ships and bulk carriers.
    for (outfit, name) in [
        (Outfit::ContainerShip, "container-ship"),
        (Outfit::BulkCarrier, "bulk-carrier"),
    ] {
        let c = TargetClass::CargoShip;
        rows.push((c, format!("cargo_ship {name}"), specs(c, Some(outfit))));
    }
    rows.retain(|(_, label, _)| label != "cargo_ship");
    let grazing_max = SHIP_GRAZING_MAX_ELEVATION_DEG;
    for (c, label, specs) in rows {
        // The reference is the middle vessel's.
        let spec = &specs[specs.len() / 2];
        let (mut free, mut sea) = (Vec::new(), Vec::new());
        for spec in &specs {
            let (f, o) = aspect_rcs(&Scene::from_spec(spec).unwrap());
            free.extend(f);
            sea.extend(o);
        }
        let (f, o) = (spread(&free), spread(&sea));
        report.push_str(&format!(
            "{label:>24}: free {:6.1} {:6.1} {:6.1} | sea {:6.1} {:6.1} {:6.1} dBsm",
            db(f[0]),
            db(f[1]),
            db(f[2]),
            db(o[0]),
            db(o[1]),
            db(o[2])
        ));
        let reference = c
            .reference_rcs(&spec.objects[0])
            .expect("every class but the reflector");
        if let Some(d_kt) = c.ship_displacement_kt(&spec.objects[0]) {
            let grazing_m2 = spread(&at_elevations(&sea, 0.0..=grazing_max))[1];
            let above_m2 = spread(&at_elevations(&sea, grazing_max + 1e-9..=90.0))[1];
            // The library's reference for a ship is Skolnik's grazing median.
            let formula_m2 = reference.central_m2();
            assert!((formula_m2 - skolnik_ship_median_m2(d_kt, REFERENCE_FREQ_HZ)).abs() < 1e-9);
            let rule_m2 = skolnik_ship_above_grazing_m2(d_kt);
            let off_grazing = db(grazing_m2) - db(formula_m2);
            let off_above = db(above_m2) - db(rule_m2);
            report.push_str(&format!(
                " | D {d_kt:.3} kt; sea median at 0.5-1 deg {:.1} ({off_grazing:+.1} dB from \
                 52 f^1/2 D^3/2), at 2-3 deg {:.1} ({off_above:+.1} dB from D in m^2)\n",
                db(grazing_m2),
                db(above_m2)
            ));
            let listed = OUTSIDE_REFERENCE_DB
                .iter()
                .find(|(name, _)| *name == label)
                .map(|(_, d)| *d);
            match listed {
                None if off_grazing.abs() > 6.0 => failures.push(format!(
                    "{label}: grazing median {off_grazing:+.1} dB from Skolnik's"
                )),
                Some(limit)
                    if off_grazing.abs() <= 6.0
                        || off_grazing * limit < 0.0
                        || off_grazing.abs() > limit.abs() =>
                {
                    failures.push(format!(
                        "{label}: grazing median {off_grazing:+.1} dB from Skolnik's, \
                         listed as up to {limit:+} dB"
                    ))
                }
                _ => {}
            }
            if off_above < -6.0 || above_m2 > formula_m2 {
                failures.push(format!(
                    "{label}: median above grazing {off_above:+.1} dB from D in m^2, \
                     {:+.1} dB from Skolnik's grazing median",
                    db(above_m2) - db(formula_m2)
                ));
            }
            continue;
        }
        let measured = f[1];
        let off_db = match reference {
            ReferenceRcs::Band {
                low_m2, high_m2, ..
            } => {
                report.push_str(&format!(" | band {:.1} … {:.1}\n", db(low_m2), db(high_m2)));
                if !(low_m2..=high_m2).contains(&measured) {
                    failures.push(format!(
                        "{label}: median {:.1} dBsm outside its band",
                        db(measured)
                    ));
                }
                continue;
            }
            ReferenceRcs::Median { m2, .. } => db(measured) - db(m2),
        };
        report.push_str(&format!(
            " | free median {off_db:+.1} dB from the reference\n"
        ));
        let tolerance = if c == TargetClass::LobsterPot {
            0.3
        } else {
            6.0
        };
        if off_db.abs() > tolerance {
            failures.push(format!("{label}: {off_db:+.1} dB from its reference"));
        }
    }
    eprintln!("{report}({:.2} s)", t0.elapsed().as_secs_f64());
    assert!(failures.is_empty(), "{failures:#?}\n{report}");
}
