//! Per-spoke receive chain (impulse response → noise → blanking → matched filter) and the
//! whole-frame synthesis, for short and long pulses with 2048 range bins.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use num_complex::Complex32;
use xbandsim::engine::Simulation;
use xbandsim::processing::PulseCompressor;
use xbandsim::receiver::fill_unit_noise;
use xbandsim::rng::{RngKey, Stream};
use xbandsim::waveform::{LfmChirp, Window};

const PAPER: &str = include_str!("../../../scenes/paper.toml");

fn spoke_chain(c: &mut Criterion) {
    let mut g = c.benchmark_group("matched_filter_spoke_2048_bins");
    for pulse_us in [1.0, 20.0, 50.0] {
        let chirp = LfmChirp {
            bandwidth_hz: 50e6,
            pulse_width_s: pulse_us * 1e-6,
            sample_rate_hz: 100e6,
        };
        let pc = PulseCompressor::new(&chirp, Window::Hamming, 2048);
        let mut scratch = pc.scratch();
        let mut rng = RngKey::new(1, 0, 0, Stream::ReceiverNoise).rng();
        g.throughput(Throughput::Elements(2048));
        g.bench_function(format!("{pulse_us}us_with_noise"), |b| {
            b.iter(|| {
                scratch.buffer.fill(Complex32::new(0.0, 0.0));
                scratch.buffer[700] = Complex32::new(10.0, 0.0);
                let record = pc.record_len();
                fill_unit_noise(&mut rng, &mut scratch.noise[..record]);
                pc.process(&mut scratch, true, true, false);
                scratch.buffer[100]
            })
        });
    }
    g.finish();
}

fn frame_synthesis(c: &mut Criterion) {
    let scene = xbandsim::LoadedSpec::from_toml(PAPER, "paper", std::path::Path::new("."))
        .and_then(|s| s.with_overrides(&["radar.max_range_m=3100"]))
        .and_then(|s| s.build())
        .unwrap();
    let sim = Simulation::new(scene);
    let groups = sim.echo_groups(&sim.trace());
    let mut g = c.benchmark_group("frame");
    g.sample_size(20);
    g.bench_function("paper_scene_360x2069_synthesis", |b| {
        b.iter(|| sim.synthesize(&groups, None, &xbandsim::engine::Request::new(1)))
    });
    g.finish();
}

criterion_group!(benches, spoke_chain, frame_synthesis);
criterion_main!(benches);
