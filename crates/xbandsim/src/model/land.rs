//! Model: land, validated from the scene's `[[land]]` tables and `[geo]` origin
//! (docs/formats.md): each table's polygons read (GeoJSON or `polygon_m`), placed in local
//! metres, checked ([`crate::land::check_rings`]) and given their height, edge and terrain.

use super::checks::finite;
use crate::error::{Error, Problem, Result};
use crate::land::geojson::{read_polygons, RawPolygon};
use crate::land::projection::LocalProjection;
use crate::land::structure::{box_footprint, circle_footprint};
use crate::land::{check_rings, Edge, HeightMap, Land, LandPolygon, Structure};
use crate::scene::{BuiltStructureSpec, GeoSpec, LandCrs, LandEdgeName, LandSpec};
use glam::DVec2;
use std::path::Path;
use std::sync::Arc;

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
    let height_map = build_height_map(i, t, base_dir)?;
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
        // Errors show a polygon written in the scene by its corners (one from a file, by its
        // file and feature).
        let shown = match &file {
            Some(_) => what.clone(),
            None => corners_text(r.rings[0].iter().map(|&[x, y]| (x, y))),
        };
        let rings = local_rings(&what_field, &shown, &r.rings, crs, origin)?;
        check_rings(&what_field, &shown, &rings)?;
        if let Some(h) = r.height_m.filter(|h| *h > 9000.0) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                what_field.clone(),
                what,
                format!("property height_m = {h} must be within 0..9000 m"),
            ));
        }
        // A feature's name names its polygons: a MultiPolygon's parts get `-<k>`.
        let parts = raw.iter().filter(|q| q.feature == r.feature).count();
        let part = raw[..j].iter().filter(|q| q.feature == r.feature).count();
        let name = t
            .name
            .clone()
            .map(|n| if raw.len() > 1 { format!("{n}-{j}") } else { n })
            .or_else(|| {
                r.name
                    .clone()
                    .map(|n| if parts > 1 { format!("{n}-{part}") } else { n })
            })
            .unwrap_or_else(|| format!("land-{i}-{j}"));
        if let Some(map) = &height_map {
            if r.height_m.is_some() {
                return Err(Error::invalid(
                    Problem::Conflict,
                    what_field.clone(),
                    what,
                    "the feature has a height_m property but its table takes heights from a height map: drop one",
                ));
            }
            if let Some(p) = rings.iter().flatten().find(|p| !map.covers(**p)) {
                return Err(Error::invalid(
                    Problem::Conflict,
                    field("height_map_extent_m"),
                    format!("{:?}", t.height_map_extent_m.unwrap_or_default()),
                    format!(
                        "{what} has a corner at [{:.1}, {:.1}] m outside the height map's extent: the map must cover every polygon of its table",
                        p.x, p.y
                    ),
                ));
            }
        }
        out.push(LandPolygon {
            name,
            table: i,
            source: what,
            rings,
            top_m: height_map
                .as_ref()
                .map_or(r.height_m.unwrap_or(height_m), |m| m.top_m()),
            edge,
            terrain,
            gamma_db_at_10_ghz: gamma_db,
            weibull_shape: shape,
            height_map: height_map.clone(),
            structure: None,
        });
    }
    Ok(out)
}

/// Rings as read (lon/lat or metres, as `crs` says) in local metres; lon/lat out of range
/// is refused naming `what` (a file in metres read as lon/lat, say).
fn local_rings(
    what_field: &str,
    what: &str,
    rings: &[Vec<[f64; 2]>],
    crs: LandCrs,
    origin: Option<&LocalProjection>,
) -> Result<Vec<Vec<DVec2>>> {
    if crs == LandCrs::Wgs84 {
        if let Some(&[lon, lat]) = rings
            .iter()
            .flatten()
            .find(|[lon, lat]| !(-180.0..=360.0).contains(lon) || !(-90.0..=90.0).contains(lat))
        {
            return Err(Error::invalid(
                Problem::OutOfRange,
                what_field,
                what,
                format!("position [{lon}, {lat}] is not a lon/lat in degrees (is the file in metres? then crs = \"local_m\")"),
            ));
        }
    }
    Ok(rings
        .iter()
        .map(|ring| {
            ring.iter()
                .map(|&[x, y]| match (crs, origin) {
                    (LandCrs::Wgs84, Some(o)) => o.to_local_m(x, y),
                    _ => DVec2::new(x, y),
                })
                .collect()
        })
        .collect())
}

/// A table's height map, if it has one: the file read and scaled, its extent checked.
fn build_height_map(i: usize, t: &LandSpec, base_dir: &Path) -> Result<Option<Arc<HeightMap>>> {
    let field = |f: &str| format!("land[{i}].{f}");
    let Some(file) = &t.height_map else {
        for (name, given) in [
            ("height_map_extent_m", t.height_map_extent_m.is_some()),
            ("height_map_scale_m", t.height_map_scale_m.is_some()),
        ] {
            if given {
                return Err(Error::invalid(
                    Problem::Conflict,
                    field(name),
                    "given",
                    "only a table with a `height_map` file takes this",
                ));
            }
        }
        return Ok(None);
    };
    if t.height_m.is_some() {
        return Err(Error::invalid(
            Problem::Conflict,
            field("height_m"),
            t.height_m.unwrap_or_default(),
            "a table with a height map takes its heights from the map: leave height_m out",
        ));
    }
    let extent = t.height_map_extent_m.ok_or_else(|| {
        Error::missing(
            field("height_map_extent_m"),
            "a height map needs its extent [x_min, y_min, x_max, y_max] in local metres",
        )
    })?;
    let scale = finite(
        &field("height_map_scale_m"),
        t.height_map_scale_m.unwrap_or(1.0),
    )?;
    if scale <= 0.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            field("height_map_scale_m"),
            scale,
            "must be > 0 m per unit",
        ));
    }
    let map = HeightMap::read(&field("height_map"), &base_dir.join(file), extent, scale)?;
    if map.top_m() > 9000.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            field("height_map_scale_m"),
            scale,
            format!(
                "the map's highest point comes to {:.0} m, over 9000 m",
                map.top_m()
            ),
        ));
    }
    Ok(Some(Arc::new(map)))
}

/// The structures of `tables` (`[[structure]]`), GeoJSON files found relative to
/// `base_dir`; `land` gives a base its default height (the ground under its first corner).
pub(super) fn build_structures(
    tables: &[BuiltStructureSpec],
    geo: Option<&GeoSpec>,
    base_dir: &Path,
    land: &Land,
) -> Result<Vec<Structure>> {
    let origin = match geo {
        Some(g) if tables.iter().any(|t| t.crs == Some(LandCrs::Wgs84)) => Some(build_origin(g)?),
        _ => None,
    };
    let mut out = Vec::new();
    for (i, t) in tables.iter().enumerate() {
        out.extend(build_structure_table(
            i,
            t,
            origin.as_ref(),
            base_dir,
            land,
        )?);
    }
    Ok(out)
}

fn build_structure_table(
    i: usize,
    t: &BuiltStructureSpec,
    origin: Option<&LocalProjection>,
    base_dir: &Path,
    land: &Land,
) -> Result<Vec<Structure>> {
    let field = |f: &str| format!("structure[{i}].{f}");
    let kind = t.kind.unwrap_or_default();
    let crs = t.crs.unwrap_or_default();
    let given = [
        ("polygon_m", t.polygon_m.is_some()),
        ("geojson", t.geojson.is_some()),
        ("size_m", t.size_m.is_some()),
        ("radius_m", t.radius_m.is_some()),
    ];
    let footprints: Vec<_> = given.iter().filter(|g| g.1).map(|g| g.0).collect();
    match footprints.as_slice() {
        [] => {
            return Err(Error::missing(
                field("polygon_m"),
                "a structure needs a footprint: `polygon_m`, `geojson`, a box (`position_m` and `size_m`) or a circle (`position_m` and `radius_m`)",
            ))
        }
        [_] => {}
        [_, second, ..] => {
            return Err(Error::invalid(
                Problem::Conflict,
                field(second),
                "given",
                format!("a structure has one footprint: {} and {second} are both given", footprints[0]),
            ))
        }
    }
    if (t.size_m.is_some() || t.radius_m.is_some()) != t.position_m.is_some() {
        return Err(if t.position_m.is_some() {
            Error::invalid(
                Problem::Conflict,
                field("position_m"),
                "given",
                "only a box (`size_m`) or a circle (`radius_m`) is placed by its centre",
            )
        } else {
            Error::missing(
                field("position_m"),
                "a box or a circle needs its centre [x, y] in metres",
            )
        });
    }
    if t.yaw_deg.is_some() && t.size_m.is_none() {
        return Err(Error::invalid(
            Problem::Conflict,
            field("yaw_deg"),
            t.yaw_deg.unwrap_or_default(),
            "only a box (`size_m`) has a heading",
        ));
    }
    if crs == LandCrs::Wgs84 && t.geojson.is_none() {
        return Err(Error::invalid(
            Problem::Conflict,
            field("crs"),
            "wgs84",
            "only a GeoJSON footprint is read in lon/lat",
        ));
    }
    if crs == LandCrs::Wgs84 && origin.is_none() {
        return Err(Error::missing(
            "geo.origin_lon_deg",
            format!("structure[{i}] is in lon/lat (crs = \"wgs84\"): add [geo] with origin_lon_deg and origin_lat_deg"),
        ));
    }
    let positive = |name: &str, v: f64| -> Result<f64> {
        let v = finite(&field(name), v)?;
        if v <= 0.0 {
            return Err(Error::invalid(
                Problem::OutOfRange,
                field(name),
                v,
                "must be > 0 m",
            ));
        }
        Ok(v)
    };
    let mut raw: Vec<Footprint> = Vec::new();
    let mut what_field = field("polygon_m");
    if let Some(corners) = &t.polygon_m {
        let mut corners = corners.clone();
        if corners.len() > 3 && corners.first() == corners.last() {
            corners.pop();
        }
        let ring = corners.iter().map(|&[x, y]| DVec2::new(x, y)).collect();
        raw.push(Footprint::written(field("polygon_m"), ring));
    } else if let Some(path) = &t.geojson {
        what_field = field("geojson");
        let full = base_dir.join(path);
        let file = full.display().to_string();
        for r in read_polygons(&what_field, &full)? {
            let what = format!("{file:?}: {}", r.describe());
            let rings = local_rings(&what_field, &what, &r.rings, crs, origin)?;
            raw.push(Footprint {
                what,
                name: r.name.clone(),
                rings,
                height_m: r.height_m,
            });
        }
    } else {
        let [cx, cy] = t.position_m.unwrap_or_default();
        let centre = DVec2::new(
            finite(&field("position_m"), cx)?,
            finite(&field("position_m"), cy)?,
        );
        let ring = if let Some([length, width]) = t.size_m {
            what_field = field("size_m");
            let (length, width) = (positive("size_m", length)?, positive("size_m", width)?);
            let yaw = finite(&field("yaw_deg"), t.yaw_deg.unwrap_or(0.0))?;
            box_footprint(centre, length, width, yaw.to_radians())
        } else {
            what_field = field("radius_m");
            circle_footprint(
                centre,
                positive("radius_m", t.radius_m.unwrap_or_default())?,
            )
        };
        raw.push(Footprint::written(what_field.clone(), ring));
    }
    let mut out = Vec::with_capacity(raw.len());
    let count = raw.len();
    for (j, f) in raw.into_iter().enumerate() {
        let Footprint {
            what,
            name: feature_name,
            rings,
            height_m: file_height,
        } = f;
        // A footprint written in the scene is shown by its corners (one from a file, by its
        // file and feature).
        let shown = if what == what_field {
            corners_text(rings[0].iter().map(|p| (p.x, p.y)))
        } else {
            what.clone()
        };
        check_rings(&what_field, &shown, &rings)?;
        let height = match (file_height, t.height_m) {
            (Some(h), _) => h,
            (None, Some(h)) => h,
            (None, None) => {
                return Err(Error::missing(
                    field("height_m"),
                    format!("{what} has no height: set height_m (its top over its base, m)"),
                ))
            }
        };
        let height = finite(&field("height_m"), height)?;
        if !(height > 0.0 && height <= 1000.0) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                field("height_m"),
                height,
                format!("{what}: a structure's height must be within 0..1000 m and above 0"),
            ));
        }
        let base = match t.base_m {
            Some(b) => finite(&field("base_m"), b)?,
            None => land.height_at(rings[0][0]),
        };
        if !(0.0..=9000.0).contains(&base) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                field("base_m"),
                base,
                "must be within 0..9000 m over the sea",
            ));
        }
        if t.name.as_deref().is_some_and(|n| n.trim().is_empty()) {
            return Err(Error::invalid(
                Problem::OutOfRange,
                field("name"),
                "\"\"",
                "a structure's name must not be empty",
            ));
        }
        let name = t
            .name
            .clone()
            .map(|n| if count > 1 { format!("{n}-{j}") } else { n })
            .or(feature_name.filter(|n| !n.trim().is_empty()))
            .unwrap_or_else(|| format!("structure-{i}-{j}"));
        out.push(Structure {
            name,
            kind,
            source: what,
            rings,
            base_m: base,
            top_m: base + height,
        });
    }
    Ok(out)
}

/// One footprint as read, before its checks.
struct Footprint {
    /// How errors and truth name it.
    what: String,
    /// The feature's `name` property.
    name: Option<String>,
    /// Outer ring then holes, local m.
    rings: Vec<Vec<DVec2>>,
    /// The feature's `height_m` property.
    height_m: Option<f64>,
}

impl Footprint {
    /// A footprint written in the scene (one ring, no properties).
    fn written(what: String, ring: Vec<DVec2>) -> Footprint {
        Footprint {
            what,
            name: None,
            rings: vec![ring],
            height_m: None,
        }
    }
}

/// Corners written in a scene, as an error shows them: `[[x, y], …]` (m), the first six and
/// the count of the rest.
fn corners_text(corners: impl ExactSizeIterator<Item = (f64, f64)>) -> String {
    let n = corners.len();
    let shown: Vec<String> = corners
        .take(6)
        .map(|(x, y)| format!("[{x}, {y}]"))
        .collect();
    let more = if n > 6 {
        format!(", … ({} more)", n - 6)
    } else {
        String::new()
    };
    format!("[{}{more}]", shown.join(", "))
}
