//! Clutter map, stage: cell geometry. The sea within the record is cut into patches one
//! azimuth step δ = 2π/spokes wide and one range sample Δr = c/(2fs) deep; this stage gives,
//! per range sample, what does not depend on azimuth — ground and slant range, grazing and
//! depression angles over the 4/3 earth (`sin ψ = h/R − R/(2a_e)`, beyond the horizon when
//! ψ ≤ 0), the patch's radar-equation factor with its elevation gain, the rain's volume
//! factor with its elevation integral, the NRL σ0 and the K shape's row part — and the
//! two-way azimuth weights that spread each patch over the neighbouring spokes
//! (docs/physics.md, "Sea clutter", "Rain").

use crate::antenna::Antenna;
use crate::environment::clutter::{k_shape_log10, nrl_sigma0_db};
use crate::model::{Environment, Polarisation, Radar};
use crate::propagation::sin_grazing;
use crate::special::bessel_i0;

/// The radar's side of a map: what every cell's geometry uses.
pub(super) struct MapGeometry {
    pub(super) spokes: usize,
    /// Antenna height over the sea, m.
    pub(super) h: f64,
    /// Range sample, m.
    pub(super) dr: f64,
    pub(super) lambda: f64,
    pub(super) freq_ghz: f64,
    pub(super) horizontal: bool,
    pub(super) ant: Antenna,
    /// Azimuth step 2π/spokes, rad.
    pub(super) delta: f64,
    /// Radar equation over the noise power: P_r/N per m² of σ at 1 m.
    pub(super) k_noise: f64,
    resolution_m: f64,
}

/// One range sample's geometry and mean power factors (independent of azimuth).
pub(super) struct CellGeometry {
    pub(super) ground_m: f64,
    /// Slant range r, m: the rain loss is charged along it, not along the ground track
    /// (docs/physics.md §2.7).
    pub(super) slant_m: f64,
    pub(super) grazing_rad: f64,
    pub(super) sea_factor: f64,
    pub(super) sigma0_nrl: f64,
    /// Upwind-factor exponent b and 1/I0(b) (see `wind_direction_factor`).
    pub(super) dir_b: f64,
    pub(super) dir_norm: f64,
    /// log10 ν of the empirical K shape without the swell-direction term.
    pub(super) log_nu_row: f64,
    pub(super) rain_volume_factor: f64,
    /// For a tilted beam: the depression angle, the sea factor without its elevation gain,
    /// the rain factor without its elevation integral and that integral's limits (rad).
    pub(super) depression: f64,
    pub(super) sea_factor_per_gain: f64,
    pub(super) rain_per_integral: f64,
    pub(super) rain_limits: (f64, f64),
}

impl MapGeometry {
    /// The geometry of `radar`'s map.
    pub(super) fn of(radar: &Radar) -> MapGeometry {
        let spokes = radar.spokes();
        MapGeometry {
            spokes,
            h: radar.position_m().z.max(0.0),
            dr: radar.range_bin_m(),
            lambda: radar.wavelength_m(),
            freq_ghz: radar.carrier_freq_hz() / 1e9,
            horizontal: radar.polarisation() == Polarisation::Hh,
            ant: *radar.antenna(),
            delta: std::f64::consts::TAU / spokes as f64,
            k_noise: radar.radar_equation_constant_w_m2() / radar.noise_power_w(),
            resolution_m: radar.range_resolution_m(),
        }
    }

    /// Azimuth weights Gn²(jδ) over ±2 first nulls of the antenna's azimuth [`crate::antenna::Pattern`],
    /// scaled so that Σ w_j·δ = its two-way integral (w carries Gn², the patch carries δ).
    pub(super) fn azimuth_weights(&self) -> Vec<f32> {
        let (ant, delta, spokes) = (&self.ant, self.delta, self.spokes);
        let pattern = ant.azimuth();
        let beam_integral = pattern.two_way_integral_rad();
        let null = pattern.first_null_rad();
        let half = ((2.0 * null / delta).ceil() as usize).min(spokes / 2);
        let raw: Vec<f64> = (-(half as isize)..=half as isize)
            .map(|j| ant.azimuth_pattern(j as f64 * delta).powi(2))
            .collect();
        let sum: f64 = raw.iter().sum();
        raw.iter()
            .map(|w| (w / sum * beam_integral / delta) as f32)
            .collect()
    }

    /// Every range sample's cell geometry in `env` (None at the radar and beyond the
    /// horizon), records of `samples` samples.
    pub(super) fn cells(&self, env: &Environment, samples: usize) -> Vec<Option<CellGeometry>> {
        (0..samples).map(|n| self.cell(env, n)).collect()
    }

    fn cell(&self, env: &Environment, n: usize) -> Option<CellGeometry> {
        let (h, dr, ant, k_noise) = (self.h, self.dr, &self.ant, self.k_noise);
        let r = n as f64 * dr;
        if r <= h || n == 0 {
            return None;
        }
        let ground_m = (r * r - h * h).sqrt();
        let sin_psi = sin_grazing(h, r, env.earth_curvature());
        if sin_psi <= 0.0 {
            return None;
        }
        let grazing_rad = sin_psi.asin();
        let depression = -(h / r).asin();
        let el_gain = ant.elevation_pattern(depression).powi(2);
        let atmos = env.attenuation_power(r);
        let sea_factor = ground_m * dr / grazing_rad.cos() * k_noise / r.powi(4) * el_gain * atmos;
        let sigma0_nrl = 10f64.powf(
            nrl_sigma0_db(
                self.freq_ghz,
                env.clutter().as_ref().map_or(0.0, |c| c.sea_state()),
                self.horizontal,
                grazing_rad.to_degrees(),
            ) / 10.0,
        );
        let sea_factor_per_gain = ground_m * dr / grazing_rad.cos() * k_noise / r.powi(4) * atmos;
        let rain_per_integral = r * r * dr * k_noise / r.powi(4) * atmos;
        let rain_limits = env.rain().as_ref().map_or((0.0, 0.0), |rain| {
            (depression, ((rain.top_m - h) / r).clamp(-1.0, 1.0).asin())
        });
        // Rain: elevations from the sea up to the rain top, two-way elevation pattern.
        let rain_volume_factor = env.rain().as_ref().map_or(0.0, |rain| {
            let lo = depression;
            let hi = ((rain.top_m - h) / r).clamp(-1.0, 1.0).asin();
            let steps = 48;
            let integral: f64 = (0..steps)
                .map(|i| lo + (hi - lo) * (i as f64 + 0.5) / steps as f64)
                .map(|e| ant.elevation_pattern(e).powi(2))
                .sum::<f64>()
                * (hi - lo)
                / steps as f64;
            r * r * dr * integral.max(0.0) * k_noise / r.powi(4) * atmos
        });
        let cell_area_m2 = ground_m * ant.az_beamwidth_rad * self.resolution_m / grazing_rad.cos();
        let dir_b = 0.2 * (1.0 - 2.8 * grazing_rad) * (self.lambda + 0.015).powf(-0.4);
        // exp(b·cos φ) averages to I0(b) over φ: divide by it for a unit mean.
        let dir_norm = 1.0 / bessel_i0(dir_b);
        // k_shape_default at a 45° swell angle has cos(2θ) = 0: the row part alone (the
        // swell-direction term −cos(2θ_sw)/3 is added per spoke). Unclamped: the clamp to
        // 0.1…20 applies after the swell term.
        let log_nu_row = k_shape_log10(
            grazing_rad.to_degrees(),
            cell_area_m2,
            self.horizontal,
            std::f64::consts::FRAC_PI_4,
        );
        Some(CellGeometry {
            ground_m,
            slant_m: r,
            grazing_rad,
            sea_factor,
            sigma0_nrl,
            dir_b,
            dir_norm,
            log_nu_row,
            rain_volume_factor,
            depression,
            sea_factor_per_gain,
            rain_per_integral,
            rain_limits,
        })
    }
}
