//! Choices a scene file names, shared by the modules that describe, validate and use them:
//! the file's description (`crate::scene`) and the modules that act on each choice (shapes,
//! radar, processing, scattering, display). A leaf: it imports nothing of the crate, so that
//! no module has to import one above it to name a choice (docs/architecture.md, "Layers").
//! Each enum's behaviour stays with the module it belongs to.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `object.shape`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum ShapeName {
    /// A point of given RCS (`rcs_m2`); no geometry.
    Point,
    /// A sphere (`radius_m`).
    Sphere,
    /// A flat rectangular plate (`width_m`, `height_m`).
    Plate,
    /// A triangular trihedral corner reflector (`edge_m`).
    Trihedral,
    /// A dihedral corner (`width_m`, `height_m`).
    Dihedral,
    /// A vertical cylinder (`radius_m`, `height_m`).
    Cylinder,
    /// A box (`size_m`).
    Box,
    /// A triangle mesh from a file (`mesh_file`, `mesh_units`, `mesh_scale`).
    Mesh,
    /// A procedural vessel (`length_m`; `beam_m`, `freeboard_m`, `superstructure`,
    /// `superstructure_height_m`, `mast_height_m`).
    Vessel,
    /// A procedural buoy (`radius_m`, `height_m`; `mast_height_m`, `reflector_edge_m`).
    Buoy,
}

/// How the pulses of a spoke are combined into its row of the record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Integration {
    /// Mean power of the spoke's pulses.
    #[default]
    Noncoherent,
    /// Power of the coherent sum over the number of pulses, `|Σ y_m|²/M` (zero-Doppler
    /// filter: +10·log10 M on a still target, noise stays at 0 dB).
    Coherent,
    /// The one pulse nearest the spoke's azimuth, alone.
    None,
}

/// Linear polarisation used for both transmit and receive: "HH" or "VV" in a scene file
/// (any case; "H" and "V" also read).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
pub enum Polarisation {
    /// Horizontal transmit, horizontal receive.
    #[serde(rename = "HH", alias = "hh", alias = "Hh", alias = "H", alias = "h")]
    Hh,
    /// Vertical transmit, vertical receive.
    #[serde(rename = "VV", alias = "vv", alias = "Vv", alias = "V", alias = "v")]
    Vv,
}

/// How a revolution's pulses are fired.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum ProcessingMode {
    /// One pulse per spoke, one scene state per revolution (each object where the beam
    /// crosses it): the fast path.
    #[default]
    Spoke,
    /// Every pulse at the PRF while the antenna turns; each pulse sees the scene at its own
    /// time (moving echoes advance in phase and delay from pulse to pulse).
    Pulse,
}

/// Which scattering amplitude model turns ray hits into echoes.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum ScatteringModel {
    /// Physical-optics ray tubes calibrated to the radar equation.
    #[serde(rename = "po")]
    PhysicalOptics,
    /// The seed paper's law `A = 1/(1 + ℓ²/1000)` on a uniform scan grid (uncalibrated).
    Paper,
}

/// Colour map for `ppi.png`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Colormap {
    /// Perceptually uniform blue–green–yellow.
    Viridis,
    /// Black to green, like a phosphor display.
    Green,
    /// Black to white ("grey" also reads).
    #[serde(alias = "grey")]
    Gray,
}

/// `display.motion`: what the PPI keeps fixed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Motion {
    /// Relative motion: the own ship (the antenna) at the image centre; the picture moves
    /// past it.
    #[default]
    Relative,
    /// True motion: the picture fixed to the ground, centred on the antenna's position at
    /// t = 0; the own ship moves across it.
    True,
}

/// `display.orientation`: which true bearing the PPI shows straight up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Orientation {
    /// North at the top.
    #[default]
    NorthUp,
    /// The own ship's heading at the top (needs `[own_ship]`).
    HeadUp,
    /// The own ship's course over ground at the top (its heading while it stands still;
    /// needs `[own_ship]`).
    CourseUp,
}

/// `radar.transmitter`: what makes the pulse.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Transmitter {
    /// A solid-state set: a coded pulse (LFM chirp) compressed by the matched filter, coherent
    /// from pulse to pulse.
    #[default]
    SolidState,
    /// A magnetron: an unmodulated pulse (no compression: a receiver matched to the pulse),
    /// each pulse starting at a random phase (no coherence from pulse to pulse).
    Magnetron,
}

/// `radar.pulse_length`: which of a preset's pulses a range scale fires (docs/formats.md,
/// "Radar presets").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum PulseLength {
    /// The shortest pulse: best range resolution, least energy.
    Short,
    /// The middle pulse.
    Medium,
    /// The longest pulse: most energy, coarsest range resolution.
    Long,
}

impl PulseLength {
    /// The name a scene file uses.
    pub fn name(self) -> &'static str {
        match self {
            PulseLength::Short => "short",
            PulseLength::Medium => "medium",
            PulseLength::Long => "long",
        }
    }
}

/// `receiver.stc`: the sea clutter control.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum StcMode {
    /// No sensitivity time control.
    #[default]
    Off,
    /// The manual law: `stc_level_db`, `stc_range_m`, `stc_law`.
    Manual,
    /// Adapts to the clutter measured along range in the scan.
    Auto,
}

/// `receiver.interference_rejection`: how strictly a sample must correlate with the
/// neighbouring sweeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum InterferenceRejection {
    /// Off.
    #[default]
    Off,
    /// A sample may exceed the stronger neighbouring sweep by 6 dB.
    Low,
    /// By 2 dB.
    Medium,
    /// It may not exceed the weaker neighbouring sweep.
    High,
}
