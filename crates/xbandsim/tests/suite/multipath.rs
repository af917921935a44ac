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

/// A 120 m ship 632 m out with a 9 m yacht in front of it on the same bearing and a buoy
/// elsewhere, over the sea (no noise or clutter), the radar `radar_height_m` above it, at most
/// 4096 tubes an object.
fn ship_yacht_and_buoy(radar_height_m: f64) -> xbandsim::Scene {
    scene(&format!(
        "[environment]\nnoise = false\nclutter = false\n[radar]\nposition_m = [0.0, 0.0, {radar_height_m}]\nmax_range_m = 1500.0\n[scattering]\nmax_rays_per_object = 4096\n\
         [[object]]\nname = \"ship\"\nshape = \"vessel\"\nlength_m = 120.0\nbeam_m = 18.0\nfreeboard_m = 8.0\nmast_height_m = 25.0\nyaw_deg = 35.0\nposition_m = [200.0, 600.0, 0.0]\n\
         [[object]]\nname = \"yacht\"\nshape = \"vessel\"\nlength_m = 9.0\nbeam_m = 3.0\nfreeboard_m = 0.8\nmast_height_m = 12.0\nyaw_deg = 250.0\nposition_m = [140.0, 420.0, 0.0]\n\
         [[object]]\nname = \"buoy\"\nshape = \"buoy\"\nradius_m = 0.9\nheight_m = 0.7\nmast_height_m = 4.0\nposition_m = [-300.0, 250.0, 0.0]\n",
    ))
}

/// Tube culling (`TubeGrid::window`, then `TubeGrid::coverage`: the union of the object's
/// primitives' windows, from their vertices or boxes) is exact: for ship-sized and small
/// objects over the sea, one behind another, every tube an object's coverage leaves out
/// (direct and via-sea grids) traced anyway returns nothing, and the covered tubes give
/// `trace_object`'s returns. The coverage leaves out tubes of the object's window too (the
/// ship's oblique hull, the masts), and with a plane wave (the `rcs` command's illumination)
/// the same holds.
#[test]
fn tubes_outside_the_window_return_nothing() {
    use xbandsim::scattering::po::{
        object_parts, sea_mirror, settings_for, trace_object, trace_tube, Illumination,
        ObjectOptics, SbrSettings, TubeGrid,
    };
    let s = ship_yacht_and_buoy(12.0);
    let bvh = xbandsim::scattering::build_scene_bvh(s.objects());
    // The tubes alone: the edges' fringe returns are not the grid's.
    let settings = SbrSettings {
        edge_diffraction: false,
        ..settings_for(&s)
    };
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
        let traced = trace_object(
            &bvh,
            illumination,
            centre,
            radius,
            index,
            &ObjectOptics::conductor(),
            &settings,
        );
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

/// A tube's first hit returns along the way its tube came in without shadow rays
/// (docs/physics.md §2.2): a direct tube's echo straight back, a via-sea tube's echo back via
/// the sea point where the tube reflected. Here the shadow rays of every first hit's returns
/// are cast, those the tracer leaves out included, and none is blocked, for ship-sized and
/// small objects over the sea with a yacht in front of the ship, at two radar heights. (The
/// returns it does test are there only if clear; a rule that left out a return's rays
/// where its path is not retraced would show here as a blocked one: skipping a direct
/// tube's shadow rays via the sea does.)
#[test]
fn first_hit_returns_are_clear() {
    use glam::DVec3;
    use xbandsim::geometry::Ray;
    use xbandsim::scattering::po::{
        sea_mirror, settings_for, trace_object, Illumination, ObjectOptics,
    };
    // Off the surface by this along the return (the tracer lifts along the normal).
    const LIFT_M: f64 = 1e-3;
    for radar_height_m in [6.0, 25.0] {
        let s = ship_yacht_and_buoy(radar_height_m);
        let bvh = xbandsim::scattering::build_scene_bvh(s.objects());
        let settings = settings_for(&s);
        let radar_m = s.radar().position_m();
        let radar_image_m = sea_mirror(radar_m);
        let blocked = |from: DVec3, to: DVec3| {
            let v = to - from;
            let dir = v.normalize();
            bvh.any_hit(
                &Ray {
                    origin_m: from + dir * LIFT_M,
                    dir,
                },
                v.length() - LIFT_M,
            )
        };
        // The return from `hit` via the sea: its two legs blocked?
        let blocked_via_sea = |hit: DVec3| {
            let toward_image = (radar_image_m - hit).normalize();
            let sea_point = hit + toward_image * (hit.z / -toward_image.z);
            blocked(hit, sea_point) || blocked(sea_point, radar_m)
        };
        // Returns checked: [direct tube, direct back (retraced); direct tube, via the sea;
        // via-sea tube, direct back; via-sea tube, via the sea (retraced)].
        let mut checked = [0usize; 4];
        for (index, obj) in s.objects().iter().enumerate() {
            let traced = trace_object(
                &bvh,
                Illumination::FromPoint { radar_m },
                obj.bounding_centre_m(),
                obj.shape().bounding_radius_m(),
                index as u32,
                &ObjectOptics::conductor(),
                &settings,
            );
            for r in traced.returns.iter().filter(|r| r.bounces == 1) {
                // The first hit from the launch direction and the path to it: a direct
                // tube's, or a via-sea tube's unfolded (it ends at the hit's mirror image,
                // below the sea).
                let along = radar_m + r.tx_dir * r.range_tx_m;
                let via_sea_tube = along.z < 0.0;
                let hit = if via_sea_tube {
                    sea_mirror(along)
                } else {
                    along
                };
                let exit_via_sea = usize::from(r.sea_reflections) == 1 + usize::from(via_sea_tube);
                let kind = 2 * usize::from(via_sea_tube) + usize::from(exit_via_sea);
                let is_blocked = if exit_via_sea {
                    blocked_via_sea(hit)
                } else {
                    blocked(hit, radar_m)
                };
                assert!(!is_blocked, "object {index}, kind {kind}: {r:?}");
                checked[kind] += 1;
            }
        }
        assert!(
            checked.iter().all(|&n| n > 100),
            "radar at {radar_height_m} m: only {checked:?} returns of each kind"
        );
    }
}
