//! Stage: receiver. Thermal noise and the seeds that make it reproducible.
//!
//! Noise: complex white Gaussian with power `N = k·T0·F·fs` per complex sample (W across 1 Ω;
//! Skolnik, *Radar Handbook*, 3rd ed., §2.3), i.e. `N/2` in each of I and Q. The pipeline
//! works in units of the noise rms voltage `√N`, so the generated samples have unit variance.
//!
//! Determinism: every draw comes from a PCG stream seeded from (seed, frame, spoke) through
//! SplitMix64, so the output does not depend on the number of threads.

use num_complex::Complex32;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64Mcg;

/// SplitMix64 finaliser (Steele, Lea & Flood, OOPSLA 2014): a well-mixed 64-bit hash.
#[inline]
pub fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

/// The RNG for one (seed, frame, stream) triple.
pub fn stream_rng(seed: u64, frame: u64, stream: u64) -> Pcg64Mcg {
    let s = splitmix64(
        splitmix64(splitmix64(seed) ^ frame) ^ stream.wrapping_mul(0xD1B5_4A32_D192_ED03),
    );
    Pcg64Mcg::seed_from_u64(s)
}

/// Fills `out` with complex Gaussian noise of unit power (variance ½ in I and in Q).
pub fn fill_unit_noise(rng: &mut Pcg64Mcg, out: &mut [Complex32]) {
    let sigma = std::f32::consts::FRAC_1_SQRT_2;
    for v in out.iter_mut() {
        let re: f32 = StandardNormal.sample(rng);
        let im: f32 = StandardNormal.sample(rng);
        *v = Complex32::new(re * sigma, im * sigma);
    }
}
