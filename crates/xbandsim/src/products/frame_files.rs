//! The files of one rendered frame, written as a set: `polar.npy`, `ppi.png`, `ppi_gray.png`
//! and `truth.json`, and `doppler_cube.npy`, `radial_velocity.npy`, `iq.npy`,
//! `iq_pulses.npy`, `video.npy`, `land_mask.npy`, `land_polygon.npy`, `structure_mask.npy` and
//! `land_ppi.png` when the frame has
//! them (docs/formats.md). The truth file holds no timings,
//! so the same scene and seed give byte-identical files.

use super::artefacts::ArtefactTruth;
use super::labels::ObjectTruth;
use super::output::{
    json_bytes, npy_c64_bytes, npy_f32_bytes, npy_f64_bytes, npy_i32_bytes, npy_u8_bytes,
    png_bytes, write_set,
};
use super::ppi::{colour_image_marked, gray_image, PpiGeometry, PpiSettings, ScanConverter};
use super::Video;
use super::{Frame, FrameStats};
use crate::error::{Error, Problem, Result};
use crate::model::motion::KNOT_M_PER_S;
use crate::model::revolution::ShipState;
use crate::model::Radar;
use serde::Serialize;
use std::path::Path;

#[derive(Serialize)]
struct TruthFile<'a> {
    scene: String,
    seed: u64,
    frame: u64,
    frame_start_time_s: f64,
    own_ship: Option<OwnShipTruth>,
    doppler_cube: Option<CubeAxes>,
    iq: Option<IqAxes>,
    combined_pulse: Option<CombinedPulseTruth>,
    video: Option<VideoAxes>,
    spokes: usize,
    range_bins: usize,
    range_bin_m: f64,
    image_size_px: u32,
    display_range_m: f64,
    ppi_up_azimuth_deg: f64,
    ppi_radar_px: [f64; 2],
    radar_position_m: [f64; 3],
    objects: &'a [ObjectTruth],
    artefacts: &'a [ArtefactTruth],
    /// The land in view (left out of scenes without land, whose truth is as before).
    #[serde(skip_serializing_if = "Option::is_none")]
    land: Option<LandAxes<'a>>,
    /// Deterministic counts only: timings go to the terminal, so that the same seed gives
    /// a byte-identical truth.json.
    trace: TraceCounts,
}

#[derive(Serialize)]
struct TraceCounts {
    rays_cast: u64,
    contributions: usize,
    echo_groups: usize,
}

/// The land's files and polygons.
#[derive(Serialize)]
struct LandAxes<'a> {
    /// Shape of land_mask.npy, land_polygon.npy and structure_mask.npy.
    shape: [usize; 2],
    polygons: &'a [super::land::LandPolygonTruth],
    /// The structures (left out of scenes without them).
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    structures: &'a [super::land::StructureTruth],
}

/// The axes of doppler_cube.npy.
#[derive(Serialize)]
struct CubeAxes {
    shape: [usize; 3],
    doppler_bin_hz: f64,
    zero_doppler_bin: usize,
}

/// The axes of iq.npy and iq_pulses.npy.
#[derive(Serialize)]
struct IqAxes {
    shape: [usize; 2],
    sample_rate_hz: f64,
    pulse_columns: [&'static str; 3],
}

/// The axes and levels of video.npy.
#[derive(Serialize)]
struct VideoAxes {
    shape: [usize; 2],
    bits: u32,
    max_level: u8,
    sample_m: f64,
    threshold_db: f32,
    level_step_db: f32,
}

/// Combined pulse mode: where the short pulse's bins end and their noise level.
#[derive(Serialize)]
struct CombinedPulseTruth {
    join_bin: usize,
    join_range_m: f64,
    short_pulse_noise_db: f64,
}

/// The own ship at the start of the frame.
#[derive(Serialize)]
struct OwnShipTruth {
    antenna_position_m: [f64; 3],
    velocity_mps: [f64; 3],
    speed_kn: f64,
    course_deg: Option<f64>,
    heading_deg: f64,
    roll_deg: f64,
    pitch_deg: f64,
}

impl OwnShipTruth {
    fn of(s: &ShipState) -> OwnShipTruth {
        let v = s.velocity_mps;
        OwnShipTruth {
            antenna_position_m: s.antenna_position_m.to_array(),
            velocity_mps: v.to_array(),
            speed_kn: v.x.hypot(v.y) / KNOT_M_PER_S,
            course_deg: s.course_rad().map(f64::to_degrees),
            heading_deg: s.heading_rad.to_degrees(),
            roll_deg: s.roll_rad.to_degrees(),
            pitch_deg: s.pitch_rad.to_degrees(),
        }
    }
}

impl TraceCounts {
    fn of(s: &FrameStats) -> TraceCounts {
        TraceCounts {
            rays_cast: s.rays_cast,
            contributions: s.contributions,
            echo_groups: s.echo_groups,
        }
    }
}

/// Which PPI images a frame's set holds: `ppi.png` (colour, rings, Doppler colour) and
/// `ppi_gray.png` (8-bit, no rings).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Images {
    /// `ppi.png`.
    pub colour: bool,
    /// `ppi_gray.png`.
    pub gray: bool,
}

impl Images {
    /// Both images (what `xbandsim render` writes).
    pub const BOTH: Images = Images {
        colour: true,
        gray: true,
    };
}

/// A frame's files encoded but not yet written, with what products drawn on its image need.
pub struct EncodedFrame {
    /// File names and bytes, `truth.json` among them.
    pub files: Vec<(&'static str, Vec<u8>)>,
    /// The objects' truth labelled for the image (`ppi_box_px`, `ppi_footprint_px`).
    pub objects: Vec<ObjectTruth>,
    /// The image's scan converter (pixel to polar cell).
    pub converter: ScanConverter,
    /// The frame's artefacts labelled for the image (`ppi_boxes_px`).
    pub artefacts: Vec<ArtefactTruth>,
}

/// Writes the four outputs of a frame into `out` as a set (all encoded first, then written
/// together: a failure leaves the previous set in place and no temporary files), and the
/// frame's optional products. With `[display] doppler_colour` the frame must carry its
/// radial velocities (rendered with `engine::Outputs::radial_velocity`).
pub fn write_frame_files(
    radar: &Radar,
    display: &PpiSettings,
    frame: &Frame,
    out: &Path,
    scene_name: &str,
    seed: u64,
) -> Result<()> {
    let encoded = encode_frame_files(radar, display, frame, out, scene_name, seed, Images::BOTH)?;
    write_set(out, &encoded.files)
}

/// A frame's products before encoding: the images as arrays and the truth file's bytes.
pub struct FrameProducts {
    /// The PPI in dB over the noise, `size_px²` row-major (north or head up), NaN outside the
    /// display circle.
    pub ppi_db: Vec<f32>,
    /// `ppi.png`'s pixels, RGB row-major, if asked for.
    pub colour_rgb: Option<Vec<u8>>,
    /// `ppi_gray.png`'s pixels, if asked for.
    pub gray: Option<Vec<u8>>,
    /// `video_ppi.png`'s pixels, RGB row-major: the receiver's video drawn like `ppi.png`
    /// (with a `[receiver]` table and the colour image asked for).
    pub video_rgb: Option<Vec<u8>>,
    /// `truth.json`.
    pub truth_json: Vec<u8>,
    /// The objects' truth labelled for the image (`ppi_box_px`, `ppi_footprint_px`).
    pub objects: Vec<ObjectTruth>,
    /// The image's scan converter (pixel to polar cell).
    pub converter: ScanConverter,
    /// The frame's artefacts labelled for the image (`ppi_boxes_px`).
    pub artefacts: Vec<ArtefactTruth>,
}

/// Encodes the files [`write_frame_files`] writes, with only the PPI images `images` asks
/// for; `out` names the files in errors.
pub fn encode_frame_files(
    radar: &Radar,
    display: &PpiSettings,
    frame: &Frame,
    out: &Path,
    scene_name: &str,
    seed: u64,
    images: Images,
) -> Result<EncodedFrame> {
    let p = frame_products(radar, display, frame, out, scene_name, seed, images)?;
    let size = p.converter.size_px();
    let mut files = vec![(
        "polar.npy",
        npy_f32_bytes(&[frame.spokes, frame.range_bins], &frame.polar_db),
    )];
    if let Some(rgb) = &p.colour_rgb {
        files.push((
            "ppi.png",
            png_bytes(&out.join("ppi.png"), size, size, 3, rgb)?,
        ));
    }
    if let Some(gray) = &p.gray {
        files.push((
            "ppi_gray.png",
            png_bytes(&out.join("ppi_gray.png"), size, size, 1, gray)?,
        ));
    }
    if let Some(rgb) = &p.video_rgb {
        files.push((
            "video_ppi.png",
            png_bytes(&out.join("video_ppi.png"), size, size, 3, rgb)?,
        ));
    }
    files.push(("truth.json", p.truth_json));
    if let Some(v) = &frame.video {
        files.push(("video.npy", npy_u8_bytes(&[v.spokes, v.samples], &v.levels)));
    }
    if let Some(l) = &frame.land {
        files.push((
            "land_mask.npy",
            npy_u8_bytes(&[l.spokes, l.range_bins], &l.mask()),
        ));
        files.push((
            "land_polygon.npy",
            npy_i32_bytes(&[l.spokes, l.range_bins], &l.polygon),
        ));
        if l.has_structures() {
            files.push((
                "structure_mask.npy",
                npy_i32_bytes(&[l.spokes, l.range_bins], &l.structure),
            ));
        }
        if images.colour || images.gray {
            let classes = land_ppi_classes(&p.converter, l);
            files.push((
                "land_ppi.png",
                png_bytes(&out.join("land_ppi.png"), size, size, 1, &classes)?,
            ));
        }
    }
    if let Some(c) = &frame.doppler_cube {
        files.push((
            "doppler_cube.npy",
            npy_f32_bytes(&[c.spokes, c.doppler_bins, c.range_bins], &c.values_db),
        ));
    }
    if let Some(v) = &frame.radial_velocity {
        files.push((
            "radial_velocity.npy",
            npy_f32_bytes(&[v.spokes, v.range_bins], &v.velocity_mps),
        ));
    }
    if let Some(q) = &frame.iq {
        files.push(("iq.npy", npy_c64_bytes(&[q.pulses, q.samples], &q.values)));
        let columns: Vec<f64> = (0..q.pulses)
            .flat_map(|i| {
                [
                    q.times_s[i],
                    q.azimuths_rad[i].to_degrees(),
                    q.spokes[i] as f64,
                ]
            })
            .collect();
        files.push(("iq_pulses.npy", npy_f64_bytes(&[q.pulses, 3], &columns)));
    }
    Ok(EncodedFrame {
        files,
        objects: p.objects,
        converter: p.converter,
        artefacts: p.artefacts,
    })
}

/// The PPI images (those `images` asks for) and the truth file of a frame, as
/// [`encode_frame_files`] encodes them; `out` names the truth file in errors.
pub fn frame_products(
    radar: &Radar,
    display: &PpiSettings,
    frame: &Frame,
    out: &Path,
    scene_name: &str,
    seed: u64,
    images: Images,
) -> Result<FrameProducts> {
    let conv = display.frame_scan_converter(radar, frame.own_ship.as_ref());
    let geometry = conv.geometry();
    let size = conv.size_px();
    let mut objects = frame.truth.clone();
    geometry.label(&mut objects);
    let mut artefacts = frame.artefacts.clone();
    for a in &mut artefacts {
        a.ppi_boxes_px = a.regions.iter().map(|r| geometry.pixel_box(r)).collect();
    }
    let mut ppi = vec![0f32; (size * size) as usize];
    conv.convert(&frame.polar_db, f32::NAN, &mut ppi);
    let d = display;
    let velocity = match (&frame.radial_velocity, d.doppler_colour) {
        (None, true) => {
            return Err(Error::invalid(
                Problem::Conflict,
                "display.doppler_colour",
                true,
                "this frame carries no radial velocities: render it in pulse mode with engine::Outputs { radial_velocity: true, .. }",
            ))
        }
        (v, _) => v.as_ref(),
    };
    let threshold_db = d.doppler_colour_threshold_db;
    let approaching = velocity
        .filter(|_| d.doppler_colour)
        .map(|v| move |i: usize| v.approaching(i, threshold_db));
    let colour = images.colour.then(|| {
        colour_image_marked(
            &conv,
            &ppi,
            approaching.as_ref().map(|f| f as &dyn Fn(usize) -> bool),
            d.colormap,
            d.min_db,
            d.max_db,
            d.range_ring_spacing_m,
        )
    });
    let gray = images.gray.then(|| gray_image(&ppi, d.min_db, d.max_db));
    let video_rgb = match (&frame.video, images.colour) {
        (Some(v), true) => Some(video_image(v, geometry, d)),
        _ => None,
    };
    let truth = TruthFile {
        scene: scene_name.to_string(),
        seed,
        frame: frame.frame,
        frame_start_time_s: frame.start_time_s,
        own_ship: frame.own_ship.as_ref().map(OwnShipTruth::of),
        doppler_cube: frame.doppler_cube.as_ref().map(|c| CubeAxes {
            shape: [c.spokes, c.doppler_bins, c.range_bins],
            doppler_bin_hz: c.doppler_bin_hz,
            zero_doppler_bin: c.doppler_bins / 2,
        }),
        iq: frame.iq.as_ref().map(|q| IqAxes {
            shape: [q.pulses, q.samples],
            sample_rate_hz: q.sample_rate_hz,
            pulse_columns: ["time_s", "azimuth_deg", "spoke"],
        }),
        combined_pulse: radar
            .short_pulse_noise_db()
            .map(|noise_db| CombinedPulseTruth {
                join_bin: radar.join_bin(),
                join_range_m: radar.join_range_m(),
                short_pulse_noise_db: noise_db,
            }),
        video: frame.video.as_ref().map(|v| VideoAxes {
            shape: [v.spokes, v.samples],
            bits: v.bits,
            max_level: v.max_level(),
            sample_m: v.sample_m,
            threshold_db: v.threshold_db,
            level_step_db: v.level_step_db,
        }),
        spokes: frame.spokes,
        range_bins: frame.range_bins,
        range_bin_m: frame.range_bin_m,
        image_size_px: size,
        display_range_m: conv.display_range_m(),
        ppi_up_azimuth_deg: geometry.up_azimuth_rad.to_degrees(),
        ppi_radar_px: {
            let (x, y) = geometry.radar_px();
            [x, y]
        },
        radar_position_m: frame
            .own_ship
            .map_or(radar.position_m(), |s| s.antenna_position_m)
            .to_array(),
        objects: &objects,
        artefacts: &artefacts,
        land: frame.land.as_ref().map(|l| LandAxes {
            shape: [l.spokes, l.range_bins],
            polygons: &l.polygons,
            structures: &l.structures,
        }),
        trace: TraceCounts::of(&frame.stats),
    };
    let truth_json = json_bytes(&out.join("truth.json"), &truth)?;
    Ok(FrameProducts {
        ppi_db: ppi,
        colour_rgb: colour,
        gray,
        video_rgb,
        truth_json,
        objects,
        converter: conv,
        artefacts,
    })
}

/// `land_ppi.png`'s pixels: the polar land and structure masks scan-converted like
/// `ppi.png` (nearest cell): [`LAND_PPI_SEA`] where a pixel's cell is sea (or outside the
/// display), [`LAND_PPI_LAND`] land, [`LAND_PPI_STRUCTURE`] a structure.
fn land_ppi_classes(conv: &ScanConverter, land: &super::land::LandTruth) -> Vec<u8> {
    let size = conv.size_px() as usize;
    (0..size * size)
        .map(|px| match conv.nearest_cell(px) {
            Some(i) if land.polygon.get(i).is_some_and(|&p| p >= 0) => LAND_PPI_LAND,
            Some(i) if land.structure.get(i).is_some_and(|&s| s >= 0) => LAND_PPI_STRUCTURE,
            _ => LAND_PPI_SEA,
        })
        .collect()
}

/// `land_ppi.png`'s value for sea, land seen nowhere, and pixels outside the display.
pub const LAND_PPI_SEA: u8 = 0;
/// `land_ppi.png`'s value for land whose echo the cell is.
pub const LAND_PPI_LAND: u8 = 1;
/// `land_ppi.png`'s value for a structure's footprint in view.
pub const LAND_PPI_STRUCTURE: u8 = 2;

/// The video's levels drawn like `ppi.png` (same geometry, colour map and range rings), the
/// colour scale spanning level 0 to the largest.
fn video_image(video: &Video, geometry: PpiGeometry, d: &PpiSettings) -> Vec<u8> {
    let conv = ScanConverter::for_geometry(geometry, video.spokes, video.samples, video.sample_m);
    let levels: Vec<f32> = video.levels.iter().map(|&l| f32::from(l)).collect();
    let size = conv.size_px() as usize;
    let mut ppi = vec![0f32; size * size];
    conv.convert(&levels, f32::NAN, &mut ppi);
    let top = f64::from((1u32 << video.bits) - 1);
    colour_image_marked(
        &conv,
        &ppi,
        None,
        d.colormap,
        0.0,
        top,
        d.range_ring_spacing_m,
    )
}
