//! The trace cache: the traced contributions and their echo groups of a scene state, kept so
//! that pulses and revolutions that see the same state do not trace it again.
//!
//! When is a state the same? The world holds no motion yet, so every scene time gives the
//! same state and the scene is traced once per [`crate::engine::Simulation`], on first use.
//! Time-varying worlds will key the cache by the state's time quantised to the re-trace
//! interval their accuracy needs; the engine asks the cache by scene time already.

use crate::echo::EchoGroups;
use crate::scattering::ScatterSet;
use std::sync::{Arc, Mutex};

/// The traced state of a scene at one time.
#[derive(Debug)]
pub struct Traced {
    /// Every contribution, with the ray count.
    pub set: ScatterSet,
    /// The contributions grouped into band-limited impulse responses.
    pub groups: EchoGroups,
}

/// The cache (safe to share between threads).
#[derive(Debug, Default)]
pub struct TraceCache {
    static_state: Mutex<Option<Arc<Traced>>>,
}

impl TraceCache {
    /// The traced state at `scene_time_s`, from the cache or made by `trace` (a static world:
    /// the same state at every time). The `bool` says whether it was traced now.
    pub fn get_or_trace(
        &self,
        _scene_time_s: f64,
        trace: impl FnOnce() -> Traced,
    ) -> (Arc<Traced>, bool) {
        let slot = || {
            self.static_state
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
        };
        if let Some(t) = slot().as_ref() {
            return (Arc::clone(t), false);
        }
        // Traced without holding the lock: the tracer runs on rayon's pool, and a worker that
        // waited here for a lock held by another task could deadlock. Two callers may both
        // trace the first time; tracing is deterministic, so either result is the same and
        // the first one stored is kept.
        let traced = Arc::new(trace());
        let mut guard = slot();
        match guard.as_ref() {
            Some(t) => (Arc::clone(t), false),
            None => {
                *guard = Some(Arc::clone(&traced));
                (traced, true)
            }
        }
    }
}
