//! The library's integration tests, gathered in one test binary so that a fresh clone links one
//! executable instead of nine (linking dominated the cold test build). Each module is one theme;
//! the physics modules check the real pipeline against closed forms (docs/validation.md).

mod common;

mod antenna;
mod artefacts;
mod detection;
mod determinism;
mod engine;
mod environment;
mod geometry;
mod labels;
mod land;
mod layering;
mod meshes;
mod motion;
mod multipath;
mod presets;
mod pulse;
mod pulse_modes;
mod rcs;
mod scene_errors;
mod signal_chain;
mod structures;
mod targets;
mod transmitter;
mod video;
