//! Stage: antenna — a measured pattern cut from a CSV file (`radar.azimuth_pattern_file`,
//! `radar.elevation_pattern_file`; docs/formats.md): rows `angle_deg,gain_db` (a header line
//! and `#` comments allowed), angles from the beam axis, gains in dB relative to any
//! reference (normalised to the peak). The cut is resampled once onto a uniform grid of
//! [`TABLE_STEP_DEG`] (linear in dB between the rows; outside the rows' span the nearest
//! row's gain), with a per-degree maximum for the sine-free bound, its two-way integral, its
//! half-power width and its first null. Tables are interned by content: one leaked copy per
//! distinct cut, so that [`crate::antenna::Antenna`] stays `Copy`.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// Resampling step, degrees.
pub const TABLE_STEP_DEG: f64 = 0.01;

/// A pattern cut on a uniform grid over (−180°, 180°].
#[derive(Debug, PartialEq)]
pub struct PatternTable {
    /// `Gn` (linear, one-way, peak 1) at `−180° + k·step`, k = 0 … 36000.
    values: Vec<f64>,
    /// The largest `Gn` in each whole degree `[−180 + d, −179 + d)`, d = 0 … 359.
    degree_max: Vec<f64>,
    /// `∫Gn²` over the circle, rad.
    two_way_integral_rad: f64,
    /// The −3 dB width about the peak, rad.
    beamwidth_3db_rad: f64,
    /// The first minimum off the axis (the larger of the two sides), rad.
    first_null_rad: f64,
}

impl PatternTable {
    /// Reads `text` (CSV rows `angle_deg,gain_db`); errors say which line is wrong.
    pub fn parse(text: &str) -> std::result::Result<PatternTable, String> {
        let mut rows: Vec<(f64, f64)> = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let mut cells = line.split(',').map(str::trim);
            let (Some(a), Some(g), None) = (cells.next(), cells.next(), cells.next()) else {
                return Err(format!("line {}: expected `angle_deg,gain_db`", n + 1));
            };
            match (a.parse::<f64>(), g.parse::<f64>()) {
                (Ok(a), Ok(g)) if a.is_finite() && g.is_finite() => {
                    if !(-180.0..=180.0).contains(&a) {
                        return Err(format!("line {}: angle {a} is outside -180 … 180", n + 1));
                    }
                    rows.push((a, g));
                }
                _ if rows.is_empty() => continue, // a header line
                _ => return Err(format!("line {}: `{line}` is not two numbers", n + 1)),
            }
        }
        if rows.len() < 3 {
            return Err("needs at least three rows".into());
        }
        rows.sort_by(|x, y| x.0.total_cmp(&y.0));
        if rows.windows(2).any(|w| w[0].0 == w[1].0) {
            return Err("two rows have the same angle".into());
        }
        let peak_db = rows.iter().map(|r| r.1).fold(f64::MIN, f64::max);
        let at = |deg: f64| -> f64 {
            let k = rows.partition_point(|r| r.0 <= deg);
            let db = if k == 0 {
                rows[0].1
            } else if k == rows.len() {
                rows[rows.len() - 1].1
            } else {
                let (a0, g0) = rows[k - 1];
                let (a1, g1) = rows[k];
                g0 + (g1 - g0) * (deg - a0) / (a1 - a0)
            };
            10f64.powf((db - peak_db) / 10.0)
        };
        let n = (360.0 / TABLE_STEP_DEG).round() as usize;
        let values: Vec<f64> = (0..=n)
            .map(|k| at(-180.0 + k as f64 * TABLE_STEP_DEG))
            .collect();
        let per_degree = (1.0 / TABLE_STEP_DEG).round() as usize;
        let degree_max: Vec<f64> = (0..360)
            .map(|d| {
                values[d * per_degree..=(d + 1) * per_degree]
                    .iter()
                    .copied()
                    .fold(0.0, f64::max)
            })
            .collect();
        let h = TABLE_STEP_DEG.to_radians();
        let two_way_integral_rad = values[..n].iter().map(|v| v * v * h).sum();
        // The peak's index and the half-power and first-minimum points either side of it.
        let centre = n / 2;
        let peak_k = (0..=n)
            .max_by(|&a, &b| values[a].total_cmp(&values[b]))
            .unwrap_or(centre);
        let walk = |dir: i64, stop: &dyn Fn(f64, f64) -> bool| -> f64 {
            let mut k = peak_k as i64;
            loop {
                let next = k + dir;
                if next < 0 || next > n as i64 || stop(values[k as usize], values[next as usize]) {
                    return ((k - peak_k as i64).abs() as f64 * TABLE_STEP_DEG).to_radians();
                }
                k = next;
            }
        };
        let half_right = walk(1, &|_, v| v < 0.5);
        let half_left = walk(-1, &|_, v| v < 0.5);
        // The first minimum once the main lobe is 10 dB down (a ripple on its shoulder is not
        // a null).
        let null_right = walk(1, &|v, next| v < 0.1 && next > v);
        let null_left = walk(-1, &|v, next| v < 0.1 && next > v);
        if half_left + half_right >= std::f64::consts::PI {
            return Err("it never falls 3 dB under its peak".into());
        }
        Ok(PatternTable {
            values,
            degree_max,
            two_way_integral_rad,
            beamwidth_3db_rad: half_left + half_right,
            first_null_rad: null_left.max(null_right),
        })
    }

    /// Interns `table`: the one shared copy of a cut with these values.
    pub fn intern(table: PatternTable) -> &'static PatternTable {
        static TABLES: OnceLock<Mutex<HashMap<Vec<u64>, &'static PatternTable>>> = OnceLock::new();
        let key: Vec<u64> = table.values.iter().map(|v| v.to_bits()).collect();
        let mut map = TABLES
            .get_or_init(|| Mutex::new(HashMap::new()))
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        map.entry(key).or_insert_with(|| Box::leak(Box::new(table)))
    }

    /// `Gn` at `off_axis_rad` (wrapped), linear between grid points.
    pub fn value(&self, off_axis_rad: f64) -> f64 {
        let deg = super::wrap_angle_rad(off_axis_rad).to_degrees();
        let x = (deg + 180.0) / TABLE_STEP_DEG;
        let k = (x.floor() as usize).min(self.values.len() - 2);
        let t = x - k as f64;
        self.values[k] + t * (self.values[k + 1] - self.values[k])
    }

    /// A lower bound of `1/√Gn` at `off_axis_rad`: one over the root of the largest value in
    /// the whole degree around it (and its neighbours).
    pub fn inverse_voltage_envelope(&self, off_axis_rad: f64) -> f64 {
        let deg = super::wrap_angle_rad(off_axis_rad).to_degrees();
        let d = ((deg + 180.0).floor() as i64).clamp(0, 359);
        let m = [d - 1, d, d + 1]
            .iter()
            .map(|&i| self.degree_max[i.rem_euclid(360) as usize])
            .fold(0.0, f64::max);
        if m > 0.0 {
            1.0 / m.sqrt()
        } else {
            f64::INFINITY
        }
    }

    /// `∫Gn²` over the circle, rad.
    pub fn two_way_integral_rad(&self) -> f64 {
        self.two_way_integral_rad
    }

    /// The −3 dB width, rad.
    pub fn beamwidth_3db_rad(&self) -> f64 {
        self.beamwidth_3db_rad
    }

    /// The first null (minimum) off the axis, rad.
    pub fn first_null_rad(&self) -> f64 {
        self.first_null_rad
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sinc² written as a CSV (0.05° rows) reads back as the sinc²: its values, half-power
    /// width, first null, integral and bound.
    #[test]
    fn a_tabulated_sinc2_reads_back_as_the_sinc2() {
        let bw = 3.9f64.to_radians();
        let p = crate::antenna::Pattern::sinc2(bw);
        let mut csv = String::from("angle_deg,gain_db\n");
        for i in 0..=7200 {
            let a = -180.0 + i as f64 * 0.05;
            let g = p.value(a.to_radians()).max(1e-12);
            csv.push_str(&format!("{a},{}\n", 10.0 * g.log10()));
        }
        let t = PatternTable::parse(&csv).unwrap();
        for deg in [0.0, 0.7, 1.95, 3.0, 6.0, 20.0, -45.0] {
            let (v, w) = (t.value(f64::to_radians(deg)), p.value(f64::to_radians(deg)));
            assert!((10.0 * (v / w).log10()).abs() < 0.05, "{deg}°: {v} vs {w}");
        }
        assert!((t.beamwidth_3db_rad() / bw - 1.0).abs() < 0.01);
        assert!((t.first_null_rad() / p.first_null_rad() - 1.0).abs() < 0.02);
        assert!((t.two_way_integral_rad() / p.two_way_integral_rad() - 1.0).abs() < 0.01);
        for i in 0..36_000 {
            let th = (-180.0 + i as f64 * 0.01 + 0.005f64).to_radians();
            let r = t.inverse_voltage_envelope(th);
            assert!(t.value(th) * r * r <= 1.0 + 1e-9, "{th}");
        }
        for bad in [
            "",
            "0,0\n1,-3\n",
            "a,b\n0,0\n1,x\n2,-1\n",
            "0,0\n200,-3\n1,-1\n",
        ] {
            assert!(PatternTable::parse(bad).is_err(), "{bad:?}");
        }
    }
}
