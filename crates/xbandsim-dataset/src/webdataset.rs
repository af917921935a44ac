//! WebDataset tar shards (`--format webdataset`; docs/formats.md, "Dataset directory"):
//! shard t holds samples `[t·N, (t+1)·N)` in index order. A sample's files are members
//! named `<index as 9 digits>.<file>`, a sequence's `frame_KKKK/` written `frame_KKKK.`
//! (`000000042.frame_0000.ppi_gray.png`), so WebDataset's key, the name up to its first dot,
//! is the sample. Every header is fixed (mode 0644, mtime 0, uid and gid 0, no user names),
//! so the same samples give the same bytes.
//!
//! A shard is written to `shards/shard-TTTTTT.tar.partial-<process tag>` with its manifest
//! (`shard-TTTTTT.manifest.json`: its samples, every member's size and sha256, the tar's own
//! sha256 and size); the tar is renamed into place, then the manifest, and a shard is done
//! when its manifest is there. A run stopped at any moment redoes only unfinished shards.

use crate::error::{at, DatasetError, Result};
use crate::layout::{hex, sha256_hex, Format, ManifestMember, ShardManifest};
use crate::render::{render_sample, SampleFiles};
use crate::spec::DatasetSpec;
use rayon::prelude::*;
use sha2::Digest;
use std::io::{Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

// Names this module's users reach through it ([`crate::layout`] defines them).
pub use crate::layout::{
    manifest_path, member_name, missing_samples, shard_count, shard_path, shard_samples,
};

/// A writer that hashes and counts what passes through.
struct Hashing<W: Write> {
    inner: W,
    hasher: sha2::Sha256,
    bytes: u64,
}

impl<W: Write> Write for Hashing<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hasher.update(&buf[..n]);
        self.bytes += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// What [`make_shards`] did, in samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ShardsMade {
    /// Samples of the tar shards asked for.
    pub in_shards: u64,
    /// Those in shards already done (skipped).
    pub skipped: u64,
    /// Those in shards made now.
    pub made: u64,
}

/// Makes the tar shards `shards` (in order) of the dataset of `count` samples made with
/// `seed`, `per_shard` to a shard, that are not done yet.
pub fn make_shards(
    spec: &DatasetSpec,
    out: &Path,
    (seed, count, per_shard): (u64, u64, u64),
    shards: &[u64],
    sample_done: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<ShardsMade> {
    if per_shard == 0 {
        return Err(DatasetError::argument(
            "--shard-samples",
            "0: a shard needs at least one sample".into(),
        ));
    }
    let samples = |t: &u64| shard_samples(*t, per_shard, count).count() as u64;
    let mut summary = ShardsMade {
        in_shards: shards.iter().map(samples).sum(),
        ..Default::default()
    };
    for &t in shards {
        if manifest_path(out, t).is_file() {
            summary.skipped += samples(&t);
            continue;
        }
        if stop.load(Ordering::Relaxed) {
            return Err(DatasetError::Interrupted { made: summary.made });
        }
        let written = write_shard(spec, out, seed, t, per_shard, count, sample_done, stop);
        if let Err(DatasetError::Interrupted { .. }) = written {
            return Err(DatasetError::Interrupted { made: summary.made });
        }
        written?;
        summary.made += samples(&t);
    }
    Ok(summary)
}

/// The samples of the tar shards `shards` that are not done yet (no manifest), in order.
pub fn pending_samples(out: &Path, count: u64, per_shard: u64, shards: &[u64]) -> Vec<u64> {
    if per_shard == 0 {
        return Vec::new();
    }
    shards
        .iter()
        .filter(|&&t| !manifest_path(out, t).is_file())
        .flat_map(|&t| shard_samples(t, per_shard, count))
        .collect()
}

fn write_shard(
    spec: &DatasetSpec,
    out: &Path,
    seed: u64,
    t: u64,
    per_shard: u64,
    count: u64,
    sample_done: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<()> {
    let path = shard_path(out, t);
    let dir = path.parent().unwrap_or(out).to_path_buf();
    at(&dir, std::fs::create_dir_all(&dir))?;
    let suffix = xbandsim::products::output::temp_suffix();
    let tmp = path.with_extension(format!("tar.partial-{suffix}"));
    let manifest_file = manifest_path(out, t);
    let manifest_tmp = manifest_file.with_extension(format!("json.partial-{suffix}"));
    let written = fill_shard(
        spec,
        (seed, t, per_shard, count),
        (&path, &tmp),
        (&manifest_file, &manifest_tmp),
        sample_done,
        stop,
    );
    if written.is_err() {
        // Stopped or failed (a full disk): nothing half-written stays behind.
        let _ = std::fs::remove_file(&tmp);
        let _ = std::fs::remove_file(&manifest_tmp);
    }
    written
}

/// Renders shard `t`'s samples into the tar `tmp` and its manifest into `manifest_tmp`, then
/// renames both into place (the tar first: a shard is done when its manifest is there).
fn fill_shard(
    spec: &DatasetSpec,
    (seed, t, per_shard, count): (u64, u64, u64, u64),
    (path, tmp): (&Path, &Path),
    (manifest_file, manifest_tmp): (&Path, &Path),
    sample_done: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<()> {
    let file = at(tmp, std::fs::File::create(tmp))?;
    let mut builder = tar::Builder::new(Hashing {
        inner: std::io::BufWriter::new(file),
        hasher: sha2::Sha256::new(),
        bytes: 0,
    });
    let format = Format::WebDataset {
        samples_per_shard: per_shard,
    };
    let indices: Vec<u64> = shard_samples(t, per_shard, count).collect();
    let mut members = Vec::new();
    // A few samples per worker at a time, appended in index order: memory stays bounded.
    let chunk = (rayon::current_num_threads() * 2).max(1);
    for block in indices.chunks(chunk) {
        if stop.load(Ordering::Relaxed) {
            return Err(DatasetError::Interrupted { made: 0 });
        }
        let rendered: Vec<Result<SampleFiles>> = block
            .par_iter()
            .map(|&i| {
                let r = render_sample(spec, seed, i, format);
                sample_done();
                r
            })
            .collect();
        for (&i, files) in block.iter().zip(rendered) {
            for (rel, bytes) in files? {
                let name = member_name(i, &rel);
                let mut header = tar::Header::new_ustar();
                at(tmp, header.set_path(&name))?;
                header.set_size(bytes.len() as u64);
                header.set_mode(0o644);
                header.set_mtime(0);
                header.set_uid(0);
                header.set_gid(0);
                header.set_entry_type(tar::EntryType::Regular);
                header.set_cksum();
                at(tmp, builder.append(&header, bytes.as_slice()))?;
                members.push(ManifestMember {
                    sha256: sha256_hex(&bytes),
                    size: bytes.len() as u64,
                    name,
                });
            }
        }
    }
    let mut hashing = at(tmp, builder.into_inner())?;
    at(tmp, hashing.flush())?;
    let tar_sha = hex(&hashing.hasher.finalize());
    let text = ShardManifest::bytes(
        t,
        shard_samples(t, per_shard, count),
        &members,
        hashing.bytes,
        &tar_sha,
    )?;
    at(manifest_tmp, std::fs::write(manifest_tmp, text))?;
    at(path, std::fs::rename(tmp, path))?;
    at(manifest_file, std::fs::rename(manifest_tmp, manifest_file))
}

/// Calls `f(member name, bytes)` for every member of the tar at `path` that `want` accepts,
/// in order (the others are skipped unread).
pub fn for_each_member(
    path: &Path,
    want: &dyn Fn(&str) -> bool,
    f: &mut dyn FnMut(String, Vec<u8>) -> Result<()>,
) -> Result<()> {
    let file = at(path, std::fs::File::open(path))?;
    // Members not wanted are seeked over, not read (a shard is mostly images and records).
    let mut archive = tar::Archive::new(file);
    for entry in at(path, archive.entries_with_seek())? {
        let mut entry = at(path, entry)?;
        let name = at(path, entry.path())?.to_string_lossy().to_string();
        if !want(&name) {
            continue;
        }
        let mut bytes = Vec::with_capacity(entry.size() as usize);
        at(path, entry.read_to_end(&mut bytes))?;
        f(name, bytes)?;
    }
    Ok(())
}

/// A reader that hashes what passes through.
struct HashingReader<R: Read> {
    inner: R,
    hasher: sha2::Sha256,
}

impl<R: Read> Read for HashingReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.hasher.update(&buf[..n]);
        Ok(n)
    }
}

/// What is wrong with shard t, if anything: its tar and manifest present, every member's
/// sha256 and the tar's own as the manifest says, no member more or less (read as a stream).
pub fn check_shard(out: &Path, t: u64) -> Option<String> {
    let manifest = match std::fs::read(manifest_path(out, t))
        .map_err(|e| e.to_string())
        .and_then(|b| ShardManifest::parse(&b))
    {
        Ok(m) => m,
        Err(e) => return Some(format!("manifest: {e}")),
    };
    let path = shard_path(out, t);
    let file = match std::fs::File::open(&path) {
        Ok(f) => f,
        Err(e) => return Some(format!("{}: {e}", path.display())),
    };
    let mut reader = HashingReader {
        inner: std::io::BufReader::new(file),
        hasher: sha2::Sha256::new(),
    };
    let listed = &manifest.members;
    let mut k = 0;
    {
        let mut archive = tar::Archive::new(&mut reader);
        let entries = match archive.entries() {
            Ok(e) => e,
            Err(e) => return Some(format!("{}: {e}", path.display())),
        };
        for entry in entries {
            let mut entry = match entry {
                Ok(e) => e,
                Err(e) => return Some(format!("{}: {e}", path.display())),
            };
            let name = entry
                .path()
                .map(|p| p.to_string_lossy().to_string())
                .unwrap_or_default();
            let mut data = Vec::new();
            if let Err(e) = entry.read_to_end(&mut data) {
                return Some(format!("{name}: {e}"));
            }
            let Some(m) = listed.get(k) else {
                return Some(format!("{name}: not in the manifest"));
            };
            if let Some(problem) = ShardManifest::member_problem(m, &name, &data) {
                return Some(problem);
            }
            k += 1;
        }
    }
    if k != listed.len() {
        return Some(format!("{} members missing", listed.len() - k));
    }
    // The rest of the file (the end-of-archive blocks) into the hash.
    if let Err(e) = std::io::copy(&mut reader, &mut std::io::sink()) {
        return Some(format!("{}: {e}", path.display()));
    }
    let sha = hex(&reader.hasher.finalize());
    (sha != manifest.tar_sha256)
        .then(|| format!("{}: sha256 differs from the manifest", path.display()))
}
