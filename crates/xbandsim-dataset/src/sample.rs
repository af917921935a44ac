//! Drawing one sample: sample i's scene depends only on (spec, seed, i). Its generator is
//! seeded from `splitmix64(splitmix64(seed) ^ i·0x9E3779B97F4A7C15)` and draws, in this fixed
//! order: the render seed; every `[vary]` field in name order; the number of targets; then
//! per target its class, range fraction, bearing, heading, speed, turn rate, `z_m` and its
//! object fields in name order (positions redrawn, at most 50 times, to keep
//! `min_separation_m`).

use crate::error::{DatasetError, Result};
use crate::spec::DatasetSpec;
use rand::{RngCore, SeedableRng};
use rand_pcg::Pcg64Mcg;
use xbandsim::rng::splitmix64;

/// One sample's scene, ready to render.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleScene {
    /// Sample number.
    pub index: u64,
    /// Seed of its render (noise, speckle, clutter).
    pub render_seed: u64,
    /// The scene file that renders it (`xbandsim render scene.toml --seed render_seed`).
    pub scene_toml: String,
}

/// The generator of sample `index` of a dataset made with `seed`.
pub fn sample_rng(seed: u64, index: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(splitmix64(
        splitmix64(seed) ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15),
    ))
}

fn as_f64(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

impl DatasetSpec {
    /// Draws sample `index` of the dataset made with `seed`.
    pub fn sample(&self, seed: u64, index: u64) -> Result<SampleScene> {
        let mut rng = sample_rng(seed, index);
        let render_seed = rng.next_u64();
        let mut doc = self.base_scene.clone();
        for (field, d) in &self.vary {
            xbandsim::scene::assign_field(&mut doc, field, d.sample(&mut rng))
                .map_err(|e| DatasetError::spec(format!("vary.\"{field}\""), e))?;
        }
        // The sample's radar: where targets are placed from.
        let radar = doc.get("radar").and_then(|r| r.as_table());
        let max_range_m = radar
            .and_then(|r| r.get("max_range_m"))
            .and_then(as_f64)
            .unwrap_or(1500.0);
        let origin = radar
            .and_then(|r| r.get("position_m"))
            .and_then(|p| p.as_array())
            .map_or((0.0, 0.0), |p| {
                (
                    p.first().and_then(as_f64).unwrap_or(0.0),
                    p.get(1).and_then(as_f64).unwrap_or(0.0),
                )
            });
        let t = &self.targets;
        let count =
            t.count.sample(&mut rng).as_integer().ok_or_else(|| {
                DatasetError::spec("targets.count", "must draw whole numbers".into())
            })?;
        let class_weights: Vec<f64> = t.classes.iter().map(|c| c.weight).collect();
        let total_weight: f64 = class_weights.iter().sum();
        let mut placed: Vec<(f64, f64)> = Vec::new();
        let mut objects = Vec::new();
        for k in 0..count.max(0) as usize {
            let mut u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * total_weight;
            let mut ci = t.classes.len() - 1;
            for (i, w) in class_weights.iter().enumerate() {
                if u < *w {
                    ci = i;
                    break;
                }
                u -= w;
            }
            let class = &t.classes[ci];
            let mut position = (0.0, 0.0);
            for _attempt in 0..50 {
                let r = t
                    .range_fraction
                    .sample_f64("targets.range_fraction", &mut rng)?
                    * max_range_m;
                let b = t
                    .bearing_deg
                    .sample_f64("targets.bearing_deg", &mut rng)?
                    .to_radians();
                position = (origin.0 + r * b.sin(), origin.1 + r * b.cos());
                let clear = placed
                    .iter()
                    .all(|p| (p.0 - position.0).hypot(p.1 - position.1) >= t.min_separation_m);
                if clear {
                    break;
                }
            }
            placed.push(position);
            let prefix = format!("targets.class[{ci}].");
            let heading = class
                .heading_deg
                .sample_f64(&format!("{prefix}heading_deg"), &mut rng)?;
            let speed = class
                .speed_kn
                .sample_f64(&format!("{prefix}speed_kn"), &mut rng)?;
            let turn = class
                .turn_rate_deg_per_s
                .sample_f64(&format!("{prefix}turn_rate_deg_per_s"), &mut rng)?;
            let height = class.z_m.sample_f64(&format!("{prefix}z_m"), &mut rng)?;
            let mut object = toml::Table::new();
            object.insert("name".into(), format!("{}-{k}", class.name).into());
            object.insert("class".into(), class.name.clone().into());
            for (field, d) in &class.object {
                object.insert(field.clone(), d.sample(&mut rng));
            }
            object.insert(
                "position_m".into(),
                toml::Value::Array(vec![position.0.into(), position.1.into(), height.into()]),
            );
            let heading = heading.rem_euclid(360.0);
            if speed > 0.0 {
                object.insert("speed_kn".into(), speed.into());
                object.insert("course_deg".into(), heading.into());
                if turn != 0.0 {
                    object.insert("turn_rate_deg_per_s".into(), turn.into());
                }
            } else {
                object.insert("yaw_deg".into(), heading.into());
            }
            objects.push(toml::Value::Table(object));
        }
        if !objects.is_empty() {
            match doc.get_mut("object").and_then(|v| v.as_array_mut()) {
                // Fixed objects of the base scene first, then the drawn ones.
                Some(fixed) => fixed.extend(objects),
                None => {
                    doc.insert("object".into(), toml::Value::Array(objects));
                }
            }
        }
        // Mesh files are named relative to the spec: the sample's scene names them by their
        // absolute path, so that it renders from its own folder.
        if let Some(list) = doc.get_mut("object").and_then(|v| v.as_array_mut()) {
            for o in list.iter_mut().filter_map(|o| o.as_table_mut()) {
                if let Some(toml::Value::String(file)) = o.get_mut("mesh_file") {
                    let path = std::path::Path::new(file.as_str());
                    if path.is_relative() {
                        let joined = self.base_dir.join(path);
                        let absolute = std::fs::canonicalize(&joined).unwrap_or(joined);
                        *file = absolute.display().to_string();
                    }
                }
            }
        }
        let scene_toml = toml::to_string(&doc).map_err(|e| {
            DatasetError::spec(
                "scene",
                format!("sample {index} cannot be written as TOML: {e}"),
            )
        })?;
        Ok(SampleScene {
            index,
            render_seed,
            scene_toml,
        })
    }
}
