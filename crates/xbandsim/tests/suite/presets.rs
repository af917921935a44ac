//! Radar presets and range scales: each preset's table sets the recorded range, the pulse and
//! the PRF together, and every scale and pulse a preset offers builds (docs/formats.md,
//! "Radar presets").

use xbandsim::model::radar::preset::{NAUTICAL_MILE_M, PRESETS};
use xbandsim::model::Scene;
use xbandsim::Problem;

fn build(radar_lines: &str) -> xbandsim::Result<Scene> {
    Scene::from_toml_str(
        &format!("[environment]\nclutter = false\n[radar]\n{radar_lines}\n"),
        "test",
    )
}

/// Every preset at every scale with every pulse it offers builds, with the table's range,
/// pulse width and PRF and the preset's transmitter and beam.
#[test]
fn every_preset_scale_and_pulse_builds_from_its_table() {
    for p in &PRESETS {
        for row in p.scales {
            for length in row.pulses {
                let s = build(&format!(
                    "preset = \"{}\"\nrange_scale_nm = {}\npulse_length = \"{}\"",
                    p.name,
                    row.range_nm,
                    length.name()
                ))
                .unwrap_or_else(|e| panic!("{} {} NM: {e}", p.name, row.range_nm));
                let r = s.radar();
                let pulse = p.pulses.iter().find(|q| q.length == *length).unwrap();
                assert_eq!(r.max_range_m(), row.range_nm * NAUTICAL_MILE_M);
                assert_eq!(r.range_scale_nm(), Some(row.range_nm));
                assert!((r.chirp().pulse_width_s - pulse.width_us * 1e-6).abs() < 1e-15);
                assert_eq!(r.prf_hz(), pulse.prf_hz);
                assert_eq!(r.transmitter(), p.transmitter);
                assert!(
                    (r.antenna().az_beamwidth_rad.to_degrees() - p.azimuth_beamwidth_deg).abs()
                        < 1e-12
                );
                assert_eq!(r.spokes(), p.spokes);
                // Enough bins for the scale and samples for the pulse.
                assert!(r.num_range_bins() >= 1024, "{}", r.num_range_bins());
            }
        }
    }
}

/// Without a range scale a preset starts on its default scale; the DRS4D-NXT-like set keeps
/// its fixed figures (1 µs, 1200 Hz, 1500 m).
#[test]
fn presets_start_on_their_default_scale() {
    let r = build("preset = \"magnetron-4kw-radome\"").unwrap();
    assert_eq!(r.radar().range_scale_nm(), Some(0.75));
    assert_eq!(r.radar().prf_hz(), 2100.0);
    let r = build("preset = \"drs4d-nxt\"").unwrap();
    assert_eq!(r.radar().range_scale_nm(), None);
    assert_eq!(r.radar().max_range_m(), 1500.0);
    assert_eq!(r.radar().prf_hz(), 1200.0);
    // A given max_range_m replaces the scale; a given field overrides the table's.
    let r = build("preset = \"s-band-30kw\"\nmax_range_m = 5000.0").unwrap();
    assert_eq!(r.radar().range_scale_nm(), None);
    let r = build("preset = \"s-band-30kw\"\nrange_scale_nm = 3\nprf_hz = 1000.0").unwrap();
    assert_eq!(r.radar().prf_hz(), 1000.0);
    assert!((r.radar().carrier_freq_hz() - 3.05e9).abs() < 1.0);
}

/// A scale the preset lacks, a pulse the scale does not offer, a pulse without a scale, and a
/// range given twice are refused naming the field.
#[test]
fn bad_scales_and_pulses_are_refused_naming_the_field() {
    for (lines, field, problem) in [
        (
            "preset = \"magnetron-4kw-radome\"\nrange_scale_nm = 5",
            "radar.range_scale_nm",
            Problem::OutOfRange,
        ),
        (
            "preset = \"magnetron-4kw-radome\"\nrange_scale_nm = 0.25\npulse_length = \"long\"",
            "radar.pulse_length",
            Problem::Conflict,
        ),
        (
            "pulse_length = \"long\"",
            "radar.pulse_length",
            Problem::Conflict,
        ),
        (
            "range_scale_nm = 1.5\nmax_range_m = 2000.0",
            "radar.max_range_m",
            Problem::Conflict,
        ),
    ] {
        let e = build(lines).unwrap_err();
        assert_eq!(e.field(), Some(field), "{e}");
        assert_eq!(e.problem(), Some(problem), "{e}");
    }
    // Another transmitter or beam on a preset gets its own sweep, sample rate and gain.
    let r = build(
        "preset = \"magnetron-25kw-open-array\"\nrange_scale_nm = 12\ntransmitter = \"solid_state\"",
    )
    .unwrap();
    assert!(r.radar().sample_rate_hz() >= 50e6);
    build("preset = \"magnetron-25kw-open-array\"\nazimuth_beamwidth_deg = 3.0").unwrap();
    let e = build("azimuth_beamwidth_deg = 0.01").unwrap_err();
    assert_eq!(e.field(), Some("radar.azimuth_beamwidth_deg"), "{e}");
    let e = build("range_scale_nm = 5").unwrap_err();
    assert!(e.to_string().contains("0.125, 0.25"), "{e}");
}
