//! # xbandsim
//!
//! A physics-based X-band marine radar simulator: a 3D scene becomes what a rotating
//! pulse-compression radar shows — polar (B-scope) power in dB over noise, PPI images and
//! per-object ground truth.
//!
//! The few types a user needs are re-exported at the top (the facade the CLI, the Python
//! binding and the dataset generator use): [`LoadedSpec`] reads a scene file and its
//! overrides, [`Scene`] is the validated model, [`Simulation`] renders [`Frame`]s with their
//! per-object [`ObjectTruth`], and [`Error`] says what went wrong ([`Problem`], [`Location`]).
//! The modules follow the pipeline: [`scene`] (the file) → [`model`] (the validated scene) →
//! [`geometry`] → [`scattering`] / [`propagation`] / [`environment`] → [`antenna`] / [`echo`]
//! → [`waveform`] / [`receiver`] / [`processing`] → [`products`] (frame, labels, PPI, files),
//! run by the [`engine`] on a schedule; [`rng`], [`special`] and [`constants`] serve them all.
//! docs/architecture.md maps them. Every equation is listed with its source in
//! `docs/physics.md`.
//!
//! ```no_run
//! use xbandsim::{LoadedSpec, Simulation};
//! let spec = LoadedSpec::read("scenes/paper.toml".as_ref())?
//!     .with_overrides(&["radar.pulse_width_us=2"])?;
//! let frame = Simulation::new(spec.build()?).render(42);
//! println!("{} spokes x {} bins", frame.spokes, frame.range_bins);
//! # Ok::<(), xbandsim::Error>(())
//! ```

pub mod antenna;
pub mod cache;
pub mod choice;
pub mod constants;
pub mod echo;
pub mod engine;
pub mod environment;
pub mod error;
pub mod geometry;
pub mod land;
pub mod model;
pub mod processing;
pub mod products;
pub mod propagation;
pub mod receiver;
pub mod rng;
pub mod scattering;
pub mod scene;
pub mod schedule;
pub mod signal;
pub mod special;
pub mod targets;
pub mod waveform;

pub use engine::Simulation;
pub use error::{Error, Location, Problem, Result};
pub use model::Scene;
pub use products::labels::{ObjectTruth, Visibility};
pub use products::ppi::PpiSettings;
pub use products::Frame;
pub use scene::{LoadedSpec, SceneSpec};
