//! Random streams, keyed. Every random draw of a render comes from one stream named by an
//! [`RngKey`]: (seed, frame, pulse, [`Stream`]). A stream's generator is seeded by hashing its
//! key, so a draw depends only on its key — not on the thread that makes it, the order of
//! work, a shard or a job count — which is what makes renders byte-identical run to run.
//!
//! Generator: PCG-64 MCG (O'Neill, "PCG: a family of simple fast space-efficient
//! statistically good algorithms for random number generation", 2014) seeded from the key
//! through the SplitMix64 finaliser (Steele, Lea & Flood, OOPSLA 2014). docs/architecture.md
//! ("Random streams") says why this and not a ChaCha stream, and how the key maps to the seed.

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// SplitMix64 finaliser: a well-mixed 64-bit hash.
#[inline]
pub fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// What a stream is drawn for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stream {
    /// The receiver's thermal noise of one pulse.
    ReceiverNoise,
    /// The sea-clutter and rain speckle of one pulse.
    ClutterSpeckle,
    /// The sea-clutter texture field (one per seed: it drifts from frame to frame rather than
    /// being drawn anew, so it ignores the frame and the pulse).
    ClutterTexture,
    /// The Doppler-coloured sea-clutter and rain speckle of one dwell in pulse mode (its
    /// `pulse` word is the dwell's spoke).
    ClutterDwell,
    /// The receiver's thermal noise of one pulse's short-pulse channel (combined pulse mode).
    ShortPulseNoise,
}

/// The key of one random stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RngKey {
    /// The render's seed.
    pub seed: u64,
    /// Revolution number.
    pub frame: u64,
    /// Pulse number within the revolution (today one pulse per spoke: the spoke index).
    pub pulse: u64,
    /// What the draws are for.
    pub stream: Stream,
}

/// Pulse numbers of a revolution stay below this (2^40): it keeps the clutter streams' words
/// apart from the noise streams' (`engine::Schedule::new` refuses larger pulse numbers).
pub const MAX_PULSES_PER_FRAME: u64 = 1 << 40;

const CLUTTER_WORD: u64 = MAX_PULSES_PER_FRAME;

impl RngKey {
    /// The key of `stream` for pulse `pulse` of frame `frame`.
    pub fn new(seed: u64, frame: u64, pulse: u64, stream: Stream) -> RngKey {
        RngKey {
            seed,
            frame,
            pulse,
            stream,
        }
    }

    /// The (frame word, stream word) hashed with the seed. Receiver noise: (frame, pulse);
    /// clutter speckle: (frame, 2^40 + pulse); the clutter texture: (2^64 − 1, 2^40 − 1);
    /// a pulse-mode dwell's clutter: (frame, 2^41 + spoke); the short-pulse channel's noise:
    /// (frame, 3·2^40 + pulse).
    fn words(&self) -> (u64, u64) {
        match self.stream {
            Stream::ReceiverNoise => (self.frame, self.pulse),
            Stream::ClutterSpeckle => (self.frame, CLUTTER_WORD + self.pulse),
            Stream::ClutterTexture => (u64::MAX, CLUTTER_WORD - 1),
            Stream::ClutterDwell => (self.frame, 2 * CLUTTER_WORD + self.pulse),
            Stream::ShortPulseNoise => (self.frame, 3 * CLUTTER_WORD + self.pulse),
        }
    }

    /// The 64-bit seed of this stream's generator:
    /// `h(h(h(seed) ^ frame word) ^ stream word · 0xD1B54A32D192ED03)` with `h` = SplitMix64.
    pub fn stream_seed(&self) -> u64 {
        let (frame_word, stream_word) = self.words();
        splitmix64(
            splitmix64(splitmix64(self.seed) ^ frame_word)
                ^ stream_word.wrapping_mul(0xD1B5_4A32_D192_ED03),
        )
    }

    /// A fresh generator for this stream.
    pub fn rng(&self) -> Pcg64Mcg {
        Pcg64Mcg::seed_from_u64(self.stream_seed())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Different keys give different streams; the same key the same stream.
    #[test]
    fn keys_separate_streams() {
        let mut seen = std::collections::HashSet::new();
        for seed in 0..3 {
            for frame in 0..3 {
                for pulse in 0..50 {
                    for stream in [
                        Stream::ReceiverNoise,
                        Stream::ClutterSpeckle,
                        Stream::ClutterDwell,
                        Stream::ShortPulseNoise,
                    ] {
                        let k = RngKey::new(seed, frame, pulse, stream);
                        assert!(seen.insert(k.stream_seed()), "{k:?}");
                        assert_eq!(k.stream_seed(), k.stream_seed());
                    }
                }
            }
            let texture = RngKey::new(seed, 0, 0, Stream::ClutterTexture);
            assert!(seen.insert(texture.stream_seed()));
            // The texture stream ignores frame and pulse.
            assert_eq!(
                texture.stream_seed(),
                RngKey::new(seed, 9, 7, Stream::ClutterTexture).stream_seed()
            );
        }
    }
}
