//! The dataset spec (docs/formats.md, "Dataset spec"): a base scene, the scene fields drawn
//! per sample, and the targets placed at random, each field fixed or drawn from a
//! distribution ([`crate::dist`]). Parsed into validated, immutable values; every error names
//! the field.

use crate::dist::{as_f64, Dist};
use crate::error::{DatasetError, Result};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Most revolutions per sample.
pub const MAX_FRAMES_PER_SAMPLE: u64 = 1000;

/// Most targets in one sample.
pub const MAX_TARGETS: i64 = 500;

/// A validated dataset spec.
#[derive(Debug, Clone)]
pub struct DatasetSpec {
    /// The spec's text, as read (recorded with the dataset).
    pub text: String,
    /// Directory mesh files in the base scene are found relative to.
    pub base_dir: PathBuf,
    /// Consecutive revolutions per sample (1: a single frame).
    pub frames: u64,
    /// Also write each frame's range-Doppler cube (needs pulse mode).
    pub datacube: bool,
    /// Which PPI images each frame keeps (`[dataset] image`).
    pub image: ImageKind,
    /// Every `val_every`-th sample (index mod val_every = val_every − 1) is in the
    /// validation split of the YOLO trees; 0: no validation split.
    pub val_every: u64,
    /// A pixel belongs to an object's mask when the target-only render there is at least
    /// this, dB over the mean noise (`[dataset] mask_threshold_db`, default 0).
    pub mask_threshold_db: f64,
    /// Each artefact's boxes are labelled too, under its own category after the targets'
    /// (`[dataset] artefact_labels`, default false): [`ARTEFACT_CATEGORIES`].
    pub artefact_labels: bool,
    /// Each sample is run through the classical baseline, CFAR plots and ARPA tracks
    /// (`[dataset] baseline`, default true): [`crate::baseline`].
    pub baseline: bool,
    /// The scene every sample starts from.
    pub base_scene: toml::Table,
    /// Scene fields drawn per sample, by dotted path, in name order.
    pub vary: BTreeMap<String, Dist>,
    /// The targets.
    pub targets: Targets,
    /// Procedural land per sample (`[coast]`; none without it).
    pub coast: Option<crate::coast::CoastSpec>,
}

/// The artefacts labelled as their own categories with `[dataset] artefact_labels`, and
/// their category names: every artefact that is an echo where there is no target. (A blind
/// sector weakens echoes rather than making one: it stays in truth.json alone.)
pub const ARTEFACT_CATEGORIES: [(xbandsim::products::artefacts::ArtefactKind, &str); 7] = {
    use xbandsim::products::artefacts::ArtefactKind as K;
    [
        (K::Sidelobe, "artefact_sidelobe"),
        (K::SecondTrace, "artefact_second_trace"),
        (K::Interference, "artefact_interference"),
        (K::Racon, "artefact_racon"),
        (K::Sart, "artefact_sart"),
        (K::IndirectEcho, "artefact_indirect_echo"),
        (K::MultipleEcho, "artefact_multiple_echo"),
    ]
};

/// The category of land's segmentation, in specs whose samples can have land (`[coast]`,
/// or `[[scene.land]]` in the base scene).
pub const LAND_CATEGORY: &str = "land";

/// The spec's top-level tables.
pub const TOP_FIELDS: [&str; 5] = ["dataset", "scene", "vary", "targets", "coast"];
/// The fields of `[dataset]`.
pub const DATASET_FIELDS: [&str; 7] = [
    "frames",
    "datacube",
    "image",
    "val_every",
    "mask_threshold_db",
    "artefact_labels",
    "baseline",
];
/// The fields of `[targets]`.
pub const TARGETS_FIELDS: [&str; 5] = [
    "count",
    "range_fraction",
    "bearing_deg",
    "min_separation_m",
    "class",
];
/// The fields of a `[[targets.class]]`.
pub const CLASS_FIELDS: [&str; 9] = [
    "name",
    "weight",
    "heading_deg",
    "speed_kn",
    "turn_rate_deg_per_s",
    "z_m",
    "object",
    "library",
    "size_m",
];

/// The JSON Schema (draft 2020-12) of the dataset spec, as TOML reads into JSON
/// (`xbandsim dataset schema`; docs/formats.md, "Dataset spec").
pub const JSON_SCHEMA: &str = include_str!("dataset-spec.schema.json");

/// The PPI images of a dataset's frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageKind {
    /// `ppi_gray.png` only (8-bit grayscale; the labels' image).
    Gray,
    /// `ppi.png` only (colour map, range rings; the labels' image).
    Colour,
    /// Both; the labels refer to `ppi_gray.png`.
    Both,
}

impl ImageKind {
    /// The file the labels refer to.
    pub fn labelled_file(&self) -> &'static str {
        match self {
            ImageKind::Colour => "ppi.png",
            _ => "ppi_gray.png",
        }
    }

    /// Which images a frame's set holds.
    pub fn images(&self) -> xbandsim::products::frame_files::Images {
        xbandsim::products::frame_files::Images {
            colour: *self != ImageKind::Gray,
            gray: *self != ImageKind::Colour,
        }
    }
}

/// How targets are placed.
#[derive(Debug, Clone)]
pub struct Targets {
    /// How many (whole numbers ≥ 0).
    pub count: Dist,
    /// Range from the antenna as a fraction of the sample's `radar.max_range_m`.
    pub range_fraction: Dist,
    /// Nautical bearing from the antenna, degrees.
    pub bearing_deg: Dist,
    /// Nearest two targets may come, m (positions are redrawn up to 50 times to keep it).
    pub min_separation_m: f64,
    /// The classes, at least one when `count` can exceed 0.
    pub classes: Vec<TargetClass>,
}

/// One class of target.
#[derive(Debug, Clone)]
pub struct TargetClass {
    /// Category name (the object's `class` in the scene and the label's category).
    pub name: String,
    /// Relative frequency.
    pub weight: f64,
    /// Heading of the bow, nautical degrees (default uniform over the circle).
    pub heading_deg: Dist,
    /// Speed through the water along the heading, knots (default 0).
    pub speed_kn: Dist,
    /// Constant-rate turn, degrees per second (default 0; only for moving targets).
    pub turn_rate_deg_per_s: Dist,
    /// Height of the object's reference point above the sea, m (default 0).
    pub z_m: Dist,
    /// The scene-file `[[object]]` fields (shape and dimensions), each fixed or drawn; with a
    /// library class, fields that override the library's.
    pub object: BTreeMap<String, Dist>,
    /// A class of the target library (docs/targets.md) and its size law, m.
    pub library: Option<(xbandsim::targets::TargetClass, Dist)>,
}

/// The object fields a library class gives for `size_m` and its proportion draws, as a
/// scene-file table (its `position_m` z floats it).
pub fn library_object(
    class: xbandsim::targets::TargetClass,
    size_m: f64,
    draws: &[f64; xbandsim::targets::TargetClass::DRAWS],
    field: &str,
) -> Result<toml::Table> {
    let spec = class
        .object_spec(size_m, draws)
        .map_err(|e| DatasetError::spec(field, e.to_string()))?;
    match toml::Value::try_from(&spec) {
        Ok(toml::Value::Table(t)) => Ok(t),
        _ => Err(DatasetError::spec(
            field,
            "the library's object cannot be written as TOML".into(),
        )),
    }
}

fn table<'a>(t: &'a toml::Table, key: &str, field: &str) -> Result<Option<&'a toml::Table>> {
    match t.get(key) {
        None => Ok(None),
        Some(v) => v
            .as_table()
            .map(Some)
            .ok_or_else(|| DatasetError::spec(field, "must be a table".into())),
    }
}

fn refuse_unknown(t: &toml::Table, known: &[&str], prefix: &str) -> Result<()> {
    match t.keys().find(|k| !known.contains(&k.as_str())) {
        Some(k) => Err(DatasetError::spec(
            format!("{prefix}{k}"),
            format!("unknown field (known: {})", known.join(", ")),
        )),
        None => Ok(()),
    }
}

fn dist_or(t: &toml::Table, key: &str, prefix: &str, default: Dist) -> Result<Dist> {
    t.get(key)
        .map_or(Ok(default), |v| Dist::parse(&format!("{prefix}{key}"), v))
}

fn uniform(low: f64, high: f64) -> Dist {
    Dist::Uniform { low, high }
}

fn fixed(x: f64) -> Dist {
    Dist::Fixed(toml::Value::Float(x))
}

impl DatasetSpec {
    /// The label categories: the target classes' names in the spec's order, then the classes
    /// of the base scene's fixed objects ("object" when a fixed object names none), then with
    /// `artefact_labels` the [`ARTEFACT_CATEGORIES`]. YOLO class = position; COCO category
    /// id = position + 1.
    pub fn categories(&self) -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        let fixed = self
            .base_scene
            .get("object")
            .and_then(|v| v.as_array())
            .into_iter()
            .flatten()
            .map(|o| {
                o.get("class")
                    .and_then(|c| c.as_str())
                    .unwrap_or("object")
                    .to_string()
            });
        for name in self
            .targets
            .classes
            .iter()
            .map(|c| c.name.clone())
            .chain(fixed)
        {
            if !names.contains(&name) {
                names.push(name);
            }
        }
        if self.artefact_labels {
            for (_, name) in ARTEFACT_CATEGORIES {
                if !names.iter().any(|n| n == name) {
                    names.push(name.to_string());
                }
            }
        }
        if self.has_land() && !names.iter().any(|n| n == LAND_CATEGORY) {
            names.push(LAND_CATEGORY.to_string());
        }
        names
    }

    /// Whether samples can have land: a `[coast]` table or land in the base scene.
    pub fn has_land(&self) -> bool {
        self.coast.is_some() || self.base_scene.contains_key("land")
    }

    /// Whether sample `index` is in the validation split.
    pub fn is_validation(&self, index: u64) -> bool {
        self.val_every > 0 && index % self.val_every == self.val_every - 1
    }

    /// Reads a spec file (mesh files of its base scene are found relative to its folder).
    pub fn read(path: &Path) -> Result<DatasetSpec> {
        let text = std::fs::read_to_string(path).map_err(|e| DatasetError::io(path, e))?;
        let base = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        DatasetSpec::parse(&text, base)
    }

    /// Parses and checks spec text: the tables and their fields, every distribution, and that
    /// the extremes of every drawn field give valid scenes (so a bad size or setting is an
    /// error here, naming the spec's field, not a failure at sample 1234).
    pub fn parse(text: &str, base_dir: &Path) -> Result<DatasetSpec> {
        let doc: toml::Table = toml::from_str(text)
            .map_err(|e| DatasetError::spec("(file)", e.to_string().trim_end().to_string()))?;
        refuse_unknown(&doc, &TOP_FIELDS, "")?;
        let empty = toml::Table::new();
        let d = table(&doc, "dataset", "dataset")?.unwrap_or(&empty);
        refuse_unknown(
            d,
            &[
                "frames",
                "datacube",
                "image",
                "val_every",
                "mask_threshold_db",
                "artefact_labels",
                "baseline",
            ],
            "dataset.",
        )?;
        let image = match d.get("image") {
            None => ImageKind::Gray,
            Some(v) => match v.as_str() {
                Some("gray") | Some("grey") => ImageKind::Gray,
                Some("colour") | Some("color") => ImageKind::Colour,
                Some("both") => ImageKind::Both,
                _ => {
                    return Err(DatasetError::spec(
                        "dataset.image",
                        format!("{v}: must be \"gray\", \"colour\" or \"both\""),
                    ))
                }
            },
        };
        let val_every = match d.get("val_every") {
            None => 10,
            Some(v) => v.as_integer().filter(|n| *n >= 0).ok_or_else(|| {
                DatasetError::spec(
                    "dataset.val_every",
                    format!("{v}: must be a whole number, 0 (no validation split) or more"),
                )
            })? as u64,
        };
        let mask_threshold_db = match d.get("mask_threshold_db") {
            None => 0.0,
            Some(v) => as_f64(v).filter(|x| x.is_finite()).ok_or_else(|| {
                DatasetError::spec(
                    "dataset.mask_threshold_db",
                    format!("{v}: must be a number of dB over the noise"),
                )
            })?,
        };
        let artefact_labels = match d.get("artefact_labels") {
            None => false,
            Some(v) => v.as_bool().ok_or_else(|| {
                DatasetError::spec(
                    "dataset.artefact_labels",
                    format!("{v}: must be true or false"),
                )
            })?,
        };
        let baseline = match d.get("baseline") {
            None => true,
            Some(v) => v.as_bool().ok_or_else(|| {
                DatasetError::spec("dataset.baseline", format!("{v}: must be true or false"))
            })?,
        };
        let frames = match d.get("frames") {
            None => 1,
            Some(v) => v
                .as_integer()
                .filter(|n| (1..=MAX_FRAMES_PER_SAMPLE as i64).contains(n))
                .ok_or_else(|| {
                    DatasetError::spec(
                        "dataset.frames",
                        format!("{v}: must be a whole number from 1 to {MAX_FRAMES_PER_SAMPLE}"),
                    )
                })? as u64,
        };
        let datacube = match d.get("datacube") {
            None => false,
            Some(v) => v.as_bool().ok_or_else(|| {
                DatasetError::spec("dataset.datacube", format!("{v}: must be true or false"))
            })?,
        };
        let base_scene = table(&doc, "scene", "scene")?.cloned().unwrap_or_default();
        let mut vary = BTreeMap::new();
        if let Some(v) = table(&doc, "vary", "vary")? {
            for (k, value) in v {
                vary.insert(k.clone(), Dist::parse(&format!("vary.\"{k}\""), value)?);
            }
        }
        let t = table(&doc, "targets", "targets")?.unwrap_or(&empty);
        refuse_unknown(t, &TARGETS_FIELDS, "targets.")?;
        let count = dist_or(t, "count", "targets.", Dist::Fixed(toml::Value::Integer(0)))?;
        let range_fraction = dist_or(t, "range_fraction", "targets.", uniform(0.05, 0.95))?;
        let bearing_deg = dist_or(t, "bearing_deg", "targets.", uniform(0.0, 360.0))?;
        let min_separation_m = match t.get("min_separation_m") {
            None => 30.0,
            Some(v) => as_f64(v)
                .filter(|x| x.is_finite() && *x >= 0.0)
                .ok_or_else(|| {
                    DatasetError::spec(
                        "targets.min_separation_m",
                        format!("{v}: must be a number of metres, 0 or more"),
                    )
                })?,
        };
        let mut classes = Vec::new();
        if let Some(list) = t.get("class") {
            let list = list.as_array().ok_or_else(|| {
                DatasetError::spec("targets.class", "must be [[targets.class]] tables".into())
            })?;
            for (i, c) in list.iter().enumerate() {
                let prefix = format!("targets.class[{i}].");
                let c = c.as_table().ok_or_else(|| {
                    DatasetError::spec(format!("targets.class[{i}]"), "must be a table".into())
                })?;
                classes.push(parse_class(c, &prefix)?);
            }
        }
        let targets = Targets {
            count,
            range_fraction,
            bearing_deg,
            min_separation_m,
            classes,
        };
        let coast = table(&doc, "coast", "coast")?
            .map(crate::coast::CoastSpec::parse)
            .transpose()?;
        let spec = DatasetSpec {
            coast,
            text: text.to_string(),
            base_dir: base_dir.to_path_buf(),
            frames,
            datacube,
            image,
            val_every,
            mask_threshold_db,
            artefact_labels,
            baseline,
            base_scene,
            vary,
            targets,
        };
        spec.check_extremes()?;
        if spec.has_land() && spec.targets.classes.iter().any(|c| c.name == LAND_CATEGORY) {
            return Err(DatasetError::spec(
                "targets.class",
                format!("a target class is named \"{LAND_CATEGORY}\", the land's category: rename the class"),
            ));
        }
        if spec.artefact_labels {
            let mut plain = spec.clone();
            plain.artefact_labels = false;
            if let Some(name) = plain
                .categories()
                .into_iter()
                .find(|c| ARTEFACT_CATEGORIES.iter().any(|(_, a)| a == c))
            {
                return Err(DatasetError::spec(
                    "dataset.artefact_labels",
                    format!("a target class is named \"{name}\", an artefact category's name: rename the class"),
                ));
            }
        }
        Ok(spec)
    }
}

fn parse_class(c: &toml::Table, prefix: &str) -> Result<TargetClass> {
    refuse_unknown(c, &CLASS_FIELDS, prefix)?;
    let library = match c.get("library") {
        None => None,
        Some(v) => {
            let name = v.as_str().unwrap_or_default();
            let class = xbandsim::targets::TargetClass::from_name(name).ok_or_else(|| {
                let known: Vec<&str> = xbandsim::targets::TargetClass::all()
                    .iter()
                    .map(|c| c.name())
                    .collect();
                DatasetError::spec(
                    format!("{prefix}library"),
                    format!(
                        "{v}: not a class of the target library (it has {})",
                        known.join(", ")
                    ),
                )
            })?;
            let (lo, hi) = class.size_range_m();
            let size = dist_or(c, "size_m", prefix, uniform(lo, hi))?;
            Some((class, size))
        }
    };
    if library.is_none() && c.contains_key("size_m") {
        return Err(DatasetError::spec(
            format!("{prefix}size_m"),
            "only a library class has a size law (give the object's own size fields instead)"
                .into(),
        ));
    }
    let name = match (c.get("name"), &library) {
        (None, Some((class, _))) => class.name().to_string(),
        (name, _) => name
            .and_then(|v| v.as_str())
            .filter(|s| !s.trim().is_empty())
            .ok_or_else(|| {
                DatasetError::spec(
                    format!("{prefix}name"),
                    "a class needs a name (or a library class)".into(),
                )
            })?
            .to_string(),
    };
    let weight = match c.get("weight") {
        None => 1.0,
        Some(v) => as_f64(v)
            .filter(|w| w.is_finite() && *w > 0.0)
            .ok_or_else(|| {
                DatasetError::spec(format!("{prefix}weight"), format!("{v}: must be above 0"))
            })?,
    };
    let empty = toml::Table::new();
    let object_table = match c.get("object") {
        Some(v) => v.as_table().ok_or_else(|| {
            DatasetError::spec(format!("{prefix}object"), "must be a table".into())
        })?,
        None if library.is_some() => &empty,
        None => {
            return Err(DatasetError::spec(
                format!("{prefix}object"),
                "a class needs a library class or an object table: the scene-file [[object]] fields of its shape (shape, sizes), each fixed or drawn".into(),
            ))
        }
    };
    let placed = [
        "position_m",
        "name",
        "class",
        "speed_kn",
        "course_deg",
        "velocity_mps",
        "yaw_deg",
        "track",
        "turn_rate_deg_per_s",
    ];
    let mut object = BTreeMap::new();
    for (k, v) in object_table {
        if placed.contains(&k.as_str()) {
            return Err(DatasetError::spec(
                format!("{prefix}object.{k}"),
                "is set by the generator (placement, heading, speed and name come from the class and targets tables)".into(),
            ));
        }
        object.insert(k.clone(), Dist::parse(&format!("{prefix}object.{k}"), v)?);
    }
    if library.is_none() && !object.contains_key("shape") {
        return Err(DatasetError::spec(
            format!("{prefix}object.shape"),
            "a class's object needs a shape".into(),
        ));
    }
    let speed_default = match &library {
        Some((class, _)) if !class.is_moored() => {
            let (lo, hi) = class.speed_range_kn();
            uniform(lo, hi)
        }
        _ => fixed(0.0),
    };
    Ok(TargetClass {
        name,
        weight,
        heading_deg: dist_or(c, "heading_deg", prefix, uniform(0.0, 360.0))?,
        speed_kn: dist_or(c, "speed_kn", prefix, speed_default)?,
        turn_rate_deg_per_s: dist_or(c, "turn_rate_deg_per_s", prefix, fixed(0.0))?,
        z_m: dist_or(c, "z_m", prefix, fixed(0.0))?,
        object,
        library,
    })
}

/// A value from the middle of a distribution: a range's midpoint (a log-uniform law's
/// geometric mean, a normal's clipped mean), a choice's first value, the fixed value.
pub fn middle(d: &Dist) -> toml::Value {
    match d {
        Dist::Fixed(v) => v.clone(),
        Dist::Uniform { low, high } => toml::Value::Float(0.5 * (low + high)),
        Dist::LogUniform { low, high } => toml::Value::Float((low * high).sqrt()),
        Dist::Normal { mean, min, max, .. } => toml::Value::Float(mean.clamp(*min, *max)),
        Dist::UniformInt { low, high } => toml::Value::Integer(low + (high - low) / 2),
        Dist::Choice { values, .. } => values[0].clone(),
    }
}

/// The values at a distribution's edges: its bounds (a normal's clip or mean ± 4σ), every
/// choice, or the fixed value.
pub fn extremes(d: &Dist) -> Vec<toml::Value> {
    match d {
        Dist::Fixed(v) => vec![v.clone()],
        Dist::Uniform { low, high } | Dist::LogUniform { low, high } => {
            vec![toml::Value::Float(*low), toml::Value::Float(*high)]
        }
        Dist::Normal {
            mean,
            std,
            min,
            max,
        } => vec![
            toml::Value::Float((mean - 4.0 * std).max(*min)),
            toml::Value::Float((mean + 4.0 * std).min(*max)),
        ],
        Dist::UniformInt { low, high } => {
            vec![toml::Value::Integer(*low), toml::Value::Integer(*high)]
        }
        Dist::Choice { values, .. } => values.clone(),
    }
}

#[cfg(test)]
mod schema_tests {
    use super::*;

    fn keys(v: &serde_json::Value) -> Vec<String> {
        let mut k: Vec<String> = v["properties"]
            .as_object()
            .expect("properties")
            .keys()
            .cloned()
            .collect();
        k.sort();
        k
    }

    fn sorted(fields: &[&str]) -> Vec<String> {
        let mut k: Vec<String> = fields.iter().map(|s| s.to_string()).collect();
        k.sort();
        k
    }

    /// The schema names exactly the fields the parser reads (so they cannot drift apart),
    /// and its library classes are the catalogue's.
    #[test]
    fn schema_matches_the_parser() {
        let schema: serde_json::Value = serde_json::from_str(JSON_SCHEMA).unwrap();
        assert_eq!(keys(&schema), sorted(&TOP_FIELDS));
        let p = &schema["properties"];
        assert_eq!(keys(&p["dataset"]), sorted(&DATASET_FIELDS));
        assert_eq!(keys(&p["targets"]), sorted(&TARGETS_FIELDS));
        assert_eq!(keys(&p["coast"]), sorted(&crate::coast::COAST_FIELDS));
        let class = &p["targets"]["properties"]["class"]["items"];
        assert_eq!(keys(class), sorted(&CLASS_FIELDS));
        let library: Vec<&str> = class["properties"]["library"]["enum"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap())
            .collect();
        let catalogue: Vec<&str> = xbandsim::targets::TargetClass::all()
            .iter()
            .map(|c| c.name())
            .collect();
        assert_eq!(library, catalogue);
    }
}
