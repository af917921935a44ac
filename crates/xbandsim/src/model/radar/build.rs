//! The radar from its scene-file description: presets, defaults, every field checked with
//! its located error (docs/scene-format.md), the pulse train's stagger and the combined
//! mode's short pulse.

use super::preset::RadarDefaults;
use super::*;
use crate::antenna::{uniform_aperture_gain, Antenna, PatternTable, Tapered, MAX_TAYLOR_NBAR};
use crate::choice::Transmitter;
use crate::constants::*;
use crate::error::{Error, Problem, Result};
use crate::model::checks::{finite, finite_vec, fmt_vec, positive};
use crate::scene::{AntennaPatternName, PulseModeName, RadarSpec, WindowName};
use crate::waveform::{LfmChirp, Window};

/// Validates the `[radar]` table; `environment_polarisation` is the older place a scene file
/// may give the polarisation (`environment.polarisation`), which must agree with
/// `radar.polarisation` when both are given.
pub(in crate::model) fn build_radar(
    s: &RadarSpec,
    environment_polarisation: Option<Polarisation>,
    base_dir: &std::path::Path,
) -> Result<Radar> {
    let d = RadarDefaults::of(s)?;
    let preset = d.preset;
    let position_m = finite_vec(
        "radar.position_m",
        s.position_m.unwrap_or([0.0, 0.0, preset.antenna_height_m]),
    )?;
    if position_m.z <= 0.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.position_m",
            fmt_vec(position_m),
            "the antenna must be above the sea surface (z > 0; the sea is the plane z = 0)",
        ));
    }
    let frequency_ghz = positive(
        "radar.frequency_ghz",
        s.frequency_ghz.unwrap_or(preset.frequency_ghz),
    )?;
    let transmitter = s.transmitter.unwrap_or(preset.transmitter);
    if transmitter == Transmitter::Magnetron {
        refuse_for_magnetron(s)?;
    }
    let bandwidth_mhz = match transmitter {
        Transmitter::SolidState => {
            positive(
                "radar.bandwidth_mhz",
                // A magnetron preset's pulse has no sweep: a solid-state override gets 50 MHz.
                s.bandwidth_mhz.unwrap_or(if d.bandwidth_mhz > 0.0 {
                    d.bandwidth_mhz
                } else {
                    50.0
                }),
            )?
        }
        // An unmodulated pulse: no sweep (its spectrum is about 1/T wide).
        Transmitter::Magnetron => 0.0,
    };
    let pulse_width_us = positive(
        "radar.pulse_width_us",
        s.pulse_width_us.unwrap_or(d.pulse_width_us),
    )?;
    let sample_rate_mhz = positive(
        "radar.sample_rate_mhz",
        s.sample_rate_mhz.unwrap_or(d.sample_rate_mhz),
    )?;
    let peak_power_w = positive(
        "radar.peak_power_w",
        s.peak_power_w.unwrap_or(preset.peak_power_w),
    )?;
    let noise_figure_db = finite(
        "radar.noise_figure_db",
        s.noise_figure_db.unwrap_or(preset.noise_figure_db),
    )?;
    if noise_figure_db < 0.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.noise_figure_db",
            noise_figure_db,
            "a noise figure cannot be below 0 dB",
        ));
    }
    let system_loss_db = finite("radar.system_loss_db", s.system_loss_db.unwrap_or(0.0))?;
    if system_loss_db < 0.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.system_loss_db",
            system_loss_db,
            "a loss must be 0 dB or more",
        ));
    }
    let azimuth_table = pattern_table(
        "radar.azimuth_pattern_file",
        s.azimuth_pattern_file.as_deref(),
        base_dir,
    )?;
    let elevation_table = pattern_table(
        "radar.elevation_pattern_file",
        s.elevation_pattern_file.as_deref(),
        base_dir,
    )?;
    for (table, field, given) in [
        (
            azimuth_table,
            "radar.azimuth_beamwidth_deg",
            s.azimuth_beamwidth_deg,
        ),
        (
            elevation_table,
            "radar.elevation_beamwidth_deg",
            s.elevation_beamwidth_deg,
        ),
    ] {
        if let (Some(_), Some(v)) = (table, given) {
            return Err(Error::invalid(
                Problem::Conflict,
                field,
                v,
                "a measured pattern file sets the beamwidth: leave it out",
            ));
        }
    }
    if azimuth_table.is_some() && s.antenna_pattern.is_some() {
        return Err(Error::invalid(
            Problem::Conflict,
            "radar.antenna_pattern",
            "given",
            "radar.azimuth_pattern_file is the azimuth pattern: leave antenna_pattern out",
        ));
    }
    let az_bw_deg = match azimuth_table {
        Some(t) => t.beamwidth_3db_rad().to_degrees(),
        None => positive(
            "radar.azimuth_beamwidth_deg",
            s.azimuth_beamwidth_deg
                .unwrap_or(preset.azimuth_beamwidth_deg),
        )?,
    };
    let el_bw_deg = match elevation_table {
        Some(t) => t.beamwidth_3db_rad().to_degrees(),
        None => positive(
            "radar.elevation_beamwidth_deg",
            s.elevation_beamwidth_deg
                .unwrap_or(preset.elevation_beamwidth_deg),
        )?,
    };
    for (field, bw) in [
        ("radar.azimuth_beamwidth_deg", az_bw_deg),
        ("radar.elevation_beamwidth_deg", el_bw_deg),
    ] {
        if bw < 0.05 {
            // The echo groups' azimuth cells (a tenth of the beam) must number under 2²⁰.
            return Err(Error::invalid(
                Problem::OutOfRange,
                if field.starts_with("radar.azimuth") && azimuth_table.is_some() {
                    "radar.azimuth_pattern_file"
                } else if field.starts_with("radar.elevation") && elevation_table.is_some() {
                    "radar.elevation_pattern_file"
                } else {
                    field
                },
                bw,
                "the beamwidth must be at least 0.05°",
            ));
        }
    }
    if az_bw_deg >= 180.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.azimuth_beamwidth_deg",
            az_bw_deg,
            "must be less than 180",
        ));
    }
    if el_bw_deg >= 180.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.elevation_beamwidth_deg",
            el_bw_deg,
            "must be less than 180",
        ));
    }
    let tilt_deg = finite("radar.tilt_deg", s.tilt_deg.unwrap_or(0.0))?;
    if tilt_deg.abs() > 90.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.tilt_deg",
            tilt_deg,
            "must be within -90..90",
        ));
    }
    let az_bw = az_bw_deg.to_radians();
    let el_bw = el_bw_deg.to_radians();
    // A lossless aperture with these beamwidths cannot exceed 4π/(θaz·θel) (Balanis,
    // Antenna Theory, §2.6, with Kraus's approximation; the uniform aperture reaches 0.78 of it).
    let max_gain_dbi = 10.0 * (4.0 * std::f64::consts::PI / (az_bw * el_bw)).log10();
    // The preset's gain goes with the preset's beam: another beam gets its own.
    let preset_beam = s.azimuth_beamwidth_deg.is_none()
        && s.elevation_beamwidth_deg.is_none()
        && azimuth_table.is_none()
        && elevation_table.is_none();
    let preset_gain = preset.gain_dbi.filter(|_| preset_beam);
    let peak_gain_linear = match s.gain_dbi.or(preset_gain) {
        Some(g) => {
            let g = finite("radar.gain_dbi", g)?;
            if !(0.0..=max_gain_dbi + 1.0).contains(&g) {
                return Err(Error::invalid(
                Problem::Conflict,
                    "radar.gain_dbi",
                    g,
                    format!(
                        "implausible for beamwidths {az_bw_deg}° × {el_bw_deg}°: an antenna with them has at most 4π/(θaz·θel) = {max_gain_dbi:.1} dBi (and a radar antenna has gain above 0 dBi); change the gain or the beamwidths"
                    ),
                ));
            }
            db_to_linear(g)
        }
        None => uniform_aperture_gain(az_bw, el_bw),
    };
    let prf_hz = positive("radar.prf_hz", s.prf_hz.unwrap_or(d.prf_hz))?;
    let rotation_rpm = positive(
        "radar.rotation_rpm",
        s.rotation_rpm.unwrap_or(preset.rotation_rpm),
    )?;
    let max_range_m = positive("radar.max_range_m", s.max_range_m.unwrap_or(d.max_range_m))?;
    let spokes = s.spokes.unwrap_or(preset.spokes);
    if spokes == 0 || spokes > MAX_SPOKES {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.spokes",
            spokes,
            format!("must be between 1 and {MAX_SPOKES}"),
        ));
    }
    let window = match s.window.unwrap_or_default() {
        WindowName::None => Window::None,
        WindowName::Hamming => Window::Hamming,
        WindowName::Taylor => {
            let nbar = s.taylor_nbar.unwrap_or(4);
            if !(2..=32).contains(&nbar) {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    "radar.taylor_nbar",
                    nbar,
                    "must be between 2 and 32",
                ));
            }
            let sll = finite(
                "radar.taylor_sidelobe_db",
                s.taylor_sidelobe_db.unwrap_or(-35.0),
            )?;
            if !(-120.0..=-13.5).contains(&sll) {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    "radar.taylor_sidelobe_db",
                    sll,
                    "must be between -120 and -13.5 dB",
                ));
            }
            Window::Taylor {
                nbar,
                sidelobe_db: sll,
            }
        }
    };
    let pulse_width_s = pulse_width_us * 1e-6;
    let pri_s = 1.0 / prf_hz;
    // Compared in microseconds, as written, so that 50 us at 20 kHz is caught exactly.
    if pulse_width_us >= 1e6 / prf_hz {
        return Err(Error::invalid(
                Problem::Conflict,
            "radar.pulse_width_us",
            pulse_width_us,
            format!("the pulse must be shorter than the pulse repetition interval 1/prf_hz = {:.3} us (prf_hz = {prf_hz})", pri_s * 1e6),
        ));
    }
    let stagger = build_stagger(s.prf_stagger.as_deref(), prf_hz, pulse_width_us)?;
    let sample_rate_hz = sample_rate_mhz * 1e6;
    let bandwidth_hz = bandwidth_mhz * 1e6;
    if bandwidth_hz > sample_rate_hz {
        return Err(Error::invalid(
                Problem::Conflict,
            "radar.bandwidth_mhz",
            bandwidth_mhz,
            format!("complex sampling needs sample_rate_mhz ({sample_rate_mhz}) at least equal to the bandwidth"),
        ));
    }
    let samples = (pulse_width_s * sample_rate_hz).round();
    if samples < 2.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.pulse_width_us",
            pulse_width_us,
            format!("the pulse is under two samples at sample_rate_mhz = {sample_rate_mhz}"),
        ));
    }
    if samples > 4.0e6 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.pulse_width_us",
            pulse_width_us,
            "the pulse is over 4 million samples; lower the pulse width or sample rate",
        ));
    }
    let range_bin_m = SPEED_OF_LIGHT_M_PER_S / (2.0 * sample_rate_hz);
    // Echoes from beyond c/(2·PRF) arrive after the next pulse has gone out (second-trace
    // echoes): the simulator records one pulse repetition interval, so it does not model
    // them and the recorded range must stay inside it.
    // A staggered train's shortest interval sets it.
    let shortest_pri_s = stagger.shortest_interval_s();
    let unambiguous_m = SPEED_OF_LIGHT_M_PER_S * shortest_pri_s / 2.0;
    if max_range_m + SPEED_OF_LIGHT_M_PER_S * pulse_width_s / 2.0 > unambiguous_m {
        let interval = if stagger.is_staggered() {
            format!(
                "the shortest pulse interval ({:.3} us, prf_stagger)",
                shortest_pri_s * 1e6
            )
        } else {
            format!("1/prf_hz (prf_hz = {prf_hz})")
        };
        return Err(Error::invalid(
                Problem::Conflict,
            "radar.max_range_m",
            max_range_m,
            format!(
                "beyond the unambiguous range: max_range_m plus the pulse's c·T/2 must stay within c/2 times {interval} = {:.1} km (the record is one pulse interval; echoes from farther arrive after the next pulse: [artefacts] second_trace draws them); lower max_range_m or prf_hz",
                unambiguous_m / 1000.0
            ),
        ));
    }
    let bins = max_range_m / range_bin_m;
    if bins > 4.0e6 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.max_range_m",
            max_range_m,
            "over 4 million range bins; lower max_range_m or sample_rate_mhz",
        ));
    }
    let cells = bins * spokes as f64;
    if cells > MAX_POLAR_CELLS as f64 {
        return Err(Error::invalid(
                Problem::OutOfRange,
            "radar.max_range_m",
            max_range_m,
            format!(
                "the output would have {spokes} spokes × {:.0} range bins = {:.0} M cells ({:.1} GB of polar data alone); the limit is {} M cells: lower max_range_m, spokes or sample_rate_mhz",
                bins.ceil(),
                cells / 1e6,
                cells * 4.0 / 1e9,
                MAX_POLAR_CELLS / 1_000_000
            ),
        ));
    }
    if frequency_ghz * 1e9 <= bandwidth_hz {
        return Err(Error::invalid(
            Problem::Conflict,
            "radar.frequency_ghz",
            frequency_ghz,
            "the carrier must be above the bandwidth",
        ));
    }
    let short_pulse = build_short_pulse(s, pulse_width_us, sample_rate_hz, window)?;
    let azimuth_taper = build_azimuth_taper(s, preset.sidelobes_db, az_bw)?;
    let mut polarisation = s.polarisation.unwrap_or(Polarisation::Hh);
    if let Some(pol) = environment_polarisation {
        if s.polarisation.is_some() && pol != polarisation {
            return Err(Error::invalid(
                Problem::Conflict,
                "environment.polarisation",
                format!("\"{pol}\""),
                "differs from radar.polarisation; give the polarisation once",
            ));
        }
        polarisation = pol;
    }
    Ok(Radar {
        transmitter,
        position_m,
        carrier_freq_hz: frequency_ghz * 1e9,
        chirp: LfmChirp {
            bandwidth_hz,
            pulse_width_s,
            sample_rate_hz,
        },
        window,
        peak_power_w,
        noise_figure_linear: db_to_linear(noise_figure_db),
        system_loss_linear: db_to_linear(system_loss_db),
        antenna: Antenna {
            az_beamwidth_rad: az_bw,
            el_beamwidth_rad: el_bw,
            peak_gain_linear,
            tilt_rad: tilt_deg.to_radians(),
            azimuth_taper: azimuth_taper.filter(|_| azimuth_table.is_none()),
            azimuth_table,
            elevation_table,
        },
        scan: Scan {
            prf_hz,
            rotation_rpm,
            spokes,
            max_range_m,
            stagger,
        },
        receiver_blanking: s.receiver_blanking.unwrap_or(true),
        polarisation,
        short_pulse,
        range_scale_nm: d.range_scale_nm,
    })
}

/// Validates `radar.prf_stagger`: 2 to [`MAX_PRF_STAGGER`] finite positive ratios, no
/// interval shorter than the pulse.
fn build_stagger(ratios: Option<&[f64]>, prf_hz: f64, pulse_width_us: f64) -> Result<Stagger> {
    let Some(ratios) = ratios else {
        return Ok(Stagger::none(prf_hz));
    };
    let field = "radar.prf_stagger";
    if !(2..=MAX_PRF_STAGGER).contains(&ratios.len()) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            field,
            fmt_list(ratios),
            format!(
                "give 2 to {MAX_PRF_STAGGER} pulse-interval ratios (leave it out for no stagger)"
            ),
        ));
    }
    for (i, &r) in ratios.iter().enumerate() {
        if !r.is_finite() || r <= 0.0 {
            return Err(Error::invalid(
                Problem::OutOfRange,
                format!("{field}[{i}]"),
                r,
                "a pulse-interval ratio must be a finite number above 0",
            ));
        }
    }
    let stagger = Stagger::of(ratios, prf_hz);
    if pulse_width_us >= stagger.shortest_interval_s() * 1e6 {
        return Err(Error::invalid(
            Problem::Conflict,
            field,
            fmt_list(ratios),
            format!(
                "the shortest pulse interval ({:.3} us) is not longer than the pulse (pulse_width_us = {pulse_width_us})",
                stagger.shortest_interval_s() * 1e6
            ),
        ));
    }
    Ok(stagger)
}

/// Validates `radar.antenna_pattern` and its fields into the azimuth plane's tapered pattern
/// (None: sinc²); the preset's sidelobes are the defaults.
fn build_azimuth_taper(
    s: &RadarSpec,
    preset_sidelobes_db: Option<(f64, f64, f64)>,
    az_bw_rad: f64,
) -> Result<Option<Tapered>> {
    let name = s
        .antenna_pattern
        .unwrap_or(if preset_sidelobes_db.is_some() {
            AntennaPatternName::Taylor
        } else {
            AntennaPatternName::Sinc2
        });
    let fields = [
        ("radar.sidelobe_db", s.sidelobe_db),
        ("radar.far_sidelobe_db", s.far_sidelobe_db),
        ("radar.back_lobe_db", s.back_lobe_db),
        ("radar.pattern_nbar", s.pattern_nbar.map(|n| n as f64)),
    ];
    if name == AntennaPatternName::Sinc2 {
        if let Some((field, Some(v))) = fields.iter().find(|(_, v)| v.is_some()) {
            return Err(Error::invalid(
                Problem::Conflict,
                *field,
                v,
                "only radar.antenna_pattern = \"taylor\" has these sidelobes (sinc² has its own)",
            ));
        }
        return Ok(None);
    }
    let (near, far, back) = preset_sidelobes_db.unwrap_or((-28.0, -40.0, -35.0));
    let sidelobe_db = finite("radar.sidelobe_db", s.sidelobe_db.unwrap_or(near))?;
    if !(-60.0..=-14.0).contains(&sidelobe_db) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.sidelobe_db",
            sidelobe_db,
            "must be between -60 and -14 dB (a taper lowers the uniform aperture's -13.3 dB)",
        ));
    }
    let nbar = s.pattern_nbar.unwrap_or(5);
    if !(2..=MAX_TAYLOR_NBAR).contains(&nbar) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.pattern_nbar",
            nbar,
            format!("must be between 2 and {MAX_TAYLOR_NBAR}"),
        ));
    }
    let floor_db = finite("radar.far_sidelobe_db", s.far_sidelobe_db.unwrap_or(far))?;
    if !(-90.0..=sidelobe_db).contains(&floor_db) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.far_sidelobe_db",
            floor_db,
            format!(
                "must be between -90 dB and the near sidelobes (radar.sidelobe_db = {sidelobe_db})"
            ),
        ));
    }
    let back_db = finite("radar.back_lobe_db", s.back_lobe_db.unwrap_or(back))?;
    if !(-90.0..=-10.0).contains(&back_db) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.back_lobe_db",
            back_db,
            "must be between -90 and -10 dB",
        ));
    }
    Ok(Some(Tapered::new(
        az_bw_rad,
        sidelobe_db,
        nbar,
        floor_db,
        back_db,
    )))
}

/// Reads and interns the pattern cut `file` (relative to `base_dir`) named by `field`.
fn pattern_table(
    field: &str,
    file: Option<&str>,
    base_dir: &std::path::Path,
) -> Result<Option<&'static PatternTable>> {
    let Some(file) = file else { return Ok(None) };
    let path = base_dir.join(file);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        Error::unusable(
            field,
            format!("\"{file}\""),
            "cannot be read",
            Error::io(&path, e),
        )
    })?;
    let table = PatternTable::parse(&text).map_err(|why| {
        Error::invalid(
            Problem::Unusable,
            field,
            format!("\"{file}\""),
            format!("is not a pattern cut: {why}"),
        )
    })?;
    if table.beamwidth_3db_rad() <= 0.0 {
        return Err(Error::invalid(
            Problem::Unusable,
            field,
            format!("\"{file}\""),
            "its main lobe is narrower than the 0.01° grid",
        ));
    }
    Ok(Some(PatternTable::intern(table)))
}

fn fmt_list(values: &[f64]) -> String {
    let items: Vec<String> = values.iter().map(|v| v.to_string()).collect();
    format!("[{}]", items.join(", "))
}

/// Validates `radar.pulse_mode` and the short pulse's fields (given only with "combined";
/// the short pulse at least two samples long and shorter than the long one, its bandwidth
/// within the sample rate).
fn build_short_pulse(
    s: &RadarSpec,
    pulse_width_us: f64,
    sample_rate_hz: f64,
    window: Window,
) -> Result<Option<ShortPulse>> {
    if s.pulse_mode.unwrap_or_default() == PulseModeName::Single {
        for (field, given) in [
            ("radar.short_pulse_width_us", s.short_pulse_width_us),
            ("radar.short_bandwidth_mhz", s.short_bandwidth_mhz),
        ] {
            if let Some(v) = given {
                return Err(Error::invalid(
                    Problem::Conflict,
                    field,
                    v,
                    "only combined pulse mode has a short pulse: set radar.pulse_mode = \"combined\" or leave it out",
                ));
            }
        }
        return Ok(None);
    }
    let width_us = positive(
        "radar.short_pulse_width_us",
        s.short_pulse_width_us.unwrap_or(0.08),
    )?;
    if width_us >= pulse_width_us {
        return Err(Error::invalid(
            Problem::Conflict,
            "radar.short_pulse_width_us",
            width_us,
            format!("the short pulse must be shorter than the long one (pulse_width_us = {pulse_width_us})"),
        ));
    }
    if (width_us * 1e-6 * sample_rate_hz).round() < 2.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.short_pulse_width_us",
            width_us,
            format!(
                "the short pulse is under two samples at sample_rate_mhz = {}",
                sample_rate_hz / 1e6
            ),
        ));
    }
    let (bandwidth_hz, window) = match s.short_bandwidth_mhz {
        None => (0.0, Window::None),
        Some(b) => {
            let b = positive("radar.short_bandwidth_mhz", b)?;
            if b * 1e6 > sample_rate_hz {
                return Err(Error::invalid(
                    Problem::Conflict,
                    "radar.short_bandwidth_mhz",
                    b,
                    format!(
                        "complex sampling needs sample_rate_mhz ({}) at least equal to the bandwidth",
                        sample_rate_hz / 1e6
                    ),
                ));
            }
            (b * 1e6, window)
        }
    };
    Ok(Some(ShortPulse {
        chirp: LfmChirp {
            bandwidth_hz,
            pulse_width_s: width_us * 1e-6,
            sample_rate_hz,
        },
        window,
    }))
}

/// The fields a magnetron set cannot have: a swept bandwidth (its pulse is unmodulated) and the
/// combined pulse mode (a second, coded pulse).
fn refuse_for_magnetron(s: &RadarSpec) -> Result<()> {
    if let Some(b) = s.bandwidth_mhz {
        return Err(Error::invalid(
            Problem::Conflict,
            "radar.bandwidth_mhz",
            b,
            "a magnetron transmits an unmodulated pulse (its spectrum is about 1/pulse width wide): leave bandwidth_mhz out, or set radar.transmitter = \"solid_state\"",
        ));
    }
    if s.pulse_mode == Some(PulseModeName::Combined) {
        return Err(Error::invalid(
            Problem::Conflict,
            "radar.pulse_mode",
            "\"combined\"",
            "the combined pulse mode is a solid-state set's (a coded long pulse and a short one): a magnetron fires one pulse",
        ));
    }
    Ok(())
}
