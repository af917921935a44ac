//! Drawing one sample: sample i's scene depends only on (spec, seed, i). Its generator is
//! seeded from `splitmix64(splitmix64(seed) ^ i·0x9E3779B97F4A7C15)` and draws, in this fixed
//! order: the render seed; every `[vary]` field in name order; with `[coast]`, the sample's
//! land ([`crate::coast::draw`]); the number of targets; then per target its class, heading,
//! speed, turn rate, `z_m`, a library class's size and its three proportion draws, its
//! object fields in name order, and its place. Without land the place is a range fraction
//! and a bearing (redrawn, at most 50 times, to keep `min_separation_m`; never nearer than
//! the object's extent plus 20 m). With land a place must also be on the water, its extent
//! plus 10 m from the coast, and a moving target's straight track over the next minute must
//! stay so; a target with no such place in 50 draws is left out. In a harbour, buoys mark
//! the channel (a point along it, one side or the other), stationary vessels lie at the quay
//! half the time (alongside, bow along it) and moving ones run in or out along the channel
//! half the time.

use crate::dist::{as_f64, unit_draw};
use crate::error::{DatasetError, Result};
use crate::spec::DatasetSpec;
use rand::{RngCore, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::Deserialize;
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

/// Whether a target at `p` moving at `speed_kn` on `course_deg` keeps its extent and 10 m
/// from the coast over the next minute (its position every 5 s).
fn track_clear(
    coast: &crate::coast::SampleCoast,
    p: (f64, f64),
    course_deg: f64,
    speed_kn: f64,
    extent_m: f64,
) -> bool {
    let v = speed_kn * xbandsim::model::motion::KNOT_M_PER_S;
    let (s, c) = course_deg.to_radians().sin_cos();
    (0..=12).all(|k| {
        let t = 5.0 * k as f64;
        coast.clear((p.0 + v * t * s, p.1 + v * t * c), extent_m)
    })
}

/// Clearance kept between the antenna and an object's extent, m.
pub const MIN_CLEARANCE_M: f64 = 20.0;

/// A generous extent of an object from its size fields, m: the largest of its lengths, radii,
/// heights, edges and mast heights and its box's diagonal.
pub(crate) fn extent_m(object: &toml::Table) -> f64 {
    let mut extent: f64 = 0.0;
    for key in [
        "radius_m",
        "height_m",
        "width_m",
        "edge_m",
        "length_m",
        "beam_m",
        "mast_height_m",
    ] {
        if let Some(x) = object.get(key).and_then(as_f64) {
            extent = extent.max(x.abs());
        }
    }
    if let Some(a) = object.get("size_m").and_then(|v| v.as_array()) {
        let d: f64 = a
            .iter()
            .filter_map(as_f64)
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt();
        extent = extent.max(d);
    }
    extent
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
        // Its recorded range (`max_range_m`, or its range scale's or preset's); a table the
        // loader will refuse places targets as the default radar would, and is refused later.
        let max_range_m = radar
            .and_then(|r| {
                let spec = xbandsim::scene::RadarSpec::deserialize(toml::Value::Table(r.clone()));
                spec.ok()
            })
            .and_then(|spec| xbandsim::model::radar::preset::recorded_range_m(&spec).ok())
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
        let coast = match &self.coast {
            Some(c) => crate::coast::draw(c, &mut rng, origin, max_range_m)?,
            None => None,
        };
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
            let mut u = unit_draw(&mut rng) * total_weight;
            let mut ci = t.classes.len() - 1;
            for (i, w) in class_weights.iter().enumerate() {
                if u < *w {
                    ci = i;
                    break;
                }
                u -= w;
            }
            let class = &t.classes[ci];
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
            let mut height = class.z_m.sample_f64(&format!("{prefix}z_m"), &mut rng)?;
            let mut object = match &class.library {
                // The library's object at a drawn size and proportions, floated at its z
                // (plus z_m).
                Some((library, size)) => {
                    let field = format!("{prefix}size_m");
                    let size_m = size.sample_f64(&field, &mut rng)?;
                    let mut draws = [0.0; xbandsim::targets::TargetClass::DRAWS];
                    for d in &mut draws {
                        *d = unit_draw(&mut rng);
                    }
                    let mut o = crate::spec::library_object(*library, size_m, &draws, &field)?;
                    if let Some(z) = o
                        .remove("position_m")
                        .and_then(|p| p.as_array().and_then(|a| a.get(2).and_then(as_f64)))
                    {
                        height += z;
                    }
                    o
                }
                None => toml::Table::new(),
            };
            object.insert("name".into(), format!("{}-{k}", class.name).into());
            object.insert("class".into(), class.name.clone().into());
            for (field, d) in &class.object {
                object.insert(field.clone(), d.sample(&mut rng));
            }
            // No closer to the antenna than the object's extent and a margin (the loader
            // refuses an antenna inside an object).
            let extent = extent_m(&object);
            let min_range_m = extent + MIN_CLEARANCE_M;
            let buoy = matches!(
                class.library,
                Some((
                    xbandsim::targets::TargetClass::NavigationBuoy
                        | xbandsim::targets::TargetClass::ChannelMarker,
                    _
                ))
            );
            let mut heading = heading;
            let mut position = (0.0, 0.0);
            let mut placed_ok = coast.is_none();
            // A harbour's own places: the channel's buoys, the quay's moored vessels, the
            // channel's traffic.
            if let Some(c) = &coast {
                let role = unit_draw(&mut rng);
                let along = unit_draw(&mut rng);
                let side = if unit_draw(&mut rng) < 0.5 { -1.0 } else { 1.0 };
                match (c.channel, c.quay) {
                    (Some(ch), _) if buoy => {
                        let (a, b, half) = (ch.start, ch.end, ch.half_width_m);
                        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
                        let len = dx.hypot(dy).max(1.0);
                        position = (
                            a.0 + dx * along - dy / len * half * side,
                            a.1 + dy * along + dx / len * half * side,
                        );
                        placed_ok = c.clear(position, extent.min(5.0));
                    }
                    (_, Some(quay)) if speed <= 0.0 && role < 0.5 => {
                        let (a, b, water) = (quay.from, quay.to, quay.water);
                        let beam = object
                            .get("beam_m")
                            .and_then(as_f64)
                            .unwrap_or(0.25 * extent);
                        let off = 0.5 * beam + 3.0;
                        position = (
                            a.0 + (b.0 - a.0) * along + water.0 * off,
                            a.1 + (b.1 - a.1) * along + water.1 * off,
                        );
                        heading = (b.0 - a.0).atan2(b.1 - a.1).to_degrees()
                            + if side < 0.0 { 180.0 } else { 0.0 };
                        placed_ok = !c.on_land(position)
                            && placed.iter().all(|p| {
                                (p.0 - position.0).hypot(p.1 - position.1) >= t.min_separation_m
                            });
                    }
                    (Some(ch), _) if speed > 0.0 && role < 0.5 => {
                        let (a, b) = (ch.start, ch.end);
                        position = (a.0 + (b.0 - a.0) * along, a.1 + (b.1 - a.1) * along);
                        // In (toward the entrance) or out.
                        let out = (b.0 - a.0).atan2(b.1 - a.1).to_degrees();
                        heading = if side < 0.0 { out + 180.0 } else { out };
                        placed_ok = track_clear(c, position, heading, speed, extent);
                    }
                    _ => {}
                }
            }
            for _attempt in 0..50 {
                if placed_ok && coast.is_some() {
                    break;
                }
                let r = (t
                    .range_fraction
                    .sample_f64("targets.range_fraction", &mut rng)?
                    * max_range_m)
                    .max(min_range_m);
                let b = t
                    .bearing_deg
                    .sample_f64("targets.bearing_deg", &mut rng)?
                    .to_radians();
                position = (origin.0 + r * b.sin(), origin.1 + r * b.cos());
                let clear = placed
                    .iter()
                    .all(|p| (p.0 - position.0).hypot(p.1 - position.1) >= t.min_separation_m);
                let on_water = coast.as_ref().is_none_or(|c| {
                    c.clear(position, extent)
                        && (speed <= 0.0 || track_clear(c, position, heading, speed, extent))
                });
                placed_ok = on_water;
                if clear && on_water {
                    break;
                }
            }
            if !placed_ok {
                // No place on the water in 50 draws: this sample has one target fewer.
                continue;
            }
            placed.push(position);
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
        if let Some(c) = coast {
            if !c.structures.is_empty() {
                let tables = c.structures.into_iter().map(toml::Value::Table);
                match doc.get_mut("structure").and_then(|v| v.as_array_mut()) {
                    Some(fixed) => fixed.extend(tables),
                    None => {
                        doc.insert("structure".into(), toml::Value::Array(tables.collect()));
                    }
                }
            }
            let tables = c.tables.into_iter().map(toml::Value::Table);
            match doc.get_mut("land").and_then(|v| v.as_array_mut()) {
                Some(fixed) => fixed.extend(tables),
                None => {
                    doc.insert("land".into(), toml::Value::Array(tables.collect()));
                }
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// datasets/coastal.toml over 200 samples: about 80 % have land (130–190 of 200: the
    /// binomial's ±4σ); every sample's scene builds (the loader refuses an object on land and
    /// an antenna on it); every target's reference point is on the water, more than 1 m from
    /// the coast (moored vessels lie 3 m plus half their beam off the quay); the same
    /// (seed, index) gives the same scene.
    #[test]
    fn coastal_samples_keep_their_targets_on_the_water() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets");
        let spec = DatasetSpec::read(&root.join("coastal.toml")).unwrap();
        assert!(spec.coast.is_some());
        let mut with_land = 0;
        let (mut buildings, mut hills) = (0, 0);
        for i in 0..200u64 {
            let sample = spec.sample(5, i).unwrap();
            assert_eq!(sample, spec.sample(5, i).unwrap());
            let scene = xbandsim::model::Scene::from_toml_str(&sample.scene_toml, "sample")
                .unwrap_or_else(|e| panic!("sample {i}: {e}"));
            let land = scene.environment().land();
            if land.is_empty() {
                continue;
            }
            with_land += 1;
            hills += land
                .polygons()
                .iter()
                .filter(|p| p.name.starts_with("hill-") && p.name.ends_with("-0"))
                .count();
            for o in scene.objects() {
                let p = o.position_m().truncate();
                if o.class() == "building" {
                    // A harbour's buildings stand on the land behind the quay.
                    assert!(
                        land.polygon_at(p).is_some(),
                        "sample {i}: {} at sea",
                        o.name()
                    );
                    buildings += 1;
                    continue;
                }
                let d = land.distance_to_coast_m(p).unwrap();
                assert!(
                    land.polygon_at(p).is_none(),
                    "sample {i}: {} on land",
                    o.name()
                );
                assert!(d > 1.0, "sample {i}: {} {d} m from the coast", o.name());
            }
        }
        assert!(
            (130..=190).contains(&with_land),
            "{with_land} of 200 samples with land"
        );
        assert!(buildings > 20, "{buildings} buildings in 200 samples");
        assert!(hills > 20, "{hills} hills in 200 samples");
    }
}
