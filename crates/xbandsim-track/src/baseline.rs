//! The baseline's settings (docs/tracking.md, "Dataset baseline"): `xbandsim track`'s
//! defaults, which every dataset's baseline and the live radar's ARPA output also use —
//! cell-averaging CFAR with 4 guard and 16 training cells a side at a design false-alarm
//! probability of 10⁻⁸, plots of at least 3 cells, sidelobe editing at 6 dB, the tracker's
//! default settings, tracks scored within 100 m of an object.

use xbandsim::processing::cfar::{Cfar, CfarKind};
use xbandsim::processing::plots::{PlotExtractor, SidelobeEditor};

/// Guard cells a side of the baseline's CFAR.
pub const GUARD_CELLS: usize = 4;
/// Training cells a side of the baseline's CFAR.
pub const TRAINING_CELLS: usize = 16;
/// Design false-alarm probability per cell of the baseline's CFAR.
pub const PFA: f64 = 1e-8;
/// Smallest plot the baseline keeps, cells.
pub const MIN_CELLS: usize = 3;
/// Sidelobe editing margin of the baseline's extractor, dB.
pub const SIDELOBE_MARGIN_DB: f64 = 6.0;
/// Distance within which a confirmed track is scored against an object, m.
pub const TRUTH_GATE_M: f64 = 100.0;

/// The baseline's plot extractor for `scene`'s radar (its antenna's sidelobes edited out).
pub fn extractor(scene: &xbandsim::Scene) -> xbandsim::Result<PlotExtractor> {
    let cfar = Cfar::new(CfarKind::CellAveraging, GUARD_CELLS, TRAINING_CELLS, PFA)?;
    let editor = SidelobeEditor::new(&scene.radar().antenna().azimuth(), SIDELOBE_MARGIN_DB)?;
    Ok(PlotExtractor::new(cfar, MIN_CELLS)?.with_sidelobe_editing(editor))
}
