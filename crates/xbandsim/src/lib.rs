//! # xbandsim
//!
//! A physics-based X-band marine radar simulator: a 3D scene becomes what a rotating
//! pulse-compression radar shows — polar (B-scope) power in dB over noise, PPI images and
//! per-object ground truth.
//!
//! Modules follow the pipeline: [`scene`] → [`geometry`] → [`scattering`] → [`antenna`] /
//! [`echo`] → [`waveform`] / [`receiver`] / [`processing`] → [`ppi`] / [`labels`], orchestrated
//! by [`sim`]. Every equation is listed with its source in `docs/physics.md`.
//!
//! ```no_run
//! use xbandsim::{scene::Scene, sim::Simulation};
//! let scene = Scene::load(std::path::Path::new("scenes/paper.toml")).unwrap();
//! let frame = Simulation::new(scene).render(42);
//! println!("{} spokes x {} bins", frame.spokes, frame.range_bins);
//! ```

pub mod antenna;
pub mod constants;
pub mod echo;
pub mod environment;
pub mod error;
pub mod geometry;
pub mod labels;
pub mod output;
pub mod ppi;
pub mod processing;
pub mod receiver;
pub mod scattering;
pub mod scene;
pub mod sim;
pub mod waveform;

pub use error::{Error, Result};
