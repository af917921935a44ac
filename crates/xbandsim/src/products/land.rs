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
    /// Each cell's structure (its object id), −1 where the cell is not a structure's seen
    /// footprint; spokes × bins row-major, and empty when the scene has no structures.
    pub structure: Vec<i32>,
    /// The structures, in scene order.
    pub structures: Vec<StructureTruth>,
}

/// One structure in a frame's truth.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StructureTruth {
    /// Its object id (the value in `structure_mask.npy`; its echo's label is that object's).
    pub id: u32,
    /// Name.
    pub name: String,
    /// Where it came from: `structure[i].polygon_m`, `file: feature k ("name")`, ….
    pub source: String,
    /// Height of its top over the sea, m (its base is its object's `position_m[2]`).
    pub top_m: f64,
    /// Polar cells of its footprint in view (0 when hidden or out of range).
    pub cells: usize,
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
        if land.has_no_surface() || !map.has_land() {
            return None;
        }
        let (spokes, samples) = map.shape();
        let mut polygon = vec![-1i32; spokes * range_bins];
        let mut cells = vec![0usize; land.polygons().len()];
        let footprints = &land.surface()[land.polygons().len()..];
        let mut structure = vec![
            -1i32;
            if footprints.is_empty() {
                0
            } else {
                spokes * range_bins
            }
        ];
        let mut structure_cells = vec![0usize; footprints.len()];
        for k in 0..spokes {
            for n in 0..range_bins.min(samples) {
                if let Some(p) = map.land_polygon(k, n) {
                    polygon[k * range_bins + n] = p as i32;
                    cells[p] += 1;
                } else if let Some(s) = map.structure_at(k, n) {
                    structure[k * range_bins + n] =
                        footprints[s].structure.map_or(-1, |o| o as i32);
                    structure_cells[s] += 1;
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
        let structures = footprints
            .iter()
            .zip(&structure_cells)
            .map(|(f, &cells)| StructureTruth {
                id: f.structure.unwrap_or_default(),
                name: f.name.clone(),
                source: f.source.clone(),
                top_m: f.top_m,
                cells,
            })
            .collect();
        Some(LandTruth {
            spokes,
            range_bins,
            polygon,
            polygons,
            structure,
            structures,
        })
    }

    /// Whether the scene has structures (`structure_mask.npy` is written).
    pub fn has_structures(&self) -> bool {
        !self.structures.is_empty()
    }

    /// `land_mask.npy`'s values: 1 where the cell's echo is land's, else 0.
    pub fn mask(&self) -> Vec<u8> {
        self.polygon.iter().map(|&p| u8::from(p >= 0)).collect()
    }
}
