//! The dataset folder's layout (`xbandsim_dataset::layout`), for the Python package's readers
//! and its URL runs (`xbandsim.data`, `xbandsim.distributed`): names, paths relative to the
//! dataset folder (`/`-separated), the record and the manifests' checks, as Rust has them.

use super::dataset_error;
use pyo3::prelude::*;
use pyo3::pybacked::PyBackedBytes;
use pyo3::types::PyDict;
use std::path::PathBuf;
use xbandsim_dataset::layout::{self, Format, ShardManifest};

/// Sample `index`'s folder: `samples/<group>/<index>`.
#[pyfunction]
pub fn sample_dir(index: u64) -> String {
    layout::sample_rel(index)
}

/// The samples whose folders are in the dataset folder `out`, in index order.
#[pyfunction]
pub fn sample_indices(py: Python<'_>, out: PathBuf) -> PyResult<Vec<u64>> {
    layout::sample_indices(&out).map_err(|e| dataset_error(py, e))
}

/// Frame `frame`'s `file` relative to its sample (`frame_KKKK/file` in a sequence).
#[pyfunction]
pub fn frame_file(frames: u64, frame: u64, file: &str) -> String {
    layout::frame_file(frames, frame, file)
}

/// The frame of a sample's file from its relative name (None: not in a frame folder).
#[pyfunction]
pub fn frame_of(rel: &str) -> Option<u64> {
    layout::frame_of(rel)
}

/// The COCO image id annotations.json gives frame `frame` of sample `index`.
#[pyfunction]
pub fn coco_image_id(index: u64, frames: u64, frame: u64) -> u64 {
    layout::coco_image_id(index, frames, frame)
}

/// A sample's key in its tar shard (WebDataset's `__key__`).
#[pyfunction]
pub fn sample_key(index: u64) -> String {
    layout::sample_key(index)
}

/// A file's member name after the key (its `/` as `.`).
#[pyfunction]
pub fn member_extension(rel: &str) -> String {
    layout::member_extension(rel)
}

/// Sample `index`'s file `rel` as a tar shard's member name.
#[pyfunction]
pub fn member_name(index: u64, rel: &str) -> String {
    layout::member_name(index, rel)
}

/// A member's (sample, relative file name); None for a name that is not a sample's.
#[pyfunction]
pub fn parse_member_name(name: &str) -> Option<(u64, String)> {
    layout::parse_member_name(name)
}

/// Tar shards of a dataset of `count` samples, `per_shard` to a shard.
#[pyfunction]
pub fn shard_count(count: u64, per_shard: u64) -> u64 {
    layout::shard_count(count, per_shard)
}

/// The samples of tar shard `t`: (first, end).
#[pyfunction]
pub fn shard_samples(t: u64, per_shard: u64, count: u64) -> (u64, u64) {
    let r = layout::shard_samples(t, per_shard, count);
    (r.start, r.end)
}

/// Tar shard `t`'s file.
#[pyfunction]
pub fn shard_file(t: u64) -> String {
    layout::shard_rel(t)
}

/// Tar shard `t`'s manifest.
#[pyfunction]
pub fn shard_manifest_file(t: u64) -> String {
    layout::manifest_rel(t)
}

/// The shard a tar's file name is; None for another file.
#[pyfunction]
pub fn parse_shard_file_name(name: &str) -> Option<u64> {
    layout::parse_shard_file_name(name)
}

/// The index files of a complete dataset of sample folders (`shard_samples` None) or tar
/// shards.
#[pyfunction]
#[pyo3(signature = (shard_samples=None))]
pub fn index_files(shard_samples: Option<u64>) -> Vec<&'static str> {
    let format = match shard_samples {
        Some(n) => Format::WebDataset {
            samples_per_shard: n,
        },
        None => Format::Dir,
    };
    format.index_files().to_vec()
}

/// The record of the dataset in `out` (its dataset.json): `count`, `frames`, `seed`
/// (None where it has none), `shard_samples` (None for sample folders) and `cli_args`
/// (the `xbandsim dataset` options of its format).
#[pyfunction]
pub fn read_record<'py>(py: Python<'py>, out: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let r = layout::read_record(&out).map_err(|e| dataset_error(py, e))?;
    let d = PyDict::new(py);
    d.set_item("count", r.count)?;
    d.set_item("frames", r.frames)?;
    d.set_item("seed", r.seed)?;
    let per_shard = match r.format {
        Format::Dir => None,
        Format::WebDataset { samples_per_shard } => Some(samples_per_shard),
    };
    d.set_item("shard_samples", per_shard)?;
    d.set_item("cli_args", r.format.cli_args())?;
    Ok(d)
}

/// The label members (coco.json, targets.jsonl) of the shard whose manifest is at
/// `manifest`, in tar order: (name, start, end) of each one's bytes in the tar.
#[pyfunction]
pub fn shard_label_ranges(py: Python<'_>, manifest: PathBuf) -> PyResult<Vec<(String, u64, u64)>> {
    let m = ShardManifest::read(&manifest).map_err(|e| dataset_error(py, e))?;
    Ok(m.data_ranges()
        .into_iter()
        .filter(|(member, _, _)| layout::is_label_member(&member.name))
        .map(|(member, start, end)| (member.name.clone(), start, end))
        .collect())
}

/// What is wrong with members read from the shard whose manifest is at `manifest`
/// ((name, bytes) each), if anything: None when each is as the manifest lists it.
#[pyfunction]
pub fn check_shard_members(
    py: Python<'_>,
    manifest: PathBuf,
    members: Vec<(String, PyBackedBytes)>,
) -> PyResult<Option<String>> {
    let m = ShardManifest::read(&manifest).map_err(|e| dataset_error(py, e))?;
    Ok(m.check_members(members.iter().map(|(n, b)| (n.as_str(), &b[..]))))
}

/// Adds the functions and the names of the record and the card.
pub fn add(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("RECORD_FILE", layout::RECORD)?;
    m.add("CARD_FILE", layout::CARD)?;
    m.add_function(wrap_pyfunction!(sample_dir, m)?)?;
    m.add_function(wrap_pyfunction!(sample_indices, m)?)?;
    m.add_function(wrap_pyfunction!(frame_file, m)?)?;
    m.add_function(wrap_pyfunction!(frame_of, m)?)?;
    m.add_function(wrap_pyfunction!(coco_image_id, m)?)?;
    m.add_function(wrap_pyfunction!(sample_key, m)?)?;
    m.add_function(wrap_pyfunction!(member_extension, m)?)?;
    m.add_function(wrap_pyfunction!(member_name, m)?)?;
    m.add_function(wrap_pyfunction!(parse_member_name, m)?)?;
    m.add_function(wrap_pyfunction!(shard_count, m)?)?;
    m.add_function(wrap_pyfunction!(shard_samples, m)?)?;
    m.add_function(wrap_pyfunction!(shard_file, m)?)?;
    m.add_function(wrap_pyfunction!(shard_manifest_file, m)?)?;
    m.add_function(wrap_pyfunction!(parse_shard_file_name, m)?)?;
    m.add_function(wrap_pyfunction!(index_files, m)?)?;
    m.add_function(wrap_pyfunction!(read_record, m)?)?;
    m.add_function(wrap_pyfunction!(shard_label_ranges, m)?)?;
    m.add_function(wrap_pyfunction!(check_shard_members, m)?)?;
    Ok(())
}
