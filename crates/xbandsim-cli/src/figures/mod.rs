//! `xbandsim figures`: the seed paper's Fig. 2 (antenna pattern), Fig. 3 (signal chain) and
//! Fig. 4 (PPIs for 1, 20 and 50 µs pulses), drawn with plotters from the library's outputs.

use anyhow::{Context, Result};
use num_complex::Complex32;
use plotters::prelude::*;
use std::path::Path;
use xbandsim::antenna::sinc2_pattern;
use xbandsim::constants::linear_to_db;
use xbandsim::echo::EchoGroups;
use xbandsim::engine::Simulation;
use xbandsim::products::frame_files::{frame_products, Images};
use xbandsim::products::ppi::PpiSettings;
use xbandsim::products::ppi::{colour_image, ScanConverter};
use xbandsim::scene::{LoadedSpec, ObjectSpec, SceneSpec, ShapeName};
use xbandsim::Scene;

mod plot;

use plot::{panel_grid, plot_err, save_rgb, time_panel};
pub use plot::{register_fonts, FONT};

/// Runs `xbandsim figures`.
pub fn run(out: &Path, scene_path: &Path, seed: u64) -> Result<()> {
    register_fonts()?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let loaded = LoadedSpec::read(scene_path)?;
    let scene = loaded.build()?;
    let t0 = std::time::Instant::now();
    fig2(out, &scene)?;
    crate::say!("wrote {}", out.join("fig2_antenna_pattern.png").display());
    fig3(out, loaded.spec(), loaded.base_dir(), seed)?;
    crate::say!("wrote {}", out.join("fig3_signal_chain.png").display());
    fig4(out, loaded.spec(), loaded.base_dir(), seed)?;
    crate::say!("wrote {}", out.join("fig4_ppi_pulse_widths.png").display());
    let dir = loaded.base_dir();
    fig5(
        out,
        &dir.join("sea-state-4-rain.toml"),
        &dir.join("harbour-calm.toml"),
        seed,
    )?;
    crate::say!("wrote {}", out.join("fig5_sea_clutter_rain.png").display());
    object_frames(out)?;
    crate::say!("wrote {}", out.join("object_frames.png").display());
    fig6(
        out,
        &dir.join("harbour-calm.toml"),
        &dir.join("sea-state-4-rain.toml"),
        seed,
    )?;
    crate::say!("wrote {}", out.join("fig6_receiver_video.png").display());
    target_rcs(out)?;
    crate::say!("wrote {}", out.join("target_rcs_by_class.png").display());
    crate::say!("figures done in {:.1} s", t0.elapsed().as_secs_f64());
    Ok(())
}

/// Fig. 2: one-way and two-way normalised power patterns in azimuth and elevation.
fn fig2(out: &Path, scene: &Scene) -> Result<()> {
    let ant = scene.radar().antenna();
    save_rgb(&out.join("fig2_antenna_pattern.png"), 1200, 500, |root| {
        root.fill(&WHITE).map_err(plot_err)?;
        let (left, right) = root.split_horizontally(600);
        for (area, name, bw_rad, span_deg) in [
            (left, "Azimuth", ant.az_beamwidth_rad, 15.0),
            (right, "Elevation", ant.el_beamwidth_rad, 80.0),
        ] {
            let mut chart = ChartBuilder::on(&area)
                .caption(
                    format!(
                        "{name} pattern, 3-dB beamwidth {:.1} deg",
                        bw_rad.to_degrees()
                    ),
                    (FONT, 20),
                )
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(55)
                .build_cartesian_2d(-span_deg..span_deg, -60f64..2f64)
                .map_err(plot_err)?;
            chart
                .configure_mesh()
                .x_desc("angle off boresight (deg)")
                .y_desc("normalised power (dB)")
                .label_style((FONT, 14))
                .draw()
                .map_err(plot_err)?;
            let pts = |power: i32| -> Vec<(f64, f64)> {
                (0..=2000)
                    .map(|i| {
                        let a = -span_deg + 2.0 * span_deg * i as f64 / 2000.0;
                        let g = sinc2_pattern(a.to_radians(), bw_rad).powi(power);
                        (a, linear_to_db(g.max(1e-12)).max(-60.0))
                    })
                    .collect()
            };
            chart
                .draw_series(LineSeries::new(pts(1), BLUE.stroke_width(2)))
                .map_err(plot_err)?
                .label("one-way Gn = sinc^2(2.783 theta/theta3dB)")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE.stroke_width(2)));
            chart
                .draw_series(LineSeries::new(pts(2), RED.stroke_width(2)))
                .map_err(plot_err)?
                .label("two-way Gn^2")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
            for (level, colour) in [(-3.0103, BLACK.mix(0.5)), (-6.0206, BLACK.mix(0.3))] {
                chart
                    .draw_series(LineSeries::new(
                        vec![(-span_deg, level), (span_deg, level)],
                        colour,
                    ))
                    .map_err(plot_err)?;
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::LowerRight)
                .label_font((FONT, 13))
                .background_style(WHITE.mix(0.9))
                .border_style(BLACK)
                .draw()
                .map_err(plot_err)?;
        }
        Ok(())
    })
}

/// Fig. 3: (a) the chirp, (b) echoes from three ranges, (c) the received record with noise,
/// (d) the matched-filter output — all from the library's signal chain.
fn fig3(out: &Path, base: &SceneSpec, base_dir: &Path, seed: u64) -> Result<()> {
    // The scene file's radar, with three point targets on the north axis in free space (as
    // in the paper), 1 µs pulse, blanking on.
    let mut spec = base.clone();
    spec.environment.clutter = Some(false);
    spec.environment.multipath = Some(false);
    spec.environment.rain = Some(false);
    spec.radar.pulse_width_us = Some(1.0);
    spec.radar.max_range_m = Some(900.0);
    spec.radar.spokes = Some(360);
    spec.radar.receiver_blanking = Some(true);
    spec.radar.position_m = Some([0.0, 0.0, 4.0]);
    spec.objects = [(250.0, 1.0), (450.0, 10.0), (700.0, 30.0)]
        .iter()
        .enumerate()
        .map(|(i, &(r, rcs))| ObjectSpec {
            name: Some(format!("t{i}")),
            shape: Some(ShapeName::Point),
            rcs_m2: Some(rcs),
            position_m: Some([0.0, r, 4.0]),
            ..ObjectSpec::default()
        })
        .collect();
    let three = Scene::from_spec_in(&spec, base_dir)?;
    let sim = Simulation::new(three);
    let set = sim.trace();
    let raw = sim.raw_spoke(
        None,
        &sim.echo_groups(&set),
        0.0,
        xbandsim::rng::FrameKey::new(seed, 0),
        0,
    );
    let radar = sim.scene().radar();
    let fs = radar.sample_rate_hz();
    let chirp = radar.chirp();
    let range_bin_m = radar.range_bin_m();
    // Per-target echoes, each alone.
    let per_target: Vec<Vec<Complex32>> = (0..3u32)
        .map(|k| {
            let only: Vec<_> = set
                .contributions
                .iter()
                .filter(|c| c.object == k)
                .cloned()
                .collect();
            let subset = xbandsim::scattering::ScatterSet {
                contributions: only,
                ..Default::default()
            };
            let g: EchoGroups = sim.echo_groups(&subset);
            sim.raw_spoke(None, &g, 0.0, xbandsim::rng::FrameKey::new(seed, 0), 0)
                .echo_iq
        })
        .collect();
    save_rgb(&out.join("fig3_signal_chain.png"), 1400, 1000, |root| {
        root.fill(&WHITE).map_err(plot_err)?;
        let panels = root.split_evenly((2, 2));
        // (a) chirp
        {
            let s = chirp.samples();
            let t_us: Vec<f64> = (0..s.len()).map(|i| i as f64 / fs * 1e6).collect();
            let mut chart = ChartBuilder::on(&panels[0])
                .caption(
                    format!(
                        "(a) transmitted LFM chirp: B = {:.0} MHz, T = {:.1} us",
                        chirp.bandwidth_hz / 1e6,
                        chirp.pulse_width_s * 1e6
                    ),
                    (FONT, 18),
                )
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(55)
                .right_y_label_area_size(55)
                .build_cartesian_2d(0f64..chirp.pulse_width_s * 1e6, -1.2f64..1.2f64)
                .map_err(plot_err)?
                .set_secondary_coord(0f64..chirp.pulse_width_s * 1e6, -30f64..30f64);
            chart
                .configure_mesh()
                .x_desc("time (us)")
                .y_desc("Re s(t)")
                .label_style((FONT, 13))
                .draw()
                .map_err(plot_err)?;
            chart
                .configure_secondary_axes()
                .y_desc("instantaneous frequency (MHz)")
                .label_style((FONT, 13))
                .draw()
                .map_err(plot_err)?;
            chart
                .draw_series(LineSeries::new(
                    t_us.iter().zip(&s).map(|(&t, v)| (t, v.re)),
                    BLUE,
                ))
                .map_err(plot_err)?;
            chart
                .draw_secondary_series(LineSeries::new(
                    t_us.iter()
                        .map(|&t| (t, chirp.instantaneous_frequency_hz(t * 1e-6) / 1e6)),
                    RED.stroke_width(2),
                ))
                .map_err(plot_err)?;
        }
        // (b) echoes, each target alone; (c) the received record with noise.
        let to_points = |iq: &[Complex32]| -> Vec<(f64, f64)> {
            iq.iter()
                .enumerate()
                .map(|(i, v)| (i as f64 / fs * 1e6, v.re as f64))
                .collect()
        };
        let echoes: Vec<(Vec<(f64, f64)>, RGBColor)> = per_target
            .iter()
            .zip([BLUE, GREEN, RED])
            .map(|(e, c)| (to_points(e), c))
            .collect();
        time_panel(
            &panels[1],
            "(b) echoes from 250 m (1 m2), 450 m (10 m2), 700 m (30 m2)",
            &echoes,
        )?;
        time_panel(
            &panels[2],
            "(c) received: echoes + thermal noise kT0F fs, blanked while transmitting",
            &[(to_points(&raw.received_iq), BLACK)],
        )?;
        // (d) matched-filter output
        {
            let db: Vec<f64> = raw
                .compressed
                .iter()
                .map(|c| 10.0 * (c.norm_sqr() as f64).max(1e-12).log10())
                .collect();
            let top = db.iter().cloned().fold(0.0, f64::max) + 5.0;
            let mut chart = ChartBuilder::on(&panels[3])
                .caption(
                    "(d) matched-filter output (dB over mean noise power)",
                    (FONT, 18),
                )
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(55)
                .build_cartesian_2d(0f64..db.len() as f64 * range_bin_m, -20f64..top)
                .map_err(plot_err)?;
            chart
                .configure_mesh()
                .x_desc("range (m)")
                .y_desc("power (dB)")
                .label_style((FONT, 13))
                .draw()
                .map_err(plot_err)?;
            chart
                .draw_series(LineSeries::new(
                    db.iter()
                        .enumerate()
                        .map(|(j, &v)| (j as f64 * range_bin_m, v.max(-20.0))),
                    BLUE,
                ))
                .map_err(plot_err)?;
        }
        Ok(())
    })
}

/// Fig. 4: PPIs for 1, 20 and 50 µs pulses; top row as in the paper (receiver not blanked),
/// bottom row as a real radar (blanked while transmitting, so targets within c·T/2 eclipse).
fn fig4(out: &Path, spec: &SceneSpec, base_dir: &Path, seed: u64) -> Result<()> {
    let panel = 400u32;
    let mut images: Vec<(String, Vec<u8>)> = Vec::new();
    for blanking in [false, true] {
        for pw in [1.0, 20.0, 50.0] {
            let mut s = spec.clone();
            s.radar.pulse_width_us = Some(pw);
            s.radar.receiver_blanking = Some(blanking);
            let scene = Scene::from_spec_in(&s, base_dir)
                .with_context(|| format!("fig. 4 scene with pulse_width_us = {pw}"))?;
            let display = PpiSettings::from_spec(&s.display)?;
            let extra_db = 20.0 * f64::log10(pw);
            let title = format!(
                "{pw} us, {}",
                if blanking {
                    "blanked (real receiver)"
                } else {
                    "not blanked (as in paper)"
                }
            );
            images.push((title, ppi_panel(scene, &display, panel, seed, extra_db)));
        }
    }
    panel_grid(&out.join("fig4_ppi_pulse_widths.png"), "PPI vs pulse width (colour scale 0 .. 70 + 20 log10(T/1us) dB over noise; rings every 100 m)", &images, panel, 3)
}

/// One PPI image (RGB) of a scene, `size` pixels, colour scale raised by `extra_db`.
fn ppi_panel(scene: Scene, d: &PpiSettings, size: u32, seed: u64, extra_db: f64) -> Vec<u8> {
    let sim = Simulation::new(scene);
    let frame = sim.render(seed);
    let r = sim.scene().radar();
    let conv = ScanConverter::new(
        size,
        r.max_range_m(),
        r.spokes(),
        r.num_range_bins(),
        r.range_bin_m(),
    );
    let mut ppi = vec![0f32; (size * size) as usize];
    conv.convert(&frame.polar_db, f32::NAN, &mut ppi);
    colour_image(
        &conv,
        &ppi,
        d.colormap,
        d.min_db,
        d.max_db + extra_db,
        d.range_ring_spacing_m,
    )
}

/// Fig. 5 (ours): the same open-water scene without and with sea clutter and rain, and the
/// calm harbour.
fn fig5(out: &Path, sea_scene: &Path, harbour_scene: &Path, seed: u64) -> Result<()> {
    let panel = 400u32;
    let sea = LoadedSpec::read(sea_scene)?;
    let (spec, dir) = (sea.spec(), sea.base_dir());
    let mut images = Vec::new();
    for (title, clutter, rain) in [
        ("no clutter, no rain", false, false),
        ("sea clutter (SS 4, K)", true, false),
        ("sea clutter + rain cell", true, true),
    ] {
        let mut s = spec.clone();
        s.environment.clutter = Some(clutter);
        s.environment.rain = Some(rain);
        let scene = Scene::from_spec_in(&s, dir)
            .with_context(|| format!("in scene {}", sea_scene.display()))?;
        let display = PpiSettings::from_spec(&s.display)?;
        images.push((
            title.to_string(),
            ppi_panel(scene, &display, panel, seed, 0.0),
        ));
    }
    let harbour_spec = LoadedSpec::read(harbour_scene)?;
    let harbour = harbour_spec.build()?;
    let harbour_display = harbour_spec.ppi_settings()?;
    images.push((
        "calm harbour (SS 1)".to_string(),
        ppi_panel(harbour, &harbour_display, panel, seed, 0.0),
    ));
    panel_grid(&out.join("fig5_sea_clutter_rain.png"), "Sea and weather: wind from the north (upwind brighter), rain cell to the east (0 .. 60 dB over noise)", &images, panel, 4)
}

/// The object frames of docs/formats.md: each shape at zero rotation, seen from above
/// (x east, y north) and from the side (y, z), with the direction of aspect (0°, 0°).
fn object_frames(out: &Path) -> Result<()> {
    use glam::{DMat3, DVec3};
    use xbandsim::geometry::{PrimitiveKind, ShapeGeometry};
    let shapes: Vec<(&str, ShapeGeometry)> = vec![
        (
            "plate 2 x 1 m",
            ShapeGeometry::Plate {
                width_m: 2.0,
                height_m: 1.0,
            },
        ),
        (
            "trihedral edge 1.5 m",
            ShapeGeometry::Trihedral { edge_m: 1.5 },
        ),
        (
            "dihedral 1 x 1.5 m",
            ShapeGeometry::Dihedral {
                width_m: 1.0,
                height_m: 1.5,
            },
        ),
        (
            "cylinder r 0.5, h 1.5 m",
            ShapeGeometry::Cylinder {
                radius_m: 0.5,
                height_m: 1.5,
            },
        ),
        (
            "box 2 x 1 x 1 m",
            ShapeGeometry::Box {
                size_m: DVec3::new(2.0, 1.0, 1.0),
            },
        ),
        (
            "vessel mesh (1/10 scale)",
            ShapeGeometry::Mesh {
                mesh: std::sync::Arc::new({
                    let mut m = xbandsim::geometry::mesh::vessel(30.0, 16);
                    m.vertices_m.iter_mut().for_each(|v| *v *= 0.1);
                    m
                }),
            },
        ),
    ];
    let circle = |centre: DVec3, normal: DVec3, radius_m: f64| -> Vec<DVec3> {
        let u = if normal.x.abs() < 0.9 {
            normal.cross(DVec3::X)
        } else {
            normal.cross(DVec3::Y)
        }
        .normalize();
        let v = normal.cross(u);
        (0..=48)
            .map(|i| std::f64::consts::TAU * i as f64 / 48.0)
            .map(|a| centre + (u * a.cos() + v * a.sin()) * radius_m)
            .collect()
    };
    save_rgb(&out.join("object_frames.png"), 1500, 560, |root| {
        root.fill(&WHITE).map_err(plot_err)?;
        root.draw(&Text::new("Object frames at zero rotation: every shape faces +y; red arrow = direction to a radar at aspect (0 deg, 0 deg); yaw turns +y toward +x", (15, 8), (FONT, 17))).map_err(plot_err)?;
        let area = root.margin(35, 5, 5, 5);
        let cols = area.split_evenly((2, shapes.len()));
        for (k, (name, shape)) in shapes.iter().enumerate() {
            for (row, ia, ib, xl, yl) in [
                (0usize, 0usize, 1usize, "x (east)", "y (north)"),
                (1, 1, 2, "y (north)", "z (up)"),
            ] {
                let panel = &cols[row * shapes.len() + k];
                let mut chart = ChartBuilder::on(panel)
                    .caption(
                        if row == 0 {
                            format!("{name}: top")
                        } else {
                            "side".to_string()
                        },
                        (FONT, 14),
                    )
                    .margin(6)
                    .x_label_area_size(28)
                    .y_label_area_size(32)
                    .build_cartesian_2d(-1.8f64..1.8f64, -1.8f64..1.8f64)
                    .map_err(plot_err)?;
                chart
                    .configure_mesh()
                    .x_desc(xl)
                    .y_desc(yl)
                    .label_style((FONT, 11))
                    .x_labels(5)
                    .y_labels(5)
                    .draw()
                    .map_err(plot_err)?;
                let proj = move |v: DVec3| (v.to_array()[ia], v.to_array()[ib]);
                for p in shape.primitives(DVec3::ZERO, DMat3::IDENTITY, 0) {
                    let outline: Vec<DVec3> = match p.kind {
                        PrimitiveKind::Triangle { v0, e1, e2 } => vec![v0, v0 + e1, v0 + e2, v0],
                        PrimitiveKind::Parallelogram {
                            corner,
                            edge_u,
                            edge_v,
                        } => vec![
                            corner,
                            corner + edge_u,
                            corner + edge_u + edge_v,
                            corner + edge_v,
                            corner,
                        ],
                        PrimitiveKind::Sphere { centre, radius_m } => {
                            circle(centre, if row == 0 { DVec3::Z } else { DVec3::X }, radius_m)
                        }
                        PrimitiveKind::Disk {
                            centre,
                            normal,
                            radius_m,
                        } => circle(centre, normal, radius_m),
                        PrimitiveKind::Cylinder {
                            base,
                            axis,
                            radius_m,
                            height_m,
                        } => {
                            let top = base + axis * height_m;
                            vec![
                                base + DVec3::X * radius_m,
                                top + DVec3::X * radius_m,
                                top - DVec3::X * radius_m,
                                base - DVec3::X * radius_m,
                                base + DVec3::X * radius_m,
                                base + DVec3::Y * radius_m,
                                top + DVec3::Y * radius_m,
                                top - DVec3::Y * radius_m,
                                base - DVec3::Y * radius_m,
                                base + DVec3::Y * radius_m,
                            ]
                        }
                    };
                    chart
                        .draw_series(LineSeries::new(
                            outline.into_iter().map(proj),
                            BLUE.mix(0.8),
                        ))
                        .map_err(plot_err)?;
                }
                let arrow_end = proj(DVec3::new(0.0, 1.6, 0.0));
                chart
                    .draw_series(LineSeries::new(
                        vec![proj(DVec3::ZERO), arrow_end],
                        RED.stroke_width(2),
                    ))
                    .map_err(plot_err)?;
                chart
                    .draw_series(std::iter::once(Circle::new(arrow_end, 4, RED.filled())))
                    .map_err(plot_err)?;
            }
        }
        Ok(())
    })
}

/// Draws the pixel boxes `boxes` into `rgb` (side `size`) in yellow.
fn draw_boxes(rgb: &mut [u8], size: u32, boxes: &[Option<[f64; 4]>]) {
    let s = size as i64;
    let mut put = |x: i64, y: i64| {
        if (0..s).contains(&x) && (0..s).contains(&y) {
            let k = ((y * s + x) * 3) as usize;
            rgb[k..k + 3].copy_from_slice(&[255, 220, 0]);
        }
    };
    for b in boxes.iter().flatten() {
        let [x0, y0, x1, y1] = b.map(|v| v.round() as i64);
        for x in x0..=x1 {
            put(x, y0);
            put(x, y1);
        }
        for y in y0..=y1 {
            put(x0, y);
            put(x1, y);
        }
    }
}

/// The calibrated PPI and the receiver video's PPI of a frame, the artefacts' boxes drawn
/// on the video when `boxes` is set.
fn calibrated_and_video(
    spec: &SceneSpec,
    dir: &Path,
    size: u32,
    seed: u64,
    boxes: bool,
) -> Result<(Vec<u8>, Vec<u8>)> {
    let mut s = spec.clone();
    s.display.image_size_px = Some(size);
    let scene = Scene::from_spec_in(&s, dir)?;
    let display = PpiSettings::from_spec(&s.display)?;
    let sim = Simulation::new(scene);
    let frame = sim.render(seed);
    let p = frame_products(
        sim.scene().radar(),
        &display,
        &frame,
        Path::new("."),
        "figure",
        seed,
        Images {
            colour: true,
            gray: false,
        },
    )?;
    let truth: serde_json::Value = serde_json::from_slice(&p.truth_json)?;
    let mut video = p.video_rgb.context("the scene has no [receiver] table")?;
    if boxes {
        let boxes: Vec<Option<[f64; 4]>> = truth["artefacts"]
            .as_array()
            .into_iter()
            .flatten()
            .flat_map(|a| a["ppi_boxes_px"].as_array().cloned().unwrap_or_default())
            .map(|b| serde_json::from_value(b).ok())
            .collect();
        draw_boxes(&mut video, size, &boxes);
    }
    Ok((p.colour_rgb.context("colour image asked for")?, video))
}

/// Fig. 6 (ours): the calibrated PPI and the receiver's video of the same scene at typical
/// control settings — the harbour approach, and a sea at state 4 with rain — and the
/// artefacts: a ship's sidelobe echoes on an
/// open array, another radar's interference (4096 sweeps, its PRF near a multiple of the
/// sweep rate: the curved dotted lines) without and with rejection, a second-trace echo, a
/// racon, a SART, a funnel's blind sector with its indirect echo and a ship abeam's multiple
/// echoes, their labels' boxes drawn in yellow.
fn fig6(out: &Path, harbour_scene: &Path, sea_scene: &Path, seed: u64) -> Result<()> {
    let panel = 400u32;
    let receiver = |text: &str| -> Result<xbandsim::scene::ReceiverSpec> {
        toml::from_str(text).context("figure receiver settings")
    };
    // The harbour approach at a harbour's settings: manual STC over the near water, no FTC.
    let harbour = LoadedSpec::read(harbour_scene)?;
    let mut s = harbour.spec().clone();
    s.receiver = Some(receiver(
        "stc = \"manual\"\nstc_level_db = 15.0\nstc_range_m = 600.0\ninterference_rejection = \"low\"\nvideo_spokes = 2048\nvideo_samples = 512\n",
    )?);
    let (calibrated, video) = calibrated_and_video(&s, harbour.base_dir(), panel, seed, false)?;
    let mut images = vec![
        (
            "harbour: calibrated (0 .. 60 dB over noise)".to_string(),
            calibrated,
        ),
        (
            "harbour: receiver video, manual STC, 4 bits".to_string(),
            video,
        ),
    ];
    let sea = LoadedSpec::read(sea_scene)?;
    let (spec, dir) = (sea.spec(), sea.base_dir());
    let mut s = spec.clone();
    s.receiver = Some(receiver(
        "stc = \"auto\"\nftc_time_constant_us = 0.5\ninterference_rejection = \"medium\"\nvideo_spokes = 2048\nvideo_samples = 512\n",
    )?);
    let (calibrated, video) = calibrated_and_video(&s, dir, panel, seed, false)?;
    images.push(("sea state 4, rain: calibrated".to_string(), calibrated));
    images.push(("sea state 4, rain: video, auto STC, FTC".to_string(), video));
    // A ship 1.1 km off an open array: its echo through the near sidelobes draws arcs.
    let mut near: SceneSpec = toml::from_str(
        "[radar]\npreset = \"magnetron-25kw-open-array\"\nrange_scale_nm = 0.75\n\
         [environment]\nclutter = false\n[receiver]\nvideo_spokes = 2048\n\
         [[object]]\nname = \"ship\"\nshape = \"point\"\nrcs_m2 = 30.0\nposition_m = [700.0, 900.0, 10.0]\n",
    )
    .context("figure scene")?;
    near.display.range_ring_spacing_m = Some(250.0);
    let (_, sidelobes) = calibrated_and_video(&near, dir, panel, seed, true)?;
    images.push((
        "artefact: sidelobe echoes (labelled)".to_string(),
        sidelobes,
    ));
    let interfered = |rejection: &str| -> Result<Vec<u8>> {
        let mut t: SceneSpec = toml::from_str(&format!(
            "[radar]\npreset = \"magnetron-4kw-radome\"\nrange_scale_nm = 1.5\nspokes = 4096\n\
             [environment]\nclutter = false\n\
             [receiver]\nvideo_spokes = 2048\ninterference_rejection = \"{rejection}\"\n\
             [[artefacts.interferer]]\nname = \"radar\"\nposition_m = [1500.0, 800.0, 8.0]\nprf_hz = 1648.2\n"
        ))
        .context("figure scene")?;
        t.display.range_ring_spacing_m = Some(500.0);
        Ok(calibrated_and_video(&t, dir, panel, seed, rejection == "off")?.1)
    };
    images.push((
        "artefact: interference (labelled)".to_string(),
        interfered("off")?,
    ));
    images.push((
        "... with interference rejection".to_string(),
        interfered("high")?,
    ));
    // One panel per other artefact, each with its labels' boxes.
    let artefact = |text: &str, ring_m: f64| -> Result<Vec<u8>> {
        let mut t: SceneSpec = toml::from_str(text).context("figure scene")?;
        t.display.range_ring_spacing_m = Some(ring_m);
        Ok(calibrated_and_video(&t, dir, panel, seed, true)?.1)
    };
    let quiet = "[environment]\nclutter = false\n[receiver]\nvideo_spokes = 2048\n";
    let radome = "[radar]\npreset = \"magnetron-4kw-radome\"\nrange_scale_nm = 1.5\n";
    images.push((
        "artefact: second trace (9 km ship, 7.5 km unambiguous)".to_string(),
        artefact(
            &format!(
                "[radar]\nprf_hz = 20000.0\nmax_range_m = 3000.0\n{quiet}\
                 [artefacts]\nsecond_trace = true\n\
                 [[object]]\nname = \"far ship\"\nshape = \"point\"\nrcs_m2 = 1.0e6\nposition_m = [3000.0, 8500.0, 10.0]\n"
            ),
            1000.0,
        )?,
    ));
    images.push((
        "artefact: racon K".to_string(),
        artefact(
            &format!(
                "{radome}{quiet}[[artefacts.racon]]\nname = \"racon\"\nposition_m = [-600.0, 900.0, 6.0]\nmorse = \"K\"\nlength_nm = 0.5\n"
            ),
            500.0,
        )?,
    ));
    images.push((
        "artefact: SART (12 dots)".to_string(),
        artefact(
            &format!(
                "[radar]\npreset = \"magnetron-4kw-radome\"\nrange_scale_nm = 6.0\n{quiet}\
                 [[artefacts.sart]]\nname = \"sart\"\nposition_m = [1200.0, 800.0, 1.0]\n"
            ),
            2000.0,
        )?,
    ));
    images.push((
        "artefact: funnel's blind sector and indirect echo".to_string(),
        artefact(
            &format!(
                "{radome}{quiet}[own_ship]\nheading_deg = 0.0\ncourse_deg = 0.0\n\
                 [[own_ship.structure]]\nname = \"funnel\"\nfrom_deg = 165.0\nto_deg = 195.0\n\
                 loss_db = 20.0\nindirect_db = -8.0\ndistance_m = 15.0\n\
                 [[object]]\nname = \"ship ahead\"\nshape = \"point\"\nrcs_m2 = 3.0e4\nposition_m = [150.0, 1200.0, 10.0]\n\
                 [[object]]\nname = \"buoy astern\"\nshape = \"point\"\nrcs_m2 = 30.0\nposition_m = [-60.0, -1500.0, 2.0]\n"
            ),
            500.0,
        )?,
    ));
    images.push((
        "artefact: multiple echoes of a ship abeam".to_string(),
        artefact(
            &format!(
                "{radome}{quiet}[own_ship]\nheading_deg = 0.0\ncourse_deg = 0.0\n\
                 [artefacts.multiple_echoes]\nmax_order = 4\n\
                 [[object]]\nname = \"tanker\"\nshape = \"vessel\"\nlength_m = 150.0\nposition_m = [700.0, 0.0, 0.0]\n"
            ),
            500.0,
        )?,
    ));
    panel_grid(
        &out.join("fig6_receiver_video.png"),
        "Receiver video and artefacts (video levels 0 .. 15; artefact labels in yellow)",
        &images,
        panel,
        4,
    )
}

/// The target library's RCS against its references: each class at its middle size and
/// draws, HH, 9.41 GHz, λ/2 ray tubes up to 32 768 per aspect (as
/// `targets::class_rcs_matches_published_references`): the RCS over the azimuth of the
/// radar from the bow at 1° elevation in free space and over the sea (radar 15 m up, the
/// default sea), the median the reference is compared with (a ship's over the sea at 0.5° and
/// 1°, [`TargetClass::reference_is_over_sea`]; the others' in free space over 0.5°–3°), and
/// the class's published reference
/// ([`TargetClass::reference_rcs`]) with ±6 dB about it; the corner reflector's line is its
/// closed form on its axis. docs/targets.md gives the sources.
fn target_rcs(out: &Path) -> Result<()> {
    use xbandsim::scattering::rcs::{RcsSettings, RcsTarget};
    use xbandsim::targets::{ReferenceRcs, TargetClass};
    let settings = RcsSettings {
        freq_hz: xbandsim::targets::REFERENCE_FREQ_HZ,
        polarisation: xbandsim::model::Polarisation::Hh,
        ray_spacing_wavelengths: 0.5,
        max_rays: 32_768,
        max_bounces: 3,
        edge_diffraction: true,
    };
    const RADAR_HEIGHT_M: f64 = 15.0;
    let sea = *Scene::from_spec(&SceneSpec::default())?
        .environment()
        .sea()
        .expect("the default environment has its sea");
    let azimuths_deg: Vec<f64> = (0..90).map(|i| 4.0 * i as f64 + 2.0).collect();
    let elevations_deg = [1.0f64, 0.5, 2.0, 3.0];
    struct Panel {
        title: String,
        free_dbsm: Vec<(f64, f64)>,
        sea_dbsm: Vec<(f64, f64)>,
        median_dbsm: f64,
        over_sea: bool,
        reference_dbsm: Option<f64>,
        /// The shaded band, dBsm: ±6 dB about a median, or a band reference's own ends.
        band_dbsm: Option<(f64, f64)>,
    }
    let mut panels = Vec::new();
    for class in TargetClass::all() {
        let (lo, hi) = class.size_range_m();
        let size = 0.5 * (lo + hi);
        let mut spec = class.object_spec(size, &[0.5; 3])?;
        spec.name = Some(class.name().to_string());
        // Away from the scene's radar (the sweeps place their own).
        let z = spec.position_m.map_or(0.0, |p| p[2]);
        spec.position_m = Some([0.0, 500.0, z]);
        let scene = Scene::from_spec(&SceneSpec {
            objects: vec![spec.clone()],
            ..SceneSpec::default()
        })?;
        let target = RcsTarget::new(&scene.objects()[0]);
        let aspects: Vec<(f64, f64)> = elevations_deg
            .iter()
            .flat_map(|el| {
                azimuths_deg
                    .iter()
                    .map(move |az| (az.to_radians(), el.to_radians()))
            })
            .collect();
        let to_db = |v: Vec<f64>| -> Vec<f64> {
            v.into_iter().map(|s| linear_to_db(s.max(1e-6))).collect()
        };
        let free = to_db(target.sweep_m2(&aspects, &settings));
        let on_sea = to_db(target.over_sea_sweep_m2(&aspects, RADAR_HEIGHT_M, &sea, &settings));
        // A ship's reference holds at grazing incidence over the sea; the others' over
        // 0.5-3 deg in free space.
        let over_sea = class.reference_is_over_sea();
        let mut sorted = if over_sea {
            let grazing = xbandsim::targets::SHIP_GRAZING_MAX_ELEVATION_DEG;
            on_sea
                .chunks(azimuths_deg.len())
                .zip(elevations_deg)
                .filter(|(_, el)| *el <= grazing)
                .flat_map(|(v, _)| v.iter().copied())
                .collect()
        } else {
            free.clone()
        };
        sorted.sort_by(f64::total_cmp);
        let median_dbsm = sorted[sorted.len() / 2];
        let at_one = |v: &[f64]| -> Vec<(f64, f64)> {
            azimuths_deg
                .iter()
                .copied()
                .zip(v[..azimuths_deg.len()].iter().copied())
                .collect()
        };
        let reference = class.reference_rcs(&spec);
        let reference_dbsm = match (&reference, *class) {
            (Some(r), _) => Some(linear_to_db(r.central_m2())),
            (None, TargetClass::CornerReflector) => {
                let lambda = xbandsim::constants::wavelength_m(settings.freq_hz);
                Some(linear_to_db(
                    4.0 * std::f64::consts::PI * size.powi(4) / (3.0 * lambda * lambda),
                ))
            }
            (None, _) => None,
        };
        panels.push(Panel {
            title: format!(
                "{} ({} {size:.1} m){}",
                class.name(),
                class.size_meaning(),
                if over_sea { ", over the sea" } else { "" }
            ),
            free_dbsm: at_one(&free),
            sea_dbsm: at_one(&on_sea),
            median_dbsm,
            over_sea,
            reference_dbsm,
            band_dbsm: reference.map(|r| match r {
                ReferenceRcs::Band {
                    low_m2, high_m2, ..
                } => (linear_to_db(low_m2), linear_to_db(high_m2)),
                ReferenceRcs::Median { m2, .. } => (linear_to_db(m2) - 6.0, linear_to_db(m2) + 6.0),
            }),
        });
    }
    let (cols, pw, ph) = (4u32, 420u32, 320u32);
    let rows = (panels.len() as u32).div_ceil(cols);
    save_rgb(
        &out.join("target_rcs_by_class.png"),
        cols * pw,
        rows * ph + 40,
        |root| {
            root.fill(&WHITE).map_err(plot_err)?;
            root.draw(&Text::new(
                "RCS (dBsm) at 1 deg elevation, free space (blue) and over the sea, radar 15 m up (orange); red: the median the reference is compared with (ships: over the sea at 0.5-1 deg; others: free space at 0.5-3 deg); green: the reference, shaded +-6 dB or its band",
                (10, 10),
                (FONT, 14),
            ))
            .map_err(plot_err)?;
            let body = root.margin(40, 0, 0, 0);
            let areas = body.split_evenly((rows as usize, cols as usize));
            for (area, p) in areas.iter().zip(&panels) {
                let values = p
                    .free_dbsm
                    .iter()
                    .chain(&p.sea_dbsm)
                    .map(|q| q.1)
                    .chain([p.median_dbsm]);
                let (mut y_lo, mut y_hi) = values
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                        (a.min(v), b.max(v))
                    });
                if let Some(r) = p.reference_dbsm {
                    y_lo = y_lo.min(r - 8.0);
                    y_hi = y_hi.max(r + 8.0);
                }
                if let Some((lo, hi)) = p.band_dbsm {
                    y_lo = y_lo.min(lo - 2.0);
                    y_hi = y_hi.max(hi + 2.0);
                }
                let (y_lo, y_hi) = ((y_lo / 10.0).floor() * 10.0, (y_hi / 10.0).ceil() * 10.0);
                let mut chart = ChartBuilder::on(area)
                    .caption(&p.title, (FONT, 14))
                    .margin(8)
                    .x_label_area_size(40)
                    .y_label_area_size(40)
                    .build_cartesian_2d(0f64..360f64, y_lo..y_hi)
                    .map_err(plot_err)?;
                chart
                    .configure_mesh()
                    .x_labels(7)
                    .y_labels(6)
                    .x_desc("azimuth of the radar from the bow (deg)")
                    .label_style((FONT, 11))
                    .draw()
                    .map_err(plot_err)?;
                if let Some((lo, hi)) = p.band_dbsm {
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [(0.0, lo), (360.0, hi)],
                            GREEN.mix(0.15).filled(),
                        )))
                        .map_err(plot_err)?;
                }
                if let Some(r) = p.reference_dbsm {
                    chart
                        .draw_series(LineSeries::new(
                            vec![(0.0, r), (360.0, r)],
                            GREEN.stroke_width(2),
                        ))
                        .map_err(plot_err)?;
                }
                let orange = RGBColor(230, 120, 0);
                chart
                    .draw_series(LineSeries::new(
                        p.sea_dbsm.iter().copied(),
                        orange.stroke_width(if p.over_sea { 2 } else { 1 }),
                    ))
                    .map_err(plot_err)?;
                chart
                    .draw_series(LineSeries::new(
                        p.free_dbsm.iter().copied(),
                        BLUE.stroke_width(if p.over_sea { 1 } else { 2 }),
                    ))
                    .map_err(plot_err)?;
                chart
                    .draw_series(LineSeries::new(
                        vec![(0.0, p.median_dbsm), (360.0, p.median_dbsm)],
                        RED.stroke_width(2),
                    ))
                    .map_err(plot_err)?;
            }
            Ok(())
        },
    )
}
