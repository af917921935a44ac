//! Stage: engine, the traced world — what depends on the world and the carrier alone: the
//! scene's objects and environment, their BVH and every revolution's trace (docs/architecture.md,
//! "Traced world and receive chain"). The waveform, the matched filter and the receiver are
//! cheap to rebuild and are not here: every [`crate::engine::Simulation`] made from a world by
//! [`crate::engine::Simulation::with_scene`] shares it, so an RL environment that changes the
//! pulse at any step traces each revolution once, not once per pulse choice.

use super::trace_cache::{TraceCache, TracedWorld};
use crate::geometry::Bvh;
use crate::model::{Revolution, Scene, SceneObject};
use crate::scattering::po::StillTraces;
use crate::scattering::{build_scene_bvh, scene_bvh_of, scene_primitives_of, trace_scene_keeping};
use std::sync::{Arc, OnceLock};

/// Fewest primitives of the still objects for a moving scene's BVH to take them as a static
/// level of their own (a function of the scene alone, so a frame's bytes do not depend on
/// which frames were rendered before it).
pub const STATIC_LEVEL_MIN_PRIMITIVES: usize = 20_000;

/// A scene's traced world (safe to share between threads).
#[derive(Debug)]
pub struct World {
    scene: Arc<Scene>,
    /// The BVH of the scene as written, built on first use: a moving scene's revolutions
    /// build their own (so a dataset sample with moving targets builds one BVH, not two).
    bvh: OnceLock<Arc<Bvh>>,
    /// The static level of a moving scene's two-level BVH: every object without a motion
    /// (structures, moored ships, buoys), built once; None when all move, with an own ship,
    /// or when they hold fewer than [`STATIC_LEVEL_MIN_PRIMITIVES`] primitives.
    static_bvh: OnceLock<Option<Arc<Bvh>>>,
    /// The traces of a moving scene's still objects, kept across revolutions where no moving
    /// object meets their rays (`scattering::po` "still"); used with the static level.
    still_traces: StillTraces,
    states: TraceCache<TracedWorld>,
}

impl World {
    /// The world of `scene` (nothing traced yet).
    pub fn new(scene: Arc<Scene>) -> World {
        let still = scene
            .objects()
            .iter()
            .map(|o| o.motion().is_none())
            .collect();
        World {
            scene,
            bvh: OnceLock::new(),
            static_bvh: OnceLock::new(),
            still_traces: StillTraces::new(still),
            states: TraceCache::default(),
        }
    }

    /// The scene its traces are of.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Whether this world's traces serve `scene`: the same world but for the radar's waveform
    /// and receiver ([`Scene::same_world_as`]), and the same objects in sight. A trace skips
    /// an extended object wholly beyond the recorded range, max range + c·T/2
    /// ([`crate::scattering::po::out_of_sight`]), which depends on the pulse length T: two
    /// pulses of different length share a world only when every object is a point (points
    /// are never skipped), since a moving object may cross that reach in some revolution.
    pub fn serves(&self, scene: &Scene) -> bool {
        let mine = self.scene.radar();
        self.scene.same_world_as(scene)
            && (mine.eclipse_range_m() == scene.radar().eclipse_range_m()
                || scene.objects().iter().all(|o| o.shape().is_point()))
    }

    /// The BVH of the scene as written (every object at its t = 0 pose).
    pub fn bvh(&self) -> &Arc<Bvh> {
        self.bvh
            .get_or_init(|| Arc::new(build_scene_bvh(self.scene.objects())))
    }

    /// The static level: the primitives of every object that has no motion.
    fn static_bvh(&self) -> Option<&Arc<Bvh>> {
        self.static_bvh
            .get_or_init(|| {
                let objects = self.scene.objects();
                let fixed =
                    |_: usize, o: &SceneObject| o.motion().is_none() && !o.shape().is_point();
                let count = objects
                    .iter()
                    .enumerate()
                    .filter(|(i, o)| fixed(*i, o))
                    .count();
                // With an own ship every object is placed anew each revolution (where the
                // beam meets it from the moving antenna): nothing stays where it was built.
                if count == 0
                    || objects.iter().all(|o| o.motion().is_none())
                    || self.scene.own_ship().is_some()
                {
                    return None;
                }
                let bvh = scene_bvh_of(objects, fixed);
                // A small static part is rebuilt with the moving objects in less time than a
                // second traversal per ray costs (a dataset sample's buoys): one level then
                // (its build here, as small, is cheap to throw away).
                if bvh.primitives().len() < STATIC_LEVEL_MIN_PRIMITIVES {
                    return None;
                }
                Some(Arc::new(bvh))
            })
            .as_ref()
    }

    /// A moving scene's BVH for one revolution's `scene`, and whether it is two-level: the
    /// moving objects' level over the static one when every object without a motion stands
    /// where it stood (it does unless a revolution moves the world), else one level over all.
    fn revolution_bvh(&self, scene: &Scene) -> (Bvh, bool) {
        let written = self.scene.objects();
        let objects = scene.objects();
        if let Some(fixed) = self.static_bvh() {
            let unmoved = objects.len() == written.len()
                && objects.iter().zip(written).all(|(now, then)| {
                    then.motion().is_some()
                        || (now.position_m() == then.position_m()
                            && now.rotation() == then.rotation())
                });
            if unmoved {
                let bvh = Bvh::over_static(
                    Arc::clone(fixed),
                    scene_primitives_of(objects, |k, _| written[k].motion().is_some()),
                );
                return (bvh, true);
            }
        }
        (build_scene_bvh(objects), false)
    }

    /// How many still objects' traces were reused from an earlier revolution so far.
    pub fn still_traces_reused(&self) -> u64 {
        self.still_traces.reused()
    }

    /// The traced state of the revolution starting at `start_time_s` whose beam crossings are
    /// sought from `lead_s` before it, from the cache or traced now (the `bool`); a still
    /// scene is traced once for all times. A moving scene's still objects keep their traces
    /// between revolutions while no moving object meets their rays (the same bytes).
    pub fn traced(&self, start_time_s: f64, lead_s: f64) -> (Arc<TracedWorld>, bool) {
        let still = self.scene.is_still();
        self.states.get_or_trace(start_time_s, still, || {
            let revolution = Revolution::with_lead(&self.scene, start_time_s, lead_s);
            let (bvh, kept) = if still {
                (Arc::clone(self.bvh()), None)
            } else {
                let (bvh, two_level) = self.revolution_bvh(revolution.scene());
                (Arc::new(bvh), two_level.then_some(&self.still_traces))
            };
            let set = Arc::new(trace_scene_keeping(revolution.scene(), &bvh, kept));
            TracedWorld { bvh, set }
        })
    }
}
