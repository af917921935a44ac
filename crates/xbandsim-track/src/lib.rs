//! # xbandsim-track
//!
//! An ARPA-class tracker for the plots of xbandsim's extractor
//! (`xbandsim::processing::plots`): what a marine radar's automatic radar plotting aid does
//! with its plots, as the baseline a learned tracker is measured against (docs/tracking.md).
//!
//! - [`filter`]: Kalman filters of constant velocity and coordinated turns on the local ENU
//!   plane;
//! - [`imm`]: the interacting multiple model estimator over them;
//! - [`assign`]: global-nearest-neighbour assignment (the Hungarian method);
//! - [`tracker`]: plots to measurements (own-ship motion compensated), gating, association,
//!   M-of-N initiation, lost and merged tracks, CPA/TCPA.

pub mod assign;
pub mod filter;
pub mod imm;
pub mod tracker;

pub use tracker::{
    closest_approach, Scan, ScanReport, Track, TrackEnd, TrackReport, TrackStatus, Tracker,
    TrackerSettings,
};
