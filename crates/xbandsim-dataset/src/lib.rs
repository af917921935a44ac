//! Labelled training datasets from randomised xbandsim scenes (`xbandsim dataset`,
//! docs/formats.md "Dataset spec" and "Dataset directory"): a spec of distributions
//! ([`dist`], [`spec`]), each sample's scene drawn from (spec, seed, index) alone
//! ([`sample`]), rendered and written atomically with resume ([`generate`]).

pub mod dist;
pub mod error;
pub mod generate;
pub mod sample;
pub mod spec;

pub use error::{DatasetError, Result};
pub use generate::{generate, make_sample, sample_dir, Request, Shard, Summary};
pub use spec::DatasetSpec;
