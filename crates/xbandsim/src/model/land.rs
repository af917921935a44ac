//! Model: land, validated from the scene's `[[land]]` tables and `[geo]` origin
//! (docs/formats.md): each table's polygons read (GeoJSON or `polygon_m`), placed in local
//! metres, checked ([`crate::land::check_rings`]) and given their height, edge and terrain.

use super::checks::finite;
use crate::error::{Error, Problem, Result};
use crate::land::geojson::{read_polygons, RawPolygon};
use crate::land::projection::LocalProjection;
use crate::land::{check_rings, Edge, Land, LandPolygon};
use crate::scene::{GeoSpec, LandCrs, LandEdgeName, LandSpec};
use glam::DVec2;
use std::path::Path;

/// The land of `tables`, GeoJSON files found relative to `base_dir`.
pub(super) fn build_land(
    tables: &[LandSpec],
    geo: Option<&GeoSpec>,
    base_dir: &Path,
) -> Result<Land> {
    let origin = geo.map(build_origin).transpose()?;
    let mut polygons = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        polygons.extend(build_table(i, t, origin.as_ref(), base_dir)?);
    }
    Ok(Land::new(polygons))
}

fn build_origin(g: &GeoSpec) -> Result<LocalProjection> {
    let lon = finite(
        "geo.origin_lon_deg",
        g.origin_lon_deg.ok_or_else(|| {
            Error::missing("geo.origin_lon_deg", "[geo] places the scene on the earth")
        })?,
    )?;
    let lat = finite(
        "geo.origin_lat_deg",
        g.origin_lat_deg.ok_or_else(|| {
            Error::missing("geo.origin_lat_deg", "[geo] places the scene on the earth")
        })?,
    )?;
    if !(-180.0..=360.0).contains(&lon) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "geo.origin_lon_deg",
            lon,
            "must be within -180..360 degrees",
        ));
    }
    if !(-89.0..=89.0).contains(&lat) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            "geo.origin_lat_deg",
            lat,
            "must be within -89..89 degrees (the local projection is not made for the poles)",
        ));
    }
    Ok(LocalProjection::new(lon, lat))
}

fn build_table(
    i: usize,
    t: &LandSpec,
    origin: Option<&LocalProjection>,
    base_dir: &Path,
) -> Result<Vec<LandPolygon>> {
    let field = |f: &str| format!("land[{i}].{f}");
    let height_m = finite(&field("height_m"), t.height_m.unwrap_or(10.0))?;
    if !(0.0..=9000.0).contains(&height_m) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            field("height_m"),
            height_m,
            "must be within 0..9000 m",
        ));
    }
    let edge = match t.edge.unwrap_or_default() {
        LandEdgeName::Cliff => {
            if t.beach_width_m.is_some() {
                return Err(Error::invalid(
                    Problem::Conflict,
                    field("beach_width_m"),
                    t.beach_width_m.unwrap_or_default(),
                    "only a beach has a slope width: set edge = \"beach\" or leave it out",
                ));
            }
            Edge::Cliff
        }
        LandEdgeName::Beach => {
            let w = finite(&field("beach_width_m"), t.beach_width_m.unwrap_or(50.0))?;
            if w <= 0.0 {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    field("beach_width_m"),
                    w,
                    "must be > 0 m",
                ));
            }
            Edge::Beach { width_m: w }
        }
    };
    let terrain = t.terrain.unwrap_or_default();
    let gamma_db = finite(
        &field("gamma_db"),
        t.gamma_db.unwrap_or(terrain.gamma_db_at_10_ghz()),
    )?;
    if !(-60.0..=20.0).contains(&gamma_db) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            field("gamma_db"),
            gamma_db,
            "must be within -60..20 dB",
        ));
    }
    let shape = finite(
        &field("weibull_shape"),
        t.weibull_shape.unwrap_or(terrain.weibull_shape()),
    )?;
    if !(0.2..=4.0).contains(&shape) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            field("weibull_shape"),
            shape,
            "must be within 0.2..4 (2 is Rayleigh; smaller is spikier)",
        ));
    }
    let crs = t.crs.unwrap_or_default();
    let (raw, what_field, file): (Vec<RawPolygon>, String, Option<String>) =
        match (&t.geojson, &t.polygon_m) {
            (Some(_), Some(_)) => {
                return Err(Error::invalid(
                    Problem::Conflict,
                    field("polygon_m"),
                    "given",
                    "a land table takes its polygons from `geojson` or from `polygon_m`, not both",
                ))
            }
            (None, None) => {
                return Err(Error::missing(
                    field("geojson"),
                    "a land table needs `geojson` (a file) or `polygon_m` (corners in metres)",
                ))
            }
            (Some(path), None) => {
                let f = field("geojson");
                let full = base_dir.join(path);
                (
                    read_polygons(&f, &full)?,
                    f,
                    Some(full.display().to_string()),
                )
            }
            (None, Some(corners)) => {
                // A ring written closed (its last corner its first) is the same ring.
                let mut corners = corners.clone();
                if corners.len() > 3 && corners.first() == corners.last() {
                    corners.pop();
                }
                if crs != LandCrs::LocalM {
                    return Err(Error::invalid(
                        Problem::Conflict,
                        field("crs"),
                        "wgs84",
                        "`polygon_m` is in metres: crs must be \"local_m\"",
                    ));
                }
                (
                    vec![RawPolygon {
                        feature: 0,
                        name: None,
                        height_m: None,
                        rings: vec![corners],
                    }],
                    field("polygon_m"),
                    None,
                )
            }
        };
    if crs == LandCrs::Wgs84 && origin.is_none() {
        return Err(Error::missing(
            "geo.origin_lon_deg",
            format!("land[{i}] is in lon/lat (crs = \"wgs84\"): add [geo] with origin_lon_deg and origin_lat_deg"),
        ));
    }
    let mut out = Vec::with_capacity(raw.len());
    for (j, r) in raw.iter().enumerate() {
        let what = match &file {
            Some(f) => format!("{f:?}: {}", r.describe()),
            None => format!("land[{i}].polygon_m"),
        };
        let rings: Vec<Vec<DVec2>> = r
            .rings
            .iter()
            .map(|ring| {
                ring.iter()
                    .map(|&[x, y]| match (crs, origin) {
                        (LandCrs::Wgs84, Some(o)) => o.to_local_m(x, y),
                        _ => DVec2::new(x, y),
                    })
                    .collect()
            })
            .collect();
        if crs == LandCrs::Wgs84 {
            if let Some(&[lon, lat]) =
                r.rings.iter().flatten().find(|[lon, lat]| {
                    !(-180.0..=360.0).contains(lon) || !(-90.0..=90.0).contains(lat)
                })
            {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    what_field.clone(),
                    what,
                    format!("position [{lon}, {lat}] is not a lon/lat in degrees (is the file in metres? then crs = \"local_m\")"),
                ));
            }
        }
        check_rings(&what_field, &what, &rings)?;
        if let Some(h) = r.height_m.filter(|h| *h > 9000.0) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                what_field.clone(),
                what,
                format!("property height_m = {h} must be within 0..9000 m"),
            ));
        }
        let name = t
            .name
            .clone()
            .map(|n| if raw.len() > 1 { format!("{n}-{j}") } else { n })
            .or_else(|| r.name.clone())
            .unwrap_or_else(|| format!("land-{i}-{j}"));
        out.push(LandPolygon {
            name,
            table: i,
            source: what,
            rings,
            top_m: r.height_m.unwrap_or(height_m),
            edge,
            terrain,
            gamma_db_at_10_ghz: gamma_db,
            weibull_shape: shape,
        });
    }
    Ok(out)
}
