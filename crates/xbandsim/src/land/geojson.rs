//! Land input: polygons from a GeoJSON file (RFC 7946). A FeatureCollection, a Feature or a
//! bare geometry; each feature's geometry must be a Polygon or a MultiPolygon (outer ring,
//! then holes; each ring closed: its last position equals its first). A feature's `name`
//! property names its polygons and a numeric `height_m` property overrides the table's
//! height. Errors name the file and the feature (its index in the collection, and its name
//! when it has one).

use crate::error::{Error, Problem, Result};
use serde_json::Value;
use std::path::Path;

/// One polygon as read: rings of `[x, y]` positions (lon/lat or metres, as the file is),
/// the closing position removed.
#[derive(Debug, Clone, PartialEq)]
pub struct RawPolygon {
    /// Index of its feature in the file (0 for a bare geometry).
    pub feature: usize,
    /// The feature's `name` property.
    pub name: Option<String>,
    /// The feature's `height_m` property.
    pub height_m: Option<f64>,
    /// Outer ring, then holes.
    pub rings: Vec<Vec<[f64; 2]>>,
}

impl RawPolygon {
    /// How errors and truth name it: `feature 3` or `feature 3 ("Mole")`.
    pub fn describe(&self) -> String {
        match &self.name {
            Some(n) => format!("feature {} ({n:?})", self.feature),
            None => format!("feature {}", self.feature),
        }
    }
}

/// Reads every polygon of the GeoJSON file at `path`; `field` (`land[0].geojson`) names the
/// scene field in errors.
pub fn read_polygons(field: &str, path: &Path) -> Result<Vec<RawPolygon>> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::unusable(
            field,
            format!("{:?}", path.display().to_string()),
            "cannot read the GeoJSON file",
            Error::io(path, e),
        )
    })?;
    parse_polygons(field, &path.display().to_string(), &text)
}

/// [`read_polygons`] of GeoJSON text; `file` names it in errors.
pub fn parse_polygons(field: &str, file: &str, text: &str) -> Result<Vec<RawPolygon>> {
    let bad =
        |reason: String| Error::invalid(Problem::Unusable, field, format!("{file:?}"), reason);
    let root: Value =
        serde_json::from_str(text).map_err(|e| bad(format!("not valid JSON: {e}")))?;
    let kind = root.get("type").and_then(Value::as_str).unwrap_or("");
    let features: Vec<&Value> = match kind {
        "FeatureCollection" => root
            .get("features")
            .and_then(Value::as_array)
            .ok_or_else(|| bad("a FeatureCollection needs a \"features\" array".into()))?
            .iter()
            .collect(),
        "Feature" | "Polygon" | "MultiPolygon" => vec![&root],
        other => {
            return Err(bad(format!(
                "the top level is a {other:?}; expected a FeatureCollection, a Feature, a Polygon or a MultiPolygon"
            )))
        }
    };
    let mut out = Vec::new();
    for (k, feature) in features.into_iter().enumerate() {
        let (geometry, props) = if feature.get("type").and_then(Value::as_str) == Some("Feature") {
            (
                feature.get("geometry").unwrap_or(&Value::Null),
                feature.get("properties"),
            )
        } else {
            (feature, None)
        };
        let name = props
            .and_then(|p| p.get("name"))
            .and_then(Value::as_str)
            .map(str::to_string);
        let what = match &name {
            Some(n) => format!("feature {k} ({n:?})"),
            None => format!("feature {k}"),
        };
        let height_m = match props.and_then(|p| p.get("height_m")) {
            None | Some(Value::Null) => None,
            Some(v) => Some(
                v.as_f64()
                    .filter(|h| h.is_finite() && *h >= 0.0)
                    .ok_or_else(|| {
                        bad(format!(
                            "{what}: property height_m = {v} is not a height ≥ 0 in metres"
                        ))
                    })?,
            ),
        };
        let gkind = geometry.get("type").and_then(Value::as_str);
        let coords = geometry.get("coordinates");
        let polygons: Vec<&Value> = match (gkind, coords) {
            (Some("Polygon"), Some(c)) => vec![c],
            (Some("MultiPolygon"), Some(Value::Array(list))) => list.iter().collect(),
            (Some("Polygon" | "MultiPolygon"), _) => {
                return Err(bad(format!("{what}: its geometry has no usable \"coordinates\"")))
            }
            (Some(other), _) => {
                return Err(bad(format!(
                    "{what}: its geometry is a {other}; land needs Polygon or MultiPolygon (close coastline lines into polygons first: docs/coastlines.md)"
                )))
            }
            (None, _) => return Err(bad(format!("{what}: it has no geometry"))),
        };
        for (j, poly) in polygons.into_iter().enumerate() {
            let rings = poly
                .as_array()
                .ok_or_else(|| bad(format!("{what}: polygon {j} is not an array of rings")))?;
            if rings.is_empty() {
                return Err(bad(format!("{what}: polygon {j} has no rings")));
            }
            let mut parsed = Vec::with_capacity(rings.len());
            for (r, ring) in rings.iter().enumerate() {
                let positions = ring.as_array().ok_or_else(|| {
                    bad(format!(
                        "{what}: polygon {j} ring {r} is not an array of positions"
                    ))
                })?;
                let mut pts = Vec::with_capacity(positions.len());
                for (i, p) in positions.iter().enumerate() {
                    let xy = p
                        .as_array()
                        .filter(|a| a.len() >= 2)
                        .and_then(|a| Some([a[0].as_f64()?, a[1].as_f64()?]))
                        .filter(|a| a[0].is_finite() && a[1].is_finite())
                        .ok_or_else(|| {
                            bad(format!(
                                "{what}: polygon {j} ring {r} position {i} = {p} is not [x, y] numbers"
                            ))
                        })?;
                    pts.push(xy);
                }
                if pts.len() < 4 || pts.first() != pts.last() {
                    return Err(bad(format!(
                        "{what}: polygon {j} ring {r} is open: a ring needs at least 4 positions and its last must equal its first (RFC 7946 §3.1.6)"
                    )));
                }
                pts.pop();
                parsed.push(pts);
            }
            out.push(RawPolygon {
                feature: k,
                name: name.clone(),
                height_m,
                rings: parsed,
            });
        }
    }
    if out.is_empty() {
        return Err(bad("the file has no polygons".into()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collections_features_and_bare_geometries_are_read() {
        let text = r#"{"type":"FeatureCollection","features":[
          {"type":"Feature","properties":{"name":"Isle","height_m":12},
           "geometry":{"type":"Polygon","coordinates":[[[0,0],[10,0],[10,10],[0,0]]]}},
          {"type":"Feature","properties":null,
           "geometry":{"type":"MultiPolygon","coordinates":[
             [[[20,0],[30,0],[30,10],[20,0]]],
             [[[40,0],[50,0],[50,10],[40,0]],[[45,1],[46,1],[46,2],[45,1]]]]}}]}"#;
        let p = parse_polygons("land[0].geojson", "x.geojson", text).unwrap();
        assert_eq!(p.len(), 3);
        assert_eq!(p[0].name.as_deref(), Some("Isle"));
        assert_eq!(p[0].height_m, Some(12.0));
        assert_eq!(p[0].rings[0].len(), 3);
        assert_eq!((p[1].feature, p[2].feature, p[2].rings.len()), (1, 1, 2));
        let bare = r#"{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,0]]]}"#;
        assert_eq!(parse_polygons("f", "b", bare).unwrap().len(), 1);
    }

    #[test]
    fn bad_files_name_the_file_and_the_feature() {
        let cases = [
            ("{", "not valid JSON"),
            (
                r#"{"type":"Point","coordinates":[0,0]}"#,
                "top level is a \"Point\"",
            ),
            (
                r#"{"type":"FeatureCollection","features":[{"type":"Feature","properties":{"name":"Cape"},"geometry":{"type":"LineString","coordinates":[[0,0],[1,1]]}}]}"#,
                "feature 0 (\"Cape\"): its geometry is a LineString",
            ),
            (
                r#"{"type":"Polygon","coordinates":[[[0,0],[1,0],[1,1],[0,1]]]}"#,
                "feature 0: polygon 0 ring 0 is open",
            ),
            (
                r#"{"type":"Polygon","coordinates":[[[0,0],[1,"a"],[1,1],[0,0]]]}"#,
                "position 1",
            ),
            (
                r#"{"type":"FeatureCollection","features":[]}"#,
                "no polygons",
            ),
        ];
        for (text, want) in cases {
            let e = parse_polygons("land[1].geojson", "coast.geojson", text).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains("land[1].geojson"), "{msg}");
            assert!(msg.contains("coast.geojson"), "{msg}");
            assert!(msg.contains(want), "{msg} lacks {want}");
        }
    }
}
