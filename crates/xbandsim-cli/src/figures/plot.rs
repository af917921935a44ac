//! Drawing helpers of `xbandsim figures`: fonts, RGB buffers written as PNG, time-series
//! panels and image grids (plotters).

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::Path;
use xbandsim::products::output::write_png;

/// The font family of every label.
pub const FONT: &str = "sans-serif";

pub(super) fn plot_err<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("drawing failed: {e:?}")
}

/// Registers the embedded DejaVu Sans font with plotters (no system fonts are needed).
pub fn register_fonts() -> Result<()> {
    plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular())
        .map_err(|_| anyhow!("embedded font is invalid"))?;
    plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold())
        .map_err(|_| anyhow!("embedded font is invalid"))?;
    Ok(())
}

/// Draws with plotters into an RGB buffer and writes it atomically as PNG.
pub(super) fn save_rgb(
    path: &Path,
    w: u32,
    h: u32,
    draw: impl FnOnce(DrawingArea<BitMapBackend, plotters::coord::Shift>) -> Result<()>,
) -> Result<()> {
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        draw(root.clone())?;
        root.present().map_err(plot_err)?;
    }
    write_png(path, w, h, 3, &buf)?;
    Ok(())
}

/// A panel of real-part time series (µs, noise-rms units) sharing symmetric y limits.
pub(super) fn time_panel(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    caption: &str,
    series: &[(Vec<(f64, f64)>, RGBColor)],
) -> Result<()> {
    let t_max = series
        .iter()
        .flat_map(|(p, _)| p.last().map(|l| l.0))
        .fold(1e-3, f64::max);
    let peak = series
        .iter()
        .flat_map(|(p, _)| p.iter().map(|q| q.1.abs()))
        .fold(1e-6, f64::max)
        * 1.1;
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(0f64..t_max, -peak..peak)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_desc("time after transmission (us)")
        .y_desc("Re r(t) / noise rms")
        .label_style((FONT, 13))
        .draw()
        .map_err(plot_err)?;
    for (points, colour) in series {
        chart
            .draw_series(LineSeries::new(points.iter().copied(), colour))
            .map_err(plot_err)?;
    }
    Ok(())
}

/// Square images with titles in a grid of `cols` columns, written as one PNG.
pub(super) fn panel_grid(
    path: &Path,
    heading: &str,
    images: &[(String, Vec<u8>)],
    panel: u32,
    cols: u32,
) -> Result<()> {
    let rows = (images.len() as u32).div_ceil(cols);
    let (w, h) = (panel * cols + 10 * (cols + 1), rows * (panel + 40) + 40);
    save_rgb(path, w, h, |root| {
        root.fill(&WHITE).map_err(plot_err)?;
        root.draw(&Text::new(heading.to_string(), (20, 8), (FONT, 18)))
            .map_err(plot_err)?;
        for (i, (title, rgb)) in images.iter().enumerate() {
            let (col, row) = (i as u32 % cols, i as u32 / cols);
            let x0 = 10 + col * (panel + 10);
            let y0 = 40 + row * (panel + 40);
            root.draw(&Text::new(
                title.clone(),
                (x0 as i32 + 5, y0 as i32),
                (FONT, 16),
            ))
            .map_err(plot_err)?;
            for y in 0..panel {
                for x in 0..panel {
                    let k = ((y * panel + x) * 3) as usize;
                    root.draw_pixel(
                        ((x0 + x) as i32, (y0 + 20 + y) as i32),
                        &RGBColor(rgb[k], rgb[k + 1], rgb[k + 2]),
                    )
                    .map_err(plot_err)?;
                }
            }
        }
        Ok(())
    })
}
