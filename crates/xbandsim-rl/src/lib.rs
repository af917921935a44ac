//! # xbandsim-rl
//!
//! The reinforcement-learning core behind the Gymnasium environments `xbandsim/Detection-v0`
//! and `xbandsim/Tracking-v0` (the Python package wraps it and converts types, nothing
//! else): the seed paper's MDP (§V.B) with a radar operator's controls. Each step is one
//! antenna revolution simulated by the library:
//!
//! - [`curriculum`] draws an episode's scene from a level (sea state, rain cells, own ship,
//!   moving point targets);
//! - [`action`] is what the operator sets: scan or quadrant dwell, pulse, gain, sea and rain
//!   clutter controls, pulses per spoke;
//! - [`display`] is the display chain (FTC, STC, gain) and the plot extractor;
//! - [`episode`] runs the revolutions, tracks the plots with the baseline ARPA tracker
//!   (`xbandsim-track`) and scores plots or tracks against the ground truth.
//!
//! docs/rl.md states the MDP, the rewards and their shaping.

pub mod action;
pub mod curriculum;
pub mod display;
pub mod episode;

pub use action::{Action, PulseChoice, Scan, ACTION_NAMES, ACTION_NVEC};
pub use curriculum::{Task, LEVELS};
pub use episode::{Episode, EpisodeConfig, Reward, StepOutcome, TargetReport};
