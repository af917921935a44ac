//! Signal source: the receiver's thermal noise. Complex white Gaussian with power
//! `N = k·T0·F·fs` per complex sample (W across 1 Ω; Skolnik, *Radar Handbook*, 3rd ed.,
//! §2.3), i.e. `N/2` in each of I and Q. The pipeline works in units of the noise rms voltage
//! `√N`, so the samples have unit variance. Pulse p of frame f draws from the stream
//! `(seed, f, p, ReceiverNoise)` (`crate::rng`); the short-pulse channel of combined pulse
//! mode has its own stream.
//!
//! Noise enters the matched filter apart from the echoes (the fused filter forms the echo
//! record in the frequency domain and filters the noise on its own), so the engine asks for
//! it whole ([`ThermalNoise::fill`]); as a [`Source`] it adds the same samples to a record
//! formed in time.

use super::{PulseAt, Source, SourceScratch};
use crate::rng::{FrameKey, Stream};
use num_complex::Complex32;
use rand_pcg::Pcg64Mcg;

/// Thermal noise drawn from one kind of stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ThermalNoise {
    stream: Stream,
}

impl ThermalNoise {
    /// Noise from the streams `stream` of each pulse.
    pub fn new(stream: Stream) -> ThermalNoise {
        ThermalNoise { stream }
    }

    /// The stream it draws from.
    pub fn stream(&self) -> Stream {
        self.stream
    }

    /// Fills `out` with pulse `pulse`'s unit-power noise of the revolution `key`.
    pub fn fill(&self, key: FrameKey, pulse: u64, out: &mut [Complex32]) {
        let mut rng = key.pulse(pulse, self.stream).rng();
        fill_unit_noise(&mut rng, out);
    }
}

impl Source for ThermalNoise {
    /// Adds the pulse's noise to every sample of `samples`. Returns None: noise is no echo.
    fn add_to_pulse(
        &self,
        at: &PulseAt,
        scratch: &mut SourceScratch,
        samples: &mut [Complex32],
    ) -> Option<usize> {
        let work = &mut scratch.mover;
        work.resize(samples.len(), Complex32::new(0.0, 0.0));
        self.fill(at.key, at.pulse.number, &mut work[..samples.len()]);
        for (s, n) in samples.iter_mut().zip(work.iter()) {
            *s += n;
        }
        None
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
