//! Model: a land polygon's height map — a regular grid of ground heights read from a 16-bit
//! grey PNG or a 2-D `.npy` array (docs/formats.md `[[land]]`, "height maps").
//!
//! The grid's first row is its north edge and its first column its west edge; its corner
//! samples sit on the corners of its extent `[x_min, y_min, x_max, y_max]` (local metres),
//! so sample `(r, c)` is at `x = x_min + c·(x_max − x_min)/(cols − 1)`,
//! `y = y_max − r·(y_max − y_min)/(rows − 1)`. Heights are the stored values times the
//! vertical scale, in metres; between samples they are interpolated bilinearly, and below
//! the sea they count as 0 (the sea).

use crate::error::{Error, Problem, Result};
use glam::DVec2;
use std::path::Path;

/// The most samples a height map may hold (2¹⁸ × 2¹⁸ would be 256 GiB of f32: far past any
/// scene's need; 8192 × 8192 at 1 m covers 67 km²).
pub const MAX_SAMPLES: usize = 1 << 26;

/// A grid of ground heights over a rectangle.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightMap {
    /// Rows (north to south).
    rows: usize,
    /// Columns (west to east).
    cols: usize,
    /// Heights, m, row-major.
    heights_m: Vec<f32>,
    /// West and south edges, m.
    min_m: DVec2,
    /// East and north edges, m.
    max_m: DVec2,
    /// The highest height, m.
    top_m: f64,
}

impl HeightMap {
    /// A map of `rows × cols` heights (row-major, north row first) over `extent_m`
    /// `[x_min, y_min, x_max, y_max]`; `what` names the map in errors, `field` the field.
    pub fn new(
        field: &str,
        what: &str,
        rows: usize,
        cols: usize,
        heights_m: Vec<f32>,
        extent_m: [f64; 4],
    ) -> Result<HeightMap> {
        let bad = |reason: String| Error::invalid(Problem::Unusable, field, what, reason);
        if rows < 2 || cols < 2 {
            return Err(bad(format!(
                "a height map needs at least 2 × 2 samples; it has {rows} × {cols}"
            )));
        }
        if rows.checked_mul(cols).is_none_or(|n| n > MAX_SAMPLES) {
            return Err(bad(format!(
                "a height map of {rows} × {cols} samples is larger than this reader takes ({MAX_SAMPLES} samples)"
            )));
        }
        if heights_m.len() != rows * cols {
            return Err(bad(format!(
                "it holds {} heights, not {rows} × {cols}",
                heights_m.len()
            )));
        }
        if let Some(i) = heights_m.iter().position(|h| !h.is_finite()) {
            return Err(bad(format!(
                "the height at row {}, column {} is not finite ({}; too large for its scale?)",
                i / cols,
                i % cols,
                heights_m[i]
            )));
        }
        let [x0, y0, x1, y1] = extent_m;
        if !(x0.is_finite() && y0.is_finite() && x1.is_finite() && y1.is_finite())
            || x1 <= x0
            || y1 <= y0
        {
            return Err(Error::invalid(
                Problem::OutOfRange,
                field.replace("height_map", "height_map_extent_m"),
                format!("{extent_m:?}"),
                "the extent [x_min, y_min, x_max, y_max] must be finite with x_max > x_min and y_max > y_min",
            ));
        }
        let top_m = heights_m.iter().fold(0f64, |m, &h| m.max(h as f64));
        Ok(HeightMap {
            rows,
            cols,
            heights_m,
            min_m: DVec2::new(x0, y0),
            max_m: DVec2::new(x1, y1),
            top_m,
        })
    }

    /// Reads a 16-bit grey PNG or a 2-D `.npy` array (unsigned or signed 16-bit, 32- or
    /// 64-bit float) and scales its values by `scale_m` metres per unit.
    pub fn read(field: &str, path: &Path, extent_m: [f64; 4], scale_m: f64) -> Result<HeightMap> {
        let what = format!("{:?}", path.display().to_string());
        let bad = |reason: String| Error::invalid(Problem::Unusable, field, what.clone(), reason);
        let bytes = std::fs::read(path).map_err(|e| {
            Error::unusable(
                field,
                what.clone(),
                "cannot read the height map",
                Error::io(path, e),
            )
        })?;
        let (rows, cols, values) = if bytes.starts_with(b"\x89PNG") {
            read_png16(&bytes).map_err(bad)?
        } else if bytes.starts_with(b"\x93NUMPY") {
            read_npy_2d(&bytes).map_err(bad)?
        } else {
            return Err(bad(
                "not a PNG or an .npy file (a height map is a 16-bit grey PNG or a 2-D .npy array)"
                    .into(),
            ));
        };
        let heights = values.iter().map(|&v| (v * scale_m) as f32).collect();
        HeightMap::new(field, &what, rows, cols, heights, extent_m)
    }

    /// Height at `p`, m (bilinear; 0 below the sea; the edge's value outside the extent).
    #[inline]
    pub fn height_at(&self, p: DVec2) -> f64 {
        let span = self.max_m - self.min_m;
        let fx = ((p.x - self.min_m.x) / span.x * (self.cols - 1) as f64)
            .clamp(0.0, (self.cols - 1) as f64);
        let fy = ((self.max_m.y - p.y) / span.y * (self.rows - 1) as f64)
            .clamp(0.0, (self.rows - 1) as f64);
        let (c, r) = (
            (fx as usize).min(self.cols - 2),
            (fy as usize).min(self.rows - 2),
        );
        let (tx, ty) = (fx - c as f64, fy - r as f64);
        let at = |r: usize, c: usize| self.heights_m[r * self.cols + c] as f64;
        let top = at(r, c) * (1.0 - tx) + at(r, c + 1) * tx;
        let bottom = at(r + 1, c) * (1.0 - tx) + at(r + 1, c + 1) * tx;
        (top * (1.0 - ty) + bottom * ty).max(0.0)
    }

    /// The highest height, m (at least 0).
    pub fn top_m(&self) -> f64 {
        self.top_m
    }

    /// The smaller of its two sample spacings, m.
    pub fn cell_m(&self) -> f64 {
        let span = self.max_m - self.min_m;
        (span.x / (self.cols - 1) as f64).min(span.y / (self.rows - 1) as f64)
    }

    /// Whether `p` lies inside its extent.
    pub fn covers(&self, p: DVec2) -> bool {
        p.x >= self.min_m.x && p.x <= self.max_m.x && p.y >= self.min_m.y && p.y <= self.max_m.y
    }

    /// `[rows, cols]`.
    pub fn shape(&self) -> [usize; 2] {
        [self.rows, self.cols]
    }
}

/// A 16-bit grey PNG's rows, columns and values.
fn read_png16(bytes: &[u8]) -> std::result::Result<(usize, usize, Vec<f64>), String> {
    let decoder = png::Decoder::new(bytes);
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("not a readable PNG: {e}"))?;
    let info = reader.info();
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Sixteen {
        return Err(format!(
            "a height map PNG must be 16-bit grey; this one is {:?} at {:?} bits",
            info.color_type, info.bit_depth
        ));
    }
    let (cols, rows) = (info.width as usize, info.height as usize);
    if rows.checked_mul(cols).is_none_or(|n| n > MAX_SAMPLES) {
        return Err(format!(
            "a height map of {rows} × {cols} samples is larger than this reader takes ({MAX_SAMPLES} samples)"
        ));
    }
    let mut buf = vec![0u8; reader.output_buffer_size()];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| format!("cannot decode the PNG: {e}"))?;
    let values = buf[..frame.buffer_size()]
        .chunks_exact(2)
        .map(|c| u16::from_be_bytes([c[0], c[1]]) as f64)
        .collect::<Vec<_>>();
    Ok((rows, cols, values))
}

/// A 2-D little-endian `.npy` array's rows, columns and values (C order; `<u2`, `<i2`,
/// `<f4` or `<f8`).
fn read_npy_2d(bytes: &[u8]) -> std::result::Result<(usize, usize, Vec<f64>), String> {
    if bytes.len() < 10 {
        return Err("a truncated .npy file".into());
    }
    let (header_len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        2 | 3 => return Err("a truncated .npy file".into()),
        v => return Err(format!("an .npy file of version {v}, which is not read")),
    };
    let header = bytes
        .get(start..start + header_len)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or("a truncated or unreadable .npy header")?;
    if header.contains("'fortran_order': True") {
        return Err("a Fortran-ordered array: save it in C order (numpy.ascontiguousarray)".into());
    }
    let descr = ["<u2", "<i2", "<f4", "<f8"]
        .into_iter()
        .find(|d| header.contains(&format!("'{d}'")))
        .ok_or("its dtype is not uint16, int16, float32 or float64 (little-endian)")?;
    let open = header
        .find("'shape': (")
        .ok_or("no shape in the .npy header")?
        + 10;
    let close = header[open..]
        .find(')')
        .ok_or("no shape in the .npy header")?
        + open;
    let shape: Vec<usize> = header[open..close]
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<usize>().map_err(|_| format!("a bad shape {s:?}")))
        .collect::<std::result::Result<_, _>>()?;
    if shape.len() != 2 {
        return Err(format!(
            "a height map is a 2-D array (rows × columns); this one has shape {shape:?}"
        ));
    }
    if shape[0]
        .checked_mul(shape[1])
        .is_none_or(|n| n > MAX_SAMPLES)
    {
        return Err(format!(
            "a height map of {} × {} samples is larger than this reader takes ({MAX_SAMPLES} samples)",
            shape[0], shape[1]
        ));
    }
    let data = bytes.get(start + header_len..).unwrap_or_default();
    let values: Vec<f64> = match descr {
        "<u2" => data
            .chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]) as f64)
            .collect(),
        "<i2" => data
            .chunks_exact(2)
            .map(|c| i16::from_le_bytes([c[0], c[1]]) as f64)
            .collect(),
        "<f4" => data
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64)
            .collect(),
        _ => data
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
            .collect(),
    };
    if values.len() != shape[0] * shape[1] {
        return Err(format!(
            "it holds {} values, not the {} × {} its header says",
            values.len(),
            shape[0],
            shape[1]
        ));
    }
    Ok((shape[0], shape[1], values))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> HeightMap {
        // 3 × 2: north row 10, 20; middle 5, 15; south row 0, 10.
        HeightMap::new(
            "f",
            "w",
            3,
            2,
            vec![10.0, 20.0, 5.0, 15.0, 0.0, 10.0],
            [0.0, 0.0, 100.0, 200.0],
        )
        .unwrap()
    }

    #[test]
    fn corners_and_middles_are_the_samples_and_their_bilinear_means() {
        let m = ramp();
        assert_eq!(m.height_at(DVec2::new(0.0, 200.0)), 10.0);
        assert_eq!(m.height_at(DVec2::new(100.0, 200.0)), 20.0);
        assert_eq!(m.height_at(DVec2::new(0.0, 0.0)), 0.0);
        assert_eq!(m.height_at(DVec2::new(100.0, 100.0)), 15.0);
        assert!((m.height_at(DVec2::new(50.0, 150.0)) - 12.5).abs() < 1e-12);
        assert_eq!(m.top_m(), 20.0);
        assert_eq!(m.cell_m(), 100.0);
    }

    #[test]
    fn npy_and_png_read_the_same_grid() {
        let dir = tempfile::tempdir().unwrap();
        let values: Vec<u16> = vec![0, 100, 200, 300, 400, 500];
        let npy = dir.path().join("h.npy");
        let header = "{'descr': '<u2', 'fortran_order': False, 'shape': (2, 3), }";
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        let pad = 64 - (10 + header.len() + 1) % 64;
        let h = format!("{header}{}\n", " ".repeat(pad));
        b.extend_from_slice(&(h.len() as u16).to_le_bytes());
        b.extend_from_slice(h.as_bytes());
        for v in &values {
            b.extend_from_slice(&v.to_le_bytes());
        }
        std::fs::write(&npy, b).unwrap();
        let png_path = dir.path().join("h.png");
        {
            let f = std::fs::File::create(&png_path).unwrap();
            let mut enc = png::Encoder::new(f, 3, 2);
            enc.set_color(png::ColorType::Grayscale);
            enc.set_depth(png::BitDepth::Sixteen);
            let mut w = enc.write_header().unwrap();
            let data: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
            w.write_image_data(&data).unwrap();
        }
        let extent = [0.0, 0.0, 20.0, 10.0];
        let a = HeightMap::read("f", &npy, extent, 0.1).unwrap();
        let b = HeightMap::read("f", &png_path, extent, 0.1).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.shape(), [2, 3]);
        assert!((a.height_at(DVec2::new(20.0, 0.0)) - 50.0).abs() < 1e-4);
    }

    #[test]
    fn wrong_grids_are_refused_by_name() {
        let e = HeightMap::new(
            "land[0].height_map",
            "\"h.npy\"",
            1,
            4,
            vec![0.0; 4],
            [0.0, 0.0, 1.0, 1.0],
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("land[0].height_map") && e.contains("2 × 2"),
            "{e}"
        );
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.png");
        {
            let f = std::fs::File::create(&p).unwrap();
            let mut enc = png::Encoder::new(f, 2, 2);
            enc.set_color(png::ColorType::Grayscale);
            enc.set_depth(png::BitDepth::Eight);
            enc.write_header()
                .unwrap()
                .write_image_data(&[0, 1, 2, 3])
                .unwrap();
        }
        let e = HeightMap::read("land[0].height_map", &p, [0.0, 0.0, 1.0, 1.0], 1.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("16-bit grey") && e.contains("x.png"), "{e}");
    }
}
