//! Model: the radar — position, carrier, LFM waveform and matched-filter window, antenna,
//! receiver (noise figure, losses, blanking) and scan (PRF, rotation, spokes, range), in SI
//! units, validated from the scene file's `[radar]` table (docs/formats.md).

mod build;
pub mod preset;

use crate::antenna::Antenna;
use crate::constants::{
    wavelength_m, BOLTZMANN_J_PER_K, REFERENCE_TEMPERATURE_K, SPEED_OF_LIGHT_M_PER_S,
};
use crate::waveform::{LfmChirp, Window};
pub(in crate::model) use build::build_radar;
use glam::DVec3;

/// Largest number of spokes per revolution.
pub const MAX_SPOKES: usize = 8192;

/// Largest polar output, spokes × range bins (256 MB of float32; the clutter map and the
/// images take a few times that again).
pub const MAX_POLAR_CELLS: usize = 64_000_000;

/// The radar, in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Radar {
    /// What makes the pulse.
    transmitter: Transmitter,
    /// Antenna phase centre, ENU m.
    position_m: DVec3,
    /// Carrier frequency f0, Hz.
    carrier_freq_hz: f64,
    /// The transmitted LFM pulse (bandwidth, pulse width, sample rate).
    chirp: LfmChirp,
    /// Matched-filter reference window.
    window: Window,
    /// Peak transmit power Pt, W.
    peak_power_w: f64,
    /// Noise figure F (linear).
    noise_figure_linear: f64,
    /// System loss L (linear, ≥ 1).
    system_loss_linear: f64,
    /// Antenna beamwidths, gain and tilt.
    antenna: Antenna,
    /// How the antenna turns and what a revolution records.
    scan: Scan,
    /// Receiver blanked while transmitting.
    receiver_blanking: bool,
    /// Transmit and receive polarisation.
    polarisation: Polarisation,
    /// The short pulse of combined pulse mode (None: single pulse).
    short_pulse: Option<ShortPulse>,
    /// The range scale the set is on, NM (None: a range given as `max_range_m`).
    range_scale_nm: Option<f64>,
}

/// The short pulse of `pulse_mode = "combined"` (docs/physics.md §11): it serves the range
/// bins inside the long pulse's eclipse, `j < N_T`, on its own receive channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShortPulse {
    /// The pulse: unmodulated (bandwidth 0) or an LFM chirp, at the radar's sample rate.
    pub chirp: LfmChirp,
    /// Its matched-filter window: none for an unmodulated pulse, the radar's otherwise.
    pub window: Window,
}

/// Most entries in `radar.prf_stagger`.
pub const MAX_PRF_STAGGER: usize = 8;

/// The scan: pulse rate (with its stagger), rotation, spokes per revolution and recorded
/// range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scan {
    prf_hz: f64,
    rotation_rpm: f64,
    spokes: usize,
    max_range_m: f64,
    stagger: Stagger,
}

/// A staggered pulse train (docs/physics.md §10): pulse intervals cycle through
/// `T_i = r_i/mean(r)·(1/prf)`, so `prf` stays the mean rate; one entry is no stagger.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stagger {
    len: usize,
    /// Start of pulse i within a cycle, `Σ_{j<i} T_j`, s.
    offsets_s: [f64; MAX_PRF_STAGGER],
    /// The intervals `T_i`, s.
    intervals_s: [f64; MAX_PRF_STAGGER],
    /// `Σ T_i`, s.
    cycle_s: f64,
}

impl Stagger {
    /// No stagger at `prf_hz`.
    fn none(prf_hz: f64) -> Stagger {
        Stagger::of(&[1.0], prf_hz)
    }

    /// The intervals `r_i/mean(r)/prf` (`ratios`: 1..=MAX_PRF_STAGGER positive values).
    fn of(ratios: &[f64], prf_hz: f64) -> Stagger {
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        let mut offsets_s = [0.0; MAX_PRF_STAGGER];
        let mut intervals_s = [0.0; MAX_PRF_STAGGER];
        let mut t = 0.0;
        for (i, r) in ratios.iter().enumerate() {
            offsets_s[i] = t;
            intervals_s[i] = r / mean / prf_hz;
            t += intervals_s[i];
        }
        Stagger {
            len: ratios.len(),
            offsets_s,
            intervals_s,
            cycle_s: t,
        }
    }

    /// The pulse intervals of one cycle, s.
    pub fn intervals_s(&self) -> &[f64] {
        &self.intervals_s[..self.len]
    }

    /// Whether the intervals differ (more than one entry).
    pub fn is_staggered(&self) -> bool {
        self.len > 1
    }

    /// The shortest interval, s.
    pub fn shortest_interval_s(&self) -> f64 {
        self.intervals_s()
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min)
    }
}

impl Scan {
    /// Pulse repetition frequency, Hz.
    pub fn prf_hz(&self) -> f64 {
        self.prf_hz
    }

    /// Rotation rate, rev/min.
    pub fn rotation_rpm(&self) -> f64 {
        self.rotation_rpm
    }

    /// Antenna rotation period `60/rpm`, s.
    pub fn period_s(&self) -> f64 {
        60.0 / self.rotation_rpm
    }

    /// Spokes per revolution.
    pub fn spokes(&self) -> usize {
        self.spokes
    }

    /// Largest range in the outputs, m.
    pub fn max_range_m(&self) -> f64 {
        self.max_range_m
    }

    /// Azimuth of spoke `k`, `2πk/spokes` rad (nautical: 0 = north, clockwise).
    pub fn spoke_azimuth_rad(&self, k: usize) -> f64 {
        std::f64::consts::TAU * k as f64 / self.spokes as f64
    }

    /// The pulse train's stagger (one interval when unstaggered).
    pub fn stagger(&self) -> &Stagger {
        &self.stagger
    }

    /// Pulses fired in one revolution (pulse mode): `floor(prf·60/rpm)` unstaggered, else the
    /// pulses whose times fall inside the period.
    pub fn pulses_per_revolution(&self) -> usize {
        if !self.stagger.is_staggered() {
            return (self.prf_hz * self.period_s() + 1e-9).floor() as usize;
        }
        let period = self.period_s();
        let st = &self.stagger;
        let cycles = (period / st.cycle_s).floor() as usize;
        let rest = period - cycles as f64 * st.cycle_s;
        cycles * st.len
            + st.offsets_s[..st.len]
                .iter()
                .filter(|&&o| o < rest - 1e-12)
                .count()
    }

    /// Time of pulse `n` after the start of its revolution, s: `n/prf` unstaggered, else
    /// `floor(n/L)·ΣT_i + Σ_{j < n mod L} T_j` for L intervals (revolution 0's pulses; a
    /// staggered train runs on across revolutions, [`Scan::train_time_s`]).
    pub fn pulse_time_s(&self, n: usize) -> f64 {
        let st = &self.stagger;
        if !st.is_staggered() {
            return n as f64 / self.prf_hz;
        }
        self.train_time_s(n as i64)
    }

    /// Time of pulse `g` of the one continuous pulse train that runs through every
    /// revolution, s from t = 0 (g < 0 before it): `floor(g/L)·ΣT_i + Σ_{j < g mod L} T_j`.
    pub fn train_time_s(&self, g: i64) -> f64 {
        let st = &self.stagger;
        let l = st.len as i64;
        g.div_euclid(l) as f64 * st.cycle_s + st.offsets_s[g.rem_euclid(l) as usize]
    }

    /// The first pulse of the train at or after `t_s`.
    pub fn first_train_pulse_at(&self, t_s: f64) -> i64 {
        let st = &self.stagger;
        let l = st.len as i64;
        let mut g = (t_s / st.cycle_s).floor() as i64 * l;
        while self.train_time_s(g) < t_s {
            g += 1;
        }
        while g > i64::MIN + 1 && self.train_time_s(g - 1) >= t_s {
            g -= 1;
        }
        g
    }

    /// The fewest pulses a staggered train puts in any window as long as a spoke's dwell,
    /// `T/spokes`: windows starting just after each pulse of a cycle are the emptiest.
    pub fn fewest_train_pulses_per_spoke(&self) -> usize {
        let dwell_s = self.period_s() / self.spokes as f64;
        let l = self.stagger.len as i64;
        (0..l)
            .map(|j| {
                let start = self.train_time_s(j);
                let mut g = j + 1;
                while self.train_time_s(g) - start < dwell_s {
                    g += 1;
                }
                // The pulses in (t_j, t_j + dwell).
                (g - j - 1).max(0) as usize
            })
            .min()
            .unwrap_or(0)
    }

    /// Antenna azimuth when pulse `n` is fired, `2π·n/(prf·T)` rad.
    pub fn pulse_azimuth_rad(&self, n: usize) -> f64 {
        std::f64::consts::TAU * self.pulse_time_s(n) / self.period_s()
    }

    /// The spoke whose azimuth is nearest pulse `n`'s (the record row the pulse is
    /// integrated into).
    pub fn spoke_of_pulse(&self, n: usize) -> usize {
        let s = self.pulse_azimuth_rad(n) / std::f64::consts::TAU * self.spokes as f64;
        (s.round() as usize) % self.spokes
    }
}

impl Radar {
    /// This radar with `other`'s waveform and receiver: its chirp (pulse width, bandwidth,
    /// sample rate), window, short pulse and blanking. What stays is what a trace depends on.
    pub fn with_waveform_of(&self, other: &Radar) -> Radar {
        Radar {
            chirp: other.chirp,
            window: other.window,
            short_pulse: other.short_pulse,
            receiver_blanking: other.receiver_blanking,
            ..self.clone()
        }
    }

    /// The scan (PRF, rotation, spokes, range).
    pub fn scan(&self) -> &Scan {
        &self.scan
    }

    /// Antenna phase centre, ENU m.
    pub fn position_m(&self) -> DVec3 {
        self.position_m
    }

    /// The same radar with its antenna at `position_m` (the own ship carried it there).
    pub(crate) fn moved_to(&self, position_m: DVec3) -> Radar {
        Radar {
            position_m,
            ..self.clone()
        }
    }

    /// Carrier frequency f0, Hz.
    pub fn carrier_freq_hz(&self) -> f64 {
        self.carrier_freq_hz
    }

    /// The transmitted LFM pulse (bandwidth, pulse width, sample rate).
    pub fn chirp(&self) -> &LfmChirp {
        &self.chirp
    }

    /// Matched-filter reference window.
    pub fn window(&self) -> Window {
        self.window
    }

    /// The short pulse of combined pulse mode; None for a single pulse.
    pub fn short_pulse(&self) -> Option<&ShortPulse> {
        self.short_pulse.as_ref()
    }

    /// First range bin served by the long pulse in combined pulse mode: its length in
    /// samples `N_T`, the eclipse boundary (bins below come from the short pulse).
    pub fn join_bin(&self) -> usize {
        self.chirp.num_samples()
    }

    /// Combined pulse mode: the noise level of the short pulse's bins in the record's units,
    /// `20·log10(G_long/G_short)` dB over the long pulse's noise, with `G = Σw/√Σw²` each
    /// matched filter's peak gain (None for a single pulse; docs/physics.md §11).
    pub fn short_pulse_noise_db(&self) -> Option<f64> {
        let gain_db = |chirp: &LfmChirp, window: Window| {
            let n = chirp.num_samples();
            10.0 * (n as f64 * window.snr_loss_linear(n)).log10()
        };
        self.short_pulse
            .map(|p| gain_db(&self.chirp, self.window) - gain_db(&p.chirp, p.window))
    }

    /// Range of [`Radar::join_bin`], `N_T·c/(2·fs)`, m.
    pub fn join_range_m(&self) -> f64 {
        self.join_bin() as f64 * self.range_bin_m()
    }

    /// Peak transmit power Pt, W.
    pub fn peak_power_w(&self) -> f64 {
        self.peak_power_w
    }

    /// Noise figure F (linear).
    pub fn noise_figure_linear(&self) -> f64 {
        self.noise_figure_linear
    }

    /// System loss L (linear, ≥ 1).
    pub fn system_loss_linear(&self) -> f64 {
        self.system_loss_linear
    }

    /// Antenna beamwidths, gain and tilt.
    pub fn antenna(&self) -> &Antenna {
        &self.antenna
    }

    /// Pulse repetition frequency, Hz.
    pub fn prf_hz(&self) -> f64 {
        self.scan.prf_hz
    }

    /// Rotation rate, rev/min.
    pub fn rotation_rpm(&self) -> f64 {
        self.scan.rotation_rpm
    }

    /// Largest range in the outputs, m.
    pub fn max_range_m(&self) -> f64 {
        self.scan.max_range_m
    }

    /// Spokes per revolution.
    pub fn spokes(&self) -> usize {
        self.scan.spokes
    }

    /// The range scale the set is on, NM (None: a range given as `max_range_m`).
    pub fn range_scale_nm(&self) -> Option<f64> {
        self.range_scale_nm
    }

    /// Receiver blanked while transmitting.
    pub fn receiver_blanking(&self) -> bool {
        self.receiver_blanking
    }

    /// Transmit and receive polarisation.
    pub fn polarisation(&self) -> Polarisation {
        self.polarisation
    }
}

pub use crate::choice::{Polarisation, Transmitter};

impl std::fmt::Display for Polarisation {
    /// "HH" or "VV".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Polarisation::Hh => "HH",
            Polarisation::Vv => "VV",
        })
    }
}

impl std::str::FromStr for Polarisation {
    type Err = String;

    /// Parses a polarisation as a scene file writes it ("HH", "vv", "H"...).
    fn from_str(text: &str) -> std::result::Result<Polarisation, String> {
        use serde::de::{value::StrDeserializer, Deserialize};
        Polarisation::deserialize(StrDeserializer::<serde::de::value::Error>::new(text))
            .map_err(|_| format!("\"{text}\": expected \"HH\" or \"VV\""))
    }
}

impl Radar {
    /// Carrier wavelength λ, m.
    pub fn wavelength_m(&self) -> f64 {
        wavelength_m(self.carrier_freq_hz)
    }

    /// Complex sample rate fs, Hz.
    pub fn sample_rate_hz(&self) -> f64 {
        self.chirp.sample_rate_hz
    }

    /// Thermal noise power per complex sample, `k·T0·F·fs`, W.
    pub fn noise_power_w(&self) -> f64 {
        BOLTZMANN_J_PER_K
            * REFERENCE_TEMPERATURE_K
            * self.noise_figure_linear
            * self.sample_rate_hz()
    }

    /// Range spacing of output bins, `c/(2·fs)`, m.
    pub fn range_bin_m(&self) -> f64 {
        SPEED_OF_LIGHT_M_PER_S / (2.0 * self.sample_rate_hz())
    }

    /// Range resolution of the compressed pulse, `c/(2B)`, m (Skolnik, *Introduction to Radar
    /// Systems*, 3rd ed., §11.5; the half-power width of the unwindowed sinc is 0.886 of it);
    /// of an unmodulated pulse (a magnetron's), its length `c·T/2`.
    pub fn range_resolution_m(&self) -> f64 {
        if self.chirp.bandwidth_hz > 0.0 {
            SPEED_OF_LIGHT_M_PER_S / (2.0 * self.chirp.bandwidth_hz)
        } else {
            // An unmodulated pulse resolves its length, c·T/2.
            SPEED_OF_LIGHT_M_PER_S * self.chirp.pulse_width_s / 2.0
        }
    }

    /// What makes the pulse.
    pub fn transmitter(&self) -> Transmitter {
        self.transmitter
    }

    /// Number of range bins: bin j is at `j·c/(2·fs)`, up to `max_range_m`.
    pub fn num_range_bins(&self) -> usize {
        (self.scan.max_range_m / self.range_bin_m()).floor() as usize + 1
    }

    /// Range inside which echoes arrive while the pulse is still being sent, `c·T/2`, m.
    pub fn eclipse_range_m(&self) -> f64 {
        SPEED_OF_LIGHT_M_PER_S * self.chirp.pulse_width_s / 2.0
    }

    /// The radar equation's constant factor `Pt·G0²·λ²/((4π)³·L)`, W·m² (Skolnik,
    /// *Introduction to Radar Systems*, 3rd ed., eq. 2.1 with the system loss; docs/physics.md
    /// §2.4): the power received from a 1 m² target at 1 m on the beam axis. Every use of the
    /// radar equation goes through it — point targets' SNR, ray-tube voltages, clutter cells.
    pub fn radar_equation_constant_w_m2(&self) -> f64 {
        let lambda = self.wavelength_m();
        let g0 = self.antenna.peak_gain_linear;
        let four_pi_cubed = (4.0 * std::f64::consts::PI).powi(3);
        self.peak_power_w * g0 * g0 * lambda * lambda / (four_pi_cubed * self.system_loss_linear)
    }

    /// Radar-equation single-pulse SNR of a point target (linear), at the beam peak,
    /// before any window loss: `Pt·T·G0²·λ²·σ / ((4π)³·R⁴·k·T0·F·L)`
    /// (Skolnik, *Introduction to Radar Systems*, 3rd ed., eq. 2.51 with pulse compression):
    /// [`Radar::radar_equation_constant_w_m2`] × `T·σ/(R⁴·k·T0·F)`.
    pub fn point_target_snr(&self, rcs_m2: f64, range_m: f64) -> f64 {
        self.point_target_snr_for_pulse(rcs_m2, range_m, self.chirp.pulse_width_s)
    }

    /// [`Radar::point_target_snr`] for a pulse of width `pulse_width_s` (the short pulse of
    /// combined pulse mode).
    pub fn point_target_snr_for_pulse(&self, rcs_m2: f64, range_m: f64, pulse_width_s: f64) -> f64 {
        self.radar_equation_constant_w_m2() * pulse_width_s * rcs_m2
            / (range_m.powi(4)
                * BOLTZMANN_J_PER_K
                * REFERENCE_TEMPERATURE_K
                * self.noise_figure_linear)
    }

    /// The samples actually realised for the pulse (`N_T/fs`), s.
    pub fn sampled_pulse_width_s(&self) -> f64 {
        self.chirp.num_samples() as f64 / self.sample_rate_hz()
    }

    /// Azimuth of spoke `k`, rad (nautical: 0 = north, clockwise).
    pub fn spoke_azimuth_rad(&self, k: usize) -> f64 {
        self.scan.spoke_azimuth_rad(k)
    }
}
