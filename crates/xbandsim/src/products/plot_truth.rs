//! Stage: products — plots scored against the truth (docs/physics.md §15, "Scoring"): what
//! each plot of the extractor (`processing::plots`) is the echo of — a labelled object, an
//! artefact, land — or that it is a false plot.

use super::labels::PolarBox;
use super::Frame;
use crate::processing::plots::{Plot, PowerGrid};
use serde::Serialize;

/// What a plot is the echo of, by the truth of its frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PlotSource {
    /// A labelled object: the plot's box shares a cell with the object's `polar_box`.
    Object {
        /// The object's id in the truth.
        id: u32,
        /// Its name.
        name: String,
    },
    /// An artefact (sidelobe echo, second-trace echo, interference) in the truth's list.
    Artefact {
        /// Its index in the frame's artefacts.
        index: usize,
    },
    /// Land or a structure on it: a cell of the plot's box is land's in the land truth.
    Land,
    /// Nothing the truth knows: a false plot (noise, or sea clutter and rain).
    None,
}

/// A plot's cells taken to the record of `frame`: its box there (spokes may wrap). A grid
/// spoke k lies at azimuth `k·360°/K`; the box runs from the record spoke at or before its
/// first spoke to the one at or after its last (the record spokes either side of a video
/// spoke between them).
fn record_box(p: &Plot, grid: &PowerGrid, frame: &Frame) -> PolarBox {
    let record_spokes = frame.spokes;
    let scale = record_spokes as f64 / grid.spokes as f64;
    let (first, last) = p.spokes;
    let covered = (last + grid.spokes - first) % grid.spokes + 1;
    // Its last spoke counted on from its first (past the record's end when it wraps).
    let lo = (first as f64 * scale).floor() as usize;
    let hi = ((first + covered - 1) as f64 * scale).ceil() as usize;
    let (spoke_min, spoke_max) = if hi - lo + 1 >= record_spokes {
        (0, record_spokes - 1)
    } else {
        (lo % record_spokes, hi % record_spokes)
    };
    let bin = |j: usize, edge: f64| {
        (((j as f64 + edge) * grid.cell_m / frame.range_bin_m).round() as usize)
            .min(frame.range_bins.saturating_sub(1))
    };
    // A video sample spans [j, j + 1)·sample_m; a record bin is a point at j·bin_m.
    let far_edge = if grid.range_offset_cells > 0.0 {
        1.0
    } else {
        0.0
    };
    PolarBox {
        spoke_min,
        spoke_max,
        bin_min: bin(p.range_cells.0, 0.0),
        bin_max: bin(p.range_cells.1, far_edge),
    }
}

/// Whether two polar boxes share a cell.
fn boxes_overlap(a: &PolarBox, b: &PolarBox, spokes: usize) -> bool {
    if a.bin_max < b.bin_min || b.bin_max < a.bin_min {
        return false;
    }
    // a's first spoke inside b, or b's first inside a (circular intervals).
    let starts_in = |x: &PolarBox, y: &PolarBox| {
        (x.spoke_min + spokes - y.spoke_min) % spokes < y.spoke_count(spokes)
    };
    starts_in(a, b) || starts_in(b, a)
}

/// The source of each plot of `grid` (extracted from `frame`'s record or video), by the
/// frame's truth: the object whose `polar_box` shares a cell with the plot's box (the
/// nearest in range to the plot when several do), else an artefact's box, else land (a land
/// or structure cell in the plot's box), else [`PlotSource::None`].
pub fn plot_sources(plots: &[Plot], grid: &PowerGrid, frame: &Frame) -> Vec<PlotSource> {
    plots
        .iter()
        .map(|p| {
            let here = record_box(p, grid, frame);
            let object = frame
                .truth
                .iter()
                .filter(|o| {
                    o.polar_box
                        .is_some_and(|b| boxes_overlap(&b, &here, frame.spokes))
                })
                .min_by(|a, b| {
                    (a.range_m - p.range_m)
                        .abs()
                        .total_cmp(&(b.range_m - p.range_m).abs())
                });
            if let Some(o) = object {
                return PlotSource::Object {
                    id: o.id,
                    name: o.name.clone(),
                };
            }
            if let Some(index) = frame.artefacts.iter().position(|a| {
                a.polar_boxes
                    .iter()
                    .any(|b| boxes_overlap(b, &here, frame.spokes))
            }) {
                return PlotSource::Artefact { index };
            }
            if let Some(land) = &frame.land {
                let on_land = here.spoke_indices(frame.spokes).any(|k| {
                    (here.bin_min..=here.bin_max.min(land.range_bins - 1)).any(|j| {
                        // A land truth without structures has no structure grid.
                        let cell = k * land.range_bins + j;
                        let on = |grid: &[i32]| grid.get(cell).is_some_and(|&v| v >= 0);
                        on(&land.polygon) || on(&land.structure)
                    })
                });
                if on_land {
                    return PlotSource::Land;
                }
            }
            PlotSource::None
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plot_on(spokes: (usize, usize)) -> Plot {
        Plot {
            range_m: 100.0,
            azimuth_deg: 0.0,
            range_extent_m: 10.0,
            azimuth_extent_deg: 1.0,
            cells: 1,
            peak_db: 20.0,
            peak_cell: (spokes.0, 10),
            spokes,
            range_cells: (10, 12),
        }
    }

    /// Plots of a 2048-spoke video taken to a 360-spoke record: a whole ring stays whole, a
    /// spoke between two record spokes takes both, a record plot keeps its own spokes.
    #[test]
    fn plot_boxes_in_the_record() {
        let frame = Frame {
            frame: 0,
            start_time_s: 0.0,
            own_ship: None,
            spokes: 360,
            range_bins: 1000,
            range_bin_m: 1.5,
            polar_db: Vec::new(),
            doppler_cube: None,
            iq: None,
            radial_velocity: None,
            video: None,
            artefacts: Vec::new(),
            truth: Vec::new(),
            land: None,
            stats: Default::default(),
        };
        let video = PowerGrid {
            spokes: 2048,
            cells: 512,
            cell_m: 3.0,
            range_offset_cells: 0.5,
            power: Vec::new(),
        };
        // A whole ring, and rings but for a gap narrower than a record spoke.
        for spokes in [(0, 2047), (0, 2045), (2, 0), (3, 1), (100, 95)] {
            let ring = record_box(&plot_on(spokes), &video, &frame);
            assert_eq!((ring.spoke_min, ring.spoke_max), (0, 359), "{spokes:?}");
        }
        // Video spoke 1000 at 175.78°: record spokes 175 and 176; samples 10–12 span
        // 30–39 m, record bins 20–26.
        let one = record_box(&plot_on((1000, 1000)), &video, &frame);
        assert_eq!(
            (one.spoke_min, one.spoke_max, one.bin_min, one.bin_max),
            (175, 176, 20, 26)
        );
        let across = record_box(&plot_on((2040, 5)), &video, &frame);
        assert_eq!((across.spoke_min, across.spoke_max), (358, 1));
        let record = PowerGrid {
            spokes: 360,
            cells: 1000,
            cell_m: 1.5,
            range_offset_cells: 0.0,
            power: Vec::new(),
        };
        let own = record_box(&plot_on((359, 2)), &record, &frame);
        assert_eq!(
            (own.spoke_min, own.spoke_max, own.bin_min, own.bin_max),
            (359, 2, 10, 12)
        );
    }

    #[test]
    fn boxes_overlap_on_the_circle_of_spokes() {
        assert!(boxes_overlap(
            &PolarBox {
                spoke_min: 358,
                spoke_max: 2,
                bin_min: 40,
                bin_max: 44
            },
            &PolarBox {
                spoke_min: 1,
                spoke_max: 5,
                bin_min: 44,
                bin_max: 50
            },
            360
        ));
        assert!(boxes_overlap(
            &PolarBox {
                spoke_min: 1,
                spoke_max: 5,
                bin_min: 44,
                bin_max: 50
            },
            &PolarBox {
                spoke_min: 350,
                spoke_max: 1,
                bin_min: 0,
                bin_max: 44
            },
            360
        ));
        assert!(!boxes_overlap(
            &PolarBox {
                spoke_min: 358,
                spoke_max: 2,
                bin_min: 40,
                bin_max: 44
            },
            &PolarBox {
                spoke_min: 3,
                spoke_max: 357,
                bin_min: 0,
                bin_max: 100
            },
            360
        ));
        assert!(!boxes_overlap(
            &PolarBox {
                spoke_min: 358,
                spoke_max: 2,
                bin_min: 40,
                bin_max: 44
            },
            &PolarBox {
                spoke_min: 0,
                spoke_max: 0,
                bin_min: 45,
                bin_max: 100
            },
            360
        ));
    }
}
