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
//!   M-of-N initiation with a track score, lost and merged tracks, CPA/TCPA;
//! - [`accuracy`]: tracked-target accuracy against the IMO table after 1 and 3 minutes;
//! - [`score`]: MOTA, MOTP and HOTA against the truth, summed over sequences.

pub mod accuracy;
pub mod assign;
pub mod baseline;
pub mod filter;
pub mod imm;
pub mod score;
pub mod tracker;

pub use accuracy::{AccuracySample, AccuracyTally, RowResult, IMO_ACCURACY};
pub use score::{SequenceScorer, TrackingFigures, TrackingScore};
pub use tracker::{
    closest_approach, Scan, ScanReport, Track, TrackEnd, TrackReport, TrackStatus, Tracker,
    TrackerSettings,
};
