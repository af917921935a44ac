//! The live radar's shared state (docs/live.md): the scenario clock, the controls, the
//! streams every client subscribes to, and the counters the status reports. The threads that
//! make the streams (the radar, the NMEA feed, a replay) and the server's handlers all hold
//! one [`Live`].

use crate::clock::Clock;
use crate::controls::{ControlValue, Controls};
use crate::error::Result;
use crate::record::{Record, RecordKind, Recorder};
use bytes::Bytes;
use serde::Serialize;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use tokio::sync::broadcast;

/// Messages the spoke stream holds for a client that has not taken them yet: a client this
/// far behind is dropped (about 4 revolutions at 2048 spokes, 16 spokes a message).
pub const SPOKE_BACKLOG_MESSAGES: usize = 512;

/// NMEA groups held for a TCP client that has not taken them yet.
pub const NMEA_BACKLOG_GROUPS: usize = 1024;

/// The longest a client may take to accept one message before it is dropped.
pub const CLIENT_SEND_TIMEOUT: Duration = Duration::from_secs(2);

/// The longest a waiting thread sleeps before it looks at the clock, pause, restart and
/// stop again.
pub const POLL: Duration = Duration::from_millis(20);

/// What a wait for a scenario time ended with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wait {
    /// The time has come.
    Due,
    /// The scenario restarted meanwhile.
    Restarted,
    /// The server is stopping.
    Stopping,
}

/// Counters for `/api/scenario`.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Counters {
    /// Revolutions sent since the start or restart.
    pub revolutions: u64,
    /// Spoke messages sent.
    pub spoke_messages: u64,
    /// NMEA sentences sent.
    pub nmea_sentences: u64,
    /// Clients dropped for falling behind or stalling.
    pub clients_dropped: u64,
    /// The last revolution's render time, s.
    pub last_render_s: f64,
    /// The last revolution's video chain time, s.
    pub last_video_s: f64,
    /// The last revolution's plot extraction and tracking time, s (0 without an NMEA feed).
    pub last_tracker_s: f64,
}

/// The shared state.
pub struct Live {
    clock: Mutex<Clock>,
    generation: AtomicU64,
    stopping: AtomicBool,
    controls: Mutex<Controls>,
    scales_m: Vec<f64>,
    /// Counters for the status.
    pub counters: Mutex<Counters>,
    /// Spoke clients connected now.
    pub spoke_clients: AtomicU64,
    /// The spoke stream: encoded `RadarMessage`s.
    pub spokes: broadcast::Sender<Bytes>,
    /// The control stream: JSON control values.
    pub control_values: broadcast::Sender<String>,
    /// The NMEA stream: groups of sentences with their line ends.
    pub nmea: broadcast::Sender<Bytes>,
    recorder: Option<Recorder>,
    fixed_controls: bool,
    stop_signal: tokio::sync::watch::Sender<bool>,
    ended_signal: tokio::sync::watch::Sender<bool>,
    udp: Option<(std::net::UdpSocket, std::net::SocketAddr)>,
    udp_failed: AtomicBool,
    /// Held while a message is checked against the run and sent, and while a restart
    /// changes the run: a message of the old run never follows the restart's record.
    order: Mutex<()>,
}

impl Live {
    /// Live state at scenario time 0, running `speed` times the wall, with `controls` (the
    /// range scale one of `scales_m`), recording to `recorder`.
    pub fn new(
        speed: f64,
        controls: Controls,
        scales_m: Vec<f64>,
        recorder: Option<Recorder>,
    ) -> Live {
        Live {
            clock: Mutex::new(Clock::new(speed, Instant::now()).with_barrier_at_start()),
            generation: AtomicU64::new(0),
            stopping: AtomicBool::new(false),
            controls: Mutex::new(controls),
            scales_m,
            counters: Mutex::new(Counters::default()),
            spoke_clients: AtomicU64::new(0),
            spokes: broadcast::channel(SPOKE_BACKLOG_MESSAGES).0,
            control_values: broadcast::channel(64).0,
            nmea: broadcast::channel(NMEA_BACKLOG_GROUPS).0,
            recorder,
            fixed_controls: false,
            stop_signal: tokio::sync::watch::channel(false).0,
            ended_signal: tokio::sync::watch::channel(false).0,
            udp: None,
            udp_failed: AtomicBool::new(false),
            order: Mutex::new(()),
        }
    }

    /// The same, sending every NMEA group from `socket` to `to` as a datagram.
    pub fn with_udp(mut self, socket: std::net::UdpSocket, to: std::net::SocketAddr) -> Live {
        self.udp = Some((socket, to));
        self
    }

    /// The same, with controls that cannot be set and a clock without a barrier (a replay:
    /// its video was recorded, and every record is at hand).
    pub fn for_replay(mut self) -> Live {
        self.fixed_controls = true;
        self.clock
            .get_mut()
            .unwrap_or_else(|e| e.into_inner())
            .set_barrier(f64::INFINITY, Instant::now());
        self
    }

    /// A receiver that changes to true when the server stops.
    pub fn stop_signal(&self) -> tokio::sync::watch::Receiver<bool> {
        self.stop_signal.subscribe()
    }

    /// A receiver that changes to true once the stream threads have finished: nothing more
    /// will be sent.
    pub fn ended_signal(&self) -> tokio::sync::watch::Receiver<bool> {
        self.ended_signal.subscribe()
    }

    /// Tells the clients nothing more will be sent.
    pub fn end_streams(&self) {
        self.ended_signal.send_replace(true);
    }

    fn clock(&self) -> std::sync::MutexGuard<'_, Clock> {
        self.clock.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// A copy of the clock.
    pub fn clock_now(&self) -> Clock {
        *self.clock()
    }

    /// Scenario time now, s.
    pub fn time_s(&self) -> f64 {
        self.clock().time_s(Instant::now())
    }

    /// The scenario's run: it changes at each restart.
    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::SeqCst)
    }

    /// Pauses scenario time.
    pub fn pause(&self) {
        self.clock().pause(Instant::now());
    }

    /// Resumes scenario time.
    pub fn resume(&self) {
        self.clock().resume(Instant::now());
    }

    /// Sets how many times faster than the wall the scenario runs.
    pub fn set_speed(&self, speed: f64) {
        self.clock().set_speed(speed, Instant::now());
    }

    /// Back to scenario time 0: the radar and the feeds start the scenario again (a
    /// restart record marks it in the recording).
    pub fn restart(&self) {
        let _order = self.order.lock().unwrap_or_else(|e| e.into_inner());
        self.generation.fetch_add(1, Ordering::SeqCst);
        // Recorded outside the clock's lock: a recorder that waits on the disk holds up no
        // reader of the clock (nothing is sent meanwhile: `order` is held).
        self.record_restart(self.time_s());
        self.clock().restart(Instant::now());
        *self.counters.lock().unwrap_or_else(|e| e.into_inner()) = Counters::default();
    }

    /// The clock alone back to 0, run `generation` going on: a replay at a restart recorded
    /// at `time_s` (recorded again with that time); nothing once that run has been restarted.
    pub fn rewind(&self, generation: u64, time_s: f64) {
        let _order = self.order.lock().unwrap_or_else(|e| e.into_inner());
        if generation != self.generation() {
            return;
        }
        self.record_restart(time_s);
        self.clock().restart(Instant::now());
    }

    fn record_restart(&self, time_s: f64) {
        if let Some(r) = &self.recorder {
            r.write(Record {
                kind: RecordKind::Restart,
                time_s,
                payload: Bytes::new(),
            });
        }
    }

    /// Lets scenario time of run `generation` run up to `time_s` and no further (the radar's
    /// revolution in hand ends there); nothing once that run has been restarted.
    pub fn set_barrier(&self, generation: u64, time_s: f64) {
        let _order = self.order.lock().unwrap_or_else(|e| e.into_inner());
        if generation == self.generation() {
            self.clock().set_barrier(time_s, Instant::now());
        }
    }

    /// Asks every thread to stop.
    pub fn stop(&self) {
        self.stopping.store(true, Ordering::SeqCst);
        self.stop_signal.send_replace(true);
    }

    /// Whether the server is stopping.
    pub fn stopping(&self) -> bool {
        self.stopping.load(Ordering::SeqCst)
    }

    /// Waits until scenario time reaches `time_s`, or the run `generation` ends, or the
    /// server stops.
    pub fn wait_until(&self, time_s: f64, generation: u64) -> Wait {
        loop {
            if self.stopping() {
                return Wait::Stopping;
            }
            if self.generation() != generation {
                return Wait::Restarted;
            }
            // The clock's lock is let go before any sleep.
            let until = self.clock().wall_until(time_s, Instant::now());
            match until {
                Some(d) if d.is_zero() => return Wait::Due,
                Some(d) => std::thread::sleep(d.min(POLL)),
                None => std::thread::sleep(POLL),
            }
        }
    }

    /// The controls now.
    pub fn controls(&self) -> Controls {
        self.controls
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// The range scales offered, m.
    pub fn range_scales_m(&self) -> &[f64] {
        &self.scales_m
    }

    /// Sets a control; its new value goes to every control client.
    pub fn set_control(&self, value: &ControlValue) -> Result<ControlValue> {
        if self.fixed_controls {
            return Err(crate::error::ServeError::setting(
                &format!("control {}", value.id),
                value
                    .value
                    .as_ref()
                    .map_or_else(|| "(none)".into(), |v| v.to_string()),
                "a replay's controls cannot be set: its video was recorded with them",
            ));
        }
        let set = self
            .controls
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .set(value, &self.scales_m)?;
        if let Ok(text) = serde_json::to_string(&set) {
            let _ = self.control_values.send(text);
        }
        Ok(set)
    }

    /// Sends a spoke message of run `generation` to every client and the recording (nothing
    /// once that run has been restarted).
    pub fn send_spokes(&self, generation: u64, time_s: f64, message: Bytes) {
        let _order = self.order.lock().unwrap_or_else(|e| e.into_inner());
        if generation != self.generation() {
            return;
        }
        if let Some(r) = &self.recorder {
            r.write(Record {
                kind: RecordKind::Spokes,
                time_s,
                payload: message.clone(),
            });
        }
        let _ = self.spokes.send(message);
        self.counters
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .spoke_messages += 1;
    }

    /// Sends a group of NMEA sentences (`lines`, each ending CR LF) of run `generation` to
    /// every client, the UDP address (one datagram) and the recording (nothing once that run
    /// has been restarted).
    pub fn send_nmea(&self, generation: u64, time_s: f64, lines: Bytes, sentences: u64) {
        let _order = self.order.lock().unwrap_or_else(|e| e.into_inner());
        if generation != self.generation() {
            return;
        }
        if let Some((socket, to)) = &self.udp {
            if let Err(e) = socket.send_to(&lines, to) {
                if !self.udp_failed.swap(true, Ordering::SeqCst) {
                    eprintln!("xbandsim serve: NMEA to udp {to}: {e} (goes on trying)");
                }
            }
        }
        if let Some(r) = &self.recorder {
            r.write(Record {
                kind: RecordKind::Nmea,
                time_s,
                payload: lines.clone(),
            });
        }
        let _ = self.nmea.send(lines);
        self.counters
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .nmea_sentences += sentences;
    }

    /// Counts a dropped client.
    pub fn client_dropped(&self) {
        self.counters
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clients_dropped += 1;
    }

    /// A copy of the counters.
    pub fn counters(&self) -> Counters {
        self.counters
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// Ends the recording (if any): its last record written and the file closed.
    pub fn finish_recording(&self) -> Result<Option<u64>> {
        match &self.recorder {
            Some(r) => r.finish().map(Some),
            None => Ok(None),
        }
    }
}
