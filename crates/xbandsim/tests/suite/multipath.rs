//! The sea surface in the scattering: four-path lobing of point targets against the two-ray
//! model, the same lobing for a physical-optics sphere traced with SBR over the sea, and
//! shadowing of one object by another.

use super::common::*;
use xbandsim::constants::wavelength_m;
use xbandsim_validate::{
    find_lobe_range_m, find_null_range_m, multipath_point_power_db, two_ray_extremum_range_m,
    two_ray_null_range_m,
};

/// Point target: nulls where the path difference is nλ (±1 %), for two geometries.
#[test]
fn point_target_four_path_nulls() {
    let lambda = wavelength_m(9.41e9);
    for (hr, ht) in [(10.0, 5.0), (6.0, 3.0)] {
        for n in [1.0, 2.0, 3.0] {
            let expected = two_ray_extremum_range_m(n, hr, ht, lambda);
            let measured = find_null_range_m(expected, hr, ht);
            assert!(
                (measured / expected - 1.0).abs() < 0.01,
                "h {hr}/{ht} null {n}: {measured:.1} m vs {expected:.1} m"
            );
            let depth = multipath_point_power_db(measured, hr, ht, true)
                - multipath_point_power_db(measured, hr, ht, false);
            assert!(
                depth < -20.0,
                "null {n} only {depth:.1} dB below free space"
            );
        }
    }
}

/// Point target: lobe peaks where the path difference is (n + ½)λ (±1 %), about +12 dB.
#[test]
fn point_target_four_path_lobes() {
    let lambda = wavelength_m(9.41e9);
    for (hr, ht) in [(10.0, 5.0), (6.0, 3.0)] {
        for n in [0.5, 1.5, 2.5] {
            let expected = two_ray_extremum_range_m(n, hr, ht, lambda);
            let measured = find_lobe_range_m(expected, hr, ht);
            assert!(
                (measured / expected - 1.0).abs() < 0.01,
                "h {hr}/{ht} lobe {n}: {measured:.1} m vs {expected:.1} m"
            );
            let gain = multipath_point_power_db(measured, hr, ht, true)
                - multipath_point_power_db(measured, hr, ht, false);
            assert!((gain - 12.0).abs() < 0.6, "lobe {n} gain {gain:.2} dB");
        }
    }
}

fn sphere_power_db(ground_range_m: f64, multipath: bool) -> f64 {
    let text = format!(
        "[environment]\nnoise = false\nclutter = false\nsea_rms_height_m = 0.0\nmultipath = {multipath}\n[radar]\nposition_m = [0.0, 0.0, 10.0]\nspokes = 1\nmax_range_m = {}\n[[object]]\nname = \"s\"\nshape = \"sphere\"\nradius_m = 0.5\nposition_m = [0.0, {ground_range_m}, 5.0]\n",
        ground_range_m + 100.0
    );
    let (sim, frame) = render(&text, 1);
    let j = (ground_range_m / sim.scene().radar().range_bin_m()).round() as usize;
    spoke(&frame, 0)[j - 5..j + 6]
        .iter()
        .cloned()
        .fold(f32::MIN, f32::max) as f64
}

/// A PO sphere over the sea (SBR with the image grid and sea returns) lobes like the point
/// target of the two-ray model: +12 dB at the lobe peak (±1 dB) and deep at the first null.
#[test]
fn po_sphere_over_sea_follows_two_ray_model() {
    let lambda = wavelength_m(9.41e9);
    let peak = two_ray_null_range_m(1.5, 10.0, 5.0, lambda);
    let gain = sphere_power_db(peak, true) - sphere_power_db(peak, false);
    assert!((gain - 12.0).abs() < 1.0, "lobe gain {gain:.2} dB");
    let null = two_ray_null_range_m(1.0, 10.0, 5.0, lambda);
    let depth = sphere_power_db(null, true) - sphere_power_db(null, false);
    assert!(depth < -10.0, "null depth {depth:.2} dB");
}

/// An object hidden behind a larger one returns nothing and its truth says shadowed.
#[test]
fn objects_shadow_each_other() {
    let text = format!(
        "{}[[object]]\nname = \"wall\"\nshape = \"plate\"\nwidth_m = 20.0\nheight_m = 20.0\nposition_m = [0.0, 300.0, 4.0]\nyaw_deg = 180.0\n[[object]]\nname = \"hidden\"\nshape = \"sphere\"\nradius_m = 1.0\nposition_m = [0.0, 400.0, 4.0]\n",
        radar_block_no_noise("max_range_m = 600.0")
    );
    let (sim, frame) = render(&text, 1);
    let hidden = frame.truth.iter().find(|t| t.name == "hidden").unwrap();
    assert_eq!(
        hidden.visibility,
        xbandsim::products::labels::Visibility::Shadowed
    );
    let set = sim.trace();
    assert!(
        set.contributions.iter().any(|c| c.object == 0),
        "the wall returns"
    );
    assert!(
        !set.contributions.iter().any(|c| c.object == 1),
        "the hidden sphere returned something"
    );
}

/// Tube culling (`TubeGrid::window`, then `TubeGrid::coverage`: the union of the object's
/// primitives' windows, from their vertices or boxes) is exact: for ship-sized and small
/// objects over the sea, one behind another, every tube an object's coverage leaves out
/// (direct and via-sea grids) traced anyway returns nothing, and the covered tubes give `trace_object`'s returns. The coverage
/// leaves out tubes of the object's window too (the ship's oblique hull, the masts), and
/// with a plane wave (the `rcs` command's illumination) the same holds.
#[test]
fn tubes_outside_the_window_return_nothing() {
    use xbandsim::scattering::po::{
        object_parts, sea_mirror, settings_for, trace_object, trace_tube, Illumination, TubeGrid,
    };
    let s = scene(
        "[environment]\nnoise = false\nclutter = false\n[radar]\nposition_m = [0.0, 0.0, 12.0]\nmax_range_m = 1500.0\n[scattering]\nmax_rays_per_object = 4096\n\
         [[object]]\nname = \"ship\"\nshape = \"vessel\"\nlength_m = 120.0\nbeam_m = 18.0\nfreeboard_m = 8.0\nmast_height_m = 25.0\nyaw_deg = 35.0\nposition_m = [200.0, 600.0, 0.0]\n\
         [[object]]\nname = \"yacht\"\nshape = \"vessel\"\nlength_m = 9.0\nbeam_m = 3.0\nfreeboard_m = 0.8\nmast_height_m = 12.0\nyaw_deg = 250.0\nposition_m = [140.0, 420.0, 0.0]\n\
         [[object]]\nname = \"buoy\"\nshape = \"buoy\"\nradius_m = 0.9\nheight_m = 0.7\nmast_height_m = 4.0\nposition_m = [-300.0, 250.0, 0.0]\n",
    );
    let bvh = xbandsim::scattering::build_scene_bvh(s.objects());
    let settings = settings_for(&s);
    let radar_m = s.radar().position_m();
    let illumination = Illumination::FromPoint { radar_m };
    for (index, obj) in s.objects().iter().enumerate() {
        let index = index as u32;
        let (centre, radius) = (obj.bounding_centre_m(), obj.shape().bounding_radius_m());
        let bounds = bvh.object_bounds(index);
        let mut all = Vec::new();
        let (mut inside, mut outside, mut in_window) = (0usize, 0usize, 0usize);
        for via_sea in [false, true] {
            let image = if via_sea { sea_mirror(centre) } else { centre };
            let grid = TubeGrid::new(
                illumination,
                image,
                radius,
                settings.spacing_m,
                settings.max_rays,
                via_sea,
            );
            let (columns, rows) = grid.window(&bounds);
            assert!(columns.len() < grid.cells_per_side || rows.len() < grid.cells_per_side);
            let coverage = grid.coverage(&bounds, object_parts(&bvh, index));
            in_window += columns.len() * rows.len();
            for j in 0..grid.cells_per_side {
                for i in 0..grid.cells_per_side {
                    let mut out = Vec::new();
                    trace_tube(&bvh, &grid, i, j, index, &settings, &mut out);
                    if coverage.covers(i, j) {
                        inside += 1;
                        all.extend(out);
                    } else {
                        outside += 1;
                        assert!(
                            out.is_empty(),
                            "object {index} tube ({i}, {j}) outside its coverage returned"
                        );
                    }
                }
            }
        }
        assert!(
            outside > inside / 4,
            "object {index}: only {outside} tubes culled"
        );
        assert!(
            inside < in_window * 9 / 10,
            "object {index}: the coverage keeps {inside} of the windows' {in_window} tubes"
        );
        // A plane wave from the radar's direction (the `rcs` command's illumination): its
        // grid's uncovered tubes return nothing either.
        let plane_wave = Illumination::PlaneWave {
            toward_radar: (radar_m - centre).normalize(),
        };
        let grid = TubeGrid::new(
            plane_wave,
            centre,
            radius,
            settings.spacing_m,
            settings.max_rays,
            false,
        );
        let coverage = grid.coverage(&bounds, object_parts(&bvh, index));
        let mut culled = 0;
        for j in 0..grid.cells_per_side {
            for i in 0..grid.cells_per_side {
                if !coverage.covers(i, j) {
                    let mut out = Vec::new();
                    trace_tube(&bvh, &grid, i, j, index, &settings, &mut out);
                    assert!(out.is_empty(), "object {index}: plane-wave tube ({i}, {j})");
                    culled += 1;
                }
            }
        }
        assert!(culled > 0, "object {index}: no plane-wave tube culled");
        let traced = trace_object(&bvh, illumination, centre, radius, index, &settings);
        assert!(
            !traced.returns.is_empty(),
            "object {index} returned nothing"
        );
        assert_eq!(traced.returns.len(), all.len(), "object {index}");
        for (a, b) in traced.returns.iter().zip(&all) {
            assert_eq!(a.root_rcs_m, b.root_rcs_m);
            assert_eq!(a.path_m, b.path_m);
        }
    }
}
