//! Stage: engine, what one revolution is made of: its signal sources (the traced echo groups,
//! the movers, the clutter map with its speckle), its sinks (the integrator and the optional
//! products the request asks for) and the product arrays they fill spoke by spoke
//! (docs/architecture.md, "Signal chain").

use super::chain::{RevolutionSources, SinkPlan};
use super::{iq, Outputs, Simulation};
use crate::echo::EchoGroups;
use crate::model::artefacts::BlindView;
use crate::model::revolution::Revolution;
use crate::model::{ProcessingMode, Radar};
use crate::processing::sinks::{SpokeRows, VelocityRows};
use crate::processing::DopplerSpectra;
use crate::products::{DopplerCube, RadialVelocity};
use crate::rng::FrameKey;
use crate::schedule::Schedule;
use crate::signal::beacons::Beacons;
use crate::signal::clutter::{ClutterSpeckle, SeaAndRainClutter};
use crate::signal::clutter_map::{ClutterMap, ClutterSurface};
use crate::signal::interference::Interference;
use crate::signal::targets::{FilterReach, FixedEchoes, Mover, MovingEchoes, OwnShipPaths};
use crate::signal::ThisRadar;
use std::sync::Arc;

impl Simulation {
    /// The sources of the spoke-mode chain: every echo group fixed, fresh speckle.
    pub(super) fn spoke_sources<'a>(
        &'a self,
        groups: &'a EchoGroups,
        clutter: Option<&'a ClutterMap>,
    ) -> RevolutionSources<'a> {
        let at = Placement {
            antenna_m: self.scene.radar().position_m(),
            heading_rad: self.scene.own_ship().map_or(0.0, |s| s.heading_rad()),
        };
        self.sources(groups, clutter, ClutterSpeckle::PerPulse, &[], &[], at)
    }

    pub(super) fn sources<'a>(
        &'a self,
        groups: &'a EchoGroups,
        clutter: Option<&'a ClutterMap>,
        speckle: ClutterSpeckle,
        movers: &'a [Mover],
        spectra: &'a [DopplerSpectra],
        at: Placement,
    ) -> RevolutionSources<'a> {
        // The target-only render (masks) has no other transmitters.
        let artefacts = self.scene.artefacts();
        let (interferers, beacons) = if self.artefact_sources {
            (&artefacts.interferers[..], &artefacts.beacons[..])
        } else {
            (&[][..], &[][..])
        };
        let radar = self.scene.radar();
        let this = ThisRadar {
            antenna: *radar.antenna(),
            position_m: at.antenna_m,
            blind: BlindView {
                sectors: &artefacts.blind_sectors,
                heading_rad: at.heading_rad,
            },
            wavelength_m: radar.wavelength_m(),
            peak_power_w: radar.peak_power_w(),
            noise_power_w: radar.noise_power_w(),
            sample_rate_hz: radar.sample_rate_hz(),
            bandwidth_hz: receiver_bandwidth_hz(radar),
            record_len: self.compressor.record_len(),
            pulse_len: self.compressor.pulse_len().max(1),
        };
        let record = self.compressor.record_len();
        // Echoes by paths via the own ship: the indirect ones are added past the blind
        // sectors' loss; the target-only render (masks) has none of them.
        let (direct, indirect) = if !artefacts.has_paths_via_own_ship() {
            (OwnShipPaths::All, false)
        } else if self.artefact_sources {
            (
                OwnShipPaths::ThroughStructure,
                artefacts.blind_sectors.iter().any(|s| s.indirect.is_some()),
            )
        } else {
            (OwnShipPaths::None, false)
        };
        RevolutionSources {
            fixed: FixedEchoes::new(groups, *radar.antenna(), record, movers, direct),
            indirect: indirect.then(|| {
                FixedEchoes::new(
                    groups,
                    *radar.antenna(),
                    record,
                    movers,
                    OwnShipPaths::FromStructure,
                )
            }),
            clutter: clutter.map(|c| SeaAndRainClutter::new(c, speckle, record)),
            moving: MovingEchoes::new(
                groups,
                movers,
                *radar.antenna(),
                FilterReach {
                    record_len: record,
                    pulse_len: self.compressor.pulse_len(),
                    peak_gain: self.compressor.peak_gain(),
                },
                radar.scan().period_s(),
                radar.sample_rate_hz(),
                radar.wavelength_m(),
            ),
            spectra,
            interference: Interference::new(interferers, this),
            beacons: Beacons::new(beacons, this),
        }
    }

    /// The sinks of a revolution in `mode` with `outputs`: the integrator (spoke mode's
    /// power integrator, pulse mode's `[processing] integration`), the CPI collector, the pulse pair and raw I/Q.
    pub(super) fn sink_plan(&self, mode: ProcessingMode, outputs: Outputs) -> SinkPlan<'_> {
        let radar = self.scene.radar();
        let bins = self.compressor.num_bins();
        let pulse = mode == ProcessingMode::Pulse;
        let (join_bin, short_noise_db) = radar
            .short_pulse_noise_db()
            .map_or((0, 0.0), |d| (radar.join_bin().min(bins), d as f32));
        SinkPlan {
            integration: pulse.then(|| self.scene.processing().integration()),
            bins,
            doppler: self
                .doppler
                .as_ref()
                .filter(|_| pulse && outputs.doppler_cube),
            pulse_pair: (pulse && outputs.radial_velocity).then_some((
                radar.wavelength_m(),
                join_bin,
                short_noise_db,
            )),
            iq_record: outputs.iq.then_some(self.compressor.record_len()),
        }
    }

    /// Each spoke's rows of the products.
    pub(super) fn rows<'a>(
        polar: &'a mut [f32],
        bins: usize,
        cube: Option<(&'a mut [f32], usize)>,
        velocity: Option<VelocityRows<'a>>,
        iq: Option<&'a mut iq::IqCapture>,
    ) -> Vec<SpokeRows<'a>> {
        let mut rows: Vec<SpokeRows> = polar
            .chunks_mut(bins)
            .map(|p| SpokeRows {
                polar_db: p,
                doppler_db: None,
                velocity: None,
                iq: None,
            })
            .collect();
        if let Some((values, slab_len)) = cube {
            for (r, slab) in rows.iter_mut().zip(values.chunks_mut(slab_len)) {
                r.doppler_db = Some(slab);
            }
        }
        if let Some((v, e, p)) = velocity {
            let cells = v
                .chunks_mut(bins)
                .zip(e.chunks_mut(bins))
                .zip(p.chunks_mut(bins));
            for (r, ((v, e), p)) in rows.iter_mut().zip(cells) {
                r.velocity = Some((v, e, p));
            }
        }
        if let Some(capture) = iq {
            for (r, slab) in rows.iter_mut().zip(capture.slabs()) {
                r.iq = slab;
            }
        }
        rows
    }

    /// Sea and rain clutter of revolution `key` (None when the scene has neither, or in
    /// [`Simulation::targets_only`]), seen from the antenna's position at the start of the
    /// run.
    pub fn clutter_map(&self, key: FrameKey) -> Option<ClutterMap> {
        self.clutter_map_from(self.scene.radar(), key, &[])
    }

    /// Sea and rain clutter of revolution `key` seen by `radar` (this scene's radar, carried
    /// to where the own ship has taken it), spoke k's beam raised by `beam_tilt_rad[k]`. With
    /// a level beam the surface made last ([`ClutterSurface`]) is reused when it serves the
    /// same radar, seed and record: the same map, its texture alone drawn for `key.frame`.
    pub(super) fn clutter_map_from(
        &self,
        radar: &Radar,
        key: FrameKey,
        beam_tilt_rad: &[f64],
    ) -> Option<ClutterMap> {
        if !self.clutter {
            return None;
        }
        let env = self.scene.environment();
        let samples = self.compressor.record_len();
        if !beam_tilt_rad.is_empty() {
            return ClutterMap::with_beam_tilts(radar, env, key, samples, beam_tilt_rad);
        }
        // A level beam: the surface made last serves while the radar stands still.
        let kept = self
            .clutter_surface
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .clone()
            .filter(|s| s.serves(radar, env, key.seed, samples));
        let surface = match kept {
            Some(surface) => surface,
            None => {
                let surface = Arc::new(ClutterSurface::new(radar, env, key.seed, samples, &[])?);
                *self
                    .clutter_surface
                    .lock()
                    .unwrap_or_else(|poisoned| poisoned.into_inner()) = Some(Arc::clone(&surface));
                surface
            }
        };
        Some(ClutterMap::on_surface(surface, key.frame))
    }

    /// The clutter map of a revolution: each spoke's beam tilted by the deck's roll and pitch
    /// when the antenna passes it.
    pub(super) fn revolution_clutter(
        &self,
        revolution: &Revolution,
        key: FrameKey,
    ) -> Option<ClutterMap> {
        if !self.clutter {
            return None;
        }
        let tilts: Vec<f64> = if revolution.deck_moves() {
            let scan = *self.scene.radar().scan();
            (0..scan.spokes())
                .map(|k| {
                    let t = revolution.start_time_s()
                        + k as f64 / scan.spokes() as f64 * scan.period_s();
                    revolution.beam_tilt_rad(t, scan.spoke_azimuth_rad(k))
                })
                .collect()
        } else {
            Vec::new()
        };
        self.clutter_map_from(revolution.scene().radar(), key, &tilts)
    }

    /// Every dwell through the chain: the polar record, the range-Doppler cube and the
    /// radial velocities (the last two when `outputs` ask, in pulse mode).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn run_products(
        &self,
        sources: &RevolutionSources,
        schedule: &Schedule,
        key: FrameKey,
        mode: ProcessingMode,
        outputs: Outputs,
        iq: Option<&mut iq::IqCapture>,
        skip: Option<&[bool]>,
        dwell_done: &(dyn Fn() + Sync),
    ) -> (Vec<f32>, Option<DopplerCube>, Option<RadialVelocity>) {
        let radar = self.scene.radar();
        let spokes = radar.spokes();
        let bins = self.compressor.num_bins();
        let sinks = self.sink_plan(mode, outputs);
        let cpi_len = sinks.doppler.map_or(0, |p| p.pulses());
        let pairs = sinks.pulse_pair.is_some();
        let mut polar = vec![0f32; spokes * bins];
        let mut cube_values = vec![0f32; spokes * cpi_len * bins];
        let cells = if pairs { spokes * bins } else { 0 };
        let mut velocity = vec![0f32; cells];
        let mut estimated = vec![false; cells];
        let mut power = vec![0f32; cells];
        let rows = Self::rows(
            &mut polar,
            bins,
            (cpi_len > 0).then_some((&mut cube_values[..], cpi_len * bins)),
            pairs.then_some((&mut velocity[..], &mut estimated[..], &mut power[..])),
            iq,
        );
        self.run_dwells(sources, schedule, key, &sinks, rows, skip, dwell_done);
        let cube = (cpi_len > 0).then(|| DopplerCube {
            spokes,
            doppler_bins: cpi_len,
            range_bins: bins,
            doppler_bin_hz: radar.prf_hz() / cpi_len as f64,
            values_db: cube_values,
        });
        let radial_velocity = pairs.then(|| RadialVelocity {
            spokes,
            range_bins: bins,
            velocity_mps: velocity,
            estimated,
            power_db: power,
            unambiguous_mps: radar.wavelength_m() * radar.prf_hz() / 4.0,
        });
        (polar, cube, radial_velocity)
    }
}

/// The receiver's bandwidth: the chirp's sweep, or `1/T` for an unmodulated pulse.
fn receiver_bandwidth_hz(radar: &crate::model::Radar) -> f64 {
    let c = radar.chirp();
    if c.bandwidth_hz > 0.0 {
        c.bandwidth_hz
    } else {
        1.0 / c.pulse_width_s
    }
}

/// Where the antenna is for a revolution's other transmitters: its phase centre at the
/// revolution's start and the own ship's heading (for the blind sectors).
#[derive(Debug, Clone, Copy)]
pub(super) struct Placement {
    pub(super) antenna_m: glam::DVec3,
    pub(super) heading_rad: f64,
}
