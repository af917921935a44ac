//! Stage: signal processing. Pulse compression (matched filter by FFT) and the per-pulse
//! receive chain that turns an impulse response into a compressed range profile; CFAR
//! detection along range ([`cfar`]) and the plot extractor built on it ([`plots`]).

pub mod cfar;
mod matched_filter;
pub mod plots;

pub use matched_filter::{
    direct_correlation, fast_fft_len, DopplerSpectra, PulseCompressor, SpokeScratch,
};
pub mod sinks;
