//! Structures (`[[structure]]`) and height-map terrain: the quay wall's dihedral RCS, the
//! shadow a building casts on the sea, the structure mask, height maps through the clutter
//! map, and bad input refused by name (docs/physics.md §16, docs/formats.md).

use xbandsim::model::Scene;
use xbandsim::rng::FrameKey;
use xbandsim::signal::clutter_map::ClutterMap;

#[test]
fn a_quay_wall_returns_its_wall_and_sea_dihedral_rcs() {
    // Physical optics with the sea's image paths against the closed form of the face lit
    // directly and via the sea (xbandsim_validate::land::quay_wall_rcs_dbsm); a wall of
    // ship size as well as a small one.
    for (range, antenna, width, height) in [(1500.0, 15.0, 4.0, 3.0), (3000.0, 20.0, 6.0, 8.0)] {
        let (want, got) =
            xbandsim_validate::land::quay_wall_rcs_dbsm(range, antenna, width, height);
        eprintln!("quay {width}×{height} m at {range} m: {want:.2} vs {got:.2} dBsm");
        assert!((want - got).abs() < 0.3, "{want} vs {got}");
    }
}

use crate::common::clutter_map_of as map_of;

/// Ground range of sample `n` for an antenna `h` high.
fn ground_of(scene: &Scene, n: usize) -> f64 {
    let r = n as f64 * scene.radar().range_bin_m();
    let h = scene.radar().position_m().z;
    (r * r - h * h).max(0.0).sqrt()
}

/// A building taller than the antenna hides the sea behind it to the end of the record;
/// a low quay hides it only as far as geometry says: the sea at ground range `g` is seen
/// again where its depression `h/g` (less the earth's drop `g/2a_e`, 4/3 earth) is steeper
/// than the quay's far edge's. Their footprints in view are masked as theirs, not as land.
#[test]
fn structures_hide_the_sea_behind_them_as_far_as_geometry_says() {
    let text = "[radar]\nposition_m = [0.0, 0.0, 15.0]\nmax_range_m = 2500.0\nspokes = 360\n[environment]\nsea_state = 4\n[[structure]]\nname = \"warehouse\"\nposition_m = [0.0, 1000.0]\nsize_m = [20.0, 300.0]\nheight_m = 25.0\n[[structure]]\nname = \"quay\"\nkind = \"quay\"\npolygon_m = [[-150.0, -1000.0], [150.0, -1000.0], [150.0, -1100.0], [-150.0, -1100.0]]\nheight_m = 3.0\n";
    let (scene, map, samples) = map_of(text);
    let (north, south) = (0usize, 180usize);
    let structure_cells = |k: usize| {
        (0..samples)
            .filter(|&n| map.structure_at(k, n).is_some())
            .count()
    };
    // North: sea seen up to the wall, nothing after it (but the far tails of the azimuth
    // weighting from bearings past the warehouse's 17° width).
    let n_front = (0..samples)
        .rfind(|&n| ground_of(&scene, n) < 980.0)
        .unwrap();
    let front = map.mean_power(north, n_front);
    for n in 1..samples {
        let g = ground_of(&scene, n);
        if g > 20.0 && g < 985.0 {
            assert!(
                map.surface_seen(north, n),
                "sea before the warehouse at {g}"
            );
            assert!(map.mean_power(north, n) > 0.0, "sea clutter at {g}");
        }
        if g > 1011.0 {
            assert!(
                !map.surface_seen(north, n),
                "the sea behind the warehouse at {g}"
            );
            let p = map.mean_power(north, n);
            assert!(p < 1e-4 * front, "no sea clutter at {g}: {p} vs {front}");
        }
        assert!(
            map.land_polygon(north, n).is_none(),
            "a structure is not land"
        );
    }
    assert!(
        structure_cells(north) >= 1,
        "the warehouse's face is marked"
    );
    // South: the quay's top is seen (below the antenna) and masked; the sea behind it is
    // hidden to where the line over its far edge meets the sea.
    let (h, top, far) = (15.0f64, 3.0, 1100.0f64);
    let a_e = xbandsim::propagation::EFFECTIVE_EARTH_RADIUS_M;
    let edge_depression = (h - top) / far + far / (2.0 * a_e);
    let seen_again = (0..samples)
        .map(|n| ground_of(&scene, n))
        .find(|&g| g > far && h / g + g / (2.0 * a_e) <= edge_depression)
        .expect("the sea is seen again");
    // The map samples the quay's top once per range bin: its highest sample may lie up to a
    // bin short of the far edge, which moves the shadow's end by up to h/(h − H) bins.
    let bin = scene.radar().range_bin_m();
    let slack = bin * (1.0 + h / (h - top));
    for n in 1..samples {
        let g = ground_of(&scene, n);
        if g > far + 1.0 && g < seen_again - slack {
            assert!(
                !map.surface_seen(south, n),
                "the sea in the quay's shadow at {g}"
            );
        }
        if g > seen_again + slack {
            assert!(
                map.surface_seen(south, n),
                "the sea beyond the quay's shadow at {g}"
            );
        }
    }
    let quay_cells = structure_cells(south);
    let expected = (100.0 / bin).round() as usize;
    assert!(
        quay_cells.abs_diff(expected) <= 1,
        "{quay_cells} cells of the quay's top vs {expected}"
    );
}

/// Truth: `structure_mask.npy` holds the structure's object id where its footprint is in
/// view, the truth lists it with its cell count, and `land_ppi.png` marks it 2.
#[test]
fn the_structure_mask_names_each_structure_by_its_object_id() {
    let text = "[radar]\nposition_m = [0.0, 0.0, 15.0]\nmax_range_m = 1500.0\nspokes = 360\n[environment]\nsea_state = 3\n[[object]]\nname = \"boat\"\nshape = \"sphere\"\nradius_m = 2.0\nposition_m = [300.0, 0.0, 1.0]\n[[structure]]\nname = \"pier\"\nkind = \"pier\"\npolygon_m = [[-10.0, 600.0], [10.0, 600.0], [10.0, 900.0], [-10.0, 900.0]]\nheight_m = 2.5\n";
    let (sim, frame) = crate::common::render(text, 1);
    let land = frame.land.as_ref().expect("a structure makes land truth");
    assert_eq!(land.structures.len(), 1);
    let pier = &land.structures[0];
    assert_eq!((pier.id, pier.name.as_str()), (1, "pier"));
    assert!(pier.cells > 0);
    assert_eq!(
        land.structure.iter().filter(|&&s| s == 1).count(),
        pier.cells
    );
    assert!(
        land.polygon.iter().all(|&p| p == -1),
        "no land in this scene"
    );
    assert_eq!(frame.truth[1].class, "pier");
    assert!(frame.truth[1].rcs_m2.is_some_and(|r| r > 0.0));
    let dir = tempfile::tempdir().unwrap();
    let display = xbandsim::products::ppi::PpiSettings::from_spec(&Default::default()).unwrap();
    xbandsim::products::frame_files::write_frame_files(
        sim.scene().radar(),
        &display,
        &frame,
        dir.path(),
        "pier",
        1,
    )
    .unwrap();
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("truth.json")).unwrap()).unwrap();
    assert_eq!(truth["land"]["structures"][0]["name"], "pier");
    let png = std::fs::read(dir.path().join("land_ppi.png")).unwrap();
    let decoder = png::Decoder::new(&png[..]);
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0u8; reader.output_buffer_size()];
    reader.next_frame(&mut buf).unwrap();
    assert!(
        buf.contains(&2) && !buf.contains(&1),
        "the pier is class 2, no land is 1"
    );
    assert!(dir.path().join("structure_mask.npy").exists());
}

/// A height map of one constant height gives the very map a flat top of that height does;
/// a ridge's far side lies in shadow exactly where the running maximum of the elevation
/// over the map's bilinear heights says, sample by sample.
#[test]
fn height_maps_give_the_heights_they_hold() {
    let dir = tempfile::tempdir().unwrap();
    let npy = |name: &str, rows: usize, cols: usize, values: &[f32]| {
        let bytes = xbandsim::products::output::npy_f32_bytes(&[rows, cols], values);
        std::fs::write(dir.path().join(name), bytes).unwrap();
    };
    npy("flat.npy", 2, 2, &[12.0; 4]);
    // A ridge along x, 40 m high at y = 1400, falling to 0 at y = 1000 and 2200 (5 rows
    // north to south: y = 2200, 1900, 1600, 1300, 1000).
    let ridge_rows = [0.0f32, 10.0, 40.0, 30.0, 0.0];
    let ridge: Vec<f32> = ridge_rows.iter().flat_map(|&v| [v, v, v]).collect();
    npy("ridge.npy", 5, 3, &ridge);
    let scene_text = |land: &str| {
        format!("[radar]\nposition_m = [0.0, 0.0, 20.0]\nmax_range_m = 2500.0\nspokes = 360\n[environment]\nsea_state = 3\n[[land]]\npolygon_m = [[-800.0, 1000.0], [800.0, 1000.0], [800.0, 2200.0], [-800.0, 2200.0]]\n{land}\n")
    };
    let load = |text: String| {
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, text).unwrap();
        xbandsim::scene::LoadedSpec::read(&path)
            .unwrap()
            .build()
            .unwrap()
    };
    let map = |scene: &Scene| {
        let radar = scene.radar();
        let samples = (radar.max_range_m() / radar.range_bin_m()).ceil() as usize + 2;
        (
            ClutterMap::new(radar, scene.environment(), FrameKey::new(3, 0), samples).unwrap(),
            samples,
        )
    };
    let flat = load(scene_text("height_m = 12.0"));
    let mapped = load(scene_text(
        "height_map = \"flat.npy\"\nheight_map_extent_m = [-900.0, 900.0, 900.0, 2300.0]",
    ));
    let ((a, samples), (b, _)) = (map(&flat), map(&mapped));
    for k in [0usize, 10, 350] {
        for n in 0..samples {
            assert_eq!(
                a.land_mean_power(k, n),
                b.land_mean_power(k, n),
                "spoke {k} sample {n}"
            );
            assert_eq!(a.surface_seen(k, n), b.surface_seen(k, n));
        }
    }
    let hilly = load(scene_text(
        "height_map = \"ridge.npy\"\nheight_map_extent_m = [-800.0, 1000.0, 800.0, 2200.0]",
    ));
    let (m, samples) = map(&hilly);
    let land = hilly.environment().land();
    let curvature = hilly.environment().earth_curvature();
    let mut highest = f64::NEG_INFINITY;
    let (mut hidden, mut seen_land) = (0, 0);
    for n in 1..samples {
        let g = ground_of(&hilly, n);
        if g <= 0.0 {
            continue;
        }
        let z = land.height_at(glam::DVec2::new(0.0, g));
        let alpha = xbandsim::land::profile::elevation_rad(z, g, 20.0, curvature);
        let seen = alpha >= highest;
        highest = highest.max(alpha);
        if (g - 1000.0).abs() < 2.0 || (g - 2200.0).abs() < 2.0 {
            continue; // the coast's own cells: which side of it a sample falls
        }
        assert_eq!(m.surface_seen(0, n), seen, "at {g} m (height {z})");
        if g > 1000.0 && g < 2200.0 {
            if seen {
                seen_land += 1;
                assert!(m.land_polygon(0, n).is_some());
            } else {
                hidden += 1;
            }
        }
    }
    assert!(
        hidden > 100 && seen_land > 100,
        "{hidden} hidden, {seen_land} seen"
    );
}

/// Bad structures and height maps are refused naming the field, the file and the value.
#[test]
fn bad_structures_and_height_maps_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("one.npy"), b"\x93NUMPY\x01\x00\x46\x00{'descr': '<f4', 'fortran_order': False, 'shape': (3,), }                                  \n\0\0\0\0\0\0\0\0\0\0\0\0").unwrap();
    let load = |body: &str| {
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, format!("[radar]\nmax_range_m = 1500.0\n{body}")).unwrap();
        xbandsim::scene::LoadedSpec::read(&path)
            .and_then(|s| s.build())
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    let land = "[[land]]\npolygon_m = [[0.0, 500.0], [100.0, 500.0], [100.0, 600.0]]\n";
    let cases = [
        ("[[structure]]\nheight_m = 5.0\n", "structure[0].polygon_m"),
        (
            "[[structure]]\npolygon_m = [[0.0, 300.0], [10.0, 310.0], [10.0, 300.0], [0.0, 310.0]]\nheight_m = 5.0\n",
            "`structure[0].polygon_m` = [[0, 300], [10, 310], [10, 300], [0, 310]]: edges cross",
        ),
        (
            "[[structure]]\nposition_m = [0.0, 300.0]\nsize_m = [10.0, 10.0]\n",
            "structure[0].height_m",
        ),
        (
            "[[structure]]\nposition_m = [0.0, 300.0]\nsize_m = [10.0, 10.0]\nradius_m = 3.0\nheight_m = 4.0\n",
            "structure[0].radius_m",
        ),
        (
            "[[structure]]\nsize_m = [10.0, 10.0]\nheight_m = 4.0\n",
            "structure[0].position_m",
        ),
        (
            "[[structure]]\npolygon_m = [[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]]\nheight_m = 4.0\n",
            "structure[0].polygon_m",
        ),
        (
            "[[object]]\nname = \"moored\"\nshape = \"sphere\"\nradius_m = 1.0\nposition_m = [0.0, 300.0, 0.5]\n[[structure]]\nname = \"shed\"\nposition_m = [0.0, 300.0]\nsize_m = [10.0, 10.0]\nheight_m = 4.0\n",
            "object[0].position_m",
        ),
        (
            &format!("{land}height_map = \"one.npy\"\nheight_map_extent_m = [0.0, 0.0, 200.0, 700.0]\n"),
            "2-D",
        ),
        (
            &format!("{land}height_map = \"missing.npy\"\nheight_map_extent_m = [0.0, 0.0, 200.0, 700.0]\n"),
            "missing.npy",
        ),
        (
            &format!("{land}height_map = \"one.npy\"\n"),
            "land[0].height_map_extent_m",
        ),
        (
            &format!("{land}height_map_scale_m = 2.0\n"),
            "land[0].height_map_scale_m",
        ),
    ];
    // A header claiming more samples than fit (no data behind it), and a structure around
    // the radar: errors, not panics.
    std::fs::write(dir.path().join("huge.npy"), {
        let header =
            "{'descr': '<u2', 'fortran_order': False, 'shape': (4294967296, 4294967296), }";
        let h = format!("{header}\n");
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend_from_slice(&(h.len() as u16).to_le_bytes());
        b.extend_from_slice(h.as_bytes());
        b
    })
    .unwrap();
    let huge = format!(
        "{land}height_map = \"huge.npy\"\nheight_map_extent_m = [0.0, 0.0, 200.0, 700.0]\n"
    );
    let around = "[[structure]]\nname = \"mole\"\npolygon_m = [[-500.0, -10.0], [500.0, -10.0], [500.0, 10.0], [-500.0, 10.0]]\nheight_m = 4.0\nbase_m = 0.0\n";
    // Metres read as lon/lat: refused as land's are.
    std::fs::write(
        dir.path().join("shed.geojson"),
        r#"{"type":"Polygon","coordinates":[[[0,300],[10,300],[10,310],[0,310],[0,300]]]}"#,
    )
    .unwrap();
    let metres = "[geo]\norigin_lon_deg = 10.0\norigin_lat_deg = 60.0\n[[structure]]\ngeojson = \"shed.geojson\"\ncrs = \"wgs84\"\nheight_m = 5.0\n";
    let mut cases = cases.to_vec();
    cases.push((metres, "is not a lon/lat in degrees"));
    cases.push((&huge, "larger than this reader takes"));
    cases.push((around, "structure[0].polygon_m"));
    for (body, want) in cases {
        let e = load(body).expect_err(body);
        assert!(e.contains(want), "{body}: {e}");
    }
    // Footprints of one name (a pier's segments) get names of their own.
    std::fs::write(
        dir.path().join("pier.geojson"),
        r#"{"type":"FeatureCollection","features":[
          {"type":"Feature","properties":{"name":"Pier"},"geometry":{"type":"Polygon","coordinates":[[[0,300],[10,300],[10,350],[0,350],[0,300]]]}},
          {"type":"Feature","properties":{"name":"Pier"},"geometry":{"type":"Polygon","coordinates":[[[0,350],[10,350],[10,400],[0,400],[0,350]]]}}]}"#,
    )
    .unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(
        &path,
        "[radar]\nmax_range_m = 1500.0\n[[structure]]\nkind = \"pier\"\ngeojson = \"pier.geojson\"\nheight_m = 2.0\n",
    )
    .unwrap();
    let scene = xbandsim::scene::LoadedSpec::read(&path)
        .unwrap()
        .build()
        .unwrap();
    let names: Vec<&str> = scene.objects().iter().map(|o| o.name()).collect();
    assert_eq!(names, ["Pier", "Pier-1"]);
    // A map that does not cover its polygons: the file, the feature and the corner named.
    std::fs::write(
        dir.path().join("small.npy"),
        xbandsim::products::output::npy_f32_bytes(&[2, 2], &[0.0; 4]),
    )
    .unwrap();
    let e = load(&format!(
        "{land}height_map = \"small.npy\"\nheight_map_extent_m = [0.0, 0.0, 50.0, 700.0]\n"
    ))
    .unwrap_err();
    assert!(
        e.contains("land[0].height_map_extent_m") && e.contains("outside the height map"),
        "{e}"
    );
}
