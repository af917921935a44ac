//! Product: the land's ground truth of a frame (docs/formats.md, "land_mask.npy"). Which
//! polar cells show land — the cell's surface patch is land the radar sees, so the cell's
//! echo is that land's — and which polygon each is; the polygons themselves with how many
//! cells each shows. Drawn from the revolution's clutter map
//! ([`crate::signal::clutter_map::ClutterMap::land_polygon`]), the same geometry that makes
//! the land's echo and its shadow.

use crate::land::Land;
use crate::signal::clutter_map::ClutterMap;
use serde::Serialize;

/// The land of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LandTruth {
    /// Spokes (rows).
    pub spokes: usize,
    /// Range bins (columns).
    pub range_bins: usize,
    /// Each cell's polygon index, −1 where the cell's echo is not land's (water, land in
    /// shadow, beyond the record); spokes × bins row-major.
    pub polygon: Vec<i32>,
    /// The polygons, in scene order.
    pub polygons: Vec<LandPolygonTruth>,
}

/// One land polygon in a frame's truth.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LandPolygonTruth {
    /// Index (the value in `land_polygon.npy`).
    pub id: usize,
    /// Name.
    pub name: String,
    /// Where it came from: `file: feature k ("name")` or `land[i].polygon_m`.
    pub source: String,
    /// Which `[[land]]` table.
    pub table: usize,
    /// Terrain.
    pub terrain: &'static str,
    /// Height of its top, m.
    pub top_m: f64,
    /// Polar cells whose echo is its (0 when it is hidden or out of range).
    pub cells: usize,
}

impl LandTruth {
    /// The land of `map` (records of at least `range_bins` samples), None when no spoke
    /// meets land.
    pub fn of(map: &ClutterMap, land: &Land, range_bins: usize) -> Option<LandTruth> {
        if land.is_empty() || !map.has_land() {
            return None;
        }
        let (spokes, samples) = map.shape();
        let mut polygon = vec![-1i32; spokes * range_bins];
        let mut cells = vec![0usize; land.polygons().len()];
        for k in 0..spokes {
            for n in 0..range_bins.min(samples) {
                if let Some(p) = map.land_polygon(k, n) {
                    polygon[k * range_bins + n] = p as i32;
                    cells[p] += 1;
                }
            }
        }
        let polygons = land
            .polygons()
            .iter()
            .enumerate()
            .map(|(id, p)| LandPolygonTruth {
                id,
                name: p.name.clone(),
                source: p.source.clone(),
                table: p.table,
                terrain: p.terrain.as_str(),
                top_m: p.top_m,
                cells: cells[id],
            })
            .collect();
        Some(LandTruth {
            spokes,
            range_bins,
            polygon,
            polygons,
        })
    }

    /// `land_mask.npy`'s values: 1 where the cell's echo is land's, else 0.
    pub fn mask(&self) -> Vec<u8> {
        self.polygon.iter().map(|&p| u8::from(p >= 0)).collect()
    }
}
