//! A frame's labels in the formats detectors train with (docs/formats.md, "Dataset labels"):
//! COCO annotations with run-length-encoded instance masks, YOLO detect and YOLO oriented-box
//! lines, and one row per target for the targets table.
//!
//! The rule (docs/formats.md): every object of the scene is a row of the table, with its
//! visibility reason; an object gets a detection label (COCO annotation, YOLO line) only when
//! it is `visible` or `partially_eclipsed`, its echo box lies in the image, and its mask is
//! not empty. Its mask is the set of image pixels whose cell lies in its polar box and where
//! the target-only render (the same frame without noise and clutter,
//! [`xbandsim::Simulation::targets_only`]) is at least the threshold, 0 dB over the mean
//! noise by default: the pixels where its own echo is as strong as the receiver's noise. A
//! pixel whose cell lies in several objects' polar boxes belongs to the one whose box centre
//! is nearest (in box half-widths).

use crate::baseline::ObjectBaseline;
use serde::Serialize;
use serde_json::{json, Value};
use xbandsim::products::artefacts::{ArtefactKind, ArtefactTruth};
use xbandsim::products::labels::{ObjectTruth, PolarBox, Visibility};
use xbandsim::products::ppi::ScanConverter;

/// An object's instance mask on the image: row-major pixel flags.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mask {
    /// Image width, px.
    pub width: usize,
    /// Image height, px.
    pub height: usize,
    /// `width·height` flags, row-major.
    pub pixels: Vec<bool>,
}

impl Mask {
    /// The set pixels' inclusive box `[x_min, y_min, x_max, y_max]`; None when empty. Each
    /// row is tested whole (an OR over its flags, which the compiler vectorises), and only
    /// the rows with a set pixel are searched: a mask is a small patch of a large image.
    fn pixel_box(&self) -> Option<[usize; 4]> {
        debug_assert_eq!(self.pixels.len(), self.width * self.height);
        let mut b: Option<[usize; 4]> = None;
        for (y, row) in self.pixels.chunks_exact(self.width.max(1)).enumerate() {
            if !row.iter().fold(false, |any, &p| any | p) {
                continue;
            }
            let Some(first) = row.iter().position(|&p| p) else {
                continue;
            };
            let last = row.iter().rposition(|&p| p).unwrap_or(first);
            b = Some(match b {
                None => [first, y, last, y],
                Some([x0, y0, x1, _]) => [x0.min(first), y0, x1.max(last), y],
            });
        }
        b
    }

    /// The tight pixel box of the set pixels, `[x_min, y_min, x_max, y_max]` in pixel edges
    /// (a single pixel (x, y) gives `[x, y, x + 1, y + 1]`); None when empty.
    pub fn bounds(&self) -> Option<[f64; 4]> {
        self.pixel_box()
            .map(|[x0, y0, x1, y1]| [x0 as f64, y0 as f64, (x1 + 1) as f64, (y1 + 1) as f64])
    }

    /// The echo's oriented box: the smallest-area rectangle around the set pixels
    /// ([`crate::obb`]), its corners in order around it, in pixel edges clipped to the
    /// image (a corner past an edge is moved onto it); None when empty.
    pub fn oriented_box(&self) -> Option<[[f64; 2]; 4]> {
        let [x0, y0, x1, y1] = self.pixel_box()?;
        let rows = (y0..=y1).filter_map(|y| {
            let row = &self.pixels[y * self.width..][x0..=x1];
            let first = row.iter().position(|&p| p)?;
            let last = row.iter().rposition(|&p| p)?;
            Some((y, x0 + first, x0 + last))
        });
        let hull = crate::obb::convex_hull(crate::obb::row_extreme_corners(rows));
        let (w, h) = (self.width as f64, self.height as f64);
        Some(crate::obb::min_area_rectangle(&hull).map(|[x, y]| [x.clamp(0.0, w), y.clamp(0.0, h)]))
    }

    /// Pixels set (counted in their box's rows).
    pub fn area(&self) -> usize {
        self.pixel_box().map_or(0, |[x0, y0, x1, y1]| {
            (y0..=y1)
                .map(|y| {
                    let row = &self.pixels[y * self.width..][x0..=x1];
                    row.iter().map(|&p| usize::from(p)).sum::<usize>()
                })
                .sum()
        })
    }

    /// COCO's run lengths: column-major (down each column, left to right), starting with a
    /// run of zeros (possibly empty), alternating. Only the set pixels' box is read; the
    /// zeros around it are counted, not visited.
    pub fn rle_counts(&self) -> Vec<u64> {
        let (w, h) = (self.width, self.height);
        let Some([x0, y0, x1, y1]) = self.pixel_box() else {
            return vec![(w * h) as u64];
        };
        let mut runs = Runs::default();
        // Zeros down the columns left of the box and above it in its first column.
        runs.extend(false, (x0 * h + y0) as u64);
        for x in x0..=x1 {
            if x > x0 {
                // Below the box in the previous column, above it in this one.
                runs.extend(false, (h - 1 - y1 + y0) as u64);
            }
            for y in y0..=y1 {
                runs.extend(self.pixels[y * w + x], 1);
            }
        }
        // Below the box in its last column and the columns right of it.
        runs.extend(false, ((h - 1 - y1) + (w - 1 - x1) * h) as u64);
        runs.finish()
    }
}

/// Run lengths of a sequence of flags fed in stretches, starting with a run of zeros.
#[derive(Default)]
struct Runs {
    counts: Vec<u64>,
    current: bool,
    run: u64,
}

impl Runs {
    /// `n` more flags `value` (none when `n` is 0).
    #[inline]
    fn extend(&mut self, value: bool, n: u64) {
        if n == 0 {
            return;
        }
        if value != self.current {
            self.counts.push(self.run);
            self.run = 0;
            self.current = value;
        }
        self.run += n;
    }

    fn finish(mut self) -> Vec<u64> {
        self.counts.push(self.run);
        self.counts
    }
}

/// COCO's compressed RLE string of run lengths (the LEB128-like text form pycocotools reads:
/// from the third count on, each is stored as its difference from the count two before; six
/// bits per character, five of value and a continuation bit, offset by 48).
pub fn rle_string(counts: &[u64]) -> String {
    let mut s = String::new();
    for i in 0..counts.len() {
        let mut x = counts[i] as i64;
        if i > 2 {
            x -= counts[i - 2] as i64;
        }
        loop {
            let mut c = x & 0x1f;
            x >>= 5;
            let more = if c & 0x10 != 0 { x != -1 } else { x != 0 };
            if more {
                c |= 0x20;
            }
            s.push((c as u8 + 48) as char);
            if !more {
                break;
            }
        }
    }
    s
}

/// The run lengths of a COCO compressed RLE string ([`rle_string`]'s inverse, as pycocotools
/// reads it); an error names the first character that is not part of the alphabet.
pub fn rle_from_string(s: &str) -> std::result::Result<Vec<u64>, String> {
    let bytes = s.as_bytes();
    let mut counts: Vec<u64> = Vec::new();
    let mut p = 0;
    while p < bytes.len() {
        let (mut x, mut k) = (0i64, 0u32);
        loop {
            let Some(&b) = bytes.get(p) else {
                return Err(format!("RLE string ends inside a count at character {p}"));
            };
            if !(48..48 + 64).contains(&b) || k > 12 {
                return Err(format!("character {p} ({:?}) is not RLE text", b as char));
            }
            let c = i64::from(b - 48);
            x |= (c & 0x1f) << (5 * k);
            p += 1;
            k += 1;
            if c & 0x20 == 0 {
                if c & 0x10 != 0 {
                    x |= -1i64 << (5 * k);
                }
                break;
            }
        }
        if counts.len() > 2 {
            x += counts[counts.len() - 2] as i64;
        }
        counts.push(u64::try_from(x).map_err(|_| format!("negative run {x} in RLE text"))?);
    }
    Ok(counts)
}

/// A `height × width` mask, row-major, from COCO run lengths (column-major, zeros first).
pub fn mask_from_rle(
    counts: &[u64],
    height: usize,
    width: usize,
) -> std::result::Result<Vec<u8>, String> {
    let total: u64 = counts.iter().sum();
    if total != (height * width) as u64 {
        return Err(format!(
            "RLE runs cover {total} pixels, the mask has {height} x {width}"
        ));
    }
    let mut mask = vec![0u8; height * width];
    let mut at = 0usize;
    for (i, &run) in counts.iter().enumerate() {
        if i % 2 == 1 {
            for k in at..at + run as usize {
                let (x, y) = (k / height, k % height);
                mask[y * width + x] = 1;
            }
        }
        at += run as usize;
    }
    Ok(mask)
}

/// Whether an object's visibility lets it have a detection label (it is seen above the noise).
pub fn is_seen(visibility: Visibility) -> bool {
    matches!(
        visibility,
        Visibility::Visible | Visibility::PartiallyEclipsed
    )
}

fn box_contains(b: &PolarBox, spoke: usize, bin: usize) -> bool {
    let in_spokes = if b.spoke_min <= b.spoke_max {
        (b.spoke_min..=b.spoke_max).contains(&spoke)
    } else {
        spoke >= b.spoke_min || spoke <= b.spoke_max
    };
    in_spokes && (b.bin_min..=b.bin_max).contains(&bin)
}

/// Distance of a cell from a polar box's centre in half-widths (spokes wrap).
fn box_distance(b: &PolarBox, spoke: usize, bin: usize, spokes: usize) -> f64 {
    let width = b.spoke_count(spokes);
    let centre = (b.spoke_min as f64 + (width as f64 - 1.0) / 2.0) % spokes as f64;
    let mut ds = (spoke as f64 - centre).abs();
    ds = ds.min(spokes as f64 - ds);
    let bin_centre = 0.5 * (b.bin_min + b.bin_max) as f64;
    let half_bins = 0.5 * (b.bin_max - b.bin_min + 1) as f64;
    ds / (0.5 * width as f64) + (bin as f64 - bin_centre).abs() / half_bins
}

/// The spokes [`object_masks`] reads: those of the objects' polar boxes (a mask pixel lies in
/// a box, and scan conversion interpolates along the pixel's own spoke). The target-only
/// render needs no other ([`xbandsim::Simulation::only_spokes`]).
pub fn mask_spokes(objects: &[ObjectTruth], spokes: usize) -> Vec<bool> {
    let mut wanted = vec![false; spokes];
    for b in objects.iter().filter_map(|o| o.polar_box.as_ref()) {
        for k in b.spoke_indices(spokes) {
            wanted[k] = true;
        }
    }
    wanted
}

/// Every object's mask on the image of `conv` (None for objects without a polar box) from
/// the frame's target-only record `targets_only_db` (spokes × bins, dB over the mean noise)
/// at `threshold_db` over the noise of the cell's channel: in combined pulse mode
/// `short = Some((join_bin, short_pulse_noise_db))`, and the bins before the join, whose
/// noise is the short pulse's, are held to `threshold_db + short_pulse_noise_db`.
pub fn object_masks(
    objects: &[ObjectTruth],
    targets_only_db: &[f32],
    spokes: usize,
    bins: usize,
    conv: &ScanConverter,
    threshold_db: f32,
    short: Option<(usize, f32)>,
) -> Vec<Option<Mask>> {
    let size = conv.size_px() as usize;
    let mut ppi = vec![0f32; size * size];
    conv.convert(targets_only_db, f32::NAN, &mut ppi);
    let mut masks: Vec<Option<Mask>> = objects
        .iter()
        .map(|o| {
            o.polar_box.map(|_| Mask {
                width: size,
                height: size,
                pixels: vec![false; size * size],
            })
        })
        .collect();
    for (pixel, value) in ppi.iter().enumerate() {
        if value.is_nan() || *value < threshold_db {
            continue;
        }
        let Some(cell) = conv.nearest_cell(pixel) else {
            continue;
        };
        let (spoke, bin) = (cell / bins, cell % bins);
        if let Some((join, noise_db)) = short {
            if bin < join && *value < threshold_db + noise_db {
                continue;
            }
        }
        if spoke >= spokes {
            continue;
        }
        let owner = objects
            .iter()
            .enumerate()
            .filter_map(|(i, o)| {
                let b = o.polar_box.as_ref()?;
                box_contains(b, spoke, bin).then(|| (i, box_distance(b, spoke, bin, spokes)))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i);
        if let Some(mask) = owner.and_then(|i| masks[i].as_mut()) {
            mask.pixels[pixel] = true;
        }
    }
    masks
}

/// The flags of the targets table, one per physical reason an object is or is not seen.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct VisibilityFlags {
    /// Wholly inside the blanked range, or its SNR taken below 0 dB by the eclipse.
    pub eclipsed: bool,
    /// Seen with only part of its pulse received.
    pub partially_eclipsed: bool,
    /// No echo: land hides it.
    pub shadowed_by_land: bool,
    /// No echo: the line of sight is blocked by another object.
    pub shadowed: bool,
    /// Its expected SNR is below 0 dB.
    pub below_noise: bool,
    /// Wholly below the radar horizon.
    pub beyond_horizon: bool,
    /// Farther than the radar's maximum range.
    pub beyond_max_range: bool,
    /// No echo although the line of sight is clear (nothing scatters back).
    pub no_return: bool,
    /// `paper` model only: its ray grid passes around it.
    pub missed_by_ray_grid: bool,
}

impl VisibilityFlags {
    fn of(v: Visibility) -> VisibilityFlags {
        VisibilityFlags {
            eclipsed: v == Visibility::Eclipsed,
            partially_eclipsed: v == Visibility::PartiallyEclipsed,
            shadowed_by_land: v == Visibility::ShadowedByLand,
            shadowed: v == Visibility::Shadowed,
            below_noise: v == Visibility::BelowNoise,
            beyond_horizon: v == Visibility::BeyondHorizon,
            beyond_max_range: v == Visibility::BeyondMaxRange,
            no_return: v == Visibility::NoReturn,
            missed_by_ray_grid: v == Visibility::MissedByRayGrid,
        }
    }
}

/// What the labels of one frame are drawn against.
pub struct FrameContext<'a> {
    /// Sample index.
    pub sample: u64,
    /// Frame within the sample.
    pub frame: u64,
    /// Start of the frame's revolution, s.
    pub frame_start_time_s: f64,
    /// The image the labels refer to, relative to the dataset folder.
    pub image: &'a str,
    /// Image side, px.
    pub size_px: usize,
    /// Half the image's side on the sea (the display range), m.
    pub range_scale_m: f64,
    /// The radar's azimuth 3-dB beamwidth, rad.
    pub azimuth_beamwidth_rad: f64,
    /// The compressed pulse's range resolution `c/(2B)`, m.
    pub range_resolution_m: f64,
    /// Category names; an object's category is its class's position here (YOLO class
    /// index; COCO id = index + 1).
    pub categories: &'a [String],
    /// The classical baseline's result for each object, in `objects`' order
    /// ([`crate::baseline`]); `None` leaves the `baseline_` fields null.
    pub baseline: Option<&'a [ObjectBaseline]>,
}

/// One frame's labels, encoded.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameLabels {
    /// COCO image and annotations (annotation ids and the image id are given when the
    /// dataset is assembled): `{"image": {...}, "annotations": [...]}`.
    pub coco: Value,
    /// YOLO detect lines: `class x_centre y_centre width height`, normalised.
    pub yolo: String,
    /// YOLO oriented-box lines: `class x1 y1 x2 y2 x3 y3 x4 y4`, normalised.
    pub yolo_obb: String,
    /// Targets-table rows, one JSON object per line.
    pub targets_jsonl: String,
    /// Detection labels given.
    pub labelled: usize,
}

fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// A frame's artefacts and what their masks are drawn from.
#[derive(Clone, Copy)]
pub struct ArtefactInput<'a> {
    /// The artefacts, labelled for the image (`ppi_boxes_px`).
    pub artefacts: &'a [ArtefactTruth],
    /// The image's scan converter.
    pub converter: &'a ScanConverter,
    /// Range bins per spoke of the record.
    pub bins: usize,
}

impl ArtefactInput<'_> {
    /// Sets in `mask` the pixels of `boxes` — within each PPI box, those whose nearest polar
    /// cell lies in its polar box — and returns the row spans it may have set
    /// `(row, first, end)`, for clearing.
    fn fill(&self, boxes: &[(&PolarBox, [f64; 4])], mask: &mut Mask) -> Vec<(usize, usize, usize)> {
        let size = mask.width;
        let mut touched = Vec::new();
        for (polar_box, [x0, y0, x1, y1]) in boxes {
            let clamp = |v: f64| (v.max(0.0) as usize).min(size);
            let (xa, xb) = (clamp(x0.floor()), clamp(x1.ceil()));
            for y in clamp(y0.floor())..clamp(y1.ceil()) {
                for x in xa..xb {
                    let pixel = y * size + x;
                    if let Some(cell) = self.converter.nearest_cell(pixel) {
                        if box_contains(polar_box, cell / self.bins, cell % self.bins) {
                            mask.pixels[pixel] = true;
                        }
                    }
                }
                touched.push((y, xa, xb));
            }
        }
        touched
    }
}

/// A frame's land and what its mask is drawn from.
#[derive(Clone, Copy)]
pub struct LandInput<'a> {
    /// Each polar cell's land polygon, −1 for none (`land_polygon.npy`).
    pub polygon: &'a [i32],
    /// The image's scan converter.
    pub converter: &'a ScanConverter,
    /// Range bins per spoke of `polygon`.
    pub bins: usize,
}

/// Labels of a frame's objects (labelled for its image) with their masks, of the land
/// (with a `land` category: one segmentation of every pixel whose nearest polar cell shows
/// land, `iscrowd` 1 — a region, not an instance — no YOLO line, `track_id` null, the
/// polygons it shows under `"land"`), and of the
/// artefacts whose kind has a category in `ctx.categories`
/// ([`crate::spec::ARTEFACT_CATEGORIES`]): one label for each artefact — for each pulse of
/// another radar — its mask the pixels of its polar boxes, with `track_id` null and its
/// kind, source and expected level under `"artefact"` in COCO.
pub fn frame_labels(
    ctx: &FrameContext,
    objects: &[ObjectTruth],
    masks: &[Option<Mask>],
    artefacts: Option<ArtefactInput>,
    land: Option<LandInput>,
) -> FrameLabels {
    let mut out = LabelLines {
        annotations: Vec::new(),
        yolo: String::new(),
        yolo_obb: String::new(),
        side_px: ctx.size_px as f64,
    };
    let mut rows = String::new();
    let mut labelled = 0;
    for (k, (o, mask)) in objects.iter().zip(masks).enumerate() {
        let baseline = ctx.baseline.and_then(|b| b.get(k));
        let category = ctx.categories.iter().position(|c| *c == o.class);
        let area = mask.as_ref().map_or(0, Mask::area);
        // The label's box is its mask's tight box (COCO's convention); the echo box of
        // truth.json (`ppi_box_px`, where the echo can lie) must be in the image.
        let detection = match (category, o.ppi_box_px, mask.as_ref().and_then(Mask::bounds)) {
            (Some(c), Some(_), Some(b)) if is_seen(o.visibility) => Some((c, b)),
            _ => None,
        };
        let mut obb = None;
        if let (Some((c, b)), Some(mask)) = (detection, mask) {
            labelled += 1;
            obb = push_label(&mut out, c, json!(o.track_id), b, mask, area, None)
                .map(|corners| corners.map(|p| p.map(round6)));
        }
        let row = json!({
            "sample": ctx.sample,
            "frame": ctx.frame,
            "image": ctx.image,
            "time_s": ctx.frame_start_time_s + o.beam_time_s,
            "track_id": o.track_id,
            "name": o.name,
            "class": o.class,
            "category_id": category.map(|c| c + 1),
            "range_m": o.range_m,
            "azimuth_deg": o.azimuth_deg,
            "size_m": o.size_m,
            "heading_deg": o.heading_deg,
            "course_deg": o.course_deg,
            "speed_kn": o.speed_kn,
            "radial_velocity_mps": o.radial_velocity_mps,
            "aspect_deg": [o.aspect_azimuth_deg, o.aspect_elevation_deg],
            "rcs_dbsm": o.rcs_dbsm,
            "rcs_over_sea_dbsm": o.rcs_dbsm.zip(o.multipath_gain_db).map(|(r, g)| r + g),
            "expected_snr_db": o.expected_snr_db,
            "visibility": o.visibility,
            "flags": VisibilityFlags::of(o.visibility),
            "labelled": detection.is_some(),
            "baseline_detected": baseline.and_then(|b| b.detected),
            "baseline_track_id": baseline.and_then(|b| b.track_id),
            "mask_area_px": detection.map(|_| area),
            "polar_box": o.polar_box,
            "ppi_box_px": o.ppi_box_px,
            "ppi_obb_px": obb,
            "ppi_footprint_px": o.ppi_footprint_px,
            "range_scale_m": ctx.range_scale_m,
            "resolution_cell_m": [
                round6(o.range_m * ctx.azimuth_beamwidth_rad),
                round6(ctx.range_resolution_m),
            ],
        });
        rows.push_str(&row.to_string());
        rows.push('\n');
    }
    if let Some(artefacts) = artefacts {
        let mut mask = Mask {
            width: ctx.size_px,
            height: ctx.size_px,
            pixels: vec![false; ctx.size_px * ctx.size_px],
        };
        for a in artefacts.artefacts {
            let Some(c) = crate::spec::ARTEFACT_CATEGORIES
                .iter()
                .find(|(kind, _)| *kind == a.kind)
                .and_then(|(_, name)| ctx.categories.iter().position(|c| c == name))
            else {
                continue;
            };
            // Another radar's pulses are one label each; every other artefact is one label.
            let boxes: Vec<(&PolarBox, [f64; 4])> = a
                .polar_boxes
                .iter()
                .zip(&a.ppi_boxes_px)
                .filter_map(|(p, px)| px.map(|px| (p, px)))
                .collect();
            let groups: Vec<&[(&PolarBox, [f64; 4])]> = if a.kind == ArtefactKind::Interference {
                boxes.chunks(1).collect()
            } else {
                vec![&boxes[..]]
            };
            for group in groups {
                let touched = artefacts.fill(group, &mut mask);
                if let Some(b) = mask.bounds() {
                    let artefact = json!({
                        "kind": a.kind,
                        "source": a.source,
                        "expected_level_db": a.expected_level_db,
                    });
                    let area = mask.area();
                    push_label(
                        &mut out,
                        c,
                        Value::Null,
                        b,
                        &mask,
                        area,
                        Some(("artefact", artefact)),
                    );
                }
                for (y, x0, x1) in touched {
                    mask.pixels[y * ctx.size_px + x0..y * ctx.size_px + x1].fill(false);
                }
            }
        }
    }
    if let (Some(land), Some(c)) = (
        land,
        ctx.categories
            .iter()
            .position(|c| c == crate::spec::LAND_CATEGORY),
    ) {
        let size = ctx.size_px;
        let mut mask = Mask {
            width: size,
            height: size,
            pixels: vec![false; size * size],
        };
        let mut shown: Vec<i32> = Vec::new();
        for (pixel, p) in mask.pixels.iter_mut().enumerate() {
            if let Some(&id) = land
                .converter
                .nearest_cell(pixel)
                .and_then(|cell| land.polygon.get(cell))
            {
                if id >= 0 {
                    *p = true;
                    if !shown.contains(&id) {
                        shown.push(id);
                    }
                }
            }
        }
        shown.sort_unstable();
        if let Some([x0, y0, x1, y1]) = mask.bounds() {
            out.annotations.push(json!({
                "category_id": c + 1,
                "track_id": Value::Null,
                "bbox": [round6(x0), round6(y0), round6(x1 - x0), round6(y1 - y0)],
                "area": mask.area(),
                "segmentation": {
                    "size": [mask.height, mask.width],
                    "counts": rle_string(&mask.rle_counts()),
                },
                "iscrowd": 1,
                "land": { "polygons": shown },
            }));
        }
    }
    FrameLabels {
        coco: json!({
            "image": {
                "file_name": ctx.image,
                "width": ctx.size_px,
                "height": ctx.size_px,
                "sample": ctx.sample,
                "frame": ctx.frame,
            },
            "annotations": out.annotations,
        }),
        yolo: out.yolo,
        yolo_obb: out.yolo_obb,
        targets_jsonl: rows,
        labelled,
    }
}

/// A frame's detection labels as they are written: COCO annotations, YOLO detect lines and
/// YOLO oriented-box lines, coordinates normalised by the image side `side_px`.
struct LabelLines {
    annotations: Vec<Value>,
    yolo: String,
    yolo_obb: String,
    side_px: f64,
}

/// Adds one detection label of category index `c` for `mask` (its tight box `b`, `area`
/// pixels): its COCO annotation (with `track_id` and the `extra` field), its YOLO detect line
/// and its oriented-box line (every labelled echo has one: the mask's smallest rectangle,
/// whose corners it returns, px).
fn push_label(
    out: &mut LabelLines,
    c: usize,
    track_id: Value,
    b: [f64; 4],
    mask: &Mask,
    area: usize,
    extra: Option<(&str, Value)>,
) -> Option<[[f64; 2]; 4]> {
    let s = out.side_px;
    let [x0, y0, x1, y1] = b;
    let mut annotation = json!({
        "category_id": c + 1,
        "track_id": track_id,
        "bbox": [round6(x0), round6(y0), round6(x1 - x0), round6(y1 - y0)],
        "area": area,
        "segmentation": {
            "size": [mask.height, mask.width],
            "counts": rle_string(&mask.rle_counts()),
        },
        "iscrowd": 0,
    });
    if let Some((key, value)) = extra {
        annotation[key] = value;
    }
    out.annotations.push(annotation);
    out.yolo.push_str(&format!(
        "{c} {:.6} {:.6} {:.6} {:.6}\n",
        0.5 * (x0 + x1) / s,
        0.5 * (y0 + y1) / s,
        (x1 - x0) / s,
        (y1 - y0) / s
    ));
    let corners = mask.oriented_box()?;
    let mut line = c.to_string();
    for [x, y] in corners {
        line.push_str(&format!(" {:.6} {:.6}", x / s, y / s));
    }
    out.yolo_obb.push_str(&line);
    out.yolo_obb.push('\n');
    Some(corners)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Naive decoder of the compressed string (pycocotools' rleFrString, rewritten).
    fn decode(s: &str) -> Vec<u64> {
        let bytes = s.as_bytes();
        let mut counts: Vec<i64> = Vec::new();
        let mut p = 0;
        while p < bytes.len() {
            let mut x: i64 = 0;
            let mut k = 0;
            loop {
                let c = (bytes[p] - 48) as i64;
                x |= (c & 0x1f) << (5 * k);
                let more = c & 0x20 != 0;
                p += 1;
                k += 1;
                if !more {
                    if c & 0x10 != 0 {
                        x |= -1i64 << (5 * k);
                    }
                    break;
                }
            }
            let m = counts.len();
            if m > 2 {
                x += counts[m - 2];
            }
            counts.push(x);
        }
        counts.into_iter().map(|c| c as u64).collect()
    }

    #[test]
    fn rle_string_round_trips_and_matches_coco_examples() {
        // Two runs: "0" codes 0 and "1" codes 1 (48 + value).
        assert_eq!(rle_string(&[0, 1]), "01");
        for counts in [
            vec![5u64, 3, 100, 2, 7, 1000, 1, 0, 4096, 33],
            vec![0, 262144],
            vec![131072, 5, 131067],
        ] {
            assert_eq!(decode(&rle_string(&counts)), counts);
        }
    }

    #[test]
    fn rle_text_and_masks_round_trip() {
        let (h, w) = (7, 5);
        for seed in 0..40u64 {
            // A pseudo-random mask with long and short runs.
            let pixels: Vec<bool> = (0..h * w)
                .map(|i| ((i as u64 * 2654435761 + seed * 97) >> 5).is_multiple_of(2 + seed % 5))
                .collect();
            let m = Mask {
                width: w,
                height: h,
                pixels: pixels.clone(),
            };
            let counts = m.rle_counts();
            let text = rle_string(&counts);
            assert_eq!(rle_from_string(&text).unwrap(), counts, "{text}");
            let back = mask_from_rle(&counts, h, w).unwrap();
            assert_eq!(
                back,
                pixels.iter().map(|&p| u8::from(p)).collect::<Vec<_>>()
            );
        }
        // Large runs take several characters, and differences go negative.
        let counts = vec![0, 100_000, 3, 70_000, 1];
        assert_eq!(rle_from_string(&rle_string(&counts)).unwrap(), counts);
        assert!(rle_from_string("a b").is_err());
        assert!(mask_from_rle(&[3, 4], 3, 3).is_err());
    }

    /// The box-limited run lengths, bounds and area against a walk of every pixel, on empty, full,
    /// single-pixel, patch and scattered masks, at the image's edges too.
    #[test]
    fn rle_counts_and_bounds_match_a_walk_of_every_pixel() {
        fn walked_counts(m: &Mask) -> Vec<u64> {
            let (mut counts, mut current, mut run) = (Vec::new(), false, 0u64);
            for x in 0..m.width {
                for y in 0..m.height {
                    let p = m.pixels[y * m.width + x];
                    if p != current {
                        counts.push(run);
                        run = 0;
                        current = p;
                    }
                    run += 1;
                }
            }
            counts.push(run);
            counts
        }
        fn walked_bounds(m: &Mask) -> Option<[f64; 4]> {
            let set: Vec<(usize, usize)> = (0..m.pixels.len())
                .filter(|&i| m.pixels[i])
                .map(|i| (i % m.width, i / m.width))
                .collect();
            let x0 = set.iter().map(|p| p.0).min()?;
            let y0 = set.iter().map(|p| p.1).min()?;
            let x1 = set.iter().map(|p| p.0).max()?;
            let y1 = set.iter().map(|p| p.1).max()?;
            Some([x0 as f64, y0 as f64, (x1 + 1) as f64, (y1 + 1) as f64])
        }
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |n: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n as u64) as usize
        };
        // Images without pixels (0 × N, N × 0, 0 × 0): a single run of no zeros.
        for (w, h) in [(0, 5), (5, 0), (0, 0)] {
            let m = Mask {
                width: w,
                height: h,
                pixels: Vec::new(),
            };
            assert_eq!(m.rle_counts(), walked_counts(&m), "{w}x{h}");
            assert_eq!((m.bounds(), m.area()), (None, 0), "{w}x{h}");
        }
        for case in 0..300 {
            let (w, h) = (1 + next(12), 1 + next(12));
            let mut m = Mask {
                width: w,
                height: h,
                pixels: vec![false; w * h],
            };
            match case % 5 {
                0 => {}
                1 => m.pixels.fill(true),
                2 => m.pixels[next(w * h)] = true,
                3 => {
                    // A patch with holes.
                    let (x0, y0) = (next(w), next(h));
                    let (x1, y1) = (x0 + next(w - x0), y0 + next(h - y0));
                    for y in y0..=y1 {
                        for x in x0..=x1 {
                            m.pixels[y * w + x] = next(4) > 0;
                        }
                    }
                }
                _ => m.pixels.iter_mut().for_each(|p| *p = next(3) == 0),
            }
            assert_eq!(m.rle_counts(), walked_counts(&m), "case {case}: {w}x{h}");
            assert_eq!(m.bounds(), walked_bounds(&m), "case {case}: {w}x{h}");
            let walked_area = m.pixels.iter().filter(|&&p| p).count();
            assert_eq!(m.area(), walked_area, "case {case}: {w}x{h}");
        }
    }

    #[test]
    fn rle_counts_are_column_major_starting_with_zeros() {
        // 3 x 2 image (width 3, height 2): pixels (x=1, y=0) and (x=1, y=1) and (x=2, y=1).
        let mut m = Mask {
            width: 3,
            height: 2,
            pixels: vec![false; 6],
        };
        m.pixels[1] = true; // y0 x1
        m.pixels[4] = true; // y1 x1
        m.pixels[5] = true; // y1 x2
                            // Column order: (0,0) (0,1) (1,0) (1,1) (2,0) (2,1) = 0 0 1 1 0 1.
        assert_eq!(m.rle_counts(), vec![2, 2, 1, 1]);
        assert_eq!(m.area(), 3);
        m.pixels = vec![true; 6];
        assert_eq!(m.rle_counts(), vec![0, 6]);
    }

    /// A polar box's spokes, in the order and across north, agree with `box_contains`.
    /// An artefact's mask is exactly the pixels whose nearest cell lies in one of its polar
    /// boxes (a walk of every pixel of the image), boxes across north included, and the
    /// spans `fill` returns clear it whole.
    #[test]
    fn artefact_masks_are_the_pixels_of_their_polar_boxes() {
        let (size, spokes, bins, bin_m) = (64usize, 90usize, 100usize, 10.0);
        let conv = ScanConverter::new(size as u32, 1000.0, spokes, bins, bin_m);
        let geometry = conv.geometry();
        let boxes = [
            PolarBox {
                spoke_min: 10,
                spoke_max: 14,
                bin_min: 20,
                bin_max: 40,
            },
            PolarBox {
                spoke_min: 88,
                spoke_max: 1,
                bin_min: 60,
                bin_max: 70,
            },
        ];
        let region = |b: &PolarBox| {
            let n = b.spoke_count(spokes) as f64;
            let spoke_rad = std::f64::consts::TAU / spokes as f64;
            xbandsim::products::labels::EchoRegion {
                range_min_m: b.bin_min as f64 * bin_m,
                range_max_m: b.bin_max as f64 * bin_m,
                height_above_radar_m: 0.0,
                azimuth_rad: (b.spoke_min as f64 + (n - 1.0) / 2.0) * spoke_rad,
                half_width_rad: n * spoke_rad / 2.0,
            }
        };
        let with_px: Vec<(&PolarBox, [f64; 4])> = boxes
            .iter()
            .map(|b| (b, geometry.pixel_box(&region(b)).unwrap()))
            .collect();
        let input = ArtefactInput {
            artefacts: &[],
            converter: &conv,
            bins,
        };
        let mut mask = Mask {
            width: size,
            height: size,
            pixels: vec![false; size * size],
        };
        let touched = input.fill(&with_px, &mut mask);
        let walked: Vec<bool> = (0..size * size)
            .map(|p| {
                conv.nearest_cell(p)
                    .is_some_and(|c| boxes.iter().any(|b| box_contains(b, c / bins, c % bins)))
            })
            .collect();
        assert!(walked.iter().any(|&p| p));
        assert_eq!(mask.pixels, walked);
        for (y, x0, x1) in touched {
            mask.pixels[y * size + x0..y * size + x1].fill(false);
        }
        assert!(mask.pixels.iter().all(|&p| !p));
    }

    #[test]
    fn polar_box_spokes_agree_with_containment() {
        for (lo, hi) in [(3, 7), (358, 1), (0, 0), (359, 359), (5, 4)] {
            let b = PolarBox {
                spoke_min: lo,
                spoke_max: hi,
                bin_min: 0,
                bin_max: 0,
            };
            let listed: Vec<usize> = b.spoke_indices(360).collect();
            let contained: Vec<usize> = (0..360).filter(|&k| box_contains(&b, k, 0)).collect();
            let mut sorted = listed.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, contained, "box {lo}..{hi}");
            assert_eq!(listed.len(), b.spoke_count(360));
            assert_eq!(listed.first(), Some(&lo));
            assert_eq!(listed.last(), Some(&hi));
        }
    }
}
