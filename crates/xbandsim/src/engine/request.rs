//! What a caller asks the engine for: one revolution of a render, by seed and frame (the
//! scene's own scan) or by a schedule of its own, with optional outputs and a progress
//! callback. [`crate::engine::Simulation::run`] takes it.

use super::Outputs;
use crate::receiver::video_chain::EchoHistory;
use crate::rng::FrameKey;
use crate::schedule::Schedule;
use std::sync::Mutex;

/// A request for one revolution.
#[derive(Clone, Copy)]
pub struct Request<'a> {
    seed: u64,
    frame: u64,
    schedule: Option<&'a Schedule>,
    outputs: Outputs,
    progress: Option<&'a (dyn Fn() + Sync)>,
    echo_history: Option<&'a Mutex<EchoHistory>>,
}

impl std::fmt::Debug for Request<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Request")
            .field("seed", &self.seed)
            .field("frame", &self.frame)
            .field("schedule", &self.schedule.map(|s| s.frame()))
            .field("outputs", &self.outputs)
            .field("progress", &self.progress.is_some())
            .field("echo_history", &self.echo_history.is_some())
            .finish()
    }
}

impl<'a> Request<'a> {
    /// Revolution 0 of the render seeded `seed`, on the scene's own scan
    /// (`[processing] mode`), the polar record and labels only.
    pub fn new(seed: u64) -> Request<'a> {
        Request {
            seed,
            frame: 0,
            schedule: None,
            outputs: Outputs::default(),
            progress: None,
            echo_history: None,
        }
    }

    /// Revolution number `frame` (the clutter texture has drifted for `frame` antenna
    /// periods; noise and speckle are new each frame). A schedule given with
    /// [`Request::schedule`] brings its own frame, which counts instead.
    pub fn frame(mut self, frame: u64) -> Request<'a> {
        self.frame = frame;
        self
    }

    /// Runs `schedule` instead of the scene's scan (its frame replaces [`Request::frame`]).
    pub fn schedule(mut self, schedule: &'a Schedule) -> Request<'a> {
        self.frame = schedule.frame();
        self.schedule = Some(schedule);
        self
    }

    /// Also makes the optional `outputs`.
    pub fn outputs(mut self, outputs: Outputs) -> Request<'a> {
        self.outputs = outputs;
        self
    }

    /// Calls `dwell_done` after every dwell (from the worker threads), for progress bars.
    pub fn progress(mut self, dwell_done: &'a (dyn Fn() + Sync)) -> Request<'a> {
        self.progress = Some(dwell_done);
        self
    }

    /// Carries the receiver's echo averaging (`receiver.echo_average_scans`) from scan to
    /// scan in `history`: give the same history to a sequence's revolutions, in order.
    pub fn echo_history(mut self, history: &'a Mutex<EchoHistory>) -> Request<'a> {
        self.echo_history = Some(history);
        self
    }

    /// The echo-averaging history given, if any.
    pub fn echo_history_given(&self) -> Option<&'a Mutex<EchoHistory>> {
        self.echo_history
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The revolution number asked for.
    pub fn frame_number(&self) -> u64 {
        self.frame
    }

    /// The schedule given, if any.
    pub fn schedule_given(&self) -> Option<&'a Schedule> {
        self.schedule
    }

    /// The optional outputs.
    pub fn outputs_asked(&self) -> Outputs {
        self.outputs
    }

    /// The random streams of `schedule`'s revolution of this render.
    pub fn key(&self, schedule: &Schedule) -> FrameKey {
        FrameKey::new(self.seed, schedule.frame())
    }

    pub(crate) fn progress_or_none(&self) -> &'a (dyn Fn() + Sync) {
        self.progress.unwrap_or(&do_nothing)
    }
}

fn do_nothing() {}
