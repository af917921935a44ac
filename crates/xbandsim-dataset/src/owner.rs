//! Which run owns a dataset folder's temporary files (docs/formats.md, "Temporary files and
//! who owns them").
//!
//! Every run that writes into a dataset folder holds an exclusive lock on
//! `DIR/.owners/<tag>.lock`, where the tag names its host and process
//! ([`xbandsim::products::output::temp_tag`]: `<host>-<pid>-<nanos>`) and also ends the name
//! of every temporary file and folder the run writes (`.partial/<index>-<tag>-<n>/`,
//! `shards/*.partial-<tag>-<n>`, the assembly's `*.partial-<tag>-<n>` in the root). The lock
//! is the operating system's advisory file lock ([`std::fs::File::try_lock`]): it goes when
//! the process ends, however it ends (kill -9, a crash). So a lock file of this host that
//! can be locked belongs to a run that is gone, and its temporaries are removed at once by
//! the next run ([`clean`]). A lock file of another host proves less: where a file system's
//! locks do not reach across machines (NFS with `nolock`, many FUSE mounts), a live run on
//! another machine looks unlocked from here. Its temporaries, like those whose tag has no
//! lock file or where the file system has no locks at all, are removed only once untouched
//! for ten minutes, as a live writer touches its files every sample.
//!
//! One process may run several generators into one folder at once (threads of a Python
//! program): they share the process's tag and its one lock, counted in a registry keyed by
//! the folder's canonical path.

use std::collections::HashMap;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::{at, Result};

/// Folder of the owners' lock files inside a dataset folder.
pub const OWNERS_DIR: &str = ".owners";

/// How long a temporary file or folder whose owner is not known to be gone must be untouched
/// before a run deletes it as a killed run's leftover (a live writer touches its files every
/// sample).
const STALE_UNOWNED: std::time::Duration = std::time::Duration::from_secs(600);

/// The dataset root's temporary names (crate::assemble and the record's write), each
/// followed by a process tag (`xbandsim::products::output::temp_suffix`).
const ROOT_TEMPORARY_PREFIXES: [&str; 9] = [
    "annotations.partial-",
    "targets.partial-",
    "README.partial-",
    "annotations.json.annotations-",
    ".yolo.partial-",
    ".yolo_obb.partial-",
    ".yolo.old-",
    ".yolo_obb.old-",
    ".dataset.json.tmp-",
];

/// This process's locks: lock-file path (in the canonical folder) → (the locked file, runs
/// holding it).
static HELD: Mutex<Option<HashMap<PathBuf, (File, usize)>>> = Mutex::new(None);

/// A run's claim on a dataset folder: while it lives, this process's temporaries there are
/// known to be in use. Dropped by the last run of the process, the lock file goes.
#[derive(Debug)]
pub struct Owner {
    lock_path: PathBuf,
}

impl Owner {
    /// Claims `out` (a folder that exists) for this process.
    pub fn claim(out: &Path) -> Result<Owner> {
        // One key however the folder is spelt ("ds", "./ds", an absolute path).
        let out = at(out, std::fs::canonicalize(out))?;
        let dir = out.join(OWNERS_DIR);
        let lock_path = dir.join(format!("{}.lock", xbandsim::products::output::temp_tag()));
        let mut held = HELD.lock().unwrap_or_else(|p| p.into_inner());
        let held = held.get_or_insert_with(HashMap::new);
        if let Some((_, runs)) = held.get_mut(&lock_path) {
            *runs += 1;
            return Ok(Owner { lock_path });
        }
        // Another process's last run may remove the (empty) folder between the two steps.
        let mut tries = 0;
        let file = loop {
            at(&dir, std::fs::create_dir_all(&dir))?;
            match std::fs::OpenOptions::new()
                .create(true)
                .truncate(false)
                .write(true)
                .open(&lock_path)
            {
                Ok(file) => break file,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound && tries < 10 => tries += 1,
                Err(e) => return Err(crate::error::DatasetError::io(&lock_path, e)),
            }
        };
        // A file system without locks refuses here: the age rule still holds for our files.
        let _ = file.try_lock();
        held.insert(lock_path.clone(), (file, 1));
        Ok(Owner { lock_path })
    }
}

impl Drop for Owner {
    fn drop(&mut self) {
        let mut held = HELD.lock().unwrap_or_else(|p| p.into_inner());
        let Some(held) = held.as_mut() else { return };
        let last = match held.get_mut(&self.lock_path) {
            Some((_, runs)) => {
                *runs -= 1;
                *runs == 0
            }
            None => false,
        };
        if last {
            // Removed while still locked, so no other run takes it for a dead one's.
            let _ = std::fs::remove_file(&self.lock_path);
            held.remove(&self.lock_path);
            if let Some(dir) = self.lock_path.parent() {
                let _ = std::fs::remove_dir(dir); // only when no other run's lock is there
            }
        }
    }
}

/// The host part of a tag `<host>-<pid>-<nanos>` (the host may hold dashes).
fn host_of(tag: &str) -> &str {
    tag.rsplitn(3, '-').nth(2).unwrap_or("")
}

/// Whether `file` (open) is still the file at `path`: a lock file removed and made anew
/// between our open and our lock is another run's.
fn same_file(file: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), std::fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (file, path);
        true
    }
}

/// The owners of a folder's temporaries, as found by trying their locks.
struct Owners {
    /// Tags of runs alive now (their lock is held), this process's included.
    live: Vec<String>,
    /// Runs of this host that are gone: their tag and their lock file, locked by us until
    /// removed.
    dead: Vec<(String, PathBuf, File)>,
    /// Runs not known to be alive or gone (another host's lock that we could take, or a lock
    /// the file system could not try): their tag and lock file. Their temporaries go by age.
    unknown: Vec<(String, PathBuf)>,
}

impl Owners {
    fn find(out: &Path) -> Owners {
        let own = xbandsim::products::output::temp_tag();
        let here = host_of(&own).to_string();
        let mut owners = Owners {
            live: vec![own],
            dead: Vec::new(),
            unknown: Vec::new(),
        };
        let Ok(entries) = std::fs::read_dir(out.join(OWNERS_DIR)) else {
            return owners;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            let Some(tag) = name.strip_suffix(".lock") else {
                continue;
            };
            if owners.live.iter().any(|t| t == tag) {
                continue;
            }
            let Ok(file) = std::fs::OpenOptions::new().write(true).open(e.path()) else {
                continue;
            };
            match file.try_lock() {
                Ok(()) if !same_file(&file, &e.path()) => owners.live.push(tag.to_string()),
                Ok(()) if host_of(tag) == here => {
                    owners.dead.push((tag.to_string(), e.path(), file))
                }
                Ok(()) => owners.unknown.push((tag.to_string(), e.path())),
                Err(std::fs::TryLockError::WouldBlock) => owners.live.push(tag.to_string()),
                Err(std::fs::TryLockError::Error(_)) => {
                    owners.unknown.push((tag.to_string(), e.path()))
                }
            }
        }
        owners
    }

    /// Whether the temporary `name` may be removed: its owner is gone, or it is not known to
    /// be alive and `path` (down to `depth` levels) has been untouched for ten minutes.
    fn removable(&self, name: &str, path: &Path, depth: u32) -> bool {
        if self.live.iter().any(|t| name.contains(t.as_str())) {
            return false;
        }
        self.dead.iter().any(|(t, _, _)| name.contains(t.as_str())) || untouched(path, depth)
    }
}

/// Whether `path` and everything in it down to `depth` levels (a folder's time changes only
/// when its own entries do) is older than [`STALE_UNOWNED`].
fn untouched(path: &Path, depth: u32) -> bool {
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        return false;
    };
    let old = meta
        .modified()
        .ok()
        .and_then(|t| t.elapsed().ok())
        .is_some_and(|age| age > STALE_UNOWNED);
    if !old || !meta.is_dir() || depth == 0 {
        return old;
    }
    match std::fs::read_dir(path) {
        Ok(entries) => entries.flatten().all(|e| untouched(&e.path(), depth - 1)),
        Err(_) => false,
    }
}

/// Whether `name`, in `.partial/`, is a sample's temporary folder: `<index as 9 digits>-`
/// and a process tag.
fn is_partial_sample(name: &str) -> bool {
    let (index, rest) = name.split_at(name.len().min(9));
    index.len() == 9 && index.bytes().all(|b| b.is_ascii_digit()) && rest.starts_with('-')
}

/// Deletes what runs that are gone left half-written in the dataset folder `out`
/// (`.partial/<index>-<tag>-<n>/`, `shards/*.partial-<tag>-<n>`, the assembly's temporary
/// files and trees in the root) and their lock files; a live run's temporaries are left
/// alone, and nothing that is not one of xbandsim's temporary names is touched. Best effort:
/// what cannot be read or removed stays (it is never read). Returns how many entries were
/// removed.
pub fn clean(out: &Path) -> usize {
    let owners = Owners::find(out);
    let mut removed = 0;
    let mut names: Vec<String> = Vec::new();
    let mut remove = |path: &Path| {
        let gone = if path.is_dir() {
            std::fs::remove_dir_all(path)
        } else {
            std::fs::remove_file(path)
        };
        removed += usize::from(gone.is_ok());
    };
    let each = |dir: &Path, f: &mut dyn FnMut(String, PathBuf)| {
        if let Ok(entries) = std::fs::read_dir(dir) {
            for e in entries.flatten() {
                f(e.file_name().to_string_lossy().into_owned(), e.path());
            }
        }
    };
    each(&out.join(".partial"), &mut |name, path| {
        if is_partial_sample(&name) && owners.removable(&name, &path, 2) {
            remove(&path);
        } else {
            names.push(name);
        }
    });
    each(&out.join("shards"), &mut |name, path| {
        if !name.contains(".partial-") {
            return;
        }
        if owners.removable(&name, &path, 0) {
            remove(&path);
        } else {
            names.push(name);
        }
    });
    each(out, &mut |name, path| {
        if !ROOT_TEMPORARY_PREFIXES.iter().any(|p| name.starts_with(p)) {
            return;
        }
        if owners.removable(&name, &path, 3) {
            remove(&path);
        } else {
            names.push(name);
        }
    });
    for (_, lock_path, _file) in &owners.dead {
        let _ = std::fs::remove_file(lock_path);
    }
    // A lock file whose owner is not known to be alive goes once it is old and none of its
    // temporaries is left (its run, if alive, is then protected by the age rule alone).
    for (tag, lock_path) in &owners.unknown {
        if untouched(lock_path, 0) && !names.iter().any(|n| n.contains(tag.as_str())) {
            let _ = std::fs::remove_file(lock_path);
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tags_and_sample_names() {
        assert_eq!(host_of("node-7-a-1234-0000abcd"), "node-7-a");
        assert_eq!(host_of("h-1-00000000"), "h");
        assert!(is_partial_sample("000000042-host-1-0000abcd-3"));
        assert!(!is_partial_sample("00000004-host"));
        assert!(!is_partial_sample("my-notes"));
        assert!(!is_partial_sample("000000042"));
    }
}
