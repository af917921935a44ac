//! Stage: display. Polar (spokes × range bins) to Cartesian PPI scan conversion, colour maps
//! and range rings.
//!
//! The PPI has true bearing `u` at the top (`[display] orientation`: north-up u = 0, head-up
//! u = the own ship's heading, course-up u = its course) and the radar at the centre (relative
//! motion) or displaced from it by `o` = the antenna's ground displacement since t = 0 (true
//! motion, `[display] motion = "true"`; docs/formats.md): pixel (col, row) of an image of side
//! `S` covering ±R is at screen right `x = (col + ½ − S/2)·2R/S`, up `y = (S/2 − row − ½)·2R/S`,
//! i.e. at east `e = x·cos u + y·sin u`, north `n = −x·sin u + y·cos u` from the image centre;
//! seen from the radar, `(e, n) − o`, its true bearing picks the nearest spoke and its range is
//! interpolated linearly between range bins (with `o = 0` the bearing is `atan2(x, y) + u` and
//! the range `√(x²+y²)`).

use crate::error::{Error, Problem, Result};
use crate::model::checks::finite;
use crate::model::revolution::ShipState;
use crate::model::Radar;
use crate::products::labels::{EchoRegion, ObjectTruth};
use crate::scene::DisplaySpec;

/// Geometry of a square PPI image: side in pixels, the range at its edge and the true
/// bearing at its top.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PpiGeometry {
    /// Image side, px.
    pub size_px: u32,
    /// Range from the centre to the image edge, m.
    pub display_range_m: f64,
    /// True bearing shown straight up, rad (0: north-up).
    pub up_azimuth_rad: f64,
    /// Where the radar is from the image centre, `[east, north]` m: zero in relative motion,
    /// the antenna's ground displacement since t = 0 in true motion.
    pub radar_offset_m: [f64; 2],
}

impl PpiGeometry {
    /// Pixel coordinates (col, row, fractional) of a point at east/north metres from the radar.
    pub fn pixel_of(&self, east_m: f64, north_m: f64) -> (f64, f64) {
        let s = self.size_px as f64;
        let px_m = 2.0 * self.display_range_m / s;
        let [oe, on] = self.radar_offset_m;
        let (east_m, north_m) = (east_m + oe, north_m + on);
        // Turn the picture about its centre so that bearing `up` points up.
        let (sin_u, cos_u) = self.up_azimuth_rad.sin_cos();
        let right = east_m * cos_u - north_m * sin_u;
        let up = east_m * sin_u + north_m * cos_u;
        (right / px_m + s / 2.0, s / 2.0 - up / px_m)
    }

    /// Pixel coordinates (col, row, fractional) of the radar (the antenna's phase centre):
    /// the image centre `(S/2, S/2)` in relative motion.
    pub fn radar_px(&self) -> (f64, f64) {
        self.pixel_of(0.0, 0.0)
    }

    /// The radar's position on the screen from the image centre, m: `(right, up)`.
    fn radar_screen_m(&self) -> (f64, f64) {
        let [oe, on] = self.radar_offset_m;
        let (sin_u, cos_u) = self.up_azimuth_rad.sin_cos();
        (oe * cos_u - on * sin_u, oe * sin_u + on * cos_u)
    }

    /// The pixel box `[x_min, y_min, x_max, y_max]` of an echo region: the polar sector's
    /// outline (ground ranges) sampled and bounded, clipped to the displayed range and the
    /// image; None when nothing of it is in the image.
    pub fn pixel_box(&self, region: &EchoRegion) -> Option<[f64; 4]> {
        let (az, half_az) = (region.azimuth_rad, region.half_width_rad);
        let z = region.height_above_radar_m;
        let g_of = |r: f64| (r * r - z * z).max(0.0).sqrt();
        let g_lo = g_of(region.range_min_m);
        let g_hi = g_of(region.range_max_m).min(self.display_range_m * std::f64::consts::SQRT_2);
        if g_lo > self.display_range_m * std::f64::consts::SQRT_2 || g_hi < g_lo {
            return None;
        }
        let mut bx = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for k in 0..=32 {
            let a = az - half_az + 2.0 * half_az * k as f64 / 32.0;
            for g in [g_lo, g_hi] {
                let (px, py) = self.pixel_of(g * a.sin(), g * a.cos());
                bx = [bx[0].min(px), bx[1].min(py), bx[2].max(px), bx[3].max(py)];
            }
        }
        let size = self.size_px as f64;
        let clipped = [
            bx[0].clamp(0.0, size),
            bx[1].clamp(0.0, size),
            bx[2].clamp(0.0, size),
            bx[3].clamp(0.0, size),
        ];
        (clipped[2] > clipped[0] && clipped[3] > clipped[1]).then_some(clipped)
    }

    /// Sets every object's `ppi_box_px` for this image from its echo region, and its
    /// `ppi_footprint_px` where it has a box.
    pub fn label(&self, truth: &mut [ObjectTruth]) {
        for t in truth {
            t.ppi_box_px = t.echo_region.and_then(|r| self.pixel_box(&r));
            t.ppi_footprint_px = t.ppi_box_px.map(|_| {
                t.footprint_from_radar_m.map(|[e, n]| {
                    let (x, y) = self.pixel_of(e, n);
                    [x, y]
                })
            });
        }
    }
}

/// Precomputed mapping from PPI pixels to polar samples (a clone shares the table).
#[derive(Debug, Clone)]
pub struct ScanConverter {
    geometry: PpiGeometry,
    /// Per pixel: polar index of the lower bin (u32::MAX outside the display) and the weight
    /// of the upper bin.
    lut: std::sync::Arc<Vec<(u32, f32)>>,
}

/// The tables [`ScanConverter::for_geometry`] made last, by their inputs' bits (a dataset's
/// frames share a few geometries; a table of a 512-pixel image takes about 10 ms to make).
type ConverterKey = [u64; 8];

/// The converters made last ([`CONVERTER_CACHE_LEN`], [`CONVERTER_CACHE_BYTES`]).
pub(crate) static CONVERTERS: crate::cache::KeptLast<ConverterKey, ScanConverter> =
    crate::cache::KeptLast::new(CONVERTER_CACHE_LEN, CONVERTER_CACHE_BYTES);

/// Converters kept: at most this many, and at most [`CONVERTER_CACHE_BYTES`] of tables
/// (about 2 MB each at 512 pixels, 8 MB at 1024).
const CONVERTER_CACHE_LEN: usize = 16;

/// Bytes of tables kept.
const CONVERTER_CACHE_BYTES: usize = 64 << 20;

impl ScanConverter {
    /// Mapping for a square north-up image of `size_px` covering ±`display_range_m`.
    pub fn new(
        size_px: u32,
        display_range_m: f64,
        spokes: usize,
        num_bins: usize,
        range_bin_m: f64,
    ) -> ScanConverter {
        ScanConverter::oriented(size_px, display_range_m, spokes, num_bins, range_bin_m, 0.0)
    }

    /// As [`ScanConverter::new`] with true bearing `up_azimuth_rad` at the top.
    pub fn oriented(
        size_px: u32,
        display_range_m: f64,
        spokes: usize,
        num_bins: usize,
        range_bin_m: f64,
        up_azimuth_rad: f64,
    ) -> ScanConverter {
        let geometry = PpiGeometry {
            size_px,
            display_range_m,
            up_azimuth_rad,
            radar_offset_m: [0.0, 0.0],
        };
        ScanConverter::for_geometry(geometry, spokes, num_bins, range_bin_m)
    }

    /// Mapping for the image `geometry` (orientation and the radar's place in it) of a polar
    /// record of `spokes` × `num_bins` bins `range_bin_m` apart. Pixels farther than the
    /// display range from the radar map to nothing.
    pub fn for_geometry(
        geometry: PpiGeometry,
        spokes: usize,
        num_bins: usize,
        range_bin_m: f64,
    ) -> ScanConverter {
        let key: ConverterKey = [
            geometry.size_px as u64,
            geometry.display_range_m.to_bits(),
            geometry.up_azimuth_rad.to_bits(),
            geometry.radar_offset_m[0].to_bits(),
            geometry.radar_offset_m[1].to_bits(),
            spokes as u64,
            num_bins as u64,
            range_bin_m.to_bits(),
        ];
        CONVERTERS.get_or_make(
            key,
            || ScanConverter::make(geometry, spokes, num_bins, range_bin_m),
            |c| c.lut.len() * std::mem::size_of::<(u32, f32)>(),
        )
    }

    fn make(
        geometry: PpiGeometry,
        spokes: usize,
        num_bins: usize,
        range_bin_m: f64,
    ) -> ScanConverter {
        let PpiGeometry {
            size_px,
            display_range_m,
            up_azimuth_rad,
            radar_offset_m: [oe, on],
        } = geometry;
        let centred = oe == 0.0 && on == 0.0;
        let (sin_u, cos_u) = up_azimuth_rad.sin_cos();
        let s = size_px as usize;
        let px_m = 2.0 * display_range_m / size_px as f64;
        let spoke_rad = std::f64::consts::TAU / spokes as f64;
        let mut lut = Vec::with_capacity(s * s);
        for row in 0..s {
            for col in 0..s {
                let x = (col as f64 + 0.5 - s as f64 / 2.0) * px_m;
                let y = (s as f64 / 2.0 - row as f64 - 0.5) * px_m;
                let (r, az) = if centred {
                    let az = if up_azimuth_rad == 0.0 {
                        x.atan2(y).rem_euclid(std::f64::consts::TAU)
                    } else {
                        (x.atan2(y) + up_azimuth_rad).rem_euclid(std::f64::consts::TAU)
                    };
                    (x.hypot(y), az)
                } else {
                    // East and north from the image centre, then from the radar.
                    let e = x * cos_u + y * sin_u - oe;
                    let n = -x * sin_u + y * cos_u - on;
                    (e.hypot(n), e.atan2(n).rem_euclid(std::f64::consts::TAU))
                };
                if r > display_range_m {
                    lut.push((u32::MAX, 0.0));
                    continue;
                }
                let spoke = ((az / spoke_rad).round() as usize) % spokes;
                let fb = r / range_bin_m;
                let b0 = fb.floor() as usize;
                if b0 + 1 >= num_bins {
                    lut.push((u32::MAX, 0.0));
                    continue;
                }
                lut.push(((spoke * num_bins + b0) as u32, (fb - b0 as f64) as f32));
            }
        }
        ScanConverter {
            geometry,
            lut: std::sync::Arc::new(lut),
        }
    }

    /// Image side, px.
    pub fn size_px(&self) -> u32 {
        self.geometry.size_px
    }

    /// Half-width of the image, m.
    pub fn display_range_m(&self) -> f64 {
        self.geometry.display_range_m
    }

    /// Scan-converts `polar` (spokes × bins) into `out` (size² pixels, row-major);
    /// pixels outside the display get `outside`.
    pub fn convert(&self, polar: &[f32], outside: f32, out: &mut [f32]) {
        debug_assert_eq!(out.len(), self.lut.len());
        for (o, &(idx, w)) in out.iter_mut().zip(self.lut.iter()) {
            *o = if idx == u32::MAX {
                outside
            } else {
                let i = idx as usize;
                polar[i] * (1.0 - w) + polar[i + 1] * w
            };
        }
    }

    /// The image geometry.
    pub fn geometry(&self) -> PpiGeometry {
        self.geometry
    }

    /// The polar cell (spoke·bins + bin) nearest to pixel `pixel` (row-major), None outside
    /// the display.
    pub fn nearest_cell(&self, pixel: usize) -> Option<usize> {
        let (idx, w) = self.lut[pixel];
        (idx != u32::MAX).then(|| idx as usize + usize::from(w >= 0.5))
    }
}

const VIRIDIS: [[f32; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// Colour of a normalised value `t ∈ [0, 1]`.
pub fn colour(colormap: Colormap, t: f32) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    match colormap {
        Colormap::Gray => {
            let v = crate::special::round_to_u8(t * 255.0);
            [v, v, v]
        }
        Colormap::Green => [
            (t * t * 120.0) as u8,
            crate::special::round_to_u8(t * 255.0),
            (t * t * 60.0) as u8,
        ],
        Colormap::Viridis => {
            let x = t * (VIRIDIS.len() - 1) as f32;
            let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
            let f = x - i as f32;
            let a = VIRIDIS[i];
            let b = VIRIDIS[i + 1];
            [
                crate::special::round_to_u8(a[0] + (b[0] - a[0]) * f),
                crate::special::round_to_u8(a[1] + (b[1] - a[1]) * f),
                crate::special::round_to_u8(a[2] + (b[2] - a[2]) * f),
            ]
        }
    }
}

/// Normalises dB values to `[0, 1]` over `[min_db, max_db]`.
#[inline]
pub fn normalise_db(v: f32, min_db: f64, max_db: f64) -> f32 {
    ((v as f64 - min_db) / (max_db - min_db)) as f32
}

/// 8-bit gray image from PPI dB values.
pub fn gray_image(ppi_db: &[f32], min_db: f64, max_db: f64) -> Vec<u8> {
    ppi_db
        .iter()
        .map(|&v| {
            crate::special::round_to_u8(normalise_db(v, min_db, max_db).clamp(0.0, 1.0) * 255.0)
        })
        .collect()
}

/// Colour of the cells `[display] doppler_colour` marks as approaching: pure red, outside
/// every colour map.
pub const APPROACHING_RGB: [u8; 3] = [255, 0, 0];

/// RGB image from PPI dB values with range rings every `ring_spacing_m` (0 = none).
pub fn colour_image(
    conv: &ScanConverter,
    ppi_db: &[f32],
    colormap: Colormap,
    min_db: f64,
    max_db: f64,
    ring_spacing_m: f64,
) -> Vec<u8> {
    colour_image_marked(conv, ppi_db, None, colormap, min_db, max_db, ring_spacing_m)
}

/// As [`colour_image`], with the pixels whose nearest polar cell `marked` says so drawn in
/// [`APPROACHING_RGB`] (under the range rings).
pub fn colour_image_marked(
    conv: &ScanConverter,
    ppi_db: &[f32],
    marked: Option<&dyn Fn(usize) -> bool>,
    colormap: Colormap,
    min_db: f64,
    max_db: f64,
    ring_spacing_m: f64,
) -> Vec<u8> {
    let s = conv.size_px() as usize;
    let display_range_m = conv.display_range_m();
    let mut rgb = Vec::with_capacity(s * s * 3);
    for (p, &v) in ppi_db.iter().enumerate() {
        let c = if v.is_nan() {
            [0, 0, 0]
        } else if marked.is_some_and(|m| conv.nearest_cell(p).is_some_and(m)) {
            APPROACHING_RGB
        } else {
            colour(colormap, normalise_db(v, min_db, max_db))
        };
        rgb.extend_from_slice(&c);
    }
    if ring_spacing_m > 0.0 {
        let px_m = 2.0 * display_range_m / s as f64;
        let ring = [40u8, 220, 40];
        // Rings are centred on the radar (the image centre in relative motion).
        let (rx, ry) = conv.geometry().radar_screen_m();
        for row in 0..s {
            for col in 0..s {
                let x = (col as f64 + 0.5 - s as f64 / 2.0) * px_m - rx;
                let y = (s as f64 / 2.0 - row as f64 - 0.5) * px_m - ry;
                let r = x.hypot(y);
                if r > display_range_m + 0.5 * px_m {
                    continue;
                }
                let k = (r / ring_spacing_m).round();
                if k >= 1.0 && (r - k * ring_spacing_m).abs() < 0.5 * px_m {
                    let i = (row * s + col) * 3;
                    rgb[i..i + 3].copy_from_slice(&ring);
                }
            }
        }
    }
    rgb
}

pub use crate::choice::Orientation;

pub use crate::choice::Motion;

/// Reads `"relative"` or `"true"`, and also the TOML booleans `true` and `false` (what
/// `--set display.motion=true` writes), so that "true motion" reads as it is said.
impl<'de> serde::Deserialize<'de> for Motion {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Motion, D::Error> {
        #[derive(serde::Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Name(String),
            Flag(bool),
        }
        match Raw::deserialize(d)? {
            Raw::Flag(true) => Ok(Motion::True),
            Raw::Flag(false) => Ok(Motion::Relative),
            Raw::Name(name) => match name.as_str() {
                "relative" => Ok(Motion::Relative),
                "true" => Ok(Motion::True),
                other => Err(serde::de::Error::unknown_variant(
                    other,
                    &["relative", "true"],
                )),
            },
        }
    }
}

pub use crate::choice::Colormap;

/// PPI drawing settings.
#[derive(Debug, Clone, PartialEq)]
pub struct PpiSettings {
    /// Square image side, px.
    pub image_size_px: u32,
    /// Range-ring spacing, m (0 = none).
    pub range_ring_spacing_m: f64,
    /// Colour map.
    pub colormap: Colormap,
    /// Bottom of the colour scale, dB over noise.
    pub min_db: f64,
    /// Top of the colour scale, dB over noise.
    pub max_db: f64,
    /// Which bearing is at the top.
    pub orientation: Orientation,
    /// Relative or true motion.
    pub motion: Motion,
    /// Colour approaching echoes (pulse mode).
    pub doppler_colour: bool,
    /// Power an echo needs to be coloured, dB over noise.
    pub doppler_colour_threshold_db: f64,
}

impl PpiSettings {
    /// Validates the scene file's `[display]` table.
    pub fn from_spec(s: &DisplaySpec) -> Result<PpiSettings> {
        let image_size_px = s.image_size_px.unwrap_or(1024);
        if !(16..=16384).contains(&image_size_px) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "display.image_size_px",
                image_size_px,
                "must be between 16 and 16384",
            ));
        }
        let range_ring_spacing_m = finite(
            "display.range_ring_spacing_m",
            s.range_ring_spacing_m.unwrap_or(100.0),
        )?;
        if range_ring_spacing_m < 0.0 {
            return Err(Error::invalid(
                Problem::OutOfRange,
                "display.range_ring_spacing_m",
                range_ring_spacing_m,
                "must be 0 (no rings) or more",
            ));
        }
        let colormap = s.colormap.unwrap_or(Colormap::Viridis);
        let min_db = finite("display.min_db", s.min_db.unwrap_or(0.0))?;
        let max_db = finite("display.max_db", s.max_db.unwrap_or(60.0))?;
        if max_db <= min_db {
            return Err(Error::invalid(
                Problem::Conflict,
                "display.max_db",
                max_db,
                format!("must be above display.min_db ({min_db})"),
            ));
        }
        Ok(PpiSettings {
            image_size_px,
            range_ring_spacing_m,
            colormap,
            min_db,
            max_db,
            orientation: s.orientation.unwrap_or_default(),
            motion: s.motion.unwrap_or_default(),
            doppler_colour: s.doppler_colour.unwrap_or(false),
            doppler_colour_threshold_db: finite(
                "display.doppler_colour_threshold_db",
                s.doppler_colour_threshold_db.unwrap_or(10.0),
            )?,
        })
    }

    /// The true bearing at the top of a frame's image with the own ship in `own_ship` (its
    /// state at the frame's start), rad: 0 north-up; the heading (head-up); the course over
    /// ground, or the heading while it stands still (course-up). Without an own ship, 0.
    pub fn up_azimuth_rad(&self, own_ship: Option<&ShipState>) -> f64 {
        let Some(s) = own_ship else { return 0.0 };
        match self.orientation {
            Orientation::NorthUp => 0.0,
            Orientation::HeadUp => s.heading_rad,
            Orientation::CourseUp => s.course_rad().unwrap_or(s.heading_rad),
        }
    }

    /// Where the radar is from the image centre in a frame whose own ship is `own_ship` (its
    /// state at the frame's start), `[east, north]` m: zero in relative motion; in true motion
    /// the antenna's ground displacement since t = 0 (where `radar.position_m` puts it), zero
    /// without an own ship.
    pub fn radar_offset_m(&self, radar: &Radar, own_ship: Option<&ShipState>) -> [f64; 2] {
        match (self.motion, own_ship) {
            (Motion::True, Some(s)) => {
                let d = s.antenna_position_m - radar.position_m();
                [d.x, d.y]
            }
            _ => [0.0, 0.0],
        }
    }

    /// The geometry of a frame's images for `radar`'s record, with the own ship in `own_ship`
    /// (its state at the frame's start): this side, covering the max range, the orientation's
    /// bearing at the top and the radar where the motion mode puts it.
    pub fn frame_geometry(&self, radar: &Radar, own_ship: Option<&ShipState>) -> PpiGeometry {
        PpiGeometry {
            size_px: self.image_size_px,
            display_range_m: radar.max_range_m(),
            up_azimuth_rad: self.up_azimuth_rad(own_ship),
            radar_offset_m: self.radar_offset_m(radar, own_ship),
        }
    }

    /// Scan converter from `radar`'s polar record to a frame's image
    /// ([`PpiSettings::frame_geometry`]).
    pub fn frame_scan_converter(
        &self,
        radar: &Radar,
        own_ship: Option<&ShipState>,
    ) -> ScanConverter {
        ScanConverter::for_geometry(
            self.frame_geometry(radar, own_ship),
            radar.spokes(),
            radar.num_range_bins(),
            radar.range_bin_m(),
        )
    }

    /// Scan converter from `radar`'s polar record to this image, covering its max range,
    /// north-up.
    pub fn scan_converter(&self, radar: &Radar) -> ScanConverter {
        self.oriented_scan_converter(radar, 0.0)
    }

    /// As [`PpiSettings::scan_converter`] with true bearing `up_azimuth_rad` at the top.
    pub fn oriented_scan_converter(&self, radar: &Radar, up_azimuth_rad: f64) -> ScanConverter {
        ScanConverter::oriented(
            self.image_size_px,
            radar.max_range_m(),
            radar.spokes(),
            radar.num_range_bins(),
            radar.range_bin_m(),
            up_azimuth_rad,
        )
    }

    /// The image geometry for `radar`: this side, covering its max range, north-up.
    pub fn geometry(&self, radar: &Radar) -> PpiGeometry {
        PpiGeometry {
            size_px: self.image_size_px,
            display_range_m: radar.max_range_m(),
            up_azimuth_rad: 0.0,
            radar_offset_m: [0.0, 0.0],
        }
    }
}
