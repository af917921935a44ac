//! Stage: scene file. The TOML scene description as users write it ([`SceneSpec`], serde with
//! every choice an enum) and the one loader ([`LoadedSpec`]) that reads it, applies
//! `--set FIELD=VALUE` overrides and builds the validated [`Scene`](crate::model::Scene),
//! locating errors at `file:line:column` (docs/architecture.md, "Spec → model").

mod load;
mod spec;

pub use load::{assign_field, locate, LoadedSpec};
pub use spec::{
    AisClass, AntennaPatternName, ArtefactsSpec, BeaconSpec, BuiltStructureSpec,
    ClutterDistributionName, DisplaySpec, EnvironmentSpec, GeoSpec, InterfererSpec, LandCrs,
    LandEdgeName, LandSpec, MultipleEchoesSpec, ObjectSpec, OwnShipSpec, ProcessingSpec,
    PulseModeName, RadarPreset, RadarSpec, RainCellSpec, ReceiverSpec, ScatteringSpec, SceneSpec,
    ShapeName, StructureSpec, WindowName,
};
