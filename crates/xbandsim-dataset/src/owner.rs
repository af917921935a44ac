//! Which run owns a dataset folder's temporary files (docs/formats.md, "Dataset directory").
//!
//! Every run that writes into a dataset folder holds an exclusive lock on
//! `DIR/.owners/<tag>.lock`, where the tag names its host and process
//! ([`xbandsim::products::output::temp_tag`]) and also ends the name of every temporary file
//! and folder the run writes (`.partial/<index>-<tag>-<n>/`, `shards/*.partial-<tag>-<n>`,
//! the assembly's `*.partial-<tag>-<n>` in the root). The lock is the operating system's
//! advisory file lock ([`std::fs::File::try_lock`]): it goes when the process ends, however it
//! ends (kill -9, a crash, a node lost), so a lock file that can be locked belongs to a run
//! that is gone, and its temporaries are removed at once by the next run ([`clean`]).
//! Temporaries whose tag has no lock file (or where the file system has no locks) are removed
//! only once untouched for ten minutes, as a live writer touches its files every sample.
//!
//! One process may run several generators into one folder at once (threads of a Python
//! program): they share the process's tag and its one lock, counted in a registry.

use std::collections::HashMap;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::{at, Result};

/// Folder of the owners' lock files inside a dataset folder.
pub const OWNERS_DIR: &str = ".owners";

/// How long a temporary file or folder without a known owner must be untouched before a run
/// deletes it as a killed run's leftover (a live writer touches its files every sample).
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

/// This process's locks: lock-file path → (the locked file, runs holding it).
static HELD: Mutex<Option<HashMap<PathBuf, (File, usize)>>> = Mutex::new(None);

/// A run's claim on a dataset folder: while it lives, this process's temporaries there are
/// known to be in use. Dropped by the last run of the process, the lock file goes.
#[derive(Debug)]
pub struct Owner {
    lock_path: PathBuf,
}

impl Owner {
    /// Claims `out` (a dataset folder that exists) for this process.
    pub fn claim(out: &Path) -> Result<Owner> {
        let dir = out.join(OWNERS_DIR);
        let lock_path = dir.join(format!("{}.lock", xbandsim::products::output::temp_tag()));
        let mut held = HELD.lock().unwrap_or_else(|p| p.into_inner());
        let held = held.get_or_insert_with(HashMap::new);
        if let Some((_, runs)) = held.get_mut(&lock_path) {
            *runs += 1;
        } else {
            at(&dir, std::fs::create_dir_all(&dir))?;
            let file = at(
                &lock_path,
                std::fs::OpenOptions::new()
                    .create(true)
                    .truncate(false)
                    .write(true)
                    .open(&lock_path),
            )?;
            // Only a file system without locks refuses here; the age rule then still holds.
            let _ = file.try_lock();
            held.insert(lock_path.clone(), (file, 1));
        }
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

/// The owners of a folder's temporaries, as found by trying their locks.
struct Owners {
    /// Tags of runs alive now (their lock is held), this process's included.
    live: Vec<String>,
    /// Runs that are gone: their tag and their lock file, locked by us until removed.
    dead: Vec<(String, PathBuf, File)>,
}

impl Owners {
    fn find(out: &Path) -> Owners {
        let mut owners = Owners {
            live: vec![xbandsim::products::output::temp_tag()],
            dead: Vec::new(),
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
                Ok(()) => owners.dead.push((tag.to_string(), e.path(), file)),
                Err(_) => owners.live.push(tag.to_string()),
            }
        }
        owners
    }

    /// Whether the temporary `name` may be removed: its owner is gone, or it has no known
    /// owner and `path` (down to `depth` levels) has been untouched for ten minutes.
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

/// Deletes what runs that are gone left half-written in `out` (`.partial/<index>-<tag>/`,
/// `shards/*.partial-<tag>`, the assembly's temporary files and trees in the root) and their
/// lock files; a live run's temporaries are left alone. Best effort: what cannot be read or
/// removed stays (it is never read). Returns how many entries were removed.
pub fn clean(out: &Path) -> usize {
    let owners = Owners::find(out);
    let mut removed = 0;
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
        if owners.removable(&name, &path, 2) {
            remove(&path);
        }
    });
    each(&out.join("shards"), &mut |name, path| {
        if name.contains(".partial-") && owners.removable(&name, &path, 0) {
            remove(&path);
        }
    });
    each(out, &mut |name, path| {
        if ROOT_TEMPORARY_PREFIXES.iter().any(|p| name.starts_with(p))
            && owners.removable(&name, &path, 3)
        {
            remove(&path);
        }
    });
    for (_, lock_path, _file) in &owners.dead {
        let _ = std::fs::remove_file(lock_path);
    }
    removed
}
