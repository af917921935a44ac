//! Stage: scene. Parses a TOML scene file ([`SceneSpec`]) and validates it into the runtime
//! [`Scene`] in SI units: the radar (preset + overrides), environment switches, display
//! settings, scattering settings and objects with their shapes and poses.
//!
//! Every bad value is reported as an [`Error`] that names the field and the value; nothing
//! here panics on user input.

mod spec;

mod load;
pub use load::{locate, LoadedSpec};
pub use spec::{
    ClutterDistributionName, DisplaySpec, EnvironmentSpec, ObjectSpec, RadarPreset, RadarSpec,
    RainCellSpec, ScatteringSpec, SceneSpec, ShapeName, WindowName,
};

use crate::antenna::{uniform_aperture_gain, Antenna};
use crate::constants::{
    db_to_linear, wavelength_m, BOLTZMANN_J_PER_K, REFERENCE_TEMPERATURE_K, SPEED_OF_LIGHT_M_PER_S,
};
use crate::environment::clutter::{
    sea_state_rms_height_m, sea_state_wind_speed_m_per_s, ClutterDistribution, Sigma0Model,
};
use crate::environment::rain::{Rain, RainCell};
use crate::environment::{
    sea_water_permittivity, two_way_attenuation_power, SeaRoughness, SeaSurface,
};
use crate::error::{Error, Problem, Result};
use crate::geometry::{object_frame, MeshUnit, ShapeGeometry, TriangleMesh};
use crate::waveform::{LfmChirp, Window};
use glam::{DMat3, DVec3};
use std::path::Path;

/// Names of the radar presets.
pub const RADAR_PRESETS: &[&str] = &["drs4d-nxt"];

/// Names of the object shapes.
pub const SHAPES: &[&str] = &[
    "point",
    "sphere",
    "plate",
    "trihedral",
    "dihedral",
    "cylinder",
    "box",
    "mesh",
];

/// Largest number of spokes per revolution.
pub const MAX_SPOKES: usize = 8192;

/// Largest polar output, spokes × range bins (256 MB of float32; the clutter map and the
/// images take a few times that again).
pub const MAX_POLAR_CELLS: usize = 64_000_000;

/// The radar, in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Radar {
    /// Antenna phase centre, ENU m.
    pub position_m: DVec3,
    /// Carrier frequency f0, Hz.
    pub carrier_freq_hz: f64,
    /// The transmitted LFM pulse (bandwidth, pulse width, sample rate).
    pub chirp: LfmChirp,
    /// Matched-filter reference window.
    pub window: Window,
    /// Peak transmit power Pt, W.
    pub peak_power_w: f64,
    /// Noise figure F (linear).
    pub noise_figure_linear: f64,
    /// System loss L (linear, ≥ 1).
    pub system_loss_linear: f64,
    /// Antenna beamwidths, gain and tilt.
    pub antenna: Antenna,
    /// Pulse repetition frequency, Hz.
    pub prf_hz: f64,
    /// Rotation rate, rev/min.
    pub rotation_rpm: f64,
    /// Largest range in the outputs, m.
    pub max_range_m: f64,
    /// Spokes per revolution.
    pub spokes: usize,
    /// Receiver blanked while transmitting.
    pub receiver_blanking: bool,
    /// Transmit and receive polarisation.
    pub polarisation: Polarisation,
}

/// Linear polarisation used for both transmit and receive: "HH" or "VV" in a scene file
/// (any case; "H" and "V" also read).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
pub enum Polarisation {
    /// Horizontal transmit, horizontal receive.
    #[serde(rename = "HH", alias = "hh", alias = "Hh", alias = "H", alias = "h")]
    Hh,
    /// Vertical transmit, vertical receive.
    #[serde(rename = "VV", alias = "vv", alias = "Vv", alias = "V", alias = "v")]
    Vv,
}

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

    /// Number of range bins: bin j is at `j·c/(2·fs)`, up to `max_range_m`.
    pub fn num_range_bins(&self) -> usize {
        (self.max_range_m / self.range_bin_m()).floor() as usize + 1
    }

    /// Range inside which echoes arrive while the pulse is still being sent, `c·T/2`, m.
    pub fn eclipse_range_m(&self) -> f64 {
        SPEED_OF_LIGHT_M_PER_S * self.chirp.pulse_width_s / 2.0
    }

    /// Radar-equation single-pulse SNR of a point target (linear), at the beam peak,
    /// before any window loss: `Pt·T·G0²·λ²·σ / ((4π)³·R⁴·k·T0·F·L)`
    /// (Skolnik, *Introduction to Radar Systems*, 3rd ed., eq. 2.51 with pulse compression).
    pub fn point_target_snr(&self, rcs_m2: f64, range_m: f64) -> f64 {
        let lambda = self.wavelength_m();
        let g0 = self.antenna.peak_gain_linear;
        let four_pi_cubed = (4.0 * std::f64::consts::PI).powi(3);
        self.peak_power_w * self.chirp.pulse_width_s * g0 * g0 * lambda * lambda * rcs_m2
            / (four_pi_cubed
                * range_m.powi(4)
                * BOLTZMANN_J_PER_K
                * REFERENCE_TEMPERATURE_K
                * self.noise_figure_linear
                * self.system_loss_linear)
    }

    /// The samples actually realised for the pulse (`N_T/fs`), s.
    pub fn sampled_pulse_width_s(&self) -> f64 {
        self.chirp.num_samples() as f64 / self.sample_rate_hz()
    }

    /// Azimuth of spoke `k`, rad (nautical: 0 = north, clockwise).
    pub fn spoke_azimuth_rad(&self, k: usize) -> f64 {
        std::f64::consts::TAU * k as f64 / self.spokes as f64
    }
}

/// Environment: noise, the sea surface and propagation.
#[derive(Debug, Clone, PartialEq)]
pub struct Environment {
    /// Add thermal noise.
    pub noise: bool,
    /// The sea surface at z = 0 reflecting (multipath), if enabled.
    pub sea: Option<SeaSurface>,
    /// Two-way atmospheric attenuation, dB/km.
    pub two_way_attenuation_db_per_km: f64,
    /// Sea clutter, if on.
    pub clutter: Option<SeaClutter>,
    /// Rain, if on and any.
    pub rain: Option<Rain>,
    /// 4/3-earth curvature (horizon, grazing angles).
    pub earth_curvature: bool,
}

/// Sea clutter settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SeaClutter {
    /// σ0 model.
    pub model: Sigma0Model,
    /// Sea state 0–6.
    pub sea_state: f64,
    /// Direction the wind blows from, rad (nautical).
    pub wind_from_rad: f64,
    /// Direction the swell comes from, rad (nautical): sets the K shape's swell term.
    pub swell_from_rad: f64,
    /// Amplitude statistics.
    pub distribution: ClutterDistribution,
    /// Texture correlation length, m.
    pub correlation_m: f64,
    /// Texture drift speed (downwind), m/s.
    pub drift_m_per_s: f64,
}

impl Environment {
    /// Two-way power factor of the atmosphere over a one-way range, ≤ 1.
    pub fn attenuation_power(&self, range_m: f64) -> f64 {
        two_way_attenuation_power(self.two_way_attenuation_db_per_km, range_m)
    }
}

/// Colour map for `ppi.png`.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum Colormap {
    /// Perceptually uniform blue–green–yellow.
    Viridis,
    /// Black to green, like a phosphor display.
    Green,
    /// Black to white ("grey" also reads).
    #[serde(alias = "grey")]
    Gray,
}

/// PPI drawing settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Display {
    /// Square image side, px.
    pub image_size_px: u32,
    /// Range-ring spacing, m (0 = none).
    pub range_ring_spacing_m: f64,
    /// Colour map.
    pub colormap: Colormap,
    /// Bottom of the colour scale, dB over noise.
    pub min_db: f64,
    /// Top of the colour scale, dB over noise.
    pub max_db: f64,
}

/// Which scattering amplitude model turns ray hits into echoes.
#[derive(
    Debug, Clone, Copy, PartialEq, serde::Deserialize, serde::Serialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum ScatteringModel {
    /// Physical-optics ray tubes calibrated to the radar equation.
    #[serde(rename = "po")]
    PhysicalOptics,
    /// The seed paper's law `A = 1/(1 + ℓ²/1000)` on a uniform scan grid (uncalibrated).
    Paper,
}

/// Scattering settings.
#[derive(Debug, Clone, PartialEq)]
pub struct ScatteringConfig {
    /// The model.
    pub model: ScatteringModel,
    /// PO ray-tube spacing, wavelengths.
    pub ray_spacing_wavelengths: f64,
    /// PO cap on rays per object.
    pub max_rays_per_object: usize,
    /// Maximum bounces.
    pub max_bounces: usize,
    /// Paper model: rays per degree of azimuth.
    pub paper_rays_per_degree_az: usize,
    /// Paper model: rays across the elevation beamwidth.
    pub paper_rays_elevation: usize,
    /// Paper model: volts of a unit-amplitude ray.
    pub paper_reference_voltage_v: f64,
}

/// A validated scene object.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneObject {
    /// Unique name.
    pub name: String,
    /// Class label.
    pub class: String,
    /// Shape name as in the file.
    pub shape_name: String,
    /// Shape and sizes.
    pub shape: ShapeGeometry,
    /// Reference position, ENU m.
    pub position_m: DVec3,
    /// Object-to-world rotation.
    pub rotation: DMat3,
}

impl SceneObject {
    /// Height of the object's highest point, m (its position for a point object).
    pub fn top_m(&self) -> f64 {
        let prims = self.shape.primitives(self.position_m, self.rotation, 0);
        if prims.is_empty() {
            return self.position_m.z;
        }
        prims
            .iter()
            .map(|p| p.bounds().max.z)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Centre of the object's bounding sphere, ENU m.
    pub fn bounding_centre_m(&self) -> DVec3 {
        self.position_m + self.rotation * self.shape.bounding_centre_local_m()
    }
}

/// A validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The radar.
    pub radar: Radar,
    /// Environment.
    pub environment: Environment,
    /// Display settings.
    pub display: Display,
    /// Scattering settings.
    pub scattering: ScatteringConfig,
    /// Objects.
    pub objects: Vec<SceneObject>,
}

impl Scene {
    /// Reads and validates a scene file (errors name the file, line and field).
    pub fn load(path: &Path) -> Result<Scene> {
        LoadedSpec::read(path)?.build()
    }

    /// Parses and validates scene TOML; `origin` names the source in errors and mesh files are
    /// found relative to the current directory.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Scene> {
        LoadedSpec::from_toml(text, origin, Path::new("."))?.build()
    }

    /// Validates a parsed scene description; mesh files are found relative to the current
    /// directory.
    pub fn from_spec(spec: &SceneSpec) -> Result<Scene> {
        Scene::from_spec_in(spec, Path::new("."))
    }

    /// Validates a parsed scene description whose mesh files are relative to `base_dir`.
    pub fn from_spec_in(spec: &SceneSpec, base_dir: &Path) -> Result<Scene> {
        let mut radar = build_radar(&spec.radar)?;
        if let Some(pol) = spec.environment.polarisation {
            if spec.radar.polarisation.is_some() && pol != radar.polarisation {
                return Err(Error::invalid(
                    Problem::Conflict,
                    "environment.polarisation",
                    format!("\"{pol}\""),
                    "differs from radar.polarisation; give the polarisation once",
                ));
            }
            radar.polarisation = pol;
        }
        let environment = build_environment(&spec.environment, radar.carrier_freq_hz)?;
        let display = build_display(&spec.display)?;
        let scattering = build_scattering(&spec.scattering)?;
        let mut objects = Vec::with_capacity(spec.objects.len());
        for (i, o) in spec.objects.iter().enumerate() {
            let obj = build_object(i, o, base_dir)?;
            if objects.iter().any(|p: &SceneObject| p.name == obj.name) {
                return Err(Error::invalid(
                    Problem::Conflict,
                    format!("object[{i}].name"),
                    format!("\"{}\"", obj.name),
                    "another object already has this name",
                ));
            }
            let top_m = obj.top_m();
            if top_m < 0.0 {
                return Err(Error::invalid(
                Problem::OutOfRange,
                    format!("object \"{}\".position_m", obj.name),
                    fmt_vec(obj.position_m),
                    format!("the object lies entirely below the sea surface (its highest point is at z = {top_m:.2} m; the sea is the plane z = 0): a radar cannot see it; raise it"),
                ));
            }
            let clearance = obj.shape.bounding_radius_m().max(0.5);
            let dist = (obj.bounding_centre_m() - radar.position_m).length();
            if dist < clearance {
                return Err(Error::invalid(
                Problem::Conflict,
                    format!("object \"{}\".position_m", obj.name),
                    fmt_vec(obj.position_m),
                    format!("the object is at the radar's position (radar.position_m = {}); it must be at least {clearance:.2} m away", fmt_vec(radar.position_m)),
                ));
            }
            objects.push(obj);
        }
        Ok(Scene {
            radar,
            environment,
            display,
            scattering,
            objects,
        })
    }
}

fn fmt_vec(v: DVec3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}

/// A finite number, else an error naming the field.
fn finite(field: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::invalid(
            Problem::NotFinite,
            field,
            v,
            "must be a finite number",
        ))
    }
}

/// A finite number > 0.
fn positive(field: &str, v: f64) -> Result<f64> {
    finite(field, v)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(Error::invalid(
            Problem::OutOfRange,
            field,
            v,
            "must be greater than zero",
        ))
    }
}

fn finite_vec(field: &str, v: [f64; 3]) -> Result<DVec3> {
    for (k, x) in v.iter().enumerate() {
        if !x.is_finite() {
            return Err(Error::invalid(
                Problem::NotFinite,
                field,
                format!("{v:?}"),
                format!("component {k} must be a finite number"),
            ));
        }
    }
    Ok(DVec3::from_array(v))
}

fn build_radar(s: &RadarSpec) -> Result<Radar> {
    let RadarPreset::Drs4dNxt = s.preset.unwrap_or_default();
    // drs4d-nxt: Furuno DRS4D-NXT-like figures from the seed paper (f0, B, beamwidths, Pt,
    // fs); PRF, noise figure, mast height, range and rotation are typical values, assumed.
    let position_m = finite_vec("radar.position_m", s.position_m.unwrap_or([0.0, 0.0, 4.0]))?;
    if position_m.z <= 0.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "radar.position_m",
            fmt_vec(position_m),
            "the antenna must be above the sea surface (z > 0; the sea is the plane z = 0)",
        ));
    }
    let frequency_ghz = positive("radar.frequency_ghz", s.frequency_ghz.unwrap_or(9.41))?;
    let bandwidth_mhz = positive("radar.bandwidth_mhz", s.bandwidth_mhz.unwrap_or(50.0))?;
    let pulse_width_us = positive("radar.pulse_width_us", s.pulse_width_us.unwrap_or(1.0))?;
    let sample_rate_mhz = positive("radar.sample_rate_mhz", s.sample_rate_mhz.unwrap_or(100.0))?;
    let peak_power_w = positive("radar.peak_power_w", s.peak_power_w.unwrap_or(25.0))?;
    let noise_figure_db = finite("radar.noise_figure_db", s.noise_figure_db.unwrap_or(5.0))?;
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
    let az_bw_deg = positive(
        "radar.azimuth_beamwidth_deg",
        s.azimuth_beamwidth_deg.unwrap_or(3.9),
    )?;
    let el_bw_deg = positive(
        "radar.elevation_beamwidth_deg",
        s.elevation_beamwidth_deg.unwrap_or(25.0),
    )?;
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
    let peak_gain_linear = match s.gain_dbi {
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
    let prf_hz = positive("radar.prf_hz", s.prf_hz.unwrap_or(1200.0))?;
    let rotation_rpm = positive("radar.rotation_rpm", s.rotation_rpm.unwrap_or(24.0))?;
    let max_range_m = positive("radar.max_range_m", s.max_range_m.unwrap_or(1500.0))?;
    let spokes = s.spokes.unwrap_or(360);
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
    let unambiguous_m = SPEED_OF_LIGHT_M_PER_S / (2.0 * prf_hz);
    if max_range_m + SPEED_OF_LIGHT_M_PER_S * pulse_width_s / 2.0 > unambiguous_m {
        return Err(Error::invalid(
                Problem::Conflict,
            "radar.max_range_m",
            max_range_m,
            format!(
                "beyond the unambiguous range: max_range_m plus the pulse's c·T/2 must stay within c/(2·prf_hz) = {:.1} km at prf_hz = {prf_hz} (echoes from farther arrive after the next pulse, which is not modelled); lower max_range_m or prf_hz",
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
    Ok(Radar {
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
        },
        prf_hz,
        rotation_rpm,
        max_range_m,
        spokes,
        receiver_blanking: s.receiver_blanking.unwrap_or(true),
        polarisation: s.polarisation.unwrap_or(Polarisation::Hh),
    })
}

fn build_environment(s: &EnvironmentSpec, carrier_freq_hz: f64) -> Result<Environment> {
    let in_range = |field: &str, v: f64, lo: f64, hi: f64, what: &str| -> Result<f64> {
        let v = finite(field, v)?;
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(Error::invalid(
                Problem::OutOfRange,
                field,
                v,
                format!("must be within {lo}..{hi} {what}"),
            ))
        }
    };
    let temperature_c = in_range(
        "environment.sea_temperature_c",
        s.sea_temperature_c.unwrap_or(20.0),
        -2.0,
        40.0,
        "°C (the permittivity model's range)",
    )?;
    let salinity_psu = in_range(
        "environment.sea_salinity_psu",
        s.sea_salinity_psu.unwrap_or(35.0),
        0.0,
        45.0,
        "psu",
    )?;
    let sea_state = in_range(
        "environment.sea_state",
        s.sea_state.unwrap_or(2.0),
        0.0,
        6.0,
        "(Douglas/WMO sea state)",
    )?;
    let rms_height_m = in_range(
        "environment.sea_rms_height_m",
        s.sea_rms_height_m
            .unwrap_or_else(|| sea_state_rms_height_m(sea_state)),
        0.0,
        20.0,
        "m",
    )?;
    let attenuation = in_range(
        "environment.two_way_attenuation_db_per_km",
        s.two_way_attenuation_db_per_km.unwrap_or(0.0),
        0.0,
        100.0,
        "dB/km",
    )?;
    let wind_from_deg = finite(
        "environment.wind_direction_deg",
        s.wind_direction_deg.unwrap_or(0.0),
    )?;
    let wind_from_rad = wind_from_deg.to_radians();
    let swell_from_rad = finite(
        "environment.swell_direction_deg",
        s.swell_direction_deg.unwrap_or(wind_from_deg),
    )?
    .to_radians();
    let roughness = s.sea_roughness.unwrap_or(SeaRoughness::MillerBrownVegh);
    let sea = s.multipath.unwrap_or(true).then(|| SeaSurface {
        permittivity: sea_water_permittivity(carrier_freq_hz, temperature_c, salinity_psu),
        rms_height_m,
        roughness,
    });
    let model = s.clutter_model.unwrap_or(Sigma0Model::Nrl);
    let distribution = match s.clutter_distribution.unwrap_or_default() {
        ClutterDistributionName::K => ClutterDistribution::K {
            shape_nu: s
                .clutter_shape_nu
                .map(|v| in_range("environment.clutter_shape_nu", v, 0.05, 100.0, ""))
                .transpose()?,
        },
        ClutterDistributionName::Weibull => ClutterDistribution::Weibull {
            shape: in_range(
                "environment.clutter_weibull_shape",
                s.clutter_weibull_shape.unwrap_or(1.5),
                0.3,
                2.0,
                "(the amplitude's Weibull shape c; 2 is Rayleigh, and sea clutter is never less spiky than Rayleigh)",
            )?,
        },
        ClutterDistributionName::Lognormal => ClutterDistribution::LogNormal {
            sigma_db: in_range(
                "environment.clutter_lognormal_sigma_db",
                s.clutter_lognormal_sigma_db.unwrap_or(3.0),
                0.0,
                12.0,
                "dB (standard deviation of the texture's 10·log10)",
            )?,
        },
        ClutterDistributionName::Rayleigh => ClutterDistribution::Rayleigh,
    };
    let correlation_m = in_range(
        "environment.clutter_correlation_m",
        s.clutter_correlation_m.unwrap_or(30.0),
        0.5,
        10_000.0,
        "m",
    )?;
    let drift_m_per_s = in_range(
        "environment.clutter_drift_m_per_s",
        s.clutter_drift_m_per_s
            .unwrap_or(1.14 * sea_state_wind_speed_m_per_s(sea_state)),
        0.0,
        100.0,
        "m/s",
    )?;
    let clutter = s.clutter.unwrap_or(true).then_some(SeaClutter {
        model,
        sea_state,
        wind_from_rad,
        swell_from_rad,
        distribution,
        correlation_m,
        drift_m_per_s,
    });
    let uniform = in_range(
        "environment.rain_rate_mm_per_h",
        s.rain_rate_mm_per_h.unwrap_or(0.0),
        0.0,
        500.0,
        "mm/h",
    )?;
    let top_m = in_range(
        "environment.rain_top_m",
        s.rain_top_m.unwrap_or(3000.0),
        1.0,
        20_000.0,
        "m",
    )?;
    let mut cells = Vec::new();
    for (i, c) in s.rain_cells.iter().enumerate() {
        let f = |name: &str| format!("environment.rain_cell[{i}].{name}");
        let centre = c.centre_m.ok_or_else(|| {
            Error::missing(f("centre_m"), "a rain cell needs centre_m = [east, north]")
        })?;
        if centre.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid(
                Problem::NotFinite,
                f("centre_m"),
                format!("{centre:?}"),
                "must be finite numbers",
            ));
        }
        let radius_m = positive(
            &f("radius_m"),
            c.radius_m
                .ok_or_else(|| Error::missing(f("radius_m"), "a rain cell needs radius_m"))?,
        )?;
        let rate = in_range(
            &f("rate_mm_per_h"),
            c.rate_mm_per_h.ok_or_else(|| {
                Error::missing(f("rate_mm_per_h"), "a rain cell needs rate_mm_per_h")
            })?,
            0.0,
            500.0,
            "mm/h",
        )?;
        cells.push(RainCell {
            centre_m: glam::DVec2::from_array(centre),
            radius_m,
            rate_mm_per_h: rate,
        });
    }
    let rain = (s.rain.unwrap_or(true) && (uniform > 0.0 || !cells.is_empty())).then_some(Rain {
        uniform_rate_mm_per_h: uniform,
        cells,
        top_m,
    });
    Ok(Environment {
        noise: s.noise.unwrap_or(true),
        sea,
        two_way_attenuation_db_per_km: attenuation,
        clutter,
        rain,
        earth_curvature: s.earth_curvature.unwrap_or(true),
    })
}

fn build_display(s: &DisplaySpec) -> Result<Display> {
    let image_size_px = s.image_size_px.unwrap_or(1024);
    if !(16..=16384).contains(&image_size_px) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "display.image_size_px",
            image_size_px,
            "must be between 16 and 16384",
        ));
    }
    let range_ring_spacing_m = finite(
        "display.range_ring_spacing_m",
        s.range_ring_spacing_m.unwrap_or(100.0),
    )?;
    if range_ring_spacing_m < 0.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "display.range_ring_spacing_m",
            range_ring_spacing_m,
            "must be 0 (no rings) or more",
        ));
    }
    let colormap = s.colormap.unwrap_or(Colormap::Viridis);
    let min_db = finite("display.min_db", s.min_db.unwrap_or(0.0))?;
    let max_db = finite("display.max_db", s.max_db.unwrap_or(60.0))?;
    if max_db <= min_db {
        return Err(Error::invalid(
            Problem::Conflict,
            "display.max_db",
            max_db,
            format!("must be above display.min_db ({min_db})"),
        ));
    }
    Ok(Display {
        image_size_px,
        range_ring_spacing_m,
        colormap,
        min_db,
        max_db,
    })
}

fn build_scattering(s: &ScatteringSpec) -> Result<ScatteringConfig> {
    let model = s.model.unwrap_or(ScatteringModel::PhysicalOptics);
    let ray_spacing_wavelengths = positive(
        "scattering.ray_spacing_wavelengths",
        s.ray_spacing_wavelengths.unwrap_or(0.5),
    )?;
    let max_rays_per_object = s.max_rays_per_object.unwrap_or(32_768);
    if max_rays_per_object == 0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "scattering.max_rays_per_object",
            0,
            "must be at least 1",
        ));
    }
    let max_bounces = s.max_bounces.unwrap_or(3);
    if !(1..=16).contains(&max_bounces) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "scattering.max_bounces",
            max_bounces,
            "must be between 1 and 16",
        ));
    }
    let paper_rays_per_degree_az = s.paper_rays_per_degree_az.unwrap_or(100);
    if !(1..=1000).contains(&paper_rays_per_degree_az) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "scattering.paper_rays_per_degree_az",
            paper_rays_per_degree_az,
            "must be between 1 and 1000",
        ));
    }
    let paper_rays_elevation = s.paper_rays_elevation.unwrap_or(100);
    if !(1..=10_000).contains(&paper_rays_elevation) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "scattering.paper_rays_elevation",
            paper_rays_elevation,
            "must be between 1 and 10000",
        ));
    }
    let paper_reference_voltage_v = positive(
        "scattering.paper_reference_voltage_uv",
        s.paper_reference_voltage_uv.unwrap_or(1000.0),
    )? * 1e-6;
    Ok(ScatteringConfig {
        model,
        ray_spacing_wavelengths,
        max_rays_per_object,
        max_bounces,
        paper_rays_per_degree_az,
        paper_rays_elevation,
        paper_reference_voltage_v,
    })
}

fn build_object(i: usize, o: &ObjectSpec, base_dir: &Path) -> Result<SceneObject> {
    let name = o.name.clone().unwrap_or_else(|| format!("object-{i}"));
    if name.trim().is_empty() {
        return Err(Error::invalid(
            Problem::OutOfRange,
            format!("object[{i}].name"),
            "\"\"",
            "must not be empty",
        ));
    }
    let prefix = format!("object \"{name}\"");
    let f = |field: &str| format!("{prefix}.{field}");
    let shape_kind = o.shape.ok_or_else(|| {
        Error::missing(
            f("shape"),
            format!("every object needs a shape, one of: {}", SHAPES.join(", ")),
        )
    })?;
    let shape_name = shape_kind.as_str().to_string();
    let need = |field: &str, v: Option<f64>| -> Result<f64> {
        let v = v.ok_or_else(|| {
            Error::missing(f(field), format!("shape \"{shape_name}\" needs `{field}`"))
        })?;
        positive(&f(field), v)
    };
    let shape = match shape_kind {
        ShapeName::Point => ShapeGeometry::Point {
            rcs_m2: need("rcs_m2", o.rcs_m2)?,
        },
        ShapeName::Sphere => ShapeGeometry::Sphere {
            radius_m: need("radius_m", o.radius_m)?,
        },
        ShapeName::Plate => ShapeGeometry::Plate {
            width_m: need("width_m", o.width_m)?,
            height_m: need("height_m", o.height_m)?,
        },
        ShapeName::Trihedral => ShapeGeometry::Trihedral {
            edge_m: need("edge_m", o.edge_m)?,
        },
        ShapeName::Dihedral => ShapeGeometry::Dihedral {
            width_m: need("width_m", o.width_m)?,
            height_m: need("height_m", o.height_m)?,
        },
        ShapeName::Cylinder => ShapeGeometry::Cylinder {
            radius_m: need("radius_m", o.radius_m)?,
            height_m: need("height_m", o.height_m)?,
        },
        ShapeName::Box => {
            let s = o.size_m.ok_or_else(|| {
                Error::missing(f("size_m"), "shape \"box\" needs `size_m = [x, y, z]`")
            })?;
            for (k, v) in s.iter().enumerate() {
                if !v.is_finite() || *v <= 0.0 {
                    return Err(Error::invalid(
                        Problem::NotFinite,
                        f("size_m"),
                        format!("{s:?}"),
                        format!("component {k} must be a finite number greater than zero"),
                    ));
                }
            }
            ShapeGeometry::Box {
                size_m: DVec3::from_array(s),
            }
        }
        ShapeName::Mesh => {
            let file = o.mesh_file.as_deref().ok_or_else(|| {
                Error::missing(
                    f("mesh_file"),
                    "shape \"mesh\" needs `mesh_file` (an .obj, .stl, .gltf or .glb file)",
                )
            })?;
            let unit = o.mesh_units.unwrap_or(MeshUnit::Metre);
            let scale = positive(&f("mesh_scale"), o.mesh_scale.unwrap_or(1.0))?;
            let path = base_dir.join(file);
            let mesh = TriangleMesh::load(&path, unit.metres() * scale).map_err(|e| {
                Error::unusable(f("mesh_file"), format!("\"{file}\""), "cannot be used", e)
            })?;
            ShapeGeometry::Mesh {
                mesh: std::sync::Arc::new(mesh),
            }
        }
    };
    // Fields that this shape does not use are reported rather than silently ignored.
    let used: &[&str] = match shape {
        ShapeGeometry::Point { .. } => &["rcs_m2"],
        ShapeGeometry::Sphere { .. } => &["radius_m"],
        ShapeGeometry::Plate { .. } | ShapeGeometry::Dihedral { .. } => &["width_m", "height_m"],
        ShapeGeometry::Trihedral { .. } => &["edge_m"],
        ShapeGeometry::Cylinder { .. } => &["radius_m", "height_m"],
        ShapeGeometry::Box { .. } => &["size_m"],
        ShapeGeometry::Mesh { .. } => &["mesh_file", "mesh_units", "mesh_scale"],
    };
    let present = [
        ("rcs_m2", o.rcs_m2.is_some()),
        ("radius_m", o.radius_m.is_some()),
        ("width_m", o.width_m.is_some()),
        ("height_m", o.height_m.is_some()),
        ("edge_m", o.edge_m.is_some()),
        ("size_m", o.size_m.is_some()),
        ("mesh_file", o.mesh_file.is_some()),
        ("mesh_units", o.mesh_units.is_some()),
        ("mesh_scale", o.mesh_scale.is_some()),
    ];
    for (field, is_set) in present {
        if is_set && !used.contains(&field) {
            return Err(Error::invalid(
                Problem::Conflict,
                f(field),
                "(set)",
                format!(
                    "shape \"{shape_name}\" does not use `{field}`; it uses {}",
                    used.join(", ")
                ),
            ));
        }
    }
    let position_m = finite_vec(
        &f("position_m"),
        o.position_m.ok_or_else(|| {
            Error::missing(
                f("position_m"),
                "every object needs position_m = [east, north, up]",
            )
        })?,
    )?;
    let yaw = finite(&f("yaw_deg"), o.yaw_deg.unwrap_or(0.0))?.to_radians();
    let pitch = finite(&f("pitch_deg"), o.pitch_deg.unwrap_or(0.0))?.to_radians();
    let roll = finite(&f("roll_deg"), o.roll_deg.unwrap_or(0.0))?.to_radians();
    Ok(SceneObject {
        class: o.class.clone().unwrap_or_else(|| "object".to_string()),
        name,
        shape_name,
        shape,
        position_m,
        rotation: object_frame(yaw, pitch, roll),
    })
}
