//! Labelled training datasets from randomised xbandsim scenes (`xbandsim dataset`,
//! docs/formats.md "Dataset spec" and "Dataset directory"): the folder's layout, names and
//! hashes ([`layout`], the leaf every other module shares), a spec of distributions
//! ([`dist`], [`spec`]), each sample's scene drawn from (spec, seed, index) alone
//! ([`sample`]), rendered into its files ([`render`]) and labelled in COCO, YOLO and table
//! form with masks from the target-only render ([`labels`], docs/formats.md "Dataset
//! labels"), written atomically with resume as folders or tar shards ([`generate`],
//! [`webdataset`]), indexed once complete ([`assemble`]), checked ([`verify`]) and
//! summarised ([`stats`]). The modules are in layers, each importing only those below it
//! (docs/architecture.md, "The dataset crate's layers").

pub mod assemble;
pub mod baseline;
pub mod check;
pub mod coast;
pub mod dist;
pub mod error;
pub mod generate;
pub mod labels;
pub mod layout;
pub mod obb;
pub mod owner;
pub mod render;
pub mod sample;
pub mod spec;
pub mod stats;
pub mod verify;
pub mod webdataset;

pub use error::{DatasetError, Result};
pub use generate::{
    generate, generate_until, make_sample, render_sample, sample_dir, Format, Request, Shard,
    Summary,
};
pub use spec::DatasetSpec;
