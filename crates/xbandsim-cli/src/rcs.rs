//! `xbandsim rcs`: monostatic RCS of one scene object versus aspect, alone in free space.

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use plotters::prelude::*;
use serde::Serialize;
use std::path::PathBuf;
use xbandsim::constants::linear_to_db;
use xbandsim::model::{Polarisation, Scene};
use xbandsim::scattering::rcs::{RcsSettings, RcsTarget};

/// Arguments of `xbandsim rcs`.
#[derive(Args, Debug)]
pub struct RcsArgs {
    /// Scene file holding the object.
    pub scene: PathBuf,
    /// Name of the object.
    #[arg(long)]
    pub object: String,
    /// Aspect azimuths START:STOP:STEP in degrees (from the object's +y toward +x), STOP included.
    #[arg(long, default_value = "-90:90:1", allow_hyphen_values = true)]
    pub az_deg: String,
    /// Aspect elevation, degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub el_deg: f64,
    /// Polarisation, HH or VV (default: the scene's radar.polarisation).
    #[arg(long)]
    pub pol: Option<String>,
    /// Frequency, GHz (default: the scene's radar frequency).
    #[arg(long, allow_negative_numbers = true)]
    pub freq_ghz: Option<f64>,
    /// Ray-tube side in wavelengths (default 0.25).
    #[arg(long, default_value_t = 0.25, allow_negative_numbers = true)]
    pub spacing_wavelengths: f64,
    /// Cap on ray tubes per aspect; the tube side grows when the object would need more.
    #[arg(long, default_value_t = 262_144)]
    pub max_rays: usize,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also draw the RCS versus aspect into this PNG.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

#[derive(Serialize)]
struct Row {
    az_deg: f64,
    el_deg: f64,
    rcs_m2: f64,
    rcs_dbsm: f64,
}

/// Parses `START:STOP:STEP` into the angles it covers (STOP included when on the grid).
pub fn parse_range(text: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = text.split(':').collect();
    let bad = || {
        anyhow!("invalid --az-deg {text:?}: expected START:STOP:STEP in degrees, e.g. -90:90:0.5")
    };
    let v: Vec<f64> = match parts.len() {
        1 => vec![parts[0].trim().parse().map_err(|_| bad())?; 3],
        3 => parts
            .iter()
            .map(|p| p.trim().parse::<f64>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| bad())?,
        _ => return Err(bad()),
    };
    let (start, stop, step) = (v[0], v[1], if parts.len() == 1 { 1.0 } else { v[2] });
    if !(start.is_finite() && stop.is_finite() && step.is_finite()) || step <= 0.0 || stop < start {
        bail!("invalid --az-deg {text:?}: need finite START <= STOP and STEP > 0");
    }
    let n = ((stop - start) / step + 1e-9).floor() as usize + 1;
    if n > 100_000 {
        bail!("invalid --az-deg {text:?}: {n} aspects is over the limit of 100000");
    }
    Ok((0..n).map(|i| start + step * i as f64).collect())
}

/// Runs `xbandsim rcs`.
pub fn run(a: &RcsArgs) -> Result<()> {
    let scene = Scene::load(&a.scene)?;
    let object = scene
        .objects()
        .iter()
        .find(|o| o.name() == a.object)
        .ok_or_else(|| {
            let names: Vec<&str> = scene.objects().iter().map(|o| o.name()).collect();
            anyhow!(
                "no object named {:?} in {} (objects: {})",
                a.object,
                a.scene.display(),
                names.join(", ")
            )
        })?;
    let azimuths = parse_range(&a.az_deg)?;
    if !a.el_deg.is_finite() || a.el_deg.abs() > 90.0 {
        bail!("invalid --el-deg {}: must be within -90..90", a.el_deg);
    }
    let freq_hz = match a.freq_ghz {
        Some(f) if f.is_finite() && f > 0.0 => f * 1e9,
        Some(f) => bail!("invalid --freq-ghz {f}: must be a positive number"),
        None => scene.radar().carrier_freq_hz(),
    };
    let polarisation = match &a.pol {
        Some(p) => p
            .parse::<Polarisation>()
            .map_err(|e| anyhow!("invalid --pol {e}"))?,
        None => scene.radar().polarisation(),
    };
    if a.max_rays == 0 {
        bail!("invalid --max-rays 0: at least one ray tube is needed per aspect");
    }
    if !(a.spacing_wavelengths.is_finite() && a.spacing_wavelengths > 0.0) {
        bail!(
            "invalid --spacing-wavelengths {}: must be a positive number",
            a.spacing_wavelengths
        );
    }
    let settings = RcsSettings {
        freq_hz,
        polarisation,
        ray_spacing_wavelengths: a.spacing_wavelengths,
        max_rays: a.max_rays,
        max_bounces: scene.scattering().max_bounces(),
        edge_diffraction: scene.scattering().edge_diffraction(),
    };
    let target = RcsTarget::new(object);
    let el = a.el_deg.to_radians();
    let aspects: Vec<(f64, f64)> = azimuths.iter().map(|az| (az.to_radians(), el)).collect();
    let t0 = std::time::Instant::now();
    let progress = if aspects.len() >= 16 {
        crate::progress::bar(aspects.len() as u64, "rcs: aspects")
    } else {
        indicatif::ProgressBar::hidden()
    };
    let rcs = target.sweep_m2_progress(&aspects, &settings, &|| progress.inc(1));
    progress.finish_and_clear();
    let rows: Vec<Row> = azimuths
        .iter()
        .zip(&rcs)
        .map(|(&az_deg, &rcs_m2)| Row {
            az_deg,
            el_deg: a.el_deg,
            rcs_m2,
            rcs_dbsm: linear_to_db(rcs_m2.max(1e-30)),
        })
        .collect();
    // The plot is written first so that a closed stdout (`| head`) cannot lose it.
    if let Some(path) = &a.plot {
        plot(
            path,
            &rows,
            &format!(
                "{} ({}), {:.2} GHz {}, el {} deg",
                object.name(),
                object.shape_name(),
                freq_hz / 1e9,
                polarisation,
                a.el_deg
            ),
        )
        .with_context(|| format!("drawing {}", path.display()))?;
    }
    if a.json {
        crate::say!("{}", serde_json::to_string_pretty(&rows)?);
    } else {
        crate::say!(
            "# RCS of {:?} ({}) at {:.3} GHz {}, el {} deg, {} aspects in {:.2} s",
            object.name(),
            object.shape_name(),
            freq_hz / 1e9,
            polarisation,
            a.el_deg,
            rows.len(),
            t0.elapsed().as_secs_f64()
        );
        crate::say!("{:>10} {:>14} {:>10}", "az_deg", "rcs_m2", "rcs_dbsm");
        for r in &rows {
            crate::say!(
                "{:>10.3} {:>14.6e} {:>10.2}",
                r.az_deg,
                r.rcs_m2,
                r.rcs_dbsm
            );
        }
    }
    Ok(())
}

fn plot(path: &std::path::Path, rows: &[Row], title: &str) -> Result<()> {
    crate::figures::register_fonts()?;
    let (w, h) = (1000u32, 600u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e:?}"))?;
        let top = rows
            .iter()
            .map(|r| r.rcs_dbsm)
            .fold(f64::MIN, f64::max)
            .ceil()
            + 3.0;
        let (x0, x1) = (
            rows.first().map_or(0.0, |r| r.az_deg),
            rows.last().map_or(1.0, |r| r.az_deg),
        );
        let x1 = if x1 > x0 { x1 } else { x0 + 1.0 };
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, (top - 60.0)..top)
            .map_err(|e| anyhow!("{e:?}"))?;
        chart
            .configure_mesh()
            .x_desc("aspect azimuth (deg)")
            .y_desc("RCS (dBsm)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| anyhow!("{e:?}"))?;
        chart
            .draw_series(LineSeries::new(
                rows.iter().map(|r| (r.az_deg, r.rcs_dbsm.max(top - 60.0))),
                BLUE.stroke_width(2),
            ))
            .map_err(|e| anyhow!("{e:?}"))?;
        root.present().map_err(|e| anyhow!("{e:?}"))?;
    }
    xbandsim::products::output::write_png(path, w, h, 3, &buf)?;
    Ok(())
}
