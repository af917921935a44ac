//! Model: the environment — thermal noise on or off, the sea surface (multipath), sea clutter,
//! rain, atmospheric attenuation and earth curvature, validated from the scene file's
//! `[environment]` table (docs/formats.md).

use super::checks::{finite, positive};
use crate::environment::clutter::{
    sea_state_rms_height_m, sea_state_wind_speed_m_per_s, ClutterDistribution, Sigma0Model,
};
use crate::environment::rain::{Rain, RainCell};
use crate::error::{Error, Problem, Result};
use crate::propagation::{
    sea_water_permittivity, two_way_attenuation_power, SeaRoughness, SeaSurface,
};
use crate::scene::{ClutterDistributionName, EnvironmentSpec};

/// Environment: noise, the sea surface and propagation.
#[derive(Debug, Clone, PartialEq)]
pub struct Environment {
    /// Add thermal noise.
    noise: bool,
    /// The sea surface at z = 0 reflecting (multipath), if enabled.
    sea: Option<SeaSurface>,
    /// Two-way atmospheric attenuation, dB/km.
    two_way_attenuation_db_per_km: f64,
    /// Sea clutter, if on.
    clutter: Option<SeaClutter>,
    /// Rain, if on and any.
    rain: Option<Rain>,
    /// 4/3-earth curvature (horizon, grazing angles).
    earth_curvature: bool,
    /// How sea clutter and rain move (their Doppler spectra).
    clutter_doppler: ClutterDoppler,
    /// Land: where the surface is not sea (none by default).
    land: std::sync::Arc<crate::land::Land>,
}

/// The Doppler spectra of sea clutter and rain (pulse mode; docs/physics.md §10): each a
/// Gaussian in radial velocity whose mean is the scatterers' drift velocity (downwind) seen
/// along the beam, and whose standard deviation is the spread.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClutterDoppler {
    /// Direction the scatterers drift toward (downwind), rad (nautical).
    pub downwind_rad: f64,
    /// Mean drift speed of the sea scatterers, m/s.
    pub sea_velocity_mps: f64,
    /// Standard deviation of the sea scatterers' radial velocity, m/s.
    pub sea_spread_mps: f64,
    /// Drift speed of the rain (it moves with the wind), m/s.
    pub rain_velocity_mps: f64,
    /// Standard deviation of the rain's radial velocity, m/s.
    pub rain_spread_mps: f64,
}

impl Environment {
    /// Add thermal noise.
    pub fn noise(&self) -> bool {
        self.noise
    }

    /// The sea surface at z = 0 reflecting (multipath), if enabled.
    pub fn sea(&self) -> Option<&SeaSurface> {
        self.sea.as_ref()
    }

    /// Two-way atmospheric attenuation, dB/km.
    pub fn two_way_attenuation_db_per_km(&self) -> f64 {
        self.two_way_attenuation_db_per_km
    }

    /// Sea clutter, if on.
    pub fn clutter(&self) -> Option<&SeaClutter> {
        self.clutter.as_ref()
    }

    /// Rain, if on and any.
    pub fn rain(&self) -> Option<&Rain> {
        self.rain.as_ref()
    }

    /// The land (empty for open sea).
    pub fn land(&self) -> &crate::land::Land {
        &self.land
    }

    /// Whether `other` is this environment (`==`), the land taken as equal without comparing
    /// its polygons and height maps when both share it (clones of one environment do).
    pub fn is_same(&self, other: &Environment) -> bool {
        let Environment {
            noise,
            sea,
            two_way_attenuation_db_per_km,
            clutter,
            rain,
            earth_curvature,
            clutter_doppler,
            land,
        } = self;
        *noise == other.noise
            && *sea == other.sea
            && *two_way_attenuation_db_per_km == other.two_way_attenuation_db_per_km
            && *clutter == other.clutter
            && *rain == other.rain
            && *earth_curvature == other.earth_curvature
            && *clutter_doppler == other.clutter_doppler
            && (std::sync::Arc::ptr_eq(land, &other.land) || **land == *other.land)
    }

    /// This environment with `land`.
    pub fn with_land(mut self, land: crate::land::Land) -> Environment {
        self.land = std::sync::Arc::new(land);
        self
    }

    /// 4/3-earth curvature (horizon, grazing angles).
    pub fn earth_curvature(&self) -> bool {
        self.earth_curvature
    }

    /// The Doppler spectra of sea clutter and rain.
    pub fn clutter_doppler(&self) -> &ClutterDoppler {
        &self.clutter_doppler
    }
}

/// Sea clutter settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SeaClutter {
    /// σ0 model.
    model: Sigma0Model,
    /// Sea state 0–6.
    sea_state: f64,
    /// Direction the wind blows from, rad (nautical).
    wind_from_rad: f64,
    /// Direction the swell comes from, rad (nautical): sets the K shape's swell term.
    swell_from_rad: f64,
    /// Amplitude statistics.
    distribution: ClutterDistribution,
    /// Texture correlation length, m.
    correlation_m: f64,
    /// Texture drift speed (downwind), m/s.
    drift_m_per_s: f64,
}

impl SeaClutter {
    /// σ0 model.
    pub fn model(&self) -> Sigma0Model {
        self.model
    }

    /// Sea state 0–6.
    pub fn sea_state(&self) -> f64 {
        self.sea_state
    }

    /// Direction the wind blows from, rad (nautical).
    pub fn wind_from_rad(&self) -> f64 {
        self.wind_from_rad
    }

    /// Direction the swell comes from, rad (nautical): sets the K shape's swell term.
    pub fn swell_from_rad(&self) -> f64 {
        self.swell_from_rad
    }

    /// Amplitude statistics.
    pub fn distribution(&self) -> ClutterDistribution {
        self.distribution
    }

    /// Texture correlation length, m.
    pub fn correlation_m(&self) -> f64 {
        self.correlation_m
    }

    /// Texture drift speed (downwind), m/s.
    pub fn drift_m_per_s(&self) -> f64 {
        self.drift_m_per_s
    }
}

impl Environment {
    /// Two-way power factor of the atmosphere over a one-way range, ≤ 1.
    pub fn attenuation_power(&self, range_m: f64) -> f64 {
        two_way_attenuation_power(self.two_way_attenuation_db_per_km, range_m)
    }
}

pub(super) fn build_environment(
    s: &EnvironmentSpec,
    carrier_freq_hz: f64,
    horizontal: bool,
) -> Result<Environment> {
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
    // Sea clutter's mean Doppler velocity and spread scale with the wind U: about 0.25·U
    // (HH) or 0.12·U (VV) downwind and a spread of 0.1·U, assumed defaults after the X-band
    // low-grazing-angle spectra in Ward, Tough & Watts, Sea Clutter, 2nd ed., 2013, §2.6
    // (HH centroids above VV's, both growing with the wind); rain drifts with the wind with a
    // 1.5 m/s spread (typical precipitation spectrum widths, Doviak & Zrnić, Doppler Radar
    // and Weather Observations, 2nd ed., 1993, §5.3).
    let wind_mps = sea_state_wind_speed_m_per_s(sea_state);
    let speed = |field: &str, v: Option<f64>, default: f64| {
        in_range(field, v.unwrap_or(default), 0.0, 100.0, "m/s")
    };
    let clutter_doppler = ClutterDoppler {
        downwind_rad: wind_from_rad + std::f64::consts::PI,
        sea_velocity_mps: speed(
            "environment.clutter_doppler_velocity_mps",
            s.clutter_doppler_velocity_mps,
            if horizontal { 0.25 } else { 0.12 } * wind_mps,
        )?,
        sea_spread_mps: speed(
            "environment.clutter_doppler_spread_mps",
            s.clutter_doppler_spread_mps,
            (0.1 * wind_mps).max(0.1),
        )?,
        rain_velocity_mps: speed(
            "environment.rain_velocity_mps",
            s.rain_velocity_mps,
            wind_mps,
        )?,
        rain_spread_mps: speed(
            "environment.rain_doppler_spread_mps",
            s.rain_doppler_spread_mps,
            1.5,
        )?,
    };
    Ok(Environment {
        clutter_doppler,
        noise: s.noise.unwrap_or(true),
        sea,
        two_way_attenuation_db_per_km: attenuation,
        clutter,
        rain,
        earth_curvature: s.earth_curvature.unwrap_or(true),
        land: Default::default(),
    })
}
