//! Checking a dataset spec's scenes before any sample is made (docs/formats.md, "Dataset
//! spec"): when the spec is read, the base scene, then the extremes of every drawn field
//! (one at a time, the others at their middle values) and every target class's object;
//! before a run renders, every scene it will draw ([`check_samples`]). A refused scene is an
//! error naming the spec's field — the one the scene loader names, traced back to the
//! `[scene]` table, the `[vary]` entry or the target class it came from — not a failure at
//! sample 1234.

use crate::dist::as_f64;
use crate::error::{DatasetError, Result};
use crate::spec::{extremes, library_object, middle, DatasetSpec};
use rayon::prelude::*;
use xbandsim::model::ProcessingMode;

/// Why a scene was refused: the scene field at fault (as the loader names it, or a
/// `dataset.` field) and the loader's message.
struct Refusal {
    field: Option<String>,
    message: String,
}

impl DatasetSpec {
    /// Builds scene `doc` as a sample's would be, with this spec's outputs: refused by the
    /// loader, or asking for a range-Doppler cube (`dataset.datacube`) or Doppler colours
    /// (`display.doppler_colour`) in spoke mode, which only pulse mode makes.
    fn build_scene(&self, doc: &toml::Table) -> std::result::Result<(), Refusal> {
        let text = toml::to_string(doc).map_err(|e| Refusal {
            field: None,
            message: e.to_string(),
        })?;
        let loaded = xbandsim::LoadedSpec::from_toml(&text, "sample", &self.base_dir);
        // The drawn scene's lines and columns mean nothing to the spec's author: the field
        // is named instead (mapped to the spec's by the caller).
        let refused = |e: xbandsim::Error| Refusal {
            field: e.field().map(str::to_string),
            message: e.unlocated().to_string(),
        };
        let loaded = loaded.map_err(refused)?;
        let scene = loaded.build().map_err(refused)?;
        let display = loaded.ppi_settings().map_err(refused)?;
        let spoke_mode = scene.processing().mode() != ProcessingMode::Pulse;
        if spoke_mode && self.datacube {
            return Err(Refusal {
                field: Some("dataset.datacube".into()),
                message: "a range-Doppler cube needs processing.mode = \"pulse\" (set it in [scene.processing]); this scene fires one pulse per spoke".into(),
            });
        }
        if spoke_mode && display.doppler_colour {
            return Err(Refusal {
                field: Some("display.doppler_colour".into()),
                message: "Doppler colours need processing.mode = \"pulse\" (set it in [scene.processing]); this scene fires one pulse per spoke".into(),
            });
        }
        Ok(())
    }

    /// The spec field behind `scene_field`, a field of a sample's scene as the loader names
    /// it: a `dataset.` field as it is; a drawn field's `[vary]` entry; a generated target's
    /// field in its class (`object "rib-3".beam_m` → `targets.class[2].object.beam_m`, or the
    /// library class's `size_m` for a field the library sets); else the `[scene]` table's.
    pub fn spec_field(&self, scene_field: &str) -> String {
        if scene_field.starts_with("dataset.") {
            return scene_field.to_string();
        }
        if let Some(k) = self
            .vary
            .keys()
            .find(|k| *k == scene_field || k.starts_with(&format!("{scene_field}[")))
        {
            return format!("vary.\"{k}\"");
        }
        if let Some(rest) = scene_field.strip_prefix("object \"") {
            if let Some((name, field)) = rest.split_once("\".") {
                if let Some((i, c)) = self.targets.classes.iter().enumerate().find(|(_, c)| {
                    name.strip_prefix(&format!("{}-", c.name))
                        .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
                }) {
                    let top = field.split(['.', '[']).next().unwrap_or(field);
                    // Fields a sample fills from the class's own laws, not its object's.
                    let own = match top {
                        "speed_kn" => Some("speed_kn"),
                        "course_deg" | "yaw_deg" => Some("heading_deg"),
                        "turn_rate_deg_per_s" => Some("turn_rate_deg_per_s"),
                        "position_m" => Some("z_m"),
                        _ => None,
                    };
                    return match own {
                        Some(f) if !c.object.contains_key(top) => {
                            format!("targets.class[{i}].{f}")
                        }
                        _ if c.library.is_some() && !c.object.contains_key(top) => {
                            format!("targets.class[{i}].size_m")
                        }
                        _ => format!("targets.class[{i}].object.{field}"),
                    };
                }
            }
        }
        format!("scene.{scene_field}")
    }

    /// The spec error for `refusal` of a scene: at the spec field behind the scene field it
    /// names (`default` where it names none), with `what` and the loader's message.
    fn refused(&self, refusal: Refusal, default: &str, what: &str) -> DatasetError {
        let field = refusal
            .field
            .as_deref()
            .map_or_else(|| default.to_string(), |f| self.spec_field(f));
        DatasetError::spec(field, format!("{what}: {}", refusal.message))
    }

    /// Fixed objects of the base scene must not take a generated target's name
    /// (`<class>-<k>`): two objects of one name are refused in the samples that draw it.
    fn check_fixed_names(&self) -> Result<()> {
        let Some(fixed) = self.base_scene.get("object").and_then(|o| o.as_array()) else {
            return Ok(());
        };
        for (j, o) in fixed.iter().enumerate() {
            let Some(name) = o.get("name").and_then(|n| n.as_str()) else {
                continue;
            };
            for c in &self.targets.classes {
                let generated = name
                    .strip_prefix(&format!("{}-", c.name))
                    .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()));
                if generated {
                    return Err(DatasetError::spec(
                        format!("scene.object[{j}].name"),
                        format!(
                            "\"{name}\" is the name of a generated target of class \"{}\" (they are named {}-0, {}-1, …): rename the fixed object",
                            c.name, c.name, c.name
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Builds the base scene, then the scenes at the extremes of every drawn field (one
    /// field at a time, the others at their middle values), and every target class's object
    /// at its middle values and then at each field's extremes, naming the spec's field when
    /// one is refused.
    pub(crate) fn check_extremes(&self) -> Result<()> {
        let counts = extremes(&self.targets.count);
        for c in &counts {
            let n = c.as_integer().ok_or_else(|| {
                DatasetError::spec("targets.count", format!("{c}: must be a whole number"))
            })?;
            if !(0..=crate::spec::MAX_TARGETS).contains(&n) {
                return Err(DatasetError::spec(
                    "targets.count",
                    format!("{n}: must be from 0 to {}", crate::spec::MAX_TARGETS),
                ));
            }
            if n > 0 && self.targets.classes.is_empty() {
                return Err(DatasetError::spec(
                    "targets.class",
                    "targets.count can be above 0 but no [[targets.class]] is given".into(),
                ));
            }
        }
        for f in extremes(&self.targets.range_fraction) {
            let x = as_f64(&f);
            if !x.is_some_and(|x| x > 0.0 && x <= 1.0) {
                return Err(DatasetError::spec(
                    "targets.range_fraction",
                    format!("{f}: must lie in (0, 1], a fraction of radar.max_range_m"),
                ));
            }
        }
        self.check_fixed_names()?;
        let scene_with = |field: Option<(&str, &toml::Value)>| -> toml::Table {
            let mut doc = self.base_scene.clone();
            for (k, d) in &self.vary {
                let v = match field {
                    Some((f, v)) if f == k => v.clone(),
                    _ => middle(d),
                };
                let _ = xbandsim::scene::assign_field(&mut doc, k, v);
            }
            doc
        };
        // The base scene with every drawn field at its middle value first: a fault of the
        // base scene is blamed on its own field, not on the first drawn field tried.
        self.build_scene(&scene_with(None)).map_err(|r| {
            self.refused(
                r,
                "scene",
                "the base scene (drawn fields at their middle values) is refused",
            )
        })?;
        for (k, d) in &self.vary {
            for v in extremes(d) {
                let mut doc = self.base_scene.clone();
                xbandsim::scene::assign_field(&mut doc, k, v.clone())
                    .map_err(|e| DatasetError::spec(format!("vary.\"{k}\""), e))?;
                self.build_scene(&scene_with(Some((k, &v)))).map_err(|r| {
                    let field = r.field.clone();
                    match field.as_deref() {
                        Some(f) if f.starts_with("dataset.") => self.refused(r, "", "refused"),
                        _ => DatasetError::spec(
                            format!("vary.\"{k}\""),
                            format!("{v} gives a scene that is refused: {}", r.message),
                        ),
                    }
                })?;
            }
        }
        for (i, c) in self.targets.classes.iter().enumerate() {
            self.check_class(i, c, &scene_with(None))?;
        }
        Ok(())
    }

    /// Checks target class `i`: its numbers at their extremes, its library size law, then its
    /// object in the base scene `base` at its middle values and at each field's extremes.
    fn check_class(
        &self,
        i: usize,
        c: &crate::spec::TargetClass,
        base: &toml::Table,
    ) -> Result<()> {
        let number = |key: &str, d: &crate::dist::Dist, ok: &dyn Fn(f64) -> bool, why: &str| {
            for v in extremes(d) {
                let x = as_f64(&v);
                if !x.is_some_and(|x| x.is_finite() && ok(x)) {
                    return Err(DatasetError::spec(
                        format!("targets.class[{i}].{key}"),
                        format!("{v}: {why}"),
                    ));
                }
            }
            Ok(())
        };
        let max_kn = xbandsim::model::motion::MAX_SPEED_KN;
        number(
            "speed_kn",
            &c.speed_kn,
            &|x| (0.0..=max_kn).contains(&x),
            &format!("a speed must be 0 … {max_kn} knots (above the water speed record)"),
        )?;
        number(
            "heading_deg",
            &c.heading_deg,
            &|_| true,
            "must be a number of degrees",
        )?;
        number(
            "turn_rate_deg_per_s",
            &c.turn_rate_deg_per_s,
            &|_| true,
            "must be a number of degrees per second",
        )?;
        number("z_m", &c.z_m, &|_| true, "must be a number of metres")?;
        let size_field = format!("targets.class[{i}].size_m");
        if let Some((class, size)) = &c.library {
            for v in extremes(size) {
                let x = as_f64(&v).ok_or_else(|| {
                    DatasetError::spec(&size_field, format!("{v} is not a number of metres"))
                })?;
                library_object(*class, x, &[0.5; 3], &size_field)?;
            }
        }
        // The class's object with `field` at `value` and its other fields at their middle.
        let object_with = |field: Option<(&str, &toml::Value)>| -> Result<toml::Table> {
            let mut object = match &c.library {
                Some((class, size)) => {
                    let x = middle(size).as_float().unwrap_or(1.0);
                    library_object(*class, x, &[0.5; 3], &size_field)?
                }
                None => toml::Table::new(),
            };
            for (k, d) in &c.object {
                let v = match field {
                    Some((f, v)) if f == k => v.clone(),
                    _ => middle(d),
                };
                object.insert(k.clone(), v);
            }
            object.insert("name".into(), format!("{}-0", c.name).into());
            object.insert("class".into(), c.name.clone().into());
            // As a sample places it: no nearer the antenna than its extent and a margin.
            let range_m =
                (crate::sample::extent_m(&object) + crate::sample::MIN_CLEARANCE_M).max(100.0);
            object.insert(
                "position_m".into(),
                toml::Value::try_from([0.0, range_m, 0.0]).unwrap_or(toml::Value::Float(0.0)),
            );
            let mut doc = base.clone();
            doc.insert(
                "object".into(),
                toml::Value::Array(vec![toml::Value::Table(object)]),
            );
            Ok(doc)
        };
        self.build_scene(&object_with(None)?).map_err(|r| {
            self.refused(
                r,
                &format!("targets.class[{i}]"),
                "the class's object (drawn fields at their middle values) is refused",
            )
        })?;
        for (k, d) in &c.object {
            for v in extremes(d) {
                self.build_scene(&object_with(Some((k, &v)))?)
                    .map_err(|r| {
                        DatasetError::spec(
                            format!("targets.class[{i}].object.{k}"),
                            format!("{v} gives an object that is refused: {}", r.message),
                        )
                    })?;
            }
        }
        Ok(())
    }

    /// Draws sample `index`'s scene and builds it as the run will (see [`check_samples`]).
    pub fn check_sample(&self, seed: u64, index: u64) -> Result<()> {
        let sample = self.sample(seed, index)?;
        let doc: toml::Table = toml::from_str(&sample.scene_toml)
            .map_err(|e| DatasetError::spec("scene", format!("sample {index}: {e}")))?;
        self.build_scene(&doc).map_err(|r| {
            self.refused(
                r,
                "scene",
                &format!("sample {index} draws a scene that is refused"),
            )
        })
    }
}

/// Checks the scene of every sample in `indices` before any is rendered (about half a
/// millisecond a sample of the shipped specs on one core, in parallel on the current thread
/// pool, in blocks between which `stop` is honoured; more where every scene loads mesh
/// files): the first refused one, by index, is the error, naming the spec's field, so a run
/// does not stop part-way on a combination of drawn values that the spec's own check (one
/// field at a time) could not see.
pub fn check_samples(
    spec: &DatasetSpec,
    seed: u64,
    indices: &[u64],
    stop: &std::sync::atomic::AtomicBool,
) -> Result<()> {
    for block in indices.chunks(4096) {
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(DatasetError::Interrupted { made: 0 });
        }
        if let Some(e) = block
            .par_iter()
            .find_map_first(|&i| spec.check_sample(seed, i).err())
        {
            return Err(e);
        }
    }
    Ok(())
}
