//! Land: its echo against the constant-γ radar equation, its shadow and the horizon against
//! geometry, and targets hidden by it (docs/physics.md §16, docs/validation.md).

use xbandsim::land::profile::elevation_rad;
use xbandsim::propagation::EFFECTIVE_EARTH_RADIUS_M;

/// A scene of one rectangular island `[x0, x1] × [y0, y1]`, `extra` appended to its table.
fn island_scene(radar: &str, environment: &str, rect: [f64; 4], extra: &str) -> String {
    let [x0, y0, x1, y1] = rect;
    format!(
        "[radar]\n{radar}\n[environment]\n{environment}\n[[land]]\nname = \"isle\"\npolygon_m = [[{x0}, {y0}], [{x1}, {y0}], [{x1}, {y1}], [{x0}, {y1}]]\n{extra}\n"
    )
}

use crate::common::clutter_map_of as map_of;

/// A flat land top seen from above returns `σ0 = γ·sin ψ` over the cell's area: the map's
/// mean land power of each cell (130 spokes × 600 samples of one island) against
/// `γ·sin ψ·g·(∫Gn²)·Δr·sec ψ·Pt·G0²·λ²·Gn_el(α)²/((4π)³·r⁴·L·N)·(atmosphere)`, ψ the grazing
/// angle on the land (`sin ψ = (h − H)/r − r/2a_e`), every cell within 0.1 dB (the discrete
/// Δα over one sample against the derivative: 0.01 dB); the textured echo's power averaged
/// over them within 0.3 dB (its sampling error, about 0.1 dB at 3σ).
#[test]
fn a_flat_land_top_returns_gamma_sin_psi() {
    let text = island_scene(
        "position_m = [0.0, 0.0, 30.0]\nmax_range_m = 4000.0\nspokes = 720",
        "clutter = false",
        [-4000.0, 1500.0, 4000.0, 3800.0],
        "height_m = 5.0\ngamma_db = -12.0\nweibull_shape = 2.0",
    );
    let (scene, map, _) = map_of(&text);
    let radar = scene.radar();
    let env = scene.environment();
    let (h, top) = (radar.position_m().z, 5.0);
    let dr = radar.range_bin_m();
    let gamma = 10f64.powf((-12.0 + 5.0 * (radar.carrier_freq_hz() / 1e10).log10()) / 10.0);
    let k_noise = radar.radar_equation_constant_w_m2() / radar.noise_power_w();
    let beam = radar.antenna().azimuth().two_way_integral_rad();
    let (mut got, mut want) = (0.0, 0.0);
    let mut worst_db = 0f64;
    for k in (0..720).filter(|&k| !(65..=655).contains(&k)) {
        for n in (2000.0 / dr) as usize..(2000.0 / dr) as usize + 600 {
            let r = n as f64 * dr;
            let g = (r * r - h * h).sqrt();
            let sin_psi = (h - top) / r - r / (2.0 * EFFECTIVE_EARTH_RADIUS_M);
            let psi = sin_psi.asin();
            let alpha = elevation_rad(top, g, h, true);
            let area = g * beam * dr / psi.cos();
            let cell = gamma
                * sin_psi
                * area
                * k_noise
                * radar.antenna().elevation_pattern(alpha).powi(2)
                * env.attenuation_power(r)
                / r.powi(4);
            want += cell;
            worst_db =
                worst_db.max((10.0 * (map.land_mean_power(k, n) as f64 / cell).log10()).abs());
            got += map.land_echo(k, n).norm_sqr() as f64;
            assert_eq!(map.land_polygon(k, n), Some(0));
        }
    }
    assert!(
        worst_db < 0.1,
        "a cell's land mean is {worst_db:.3} dB off γ·sin ψ"
    );
    let err_db = 10.0 * (got / want).log10();
    assert!(
        err_db.abs() < 0.3,
        "textured land {err_db:+.3} dB off γ·sin ψ"
    );
}

/// The sea behind a cliff-edged island of height H, seen from h > H, is in shadow until its
/// elevation climbs back over the island's far edge g_e: `−h/g − g/2a_e = (H − h)/g_e −
/// g_e/2a_e`, a quadratic in g. The first sample the map sees again is within one range bin
/// of it; the sea and the land in between return nothing.
#[test]
fn the_shadow_behind_a_cliff_is_as_long_as_geometry_says() {
    let text = island_scene(
        "position_m = [0.0, 0.0, 20.0]\nmax_range_m = 6000.0\nspokes = 360",
        "sea_state = 3\nclutter = true",
        [-2000.0, 1000.0, 2000.0, 1400.0],
        "height_m = 10.0",
    );
    let (scene, map, samples) = map_of(&text);
    let radar = scene.radar();
    let (h, top, edge) = (radar.position_m().z, 10.0, 1400.0);
    let dr = radar.range_bin_m();
    // −h/g − g/(2a) = c  →  g²/(2a) + c·g + h = 0, the smaller root.
    let a2 = 2.0 * EFFECTIVE_EARTH_RADIUS_M;
    let c = (top - h) / edge - edge / a2;
    let g_seen = (-c - (c * c - 4.0 * h / a2).sqrt()) / (2.0 / a2);
    for k in [0usize, 5, 355] {
        let az = radar.spoke_azimuth_rad(k);
        let first = (0..samples)
            .find(|&n| {
                let r = n as f64 * dr;
                let g = (r * r - h * h).max(0.0).sqrt();
                g * az.cos() > edge + 1.0 && map.surface_seen(k, n)
            })
            .unwrap();
        let r = first as f64 * dr;
        let g = (r * r - h * h).sqrt() * az.cos();
        let g_want = g_seen;
        assert!(
            (g - g_want).abs() <= dr,
            "spoke {k}: sea seen again at {g:.1} m, geometry says {g_want:.1} m"
        );
        // In between, nothing of the surface is seen, and the sea's mean is zero on spokes
        // far inside the island's bearings.
        let past_edge = edge / az.cos() + 5.0;
        for n in ((past_edge * past_edge + h * h).sqrt() / dr) as usize..first {
            assert!(!map.surface_seen(k, n));
            assert!(map.land_polygon(k, n).is_none());
            if k == 0 {
                assert_eq!(map.mean_power(k, n), 0.0);
            }
        }
    }
}

/// A mountain beyond the radar horizon shows only its part above it: a 200 m one 40 km off,
/// seen from 15 m, returns γ times its face above the hidden height (34 m) within 0.1 dB
/// (`xbandsim_validate::land::mountain_face_power`); a 25 m one, wholly hidden, nothing.
#[test]
fn land_beyond_the_horizon_shows_only_above_it() {
    let (want, got) = xbandsim_validate::land::mountain_face_power(200.0);
    let err_db = 10.0 * (got / want).log10();
    assert!(
        err_db.abs() < 0.1,
        "face {err_db:+.3} dB off the visible part"
    );
    let (want, got) = xbandsim_validate::land::mountain_face_power(25.0);
    assert_eq!(
        (want, got),
        (0.0, 0.0),
        "a 25 m mountain behind a 34 m hidden height"
    );
}

const HIDING_ISLAND: &str = r#"
[radar]
position_m = [0.0, 0.0, 15.0]
max_range_m = 2500.0
spokes = 360

[environment]
sea_state = 3
clutter = true
multipath = true

[[land]]
name = "isle"
polygon_m = [[-300.0, 1000.0], [300.0, 1000.0], [300.0, 1400.0], [-300.0, 1400.0]]
height_m = 30.0

[[object]]
name = "open"
class = "boat"
shape = "sphere"
radius_m = 2.0
position_m = [-900.0, 1700.0, 2.0]
"#;

const HIDDEN_BOAT: &str = r#"
[[object]]
name = "hidden"
class = "boat"
shape = "sphere"
radius_m = 2.0
position_m = [0.0, 1700.0, 2.0]
"#;

/// A boat behind a 30 m island, seen from 15 m, is labelled `shadowed_by_land` with no box,
/// and leaves no echo: the frame with it is byte for byte the frame without it. The boat in
/// open water beside it is seen, and both carry their distance to the coast.
#[test]
fn a_target_in_a_land_shadow_is_labelled_and_leaves_no_echo() {
    let with = format!("{HIDING_ISLAND}{HIDDEN_BOAT}");
    let (_, frame) = crate::common::render(&with, 7);
    let hidden = &frame.truth[1];
    assert_eq!(hidden.visibility, xbandsim::Visibility::ShadowedByLand);
    assert!(hidden.shadowed_by_land);
    assert!(hidden.polar_box.is_none() && hidden.expected_snr_db.is_none());
    assert!((hidden.distance_to_coast_m.unwrap() - 300.0).abs() < 1e-9);
    let open = &frame.truth[0];
    assert_eq!(open.visibility, xbandsim::Visibility::Visible);
    assert!(!open.shadowed_by_land);
    let (_, without) = crate::common::render(HIDING_ISLAND, 7);
    assert!(
        frame.polar_db == without.polar_db,
        "the hidden boat changed the picture"
    );
    // The land's truth: a 30 m island seen from 15 m shows its near cliff face only (its
    // top is above the antenna): a cell or two on each of the ~34 spokes it spans, all at
    // its near edge.
    let land = frame.land.as_ref().expect("land truth");
    assert!(
        (30..=120).contains(&land.polygons[0].cells),
        "{}",
        land.polygons[0].cells
    );
    let bin_m = frame.range_bin_m;
    for (i, &p) in land.polygon.iter().enumerate() {
        if p >= 0 {
            let (k, n) = (i / land.range_bins, i % land.range_bins);
            let az = (k as f64 + 0.5) * std::f64::consts::TAU / 360.0;
            let g = n as f64 * bin_m;
            let (x, y) = (g * az.sin(), g * az.cos());
            assert!(
                x.abs() < 310.0 && (995.0..1010.0).contains(&y),
                "cell {k},{n}"
            );
        }
    }
}

/// Bad land input is refused naming the field, the file and the feature.
#[test]
fn bad_land_is_refused_naming_the_file_and_the_feature() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
    write(
        "bow.geojson",
        r#"{"type":"FeatureCollection","features":[
          {"type":"Feature","properties":{"name":"ok"},"geometry":{"type":"Polygon","coordinates":[[[0,5000],[10,5000],[10,5010],[0,5000]]]}},
          {"type":"Feature","properties":{"name":"Bow"},"geometry":{"type":"Polygon","coordinates":[[[0,0],[100,100],[100,0],[0,80],[0,0]]]}}]}"#,
    );
    write(
        "open.geojson",
        r#"{"type":"Polygon","coordinates":[[[0,0],[100,0],[100,100],[0,100]]]}"#,
    );
    write(
        "tall.geojson",
        r#"{"type":"Feature","properties":{"height_m":12000},"geometry":{"type":"Polygon","coordinates":[[[0,500],[10,500],[10,510],[0,500]]]}}"#,
    );
    write(
        "ll.geojson",
        r#"{"type":"Polygon","coordinates":[[[10.0,60.0],[10.01,60.0],[10.01,60.01],[10.0,60.0]]]}"#,
    );
    let load = |land: &str| {
        let text = format!("[radar]\nmax_range_m = 1500.0\n{land}");
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, text).unwrap();
        xbandsim::scene::LoadedSpec::read(&path)
            .and_then(|s| s.build())
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    let cases = [
        ("[[land]]\ngeojson = \"bow.geojson\"", vec!["land[0].geojson", "bow.geojson", "feature 1 (\"Bow\")", "edges cross"]),
        ("[[land]]\ngeojson = \"open.geojson\"", vec!["land[0].geojson", "open.geojson", "feature 0", "is open"]),
        ("[[land]]\ngeojson = \"missing.geojson\"", vec!["land[0].geojson", "missing.geojson"]),
        ("[[land]]\ngeojson = \"ll.geojson\"\ncrs = \"wgs84\"", vec!["geo.origin_lon_deg", "land[0]"]),
        ("[[land]]\npolygon_m = [[0.0, 0.0], [10.0, 0.0]]", vec!["land[0].polygon_m` = [[0, 0], [10, 0]]", "at least 3"]),
        ("[[land]]\npolygon_m = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]\nheight_m = -1.0", vec!["land[0].height_m"]),
        ("[[land]]\npolygon_m = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]\nbeach_width_m = 5.0", vec!["land[0].beach_width_m", "beach"]),
        ("[[land]]\npolygon_m = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]\nterrain = \"lava\"", vec!["lava"]),
        ("[[land]]\nheight_m = 3.0", vec!["land[0].geojson", "polygon_m"]),
        (
            "[[land]]\npolygon_m = [[-50.0, -50.0], [50.0, -50.0], [50.0, 50.0], [-50.0, 50.0]]\nheight_m = 20.0",
            vec!["radar.position_m", "the antenna stands on land", "20.0 m high"],
        ),
        ("[[land]]\ngeojson = \"tall.geojson\"", vec!["land[0].geojson", "height_m = 12000"]),
        (
            "[[land]]\npolygon_m = [[0.0, 500.0], [100.0, 500.0], [100.0, 600.0], [0.0, 600.0]]\n[[object]]\nname = \"stranded\"\nshape = \"sphere\"\nradius_m = 1.0\nposition_m = [50.0, 550.0, 1.0]",
            vec!["object[0].position_m", "stranded", "on land", "land-0-0"],
        ),
    ];
    for (land, wants) in cases {
        let err = load(land).expect_err(land);
        for want in wants {
            assert!(err.contains(want), "{land}: {err} lacks {want}");
        }
    }
    // Lon/lat with an origin loads, 1.1 km north-east-ish of it.
    let ok = format!(
        "[radar]\nmax_range_m = 1500.0\n[geo]\norigin_lon_deg = 10.0\norigin_lat_deg = 59.995\n[[land]]\ngeojson = \"{}\"\ncrs = \"wgs84\"",
        dir.path().join("ll.geojson").display()
    );
    let scene = xbandsim::model::Scene::from_toml_str(&ok, "t").unwrap();
    let poly = &scene.environment().land().polygons()[0];
    assert!(
        (poly.rings[0][0].y - 557.1).abs() < 1.0,
        "{:?}",
        poly.rings[0][0]
    );
    // A ring written closed is the same ring; an antenna on a mast above the land is fine.
    let closed = "[radar]\nposition_m = [0.0, 0.0, 30.0]\nmax_range_m = 1500.0\n[[land]]\npolygon_m = [[-50.0, -50.0], [50.0, -50.0], [50.0, 50.0], [-50.0, 50.0], [-50.0, -50.0]]\nheight_m = 20.0";
    let scene = xbandsim::model::Scene::from_toml_str(closed, "t").unwrap();
    assert_eq!(scene.environment().land().polygons()[0].rings[0].len(), 4);
}

/// A low mole near the sea's specular point takes the sea paths of a target beyond it and
/// leaves the straight ones: radar 15 m up, a 3 m mole 850–870 m out, a point target 2 m up
/// at 1 km over a smooth sea. The straight line clears the mole (3.7 m above the sea there), the leg down to the
/// specular point at 882 m does not (0.5 m): the label's multipath gain is gone (no sea path
/// left) while it stays visible with the same RCS, and without the mole it has one.
#[test]
fn a_low_mole_near_the_reflection_point_takes_the_sea_paths_only() {
    let base = "[radar]\nposition_m = [0.0, 0.0, 15.0]\nmax_range_m = 1500.0\nspokes = 360\n[environment]\nnoise = false\nclutter = false\nsea_rms_height_m = 0.0\nmultipath = true\n[[object]]\nname = \"ball\"\nshape = \"point\"\nrcs_m2 = 1.0\nposition_m = [0.0, 1000.0, 2.0]\n";
    let mole = "[[land]]\npolygon_m = [[-300.0, 850.0], [300.0, 850.0], [300.0, 870.0], [-300.0, 870.0]]\nheight_m = 3.0\n";
    let (_, open_sea) = crate::common::render(base, 1);
    let (_, behind) = crate::common::render(&format!("{base}{mole}"), 1);
    let gain = |f: &xbandsim::Frame| f.truth[0].multipath_gain_db;
    assert!(
        gain(&open_sea).is_some_and(|g| g.abs() > 0.5),
        "{:?}",
        gain(&open_sea)
    );
    assert_eq!(behind.truth[0].visibility, xbandsim::Visibility::Visible);
    assert!(!behind.truth[0].shadowed_by_land);
    assert!(
        gain(&behind).is_none_or(|g| g.abs() < 1e-9),
        "{:?}",
        gain(&behind)
    );
    assert_eq!(open_sea.truth[0].rcs_m2, behind.truth[0].rcs_m2);
}

/// A radar that stands still keeps its clutter surface (sea and rain powers, the land's rows
/// and frozen echo) between revolutions and draws only the texture anew: every revolution,
/// in any order and with another seed between, is byte for byte the one a fresh simulation
/// renders; a radar on a ship under way makes a surface per revolution. The map on a kept
/// surface is the fresh map in every cell.
#[test]
fn a_still_radar_reuses_its_clutter_surface_and_renders_the_same_bytes() {
    use xbandsim::engine::{Request, Simulation};
    use xbandsim::model::Scene;
    use xbandsim::rng::FrameKey;
    use xbandsim::signal::clutter_map::{ClutterMap, ClutterSurface};
    let rain = "\n[[environment.rain_cell]]\ncentre_m = [800.0, 600.0]\nradius_m = 500.0\nrate_mm_per_h = 8.0\n";
    let moving_boat = "\n[[object]]\nname = \"under way\"\nclass = \"boat\"\nshape = \"sphere\"\nradius_m = 2.0\nposition_m = [700.0, -900.0, 2.0]\nspeed_kn = 12.0\ncourse_deg = 80.0\n";
    let text = HIDING_ISLAND.replace("multipath = true\n", &format!("multipath = true\n{rain}"))
        + moving_boat;
    let own_ship = format!("{text}\n[own_ship]\nspeed_kn = 10.0\ncourse_deg = 45.0\n");
    for text in [text.as_str(), own_ship.as_str()] {
        let fresh = |seed: u64, frame: u64| {
            Simulation::new(Scene::from_toml_str(text, "t").unwrap())
                .run(&Request::new(seed).frame(frame))
                .unwrap()
                .polar_db
        };
        let sim = Simulation::new(Scene::from_toml_str(text, "t").unwrap());
        for (seed, frame) in [(9, 0), (9, 1), (9, 3), (10, 3), (9, 1)] {
            let kept = sim.run(&Request::new(seed).frame(frame)).unwrap().polar_db;
            assert!(
                kept == fresh(seed, frame),
                "seed {seed} frame {frame} differs from a fresh simulation's"
            );
        }
    }

    let scene = Scene::from_toml_str(&text, "t").unwrap();
    let (radar, env) = (scene.radar(), scene.environment());
    let samples = 1700;
    let kept = ClutterMap::new(radar, env, FrameKey::new(4, 0), samples).unwrap();
    let surface = kept.surface();
    assert!(surface.serves(radar, env, 4, samples));
    assert!(!surface.serves(radar, env, 5, samples), "another seed");
    assert!(
        !surface.serves(radar, env, 4, samples - 1),
        "another record"
    );
    let moved = Scene::from_toml_str(
        &text.replace(
            "position_m = [0.0, 0.0, 15.0]",
            "position_m = [0.0, 1.0, 15.0]",
        ),
        "t",
    )
    .unwrap();
    assert!(
        !surface.serves(moved.radar(), env, 4, samples),
        "another place"
    );
    let tilted = ClutterSurface::new(radar, env, 4, samples, &vec![0.01; radar.spokes()]).unwrap();
    assert!(!tilted.serves(radar, env, 4, samples), "a tilted beam");
    let drawn = ClutterMap::on_surface(std::sync::Arc::clone(surface), 3);
    let made = ClutterMap::new(radar, env, FrameKey::new(4, 3), samples).unwrap();
    let (spokes, n) = made.shape();
    assert_eq!(drawn.shape(), (spokes, n));
    let mut textured = 0;
    for k in 0..spokes {
        for j in 0..n {
            assert_eq!(drawn.power(k, j).to_bits(), made.power(k, j).to_bits());
            assert_eq!(drawn.texture(k, j).to_bits(), made.texture(k, j).to_bits());
            assert_eq!(drawn.land_echo(k, j), made.land_echo(k, j));
            textured += usize::from(drawn.texture(k, j) != kept.texture(k, j));
        }
    }
    assert!(
        textured > spokes * n / 4,
        "the texture did not drift: {textured} cells"
    );
}

/// Polygons take their feature's `name`; the parts of a MultiPolygon feature (the docs'
/// example coast's two skerries) get `-<k>`, so that every polygon truth names is one.
#[test]
fn a_multipolygons_parts_get_names_of_their_own() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = "[[land]]\ngeojson = \"scenes/land/example-coast.geojson\"\ncrs = \"wgs84\"\n\
                [geo]\norigin_lon_deg = 10.70\norigin_lat_deg = 59.90\n";
    let scene = xbandsim::scene::LoadedSpec::from_toml(text, "t", &root)
        .unwrap()
        .build()
        .unwrap();
    let names: Vec<&str> = scene
        .environment()
        .land()
        .polygons()
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    assert!(
        names.contains(&"skerries-0") && names.contains(&"skerries-1"),
        "{names:?}"
    );
    let mut unique = names.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), names.len(), "{names:?}");
}
