//! The scenario clock (docs/live.md, "The scenario clock"): scenario time as a function of
//! wall time, running `speed` times faster than the wall, which pauses, resumes and restarts.
//! Pure over the instants it is given, so every transition is tested without waiting.

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
    /// Scenario seconds the clock was held back for the radar to catch up, in all.
    held_s: f64,
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
        }
    }

    /// Scenario time at `now`, s.
    pub fn time_s(&self, now: Instant) -> f64 {
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

    /// How many times faster than the wall it runs.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// Whether it is paused.
    pub fn paused(&self) -> bool {
        self.paused
    }

    /// Scenario seconds it was held back in all (the radar behind the clock).
    pub fn held_s(&self) -> f64 {
        self.held_s
    }

    fn rebase(&mut self, now: Instant) {
        self.anchor_s = self.time_s(now);
        self.anchor_wall = now;
    }

    /// Stops scenario time at `now`.
    pub fn pause(&mut self, now: Instant) {
        self.rebase(now);
        self.paused = true;
    }

    /// Lets scenario time run again from where it stopped.
    pub fn resume(&mut self, now: Instant) {
        self.anchor_wall = now;
        self.paused = false;
    }

    /// Runs `speed` times the wall from `now` on.
    pub fn set_speed(&mut self, speed: f64, now: Instant) {
        self.rebase(now);
        self.speed = speed;
    }

    /// Back to scenario time 0 at `now` (paused or not as before).
    pub fn restart(&mut self, now: Instant) {
        self.anchor_s = 0.0;
        self.anchor_wall = now;
        self.held_s = 0.0;
    }

    /// Holds scenario time at `time_s` if it has run past it: what the radar does when a
    /// revolution is late, so that no spoke is skipped or sent in a burst.
    pub fn hold_at(&mut self, time_s: f64, now: Instant) {
        let t = self.time_s(now);
        if t > time_s {
            self.held_s += t - time_s;
            self.anchor_s = time_s;
            self.anchor_wall = now;
        }
    }

    /// Wall time from `now` until scenario time reaches `time_s` (zero if it has), or None
    /// while paused.
    pub fn wall_until(&self, time_s: f64, now: Instant) -> Option<Duration> {
        if self.paused {
            return None;
        }
        let ahead_s = (time_s - self.time_s(now)) / self.speed;
        Some(Duration::from_secs_f64(ahead_s.max(0.0)))
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
        assert_eq!(c.wall_until(18.0, at(11.0)), Some(Duration::from_secs(1)));
        assert_eq!(c.wall_until(12.0, at(11.0)), Some(Duration::ZERO));
        c.set_speed(1.0, at(11.0));
        assert_eq!(c.time_s(at(13.0)), 16.0);
        c.hold_at(15.0, at(13.0));
        assert_eq!(c.time_s(at(13.0)), 15.0);
        assert_eq!(c.held_s(), 1.0);
        c.hold_at(20.0, at(14.0));
        assert_eq!(c.time_s(at(14.0)), 16.0);
        c.restart(at(14.0));
        assert_eq!(c.time_s(at(15.0)), 1.0);
        assert_eq!(c.held_s(), 0.0);
    }
}
