//! The scenario clock (docs/live.md, "The scenario clock"): scenario time as a function of
//! wall time, running `speed` times faster than the wall, which pauses, resumes and restarts,
//! and stops at a barrier: the radar sets it at the end of the revolution it holds, so that
//! time never runs ahead of the spokes (a late revolution holds everything — NMEA feed and
//! truth included — at its start, instead of time jumping back). Pure over the instants it is
//! given, so every transition is tested without waiting.

use std::time::{Duration, Instant};

/// Scenario time against the wall.
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    speed: f64,
    paused: bool,
    /// The wall instant of `anchor_s`.
    anchor_wall: Instant,
    /// Scenario time at `anchor_wall`, s.
    anchor_s: f64,
    /// Scenario seconds the clock was held at barriers, in all.
    held_s: f64,
    /// Scenario time does not pass this (infinite: no barrier).
    barrier_s: f64,
}

impl Clock {
    /// A clock at scenario time 0 at `now`, running `speed` times the wall.
    pub fn new(speed: f64, now: Instant) -> Clock {
        Clock {
            speed,
            paused: false,
            anchor_wall: now,
            anchor_s: 0.0,
            held_s: 0.0,
            barrier_s: f64::INFINITY,
        }
    }

    /// The same, held at 0 until a barrier is set past it.
    pub fn with_barrier_at_start(mut self) -> Clock {
        self.barrier_s = 0.0;
        self
    }

    /// Scenario time at `now` without the barrier, s.
    fn unbarred_s(&self, now: Instant) -> f64 {
        if self.paused {
            self.anchor_s
        } else {
            self.anchor_s
                + now
                    .saturating_duration_since(self.anchor_wall)
                    .as_secs_f64()
                    * self.speed
        }
    }

    /// Scenario time at `now`, s.
    pub fn time_s(&self, now: Instant) -> f64 {
        self.unbarred_s(now).min(self.barrier_s)
    }

    /// How many times faster than the wall it runs.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// Whether it is paused.
    pub fn paused(&self) -> bool {
        self.paused
    }

    /// Scenario seconds it was held at barriers in all (the radar behind the clock).
    pub fn held_s(&self) -> f64 {
        self.held_s
    }

    /// The barrier, s.
    pub fn barrier_s(&self) -> f64 {
        self.barrier_s
    }

    /// Re-anchors at `now`: time goes on from where it is, the seconds it was held counted.
    fn rebase(&mut self, now: Instant) {
        let unbarred = self.unbarred_s(now);
        if unbarred > self.barrier_s {
            self.held_s += unbarred - self.barrier_s;
        }
        self.anchor_s = unbarred.min(self.barrier_s);
        self.anchor_wall = now;
    }

    /// Moves the barrier to `barrier_s` (time held at the old one goes on from there).
    pub fn set_barrier(&mut self, barrier_s: f64, now: Instant) {
        self.rebase(now);
        self.barrier_s = barrier_s;
    }

    /// Stops scenario time at `now`.
    pub fn pause(&mut self, now: Instant) {
        self.rebase(now);
        self.paused = true;
    }

    /// Lets scenario time run again from where it stopped (nothing, if it runs).
    pub fn resume(&mut self, now: Instant) {
        if self.paused {
            self.anchor_wall = now;
            self.paused = false;
        }
    }

    /// Runs `speed` times the wall from `now` on.
    pub fn set_speed(&mut self, speed: f64, now: Instant) {
        self.rebase(now);
        self.speed = speed;
    }

    /// Back to scenario time 0 at `now` (paused or not as before; a clock with a barrier
    /// held at 0 until the radar moves it).
    pub fn restart(&mut self, now: Instant) {
        self.anchor_s = 0.0;
        self.anchor_wall = now;
        self.held_s = 0.0;
        if self.barrier_s.is_finite() {
            self.barrier_s = 0.0;
        }
    }

    /// Wall time from `now` until scenario time reaches `time_s` (zero if it has), or None
    /// while paused or while the barrier stands before it.
    pub fn wall_until(&self, time_s: f64, now: Instant) -> Option<Duration> {
        if self.paused || time_s > self.barrier_s {
            return None;
        }
        let ahead_s = (time_s - self.time_s(now)) / self.speed;
        // At most a day, and zero for a time that is not a number: always a Duration.
        let ahead_s = if ahead_s.is_nan() {
            0.0
        } else {
            ahead_s.clamp(0.0, 86_400.0)
        };
        Some(Duration::from_secs_f64(ahead_s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_pauses_resumes_restarts_and_holds() {
        let t0 = Instant::now();
        let at = |s: f64| t0 + Duration::from_secs_f64(s);
        let mut c = Clock::new(4.0, t0);
        assert_eq!(c.time_s(at(2.5)), 10.0);
        c.pause(at(2.5));
        assert_eq!(c.time_s(at(100.0)), 10.0);
        assert_eq!(c.wall_until(11.0, at(3.0)), None);
        c.resume(at(10.0));
        assert_eq!(c.time_s(at(11.0)), 14.0);
        // Resuming a running clock changes nothing.
        c.resume(at(10.5));
        assert_eq!(c.time_s(at(11.0)), 14.0);
        assert_eq!(c.wall_until(18.0, at(11.0)), Some(Duration::from_secs(1)));
        assert_eq!(c.wall_until(12.0, at(11.0)), Some(Duration::ZERO));
        c.set_speed(1.0, at(11.0));
        assert_eq!(c.time_s(at(13.0)), 16.0);
        // A barrier at 17 s: time stops there, and goes on from there when it moves.
        c.set_barrier(17.0, at(13.0));
        assert_eq!(c.time_s(at(15.0)), 17.0);
        assert_eq!(c.wall_until(17.5, at(15.0)), None);
        assert_eq!(c.wall_until(16.0, at(15.0)), Some(Duration::ZERO));
        c.set_barrier(30.0, at(16.0));
        assert_eq!(c.held_s(), 2.0);
        assert_eq!(c.time_s(at(17.0)), 18.0);
        c.restart(at(17.0));
        assert_eq!(c.time_s(at(18.0)), 0.0);
        assert_eq!(c.held_s(), 0.0);
        c.set_barrier(f64::INFINITY, at(18.0));
        assert_eq!(c.time_s(at(19.0)), 1.0);
        c.restart(at(19.0));
        assert_eq!(c.time_s(at(20.0)), 1.0);
        // A time beyond any wait, or not a number, still gives a Duration.
        assert_eq!(
            c.wall_until(f64::INFINITY, at(15.0)),
            Some(Duration::from_secs(86_400))
        );
        assert_eq!(c.wall_until(f64::NAN, at(15.0)), Some(Duration::ZERO));
    }
}
