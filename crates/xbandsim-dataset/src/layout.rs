//! What a dataset folder is made of, and nothing that makes it (docs/formats.md, "Dataset
//! directory"): the storage formats, every file's and folder's name, which samples a tar shard
//! holds, the sha256 lists that say a sample or shard is whole, and the dataset record
//! `dataset.json`. The leaf of the crate: it imports only [`crate::error`], so the modules that
//! write a dataset ([`crate::generate`], [`crate::webdataset`], [`crate::assemble`]) and those
//! that read one ([`crate::stats`], [`crate::verify`], the Python package) share one source.
//!
//! ```text
//! DIR/dataset.json                        the record: spec, seed, count, format, version
//! DIR/samples/000000/000000042/           sample 42 (groups of 1000 samples per folder)
//!     files.sha256                        sha256 of every other file, written last
//!     frame_0000/ frame_0001/ …           a sequence's frames (a single frame: no folder)
//! DIR/shards/shard-000003.tar             tar shard 3: samples [3·N, 4·N)
//! DIR/shards/shard-000003.manifest.json   its members' sizes and sha256, written last
//!     000000042.frame_0000.ppi_gray.png   a member: <index as 9 digits>.<file, / as .>
//! ```

use crate::error::{at, invalid_data, DatasetError, Result};
use std::path::{Path, PathBuf};

/// The dataset record: spec, seed, count, format and software version.
pub const RECORD: &str = "dataset.json";

/// The dataset card, the last index file an assembly writes: without it the index files
/// are missing or unfinished.
pub const CARD: &str = "README.md";

/// Each sample folder's list of its files' sha256, written last.
pub const MANIFEST: &str = "files.sha256";

/// Samples per group folder under `samples/`.
pub const SAMPLES_PER_GROUP: u64 = 1000;

/// The files each frame of a sample must have (besides one PPI image).
pub const FRAME_FILES: [&str; 6] = [
    "polar.npy",
    "truth.json",
    "coco.json",
    "yolo.txt",
    "yolo_obb.txt",
    "targets.jsonl",
];

/// The index files of a complete dataset of sample folders.
pub const INDEX_FILES: [&str; 6] = [
    "annotations.json",
    "targets.jsonl",
    "baseline.jsonl",
    "yolo/data.yaml",
    "yolo_obb/data.yaml",
    CARD,
];

/// The index files of a complete dataset of tar shards (no YOLO trees: each sample's
/// yolo.txt and yolo_obb.txt are in its shard).
pub const SHARD_INDEX_FILES: [&str; 4] =
    ["annotations.json", "targets.jsonl", "baseline.jsonl", CARD];

/// How a dataset's samples are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// A folder per sample under `samples/`.
    Dir,
    /// WebDataset tar shards of `samples_per_shard` consecutive samples under `shards/`.
    WebDataset {
        /// Samples per tar shard.
        samples_per_shard: u64,
    },
}

impl Format {
    /// Where sample `index`'s image of frame `frame` is, as its labels name it: a path
    /// relative to the dataset folder, or a tar member's name.
    pub fn image_name(&self, index: u64, frames: u64, frame: u64, file: &str) -> String {
        match self {
            Format::Dir => {
                let sub = frame_subdir(frames, frame);
                let rel = sample_dir(Path::new(""), index).join(&sub).join(file);
                rel.to_string_lossy().replace('\\', "/")
            }
            Format::WebDataset { .. } => member_name(index, &frame_file(frames, frame, file)),
        }
    }

    /// The index files of a complete dataset stored so.
    pub fn index_files(&self) -> &'static [&'static str] {
        match self {
            Format::Dir => &INDEX_FILES,
            Format::WebDataset { .. } => &SHARD_INDEX_FILES,
        }
    }

    /// The `xbandsim dataset` options that choose this format (none for folders), each
    /// after a space.
    pub fn cli_args(&self) -> String {
        match self {
            Format::Dir => String::new(),
            Format::WebDataset { samples_per_shard } => {
                format!(" --format webdataset --shard-samples {samples_per_shard}")
            }
        }
    }
}

/// Folder of sample `index` under `out`.
pub fn sample_dir(out: &Path, index: u64) -> PathBuf {
    out.join("samples")
        .join(format!("{:06}", index / SAMPLES_PER_GROUP))
        .join(format!("{index:09}"))
}

/// Folder of sample `index` relative to the dataset folder, `/`-separated.
pub fn sample_rel(index: u64) -> String {
    format!("samples/{:06}/{index:09}", index / SAMPLES_PER_GROUP)
}

/// The samples whose folders are in `out` (each at its [`sample_dir`]; other entries of
/// `samples/` are not samples), in index order. Reads the folders only: a folder there is
/// whole, as samples are renamed into place.
pub fn sample_indices(out: &Path) -> Result<Vec<u64>> {
    let root = out.join("samples");
    let mut found = Vec::new();
    for group in at(&root, std::fs::read_dir(&root))? {
        let group = at(&root, group)?;
        let Some(g) = whole_number(&group.file_name().to_string_lossy()) else {
            continue;
        };
        let dir = group.path();
        if !dir.is_dir() {
            continue;
        }
        for entry in at(&dir, std::fs::read_dir(&dir))? {
            let entry = at(&dir, entry)?;
            let name = entry.file_name().to_string_lossy().to_string();
            if let Some(i) = whole_number(&name) {
                if i / SAMPLES_PER_GROUP == g
                    && sample_dir(out, i) == out.join("samples").join(group.file_name()).join(&name)
                    && entry.path().is_dir()
                {
                    found.push(i);
                }
            }
        }
    }
    found.sort_unstable();
    Ok(found)
}

/// `text` as a whole number when it is ASCII digits only.
fn whole_number(text: &str) -> Option<u64> {
    (!text.is_empty() && text.bytes().all(|b| b.is_ascii_digit()))
        .then(|| text.parse().ok())
        .flatten()
}

/// The folder of frame `frame` inside a sample's folder (the sample's folder itself when
/// samples are single frames).
pub fn frame_subdir(frames: u64, frame: u64) -> String {
    if frames == 1 {
        String::new()
    } else {
        format!("frame_{frame:04}")
    }
}

/// Frame `frame`'s `file` relative to its sample's folder (`frame_KKKK/file` in a sequence,
/// `file` for a single frame).
pub fn frame_file(frames: u64, frame: u64, file: &str) -> String {
    let sub = frame_subdir(frames, frame);
    if sub.is_empty() {
        file.to_string()
    } else {
        format!("{sub}/{file}")
    }
}

/// The frame a sample's file belongs to, from its relative name: K for `frame_KKKK/…`, none
/// for a file of a single-frame sample (or of the sample as a whole, scene.toml).
pub fn frame_of(rel: &str) -> Option<u64> {
    let (folder, _) = rel.split_once('/')?;
    whole_number(folder.strip_prefix("frame_")?)
}

/// The COCO image id that annotations.json gives frame `frame` of sample `index`.
pub fn coco_image_id(index: u64, frames: u64, frame: u64) -> u64 {
    index * frames + frame + 1
}

/// Lower-case hex sha256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    hex(&sha2::Sha256::digest(bytes))
}

/// Lower-case hex of a digest.
pub fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// A sample's [`MANIFEST`]: one `<sha256>  <relative name>` line per file (`sha256sum -c`
/// form), in the files' order.
pub fn sample_manifest(files: &[(String, Vec<u8>)]) -> String {
    let mut manifest = String::new();
    for (rel, bytes) in files {
        manifest.push_str(&format!("{}  {rel}\n", sha256_hex(bytes)));
    }
    manifest
}

/// A line of a sample's [`MANIFEST`] as (sha256, relative name); none for a malformed line.
pub fn manifest_line(line: &str) -> Option<(&str, &str)> {
    line.split_once("  ")
}

/// A sample's key in its shard: the index as nine digits (WebDataset's key, the member
/// name up to its first dot).
pub fn sample_key(index: u64) -> String {
    format!("{index:09}")
}

/// The part of a member's name after its sample's key: the file's relative name with its
/// `/` written `.` (`frame_0000/ppi_gray.png` is `frame_0000.ppi_gray.png`).
pub fn member_extension(rel: &str) -> String {
    rel.replace('/', ".")
}

/// A sample file's member name in its shard.
pub fn member_name(index: u64, rel: &str) -> String {
    format!("{}.{}", sample_key(index), member_extension(rel))
}

/// A member's sample and file (relative to the sample, `frame_KKKK/` restored), from its
/// name; none for a name that is not a sample's member.
pub fn parse_member_name(name: &str) -> Option<(u64, String)> {
    let (key, rest) = name.split_once('.')?;
    let index = whole_number(key)?;
    if rest.is_empty() {
        return None;
    }
    let rel = match rest.strip_prefix("frame_") {
        Some(after) => {
            let digits = after.bytes().take_while(u8::is_ascii_digit).count();
            match after[digits..].strip_prefix('.') {
                Some(file) if digits > 0 => format!("frame_{}/{file}", &after[..digits]),
                _ => rest.to_string(),
            }
        }
        None => rest.to_string(),
    };
    Some((index, rel))
}

/// Whether a member holds labels the assembly reads (a frame's coco.json or targets.jsonl,
/// a sample's baseline.json).
pub fn is_label_member(name: &str) -> bool {
    name.ends_with(".coco.json")
        || name.ends_with(".targets.jsonl")
        || name.ends_with(".baseline.json")
}

/// Shards of a dataset of `count` samples, `per_shard` to a shard.
pub fn shard_count(count: u64, per_shard: u64) -> u64 {
    count.div_ceil(per_shard.max(1))
}

/// The samples of shard t.
pub fn shard_samples(t: u64, per_shard: u64, count: u64) -> std::ops::Range<u64> {
    t * per_shard..((t + 1) * per_shard).min(count)
}

/// Shard t's tar file name.
pub fn shard_file_name(t: u64) -> String {
    format!("shard-{t:06}.tar")
}

/// The shard a tar file name is (the inverse of [`shard_file_name`]).
pub fn parse_shard_file_name(name: &str) -> Option<u64> {
    whole_number(name.strip_prefix("shard-")?.strip_suffix(".tar")?)
}

/// Shard t's tar relative to the dataset folder, `/`-separated.
pub fn shard_rel(t: u64) -> String {
    format!("shards/{}", shard_file_name(t))
}

/// Shard t's manifest relative to the dataset folder, `/`-separated.
pub fn manifest_rel(t: u64) -> String {
    format!("shards/shard-{t:06}.manifest.json")
}

/// Shard t's tar file.
pub fn shard_path(out: &Path, t: u64) -> PathBuf {
    out.join("shards").join(shard_file_name(t))
}

/// Shard t's manifest.
pub fn manifest_path(out: &Path, t: u64) -> PathBuf {
    out.join("shards")
        .join(format!("shard-{t:06}.manifest.json"))
}

/// Samples in shards not finished yet (a shard is done when its manifest is there).
pub fn missing_samples(out: &Path, count: u64, per_shard: u64) -> u64 {
    (0..shard_count(count, per_shard))
        .filter(|&t| !manifest_path(out, t).is_file())
        .map(|t| shard_samples(t, per_shard, count).count() as u64)
        .sum()
}

/// Bytes of a tar member's header: the shards' headers are single ustar blocks.
pub const TAR_BLOCK: u64 = 512;

/// A member as a shard's manifest lists it.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ManifestMember {
    /// Its name in the tar ([`member_name`]).
    pub name: String,
    /// Its size, bytes.
    pub size: u64,
    /// Its bytes' sha256 ([`sha256_hex`]).
    pub sha256: String,
}

/// A tar shard's manifest, `shard-TTTTTT.manifest.json`: its samples, every member's size
/// and sha256 in tar order, the tar's own sha256 and size.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ShardManifest {
    /// The members in tar order.
    pub members: Vec<ManifestMember>,
    /// The tar's sha256 (empty where the manifest lacks it).
    pub tar_sha256: String,
}

impl ShardManifest {
    /// Shard t's manifest bytes, holding the samples `samples` as `members`, in a tar of
    /// `tar_bytes` with sha256 `tar_sha256`.
    pub fn bytes(
        t: u64,
        samples: std::ops::Range<u64>,
        members: &[ManifestMember],
        tar_bytes: u64,
        tar_sha256: &str,
    ) -> Result<Vec<u8>> {
        let (first, last) = if samples.is_empty() {
            (None, None)
        } else {
            (Some(samples.start), Some(samples.end - 1))
        };
        let members: Vec<serde_json::Value> = members
            .iter()
            .map(|m| serde_json::json!({"name": m.name, "size": m.size, "sha256": m.sha256}))
            .collect();
        let manifest = serde_json::json!({
            "shard": t,
            "file": shard_file_name(t),
            "samples": [first, last],
            "tar_bytes": tar_bytes,
            "tar_sha256": tar_sha256,
            "members": members,
        });
        let mut text = serde_json::to_vec_pretty(&manifest)
            .map_err(|e| DatasetError::spec("(manifest)", e.to_string()))?;
        text.push(b'\n');
        Ok(text)
    }

    /// Reads a manifest's JSON. A member's missing field reads as empty (and so differs from
    /// any real member); a manifest without members lists none.
    pub fn parse(bytes: &[u8]) -> std::result::Result<ShardManifest, String> {
        let v: serde_json::Value = serde_json::from_slice(bytes).map_err(|e| e.to_string())?;
        let text = |m: &serde_json::Value, k: &str| m[k].as_str().unwrap_or_default().to_string();
        let members = v["members"]
            .as_array()
            .map(|list| {
                list.iter()
                    .map(|m| ManifestMember {
                        name: text(m, "name"),
                        size: m["size"].as_u64().unwrap_or(0),
                        sha256: text(m, "sha256"),
                    })
                    .collect()
            })
            .unwrap_or_default();
        Ok(ShardManifest {
            members,
            tar_sha256: text(&v, "tar_sha256"),
        })
    }

    /// Reads the manifest at `path`.
    pub fn read(path: &Path) -> Result<ShardManifest> {
        let bytes = at(path, std::fs::read(path))?;
        ShardManifest::parse(&bytes).map_err(|e| invalid_data(path, e))
    }

    /// Every member with where its data is in the tar: `(member, start, end)` byte offsets
    /// (each member is a header block and its data padded to whole blocks).
    pub fn data_ranges(&self) -> Vec<(&ManifestMember, u64, u64)> {
        let mut offset = 0;
        self.members
            .iter()
            .map(|m| {
                let start = offset + TAR_BLOCK;
                offset = start + m.size.div_ceil(TAR_BLOCK) * TAR_BLOCK;
                (m, start, start + m.size)
            })
            .collect()
    }

    /// What is wrong with the member read as `name` holding `data` where the manifest lists
    /// `listed`, if anything.
    pub fn member_problem(listed: &ManifestMember, name: &str, data: &[u8]) -> Option<String> {
        (listed.name != name || listed.sha256 != sha256_hex(data))
            .then(|| format!("{name}: differs from the manifest"))
    }

    /// What is wrong with the members `read` (name and bytes, looked up by name), if anything.
    pub fn check_members<'a>(
        &self,
        read: impl IntoIterator<Item = (&'a str, &'a [u8])>,
    ) -> Option<String> {
        read.into_iter().find_map(|(name, data)| {
            match self.members.iter().find(|m| m.name == name) {
                None => Some(format!("{name}: not in the manifest")),
                Some(listed) => ShardManifest::member_problem(listed, name, data),
            }
        })
    }
}

/// The dataset record, `dataset.json`, of the dataset of spec `spec_text` (with `frames` per
/// sample), `count` samples made with `seed` and stored as `format`: the same spec, seed and
/// count give the same bytes, so separate shard runs into one folder agree.
pub fn record_bytes(
    spec_text: &str,
    frames: u64,
    count: u64,
    seed: u64,
    format: Format,
) -> Result<Vec<u8>> {
    let (format, layout, per_shard) = match format {
        Format::Dir => (
            "dir",
            "samples/<index / 1000 as 6 digits>/<index as 9 digits>/".to_string(),
            None,
        ),
        Format::WebDataset { samples_per_shard } => (
            "webdataset",
            "shards/shard-<shard as 6 digits>.tar with <shard>.manifest.json; members <index as 9 digits>.<file>".to_string(),
            Some(samples_per_shard),
        ),
    };
    let record = serde_json::json!({
        "generator": format!("xbandsim {}", env!("CARGO_PKG_VERSION")),
        "count": count,
        "seed": seed,
        "frames_per_sample": frames,
        "format": format,
        "samples_per_shard": per_shard,
        "layout": layout,
        "spec": spec_text,
    });
    serde_json::to_vec_pretty(&record)
        .map(|mut v| {
            v.push(b'\n');
            v
        })
        .map_err(|e| DatasetError::spec("(record)", e.to_string()))
}

/// What a dataset's record says it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Record {
    /// Samples in the whole dataset.
    pub count: u64,
    /// Frames per sample.
    pub frames: u64,
    /// The dataset's seed (none in a record without one).
    pub seed: Option<u64>,
    /// How its samples are stored.
    pub format: Format,
}

/// The record of the dataset in `out`, from its `dataset.json`.
pub fn read_record(out: &Path) -> Result<Record> {
    let path = out.join(RECORD);
    let bytes = at(&path, std::fs::read(&path))?;
    let v: serde_json::Value =
        serde_json::from_slice(&bytes).map_err(|e| invalid_data(&path, e.to_string()))?;
    let format = match (v["format"].as_str(), v["samples_per_shard"].as_u64()) {
        (Some("webdataset"), Some(0)) => return Err(invalid_data(&path, "samples_per_shard is 0")),
        (Some("webdataset"), Some(n)) => Format::WebDataset {
            samples_per_shard: n,
        },
        _ => Format::Dir,
    };
    match (v["count"].as_u64(), v["frames_per_sample"].as_u64()) {
        (Some(count), Some(frames)) => Ok(Record {
            count,
            frames,
            seed: v["seed"].as_u64(),
            format,
        }),
        _ => Err(invalid_data(&path, "not an xbandsim dataset record")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_folders_and_frame_files_are_named_by_index() {
        let out = Path::new("/d");
        assert_eq!(
            sample_dir(out, 42),
            Path::new("/d/samples/000000/000000042")
        );
        assert_eq!(sample_rel(1_234_567), "samples/001234/001234567");
        assert_eq!(out.join(sample_rel(1_234_567)), sample_dir(out, 1_234_567));
        assert_eq!(frame_file(1, 0, "coco.json"), "coco.json");
        assert_eq!(frame_file(8, 3, "coco.json"), "frame_0003/coco.json");
        assert_eq!(frame_of("frame_0003/coco.json"), Some(3));
        assert_eq!(frame_of("coco.json"), None);
        assert_eq!(frame_of("frame_x/coco.json"), None);
        assert_eq!(coco_image_id(1, 8, 3), 12);
        assert_eq!(
            Format::Dir.image_name(42, 2, 1, "ppi.png"),
            "samples/000000/000000042/frame_0001/ppi.png"
        );
        assert_eq!(
            Format::WebDataset {
                samples_per_shard: 5
            }
            .image_name(42, 2, 1, "ppi.png"),
            "000000042.frame_0001.ppi.png"
        );
        assert_eq!(
            Format::WebDataset {
                samples_per_shard: 5
            }
            .cli_args(),
            " --format webdataset --shard-samples 5"
        );
    }

    #[test]
    fn member_names_parse_back_to_their_sample_and_file() {
        for (index, rel) in [
            (0, "coco.json"),
            (42, "frame_0003/ppi_gray.png"),
            (999_999_999, "scene.toml"),
            (1_000_000_000, "frame_0000/polar.npy"),
        ] {
            let name = member_name(index, rel);
            assert_eq!(parse_member_name(&name), Some((index, rel.to_string())));
        }
        assert_eq!(
            member_name(42, "frame_0003/ppi.png"),
            "000000042.frame_0003.ppi.png"
        );
        assert_eq!(parse_member_name("README.md"), None);
        assert_eq!(parse_member_name("000000001."), None);
        assert!(is_label_member("000000001.frame_0002.coco.json"));
        assert!(!is_label_member("000000001.yolo.txt"));
        assert!(is_label_member("000000001.baseline.json"));
    }

    #[test]
    fn shards_hold_consecutive_samples() {
        assert_eq!(shard_count(12, 5), 3);
        assert_eq!(shard_count(10, 5), 2);
        assert_eq!(shard_samples(2, 5, 12), 10..12);
        assert_eq!(shard_rel(3), "shards/shard-000003.tar");
        assert_eq!(manifest_rel(3), "shards/shard-000003.manifest.json");
        assert_eq!(
            Path::new("/d").join(shard_rel(3)),
            shard_path(Path::new("/d"), 3)
        );
        assert_eq!(
            Path::new("/d").join(manifest_rel(3)),
            manifest_path(Path::new("/d"), 3)
        );
        assert_eq!(parse_shard_file_name("shard-000003.tar"), Some(3));
        assert_eq!(parse_shard_file_name("shard-000003.tar.partial-1"), None);
    }

    #[test]
    fn a_manifest_reads_back_with_its_members_ranges_and_checks() {
        let members = [
            ManifestMember {
                name: member_name(5, "coco.json"),
                size: 3,
                sha256: sha256_hex(b"abc"),
            },
            ManifestMember {
                name: member_name(5, "targets.jsonl"),
                size: 600,
                sha256: sha256_hex(&[7; 600]),
            },
        ];
        let bytes = ShardManifest::bytes(1, 5..6, &members, 2560, "ff").unwrap();
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert!(text.contains("\"file\": \"shard-000001.tar\""), "{text}");
        let m = ShardManifest::parse(&bytes).unwrap();
        assert_eq!(m.members, members);
        assert_eq!(m.tar_sha256, "ff");
        let ranges: Vec<(u64, u64)> = m.data_ranges().iter().map(|r| (r.1, r.2)).collect();
        assert_eq!(ranges, [(512, 515), (1536, 2136)]);
        assert_eq!(
            m.check_members([("000000005.coco.json", &b"abc"[..])]),
            None
        );
        assert_eq!(
            m.check_members([("000000005.coco.json", &b"abd"[..])])
                .as_deref(),
            Some("000000005.coco.json: differs from the manifest")
        );
        assert_eq!(
            m.check_members([("000000006.coco.json", &b"abc"[..])])
                .as_deref(),
            Some("000000006.coco.json: not in the manifest")
        );
        assert_eq!(
            ShardManifest::parse(b"{}").unwrap(),
            ShardManifest::default()
        );
        assert!(ShardManifest::parse(b"{").is_err());
    }

    #[test]
    fn sample_manifests_list_each_file_in_sha256sum_form() {
        let files = vec![("a/b.txt".to_string(), b"abc".to_vec())];
        let text = sample_manifest(&files);
        assert_eq!(
            text,
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad  a/b.txt\n"
        );
        assert_eq!(
            manifest_line(text.trim_end()),
            Some((sha256_hex(b"abc").as_str(), "a/b.txt"))
        );
        assert_eq!(manifest_line("no separator"), None);
    }

    #[test]
    fn records_and_sample_folders_read_back() {
        let tmp = tempfile::tempdir().unwrap();
        let format = Format::WebDataset {
            samples_per_shard: 4,
        };
        let bytes = record_bytes("[dataset]\n", 2, 9, 7, format).unwrap();
        std::fs::write(tmp.path().join(RECORD), bytes).unwrap();
        let r = read_record(tmp.path()).unwrap();
        assert_eq!(
            r,
            Record {
                count: 9,
                frames: 2,
                seed: Some(7),
                format
            }
        );
        assert_eq!(r.format.index_files(), SHARD_INDEX_FILES);
        for i in [3, 1001, 2] {
            std::fs::create_dir_all(sample_dir(tmp.path(), i)).unwrap();
        }
        // Not samples: a folder in the wrong group, a name that is not an index, a file.
        std::fs::create_dir_all(tmp.path().join("samples/000000/000005000")).unwrap();
        std::fs::create_dir_all(tmp.path().join("samples/000000/.partial")).unwrap();
        std::fs::write(tmp.path().join("samples/000000/000000009"), "").unwrap();
        assert_eq!(sample_indices(tmp.path()).unwrap(), [2, 3, 1001]);
        assert!(sample_indices(&tmp.path().join("none")).is_err());
    }
}
