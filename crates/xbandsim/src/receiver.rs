//! Stage: receiver. Thermal noise, and blanking while transmitting.
//!
//! Noise: complex white Gaussian with power `N = k·T0·F·fs` per complex sample (W across 1 Ω;
//! Skolnik, *Radar Handbook*, 3rd ed., §2.3), i.e. `N/2` in each of I and Q. The pipeline
//! works in units of the noise rms voltage `√N`, so the generated samples have unit variance.
//!
//! Blanking: a real receiver is switched off while its own pulse goes out, so the first
//! `N_T` samples of the record are zero (docs/physics.md, "Eclipsing"). The fused matched
//! filter (`crate::processing`) forms the record in the frequency domain and needs the
//! exact, blanked record only when something arrives inside the blanked interval:
//! [`Receiver::echo_in_blanking`] decides that.
//!
//! Determinism: the noise of pulse p of frame f comes from the stream
//! `RngKey { seed, frame: f, pulse: p, stream: ReceiverNoise }` (`crate::rng`).

use crate::rng::{RngKey, Stream};
use num_complex::Complex32;
use rand_pcg::Pcg64Mcg;

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

    /// Whether something arrives while the pulse is still going out: clutter, which starts at
    /// the radar, or an echo whose first sample `earliest_sample` is inside the pulse. Only
    /// then does blanking change the record's echo part.
    pub fn echo_in_blanking(&self, clutter: bool, earliest_sample: Option<usize>) -> bool {
        clutter || earliest_sample.is_some_and(|e| e < self.pulse_len)
    }

    /// Fills `out` with pulse `pulse`'s unit-power noise of frame `frame` (stream
    /// `ReceiverNoise` unless [`Receiver::with_noise_stream`] chose another).
    pub fn fill_noise(&self, seed: u64, frame: u64, pulse: u64, out: &mut [Complex32]) {
        let mut rng = RngKey::new(seed, frame, pulse, self.noise_stream).rng();
        fill_unit_noise(&mut rng, out);
    }

    /// Blanks `record` while transmitting (zeroes its first `pulse_len` samples), if this
    /// receiver blanks.
    pub fn blank(&self, record: &mut [Complex32]) {
        if self.blanking {
            let n = self.pulse_len.min(record.len());
            record[..n].fill(Complex32::new(0.0, 0.0));
        }
    }
}

/// Fills `out` with complex Gaussian noise of unit power (variance ½ in I and in Q).
pub fn fill_unit_noise(rng: &mut Pcg64Mcg, out: &mut [Complex32]) {
    let sigma = std::f32::consts::FRAC_1_SQRT_2;
    for v in out.iter_mut() {
        let (re, im) = crate::rng::normal_pair(rng);
        *v = Complex32::new(re * sigma, im * sigma);
    }
}
