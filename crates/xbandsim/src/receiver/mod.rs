//! Stage: receiver — what the set does to the signal between the antenna and the display
//! (docs/architecture.md, "Signal chain"), in the order a receiver applies it:
//!
//! 1. blanking while transmitting ([`stages::Blanking`]; the thermal noise it switches off is
//!    the source [`crate::signal::noise::ThermalNoise`]);
//! 2. the matched filter (`crate::processing`);
//! 3. gain and sensitivity time control on the compressed signal ([`stages::GainStc`]);
//! 4. the detector ([`stages::Detector`]: linear power);
//! 5. the video chain ([`video_chain`]): log amplifier, sea and rain clutter controls (the
//!    rain control is [`stages::Ftc`]), interference rejection, echo averaging, gain and
//!    quantisation.
//!
//! Blanking: a real receiver is switched off while its own pulse goes out, so the first
//! `N_T` samples of the record are zero (docs/physics.md, "Eclipsing"). The fused matched
//! filter (`crate::processing`) forms the record in the frequency domain and needs the
//! exact, blanked record only when something arrives inside the blanked interval:
//! [`Receiver::echo_in_blanking`] decides that.

pub mod stages;
pub mod video_chain;

use crate::rng::{FrameKey, Stream};
pub use crate::signal::noise::fill_unit_noise;
use crate::signal::noise::ThermalNoise;
use num_complex::Complex32;

/// The receiver of a radar: whether it adds thermal noise and whether it is blanked while
/// transmitting a pulse of `pulse_len` samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Receiver {
    noise: bool,
    blanking: bool,
    pulse_len: usize,
    noise_stream: Stream,
}

impl Receiver {
    /// A receiver with or without noise and blanking, for a pulse of `pulse_len` samples.
    pub fn new(noise: bool, blanking: bool, pulse_len: usize) -> Receiver {
        Receiver {
            noise,
            blanking,
            pulse_len,
            noise_stream: Stream::ReceiverNoise,
        }
    }

    /// The same receiver drawing its noise from `stream` (the short-pulse channel of combined
    /// pulse mode has its own, [`Stream::ShortPulseNoise`]).
    pub fn with_noise_stream(self, stream: Stream) -> Receiver {
        Receiver {
            noise_stream: stream,
            ..self
        }
    }

    /// The same receiver without thermal noise.
    pub fn without_noise(self) -> Receiver {
        Receiver {
            noise: false,
            ..self
        }
    }

    /// Adds thermal noise.
    pub fn noise(&self) -> bool {
        self.noise
    }

    /// Blanked while transmitting.
    pub fn blanking(&self) -> bool {
        self.blanking
    }

    /// Whether something arrives while the pulse is still going out: a signal whose first
    /// sample `earliest_sample` is inside the pulse (clutter, which starts at the radar,
    /// reports sample 0). Only then does blanking change the record's echo part.
    pub fn echo_in_blanking(&self, earliest_sample: Option<usize>) -> bool {
        earliest_sample.is_some_and(|e| e < self.pulse_len)
    }

    /// Its thermal noise (stream `ReceiverNoise` unless [`Receiver::with_noise_stream`]
    /// chose another).
    pub fn thermal_noise(&self) -> ThermalNoise {
        ThermalNoise::new(self.noise_stream)
    }

    /// Fills `out` with pulse `pulse`'s unit-power noise of the revolution `key`.
    pub fn fill_noise(&self, key: FrameKey, pulse: u64, out: &mut [Complex32]) {
        self.thermal_noise().fill(key, pulse, out);
    }

    /// Blanks `record` while transmitting (zeroes its first `pulse_len` samples), if this
    /// receiver blanks.
    pub fn blank(&self, record: &mut [Complex32]) {
        if self.blanking {
            stages::Blanking {
                samples: self.pulse_len,
            }
            .apply(record);
        }
    }
}
