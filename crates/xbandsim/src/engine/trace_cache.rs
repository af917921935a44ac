//! The trace caches: a revolution's scene state traced (the traced world's, shared by every
//! receive chain made from it) and its echo groups (one receive chain's), kept so that pulses
//! and revolutions that see the same state do not trace or group it again.
//!
//! When is a state the same? A still scene (nothing moves: [`crate::model::Scene::is_still`])
//! is the same at every time and is traced once per [`crate::engine::World`], on first use. A moving scene's state is that of one revolution (every object where the beam crosses
//! it, [`crate::model::Revolution`]), keyed by the revolution's start time; the last
//! [`MOVING_STATES_KEPT`] are kept.

use crate::echo::EchoGroups;
use crate::geometry::Bvh;
use crate::model::Revolution;
use crate::scattering::ScatterSet;
use std::sync::{Arc, Mutex};

/// A revolution's scene state traced: what depends on the world and the carrier alone.
#[derive(Debug)]
pub struct TracedWorld {
    /// The BVH of the revolution's scene.
    pub bvh: Arc<Bvh>,
    /// Every contribution, with the ray count.
    pub set: Arc<ScatterSet>,
}

/// How many revolutions of a moving scene the cache keeps.
pub const MOVING_STATES_KEPT: usize = 2;

/// The traced state of a scene for one revolution.
#[derive(Debug)]
pub struct Traced {
    /// The revolution traced: its still scene and every object's state (for a still scene,
    /// the first revolution asked for; the scene is the same in all).
    pub revolution: Revolution,
    /// The BVH of the revolution's scene (the traced world's).
    pub bvh: Arc<Bvh>,
    /// Every contribution, with the ray count (the traced world's).
    pub set: Arc<ScatterSet>,
    /// The contributions grouped into band-limited impulse responses for this receive chain.
    pub groups: EchoGroups,
}

/// A cache of revolution states (safe to share between threads): traced worlds
/// ([`TracedWorld`]) or one receive chain's [`Traced`] states.
#[derive(Debug)]
pub struct TraceCache<T = Traced> {
    /// (start time's bits, state), newest last; one entry with key 0 for a still scene.
    states: Mutex<Vec<(u64, Arc<T>)>>,
}

impl<T> Default for TraceCache<T> {
    fn default() -> Self {
        TraceCache {
            states: Mutex::new(Vec::new()),
        }
    }
}

impl<T> TraceCache<T> {
    /// The traced state of the revolution starting at `start_time_s`, from the cache or made
    /// by `trace`; `still` says the scene is the same at every time (one state for all). The
    /// `bool` says whether it was traced now.
    pub fn get_or_trace(
        &self,
        start_time_s: f64,
        still: bool,
        trace: impl FnOnce() -> T,
    ) -> (Arc<T>, bool) {
        let key = if still { 0 } else { start_time_s.to_bits() };
        let slot = || {
            self.states
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
        };
        let find = |states: &[(u64, Arc<T>)]| {
            states
                .iter()
                .find(|(k, _)| *k == key)
                .map(|(_, t)| Arc::clone(t))
        };
        if let Some(t) = find(&slot()) {
            return (t, false);
        }
        // Traced without holding the lock: the tracer runs on rayon's pool, and a worker that
        // waited here for a lock held by another task could deadlock. Two callers may both
        // trace the same state; tracing is deterministic, so either result is the same and
        // the first one stored is kept.
        let traced = Arc::new(trace());
        let mut states = slot();
        if let Some(t) = find(&states) {
            return (t, false);
        }
        states.push((key, Arc::clone(&traced)));
        if states.len() > MOVING_STATES_KEPT {
            states.remove(0);
        }
        (traced, true)
    }
}
