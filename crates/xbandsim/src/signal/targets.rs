//! Signal sources: the targets' echoes. [`FixedEchoes`] adds the traced echo groups of the
//! objects that keep their range from the antenna, weighted by the two-way azimuth pattern at
//! the pulse's azimuth (docs/physics.md §3, §5). [`MovingEchoes`] advances every other
//! object's echo from its trace (at the beam crossing, time t_b) to the pulse's time t
//! (docs/physics.md §10): delay `2ṙ·(t − t_b)/c` (a phase ramp over the frequency bins, exact
//! for a band-limited echo), carrier phase `exp(−j4π·Δr/λ)` with `Δr = ṙ·Δt + ½·r̈·Δt²`,
//! `r̈ = (|v|² − ṙ²)/R` (straight relative motion), bearing `β̇·Δt` (the pattern weights it at
//! its moved bearing), and its chirp Doppler-shifted within the pulse
//! (`s(t)·exp(j2π·f_D·t)`, the LFM range–Doppler coupling). A mover whose walk and Doppler
//! could not change the compressed output by [`MOVING_ECHO_FOLD_ERROR`] is folded into the
//! record with its carrier phase alone; the others ("strong") enter the matched filter's
//! input spectrum through their own Doppler-shifted spectra.

use super::{earlier, PulseAt, Source, SourceScratch};
use crate::antenna::Antenna;
use crate::constants::SPEED_OF_LIGHT_M_PER_S;
use crate::echo::EchoGroups;
use crate::model::revolution::Revolution;
use num_complex::{Complex32, Complex64};

/// Groups weaker than this after the azimuth weight (noise-rms units, −80 dB) are skipped.
pub const MIN_GROUP_AMPLITUDE: f32 = 1e-4;

/// Below this error amplitude (noise-rms units after compression, −60 dB) a moving echo is
/// added with its carrier phase only, into the pulse's common impulse response: the error of
/// leaving out its sub-sample delay walk and intra-pulse Doppler is at most
/// `Σ peaks · G_mf · (π|δ| + 2π|f_D|·T)`, the sum over the object's weighted groups and
/// `G_mf = Σw/√Σw²` the matched filter's peak gain.
pub const MOVING_ECHO_FOLD_ERROR: f32 = 1e-3;

/// The echoes of the objects that are not moving relative to the antenna (all of them in
/// spoke mode): their echo groups weighted by the pattern at the pulse's azimuth.
pub struct FixedEchoes<'a> {
    groups: &'a EchoGroups,
    antenna: Antenna,
    record_len: usize,
    /// Objects left to [`MovingEchoes`].
    moving: &'a [Mover],
    /// Which of the echoes made by paths via the own ship it adds.
    paths: OwnShipPaths,
}

/// Which echoes made by paths via the own ship (`crate::scattering::via_own_ship`) a
/// [`FixedEchoes`] adds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OwnShipPaths {
    /// Every group (a scene without such paths).
    All,
    /// The direct echoes and the multiple echoes: what the blind sectors weaken.
    ThroughStructure,
    /// The direct echoes alone (the target-only render, whose record is for masks).
    None,
    /// The indirect echoes alone: what comes from the structure, past the blind sectors.
    FromStructure,
}

impl<'a> FixedEchoes<'a> {
    /// The groups of `groups` whose objects are not among `moving` and that `paths` takes,
    /// seen by `antenna`, into records of `record_len` samples.
    pub fn new(
        groups: &'a EchoGroups,
        antenna: Antenna,
        record_len: usize,
        moving: &'a [Mover],
        paths: OwnShipPaths,
    ) -> FixedEchoes<'a> {
        FixedEchoes {
            groups,
            antenna,
            record_len,
            moving,
            paths,
        }
    }

    /// Whether it adds the groups of (tagged) object `object`.
    fn takes(&self, object: u32) -> bool {
        use crate::scattering::via_own_ship::{INDIRECT_OBJECT_FLAG, MULTIPLE_OBJECT_FLAG};
        let indirect = object & INDIRECT_OBJECT_FLAG != 0;
        let multiple = object & MULTIPLE_OBJECT_FLAG != 0;
        match self.paths {
            OwnShipPaths::All => true,
            OwnShipPaths::ThroughStructure => !indirect,
            OwnShipPaths::None => !indirect && !multiple,
            OwnShipPaths::FromStructure => indirect,
        }
    }
}

impl Source for FixedEchoes<'_> {
    fn add_to_pulse(
        &self,
        at: &PulseAt,
        _scratch: &mut SourceScratch,
        samples: &mut [Complex32],
    ) -> Option<usize> {
        let record = &mut samples[..self.record_len];
        if self.moving.is_empty() && self.paths == OwnShipPaths::All {
            return self.groups.accumulate(
                &self.antenna,
                at.pulse.azimuth_rad,
                MIN_GROUP_AMPLITUDE,
                record,
            );
        }
        let is_mover = |o: u32| self.moving.iter().any(|m| m.object == o);
        self.groups.accumulate_where(
            &self.antenna,
            at.pulse.azimuth_rad,
            MIN_GROUP_AMPLITUDE,
            record,
            |o| !is_mover(o) && self.takes(o),
        )
    }
}

/// A moving object's echo in pulse mode: when it was traced and how fast its range changes.
#[derive(Debug, Clone)]
pub struct Mover {
    /// The object.
    pub object: u32,
    /// Time of its trace (the beam crossing), s.
    pub beam_time_s: f64,
    /// Range rate relative to the antenna, m/s.
    pub range_rate_mps: f64,
    /// Second derivative of its range for straight relative motion, `(|v|² − ṙ²)/R`, m/s².
    pub range_acceleration_mps2: f64,
    /// Rate of change of its bearing from the antenna, rad/s (clockwise positive).
    pub bearing_rate_rad_per_s: f64,
    /// Its Doppler shift `−2ṙ/λ`, Hz.
    pub doppler_hz: f64,
}

impl Mover {
    /// The moving echoes of a revolution: every object whose range rate or bearing rate
    /// relative to the antenna is not zero.
    pub fn of_revolution(revolution: &Revolution) -> Vec<Mover> {
        let scene = revolution.scene();
        let radar = scene.radar();
        scene
            .objects()
            .iter()
            .zip(revolution.objects())
            .enumerate()
            .filter_map(|(i, (o, state))| {
                let rel = o.position_m() - radar.position_m();
                let range = rel.length();
                if range <= 0.0 {
                    return None;
                }
                let v = state.relative_velocity_mps();
                let rate = v.dot(rel / range);
                let ground2 = rel.x * rel.x + rel.y * rel.y;
                let bearing_rate = if ground2 > 0.0 {
                    (rel.y * v.x - rel.x * v.y) / ground2
                } else {
                    0.0
                };
                (rate != 0.0 || bearing_rate != 0.0).then(|| {
                    let doppler_hz = -2.0 * rate / radar.wavelength_m();
                    Mover {
                        object: i as u32,
                        beam_time_s: state.beam_time_s,
                        range_rate_mps: rate,
                        range_acceleration_mps2: (v.length_squared() - rate * rate) / range,
                        bearing_rate_rad_per_s: bearing_rate,
                        doppler_hz,
                    }
                })
            })
            .collect()
    }
}

/// The echoes of the moving objects of a revolution, advanced to each pulse's time.
pub struct MovingEchoes<'a> {
    groups: &'a EchoGroups,
    movers: &'a [Mover],
    antenna: Antenna,
    record_len: usize,
    /// The scan's period, s: a mover is advanced within half of it from its crossing.
    period_s: f64,
    sample_rate_hz: f64,
    wavelength_m: f64,
    /// The transmitted pulse's length, s.
    pulse_s: f64,
    /// The matched filter's peak gain `Σw/√Σw²`.
    peak_gain: f32,
}

/// Where a mover is at one pulse.
#[derive(Debug, Clone, Copy)]
pub struct MoverAt {
    /// Delay walk since its trace, samples.
    pub delay_samples: f64,
    /// Carrier phase factor `exp(−j4π·Δr/λ)`.
    pub phase: Complex64,
    /// The beam's azimuth against the mover's bearing at its trace, rad.
    pub beam_az_rad: f64,
}

/// What a pulse's receiver needs to know of its matched filter to tell weak movers from
/// strong ones.
#[derive(Debug, Clone, Copy)]
pub struct FilterReach {
    /// Record length, samples.
    pub record_len: usize,
    /// The transmitted pulse's length, samples.
    pub pulse_len: usize,
    /// The matched filter's peak gain `Σw/√Σw²`.
    pub peak_gain: f64,
}

impl<'a> MovingEchoes<'a> {
    /// The `movers` among `groups`, seen by `antenna` through a matched filter `filter`, for
    /// a scan of period `period_s` at `sample_rate_hz` and `wavelength_m`.
    pub fn new(
        groups: &'a EchoGroups,
        movers: &'a [Mover],
        antenna: Antenna,
        filter: FilterReach,
        period_s: f64,
        sample_rate_hz: f64,
        wavelength_m: f64,
    ) -> MovingEchoes<'a> {
        MovingEchoes {
            groups,
            movers,
            antenna,
            record_len: filter.record_len,
            period_s,
            sample_rate_hz,
            wavelength_m,
            pulse_s: filter.pulse_len as f64 / sample_rate_hz,
            peak_gain: filter.peak_gain as f32,
        }
    }

    /// The movers.
    pub fn movers(&self) -> &[Mover] {
        self.movers
    }

    /// Mover `m` at the time of the pulse at `at`, within half a revolution of its beam
    /// crossing: a revolution's record holds each object once, where its labels put it
    /// (docs/physics.md §10).
    pub fn at_pulse(&self, m: &Mover, at: &PulseAt) -> MoverAt {
        let dt = at.pulse.time_s - m.beam_time_s;
        let dt = dt - self.period_s * (dt / self.period_s).round();
        let dr = m.range_rate_mps * dt + 0.5 * m.range_acceleration_mps2 * dt * dt;
        MoverAt {
            delay_samples: 2.0 * dr / SPEED_OF_LIGHT_M_PER_S * self.sample_rate_hz,
            phase: Complex64::from_polar(
                1.0,
                -2.0 * std::f64::consts::TAU * dr / self.wavelength_m,
            ),
            beam_az_rad: at.pulse.azimuth_rad - m.bearing_rate_rad_per_s * dt,
        }
    }

    /// Whether leaving out the mover's delay walk and intra-pulse Doppler could err by more
    /// than [`MOVING_ECHO_FOLD_ERROR`] after compression: the sum of its weighted group peaks
    /// `bound` times the filter's peak gain times `(π|δ| + 2π|f_D|·T)`.
    fn is_strong(&self, m: &Mover, delay: f64, bound: f32) -> bool {
        bound
            * self.peak_gain
            * (std::f64::consts::PI * delay.abs()
                + std::f64::consts::TAU * m.doppler_hz.abs() * self.pulse_s) as f32
            >= MOVING_ECHO_FOLD_ERROR
    }

    /// The weak movers of pulse `at` folded into `samples[..record_len]` with their carrier
    /// phase; the strong ones only move the earliest sample (their walk may bring them up to
    /// a sample earlier). Returns the earliest sample and whether any mover is strong (the
    /// engine then adds those through [`MovingEchoes::strong`]).
    pub fn add_weak(
        &self,
        at: &PulseAt,
        scratch: &mut SourceScratch,
        samples: &mut [Complex32],
    ) -> (Option<usize>, bool) {
        let record = self.record_len;
        let work = &mut scratch.mover;
        work.resize(record, Complex32::new(0.0, 0.0));
        let mut earliest = None;
        let mut any_strong = false;
        for m in self.movers {
            let a = self.at_pulse(m, at);
            work.fill(Complex32::new(0.0, 0.0));
            let (Some(e), bound) = self.groups.accumulate_groups(
                self.groups.groups_of(m.object),
                &self.antenna,
                a.beam_az_rad,
                MIN_GROUP_AMPLITUDE,
                &mut work[..record],
            ) else {
                continue;
            };
            if self.is_strong(m, a.delay_samples, bound) {
                any_strong = true;
                let e = (e as f64 + a.delay_samples.min(0.0)).floor().max(0.0) as usize;
                earliest = earlier(earliest, Some(e));
                continue;
            }
            let f = Complex32::new(a.phase.re as f32, a.phase.im as f32);
            for (b, x) in samples[..record].iter_mut().zip(&work[..record]) {
                *b += x * f;
            }
            earliest = earlier(earliest, Some(e));
        }
        (earliest, any_strong)
    }

    /// Whether mover `m` is strong at pulse `at` (the bound [`MovingEchoes::add_weak`] used),
    /// with where it is then.
    pub fn strong(&self, m: &Mover, at: &PulseAt) -> Option<MoverAt> {
        let a = self.at_pulse(m, at);
        let (e, bound) = EchoGroups::weighted_peak_bound(
            self.groups.groups_of(m.object),
            &self.antenna,
            a.beam_az_rad,
            MIN_GROUP_AMPLITUDE,
        );
        (e.is_some() && self.is_strong(m, a.delay_samples, bound)).then_some(a)
    }

    /// Mover `m`'s echo groups for a beam at `beam_az_rad` into `out` (its record part).
    pub fn accumulate(&self, m: &Mover, beam_az_rad: f64, out: &mut [Complex32]) {
        self.groups.accumulate_groups(
            self.groups.groups_of(m.object),
            &self.antenna,
            beam_az_rad,
            MIN_GROUP_AMPLITUDE,
            &mut out[..self.record_len],
        );
    }
}

impl Source for MovingEchoes<'_> {
    /// The weak movers ([`MovingEchoes::add_weak`]); the strong ones need the matched
    /// filter's spectrum and are added by the engine through [`MovingEchoes::strong`].
    fn add_to_pulse(
        &self,
        at: &PulseAt,
        scratch: &mut SourceScratch,
        samples: &mut [Complex32],
    ) -> Option<usize> {
        self.add_weak(at, scratch, samples).0
    }
}
