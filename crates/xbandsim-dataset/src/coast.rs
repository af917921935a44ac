//! Procedural coasts for datasets (docs/formats.md, "Dataset spec", `[coast]`): a sample
//! drawn with a coast gets land as `[[land]]` tables of `polygon_m` rings, in one of three
//! layouts, and its targets are placed on the water clear of it.
//!
//! - `coast`: a fractal coastline across the scene (bays and headlands), the land beyond it
//!   out past the recorded range. The line is midpoint displacement over 129 points, the
//!   displacement at level L `roughness·d·2^{−0.7·L}` (a fractal of dimension about 1.3, as
//!   measured coastlines are: Mandelbrot, "How long is the coast of Britain?", Science 156,
//!   1967), and never nearer the antenna than 40 % of its distance d.
//! - `islands`: 1–6 islands, each a star-shaped ring whose radius is a sum of six harmonics
//!   with random phases and amplitudes falling as 1/k (so it is simple, and rough).
//! - `harbour`: a coast whose middle is a straight quay, two breakwaters from it with an
//!   entrance between their heads, and a channel from the entrance toward the antenna:
//!   buoy-like targets mark the channel, stationary ships and boats lie at the quay, and
//!   moving ones run along the channel.
//!
//! Every ring is simple by construction (a graph over the coast's axis closed beyond the
//! range; a star-shaped ring; rectangles), so the loader's checks pass; polygons may overlap
//! (a breakwater's root in the coast), which land allows.

use crate::dist::{unit_draw, Dist};
use crate::error::{DatasetError, Result};
use rand_pcg::Pcg64Mcg;

/// Fields of `[coast]`.
pub const COAST_FIELDS: [&str; 11] = [
    "probability",
    "layout",
    "distance_fraction",
    "bearing_deg",
    "height_m",
    "terrain",
    "roughness",
    "islands",
    "entrance_m",
    "hills",
    "buildings",
];

/// The `[coast]` table: how often a sample has land, and the laws of its layout.
#[derive(Debug, Clone)]
pub struct CoastSpec {
    /// Share of samples with land, 0…1.
    pub probability: f64,
    /// "coast", "islands" or "harbour".
    pub layout: Dist,
    /// The coast's (or the islands') distance from the antenna, a fraction of the recorded
    /// range.
    pub distance_fraction: Dist,
    /// Bearing from the antenna to the coast, degrees.
    pub bearing_deg: Dist,
    /// Height of the land, m.
    pub height_m: Dist,
    /// Terrain name.
    pub terrain: Dist,
    /// Fractal amplitude, a fraction of the distance (0…1).
    pub roughness: Dist,
    /// How many islands (islands layout).
    pub islands: Dist,
    /// Width of a harbour's entrance, m.
    pub entrance_m: Dist,
    /// How many hills rise inland of a coast or harbour shore.
    pub hills: Dist,
    /// How many buildings stand behind a harbour's quay (`[[structure]]` tables).
    pub buildings: Dist,
}

impl CoastSpec {
    /// Parses `[coast]`.
    pub fn parse(t: &toml::Table) -> Result<CoastSpec> {
        if let Some(k) = t.keys().find(|k| !COAST_FIELDS.contains(&k.as_str())) {
            return Err(DatasetError::spec(
                format!("coast.{k}"),
                format!("unknown field (known: {})", COAST_FIELDS.join(", ")),
            ));
        }
        let dist = |key: &str, default: Dist| {
            t.get(key)
                .map_or(Ok(default), |v| Dist::parse(&format!("coast.{key}"), v))
        };
        let probability = match t.get("probability") {
            None => 1.0,
            Some(v) => crate::dist::as_f64(v)
                .filter(|p| (0.0..=1.0).contains(p))
                .ok_or_else(|| {
                    DatasetError::spec("coast.probability", format!("{v}: must be within 0..1"))
                })?,
        };
        let words = |xs: &[&str]| Dist::Choice {
            values: xs
                .iter()
                .map(|x| toml::Value::String(x.to_string()))
                .collect(),
            weights: vec![1.0; xs.len()],
        };
        let spec = CoastSpec {
            probability,
            layout: dist("layout", words(&["coast", "islands", "harbour"]))?,
            distance_fraction: dist(
                "distance_fraction",
                Dist::Uniform {
                    low: 0.35,
                    high: 0.8,
                },
            )?,
            bearing_deg: dist(
                "bearing_deg",
                Dist::Uniform {
                    low: 0.0,
                    high: 360.0,
                },
            )?,
            height_m: dist(
                "height_m",
                Dist::Uniform {
                    low: 5.0,
                    high: 40.0,
                },
            )?,
            terrain: dist(
                "terrain",
                words(&["rock", "sand", "grass", "forest", "urban"]),
            )?,
            roughness: dist(
                "roughness",
                Dist::Uniform {
                    low: 0.15,
                    high: 0.5,
                },
            )?,
            islands: dist("islands", Dist::UniformInt { low: 1, high: 6 })?,
            entrance_m: dist(
                "entrance_m",
                Dist::Uniform {
                    low: 60.0,
                    high: 160.0,
                },
            )?,
            hills: dist("hills", Dist::Fixed(toml::Value::Integer(0)))?,
            buildings: dist("buildings", Dist::Fixed(toml::Value::Integer(0)))?,
        };
        // Every value each law can draw is checked here, not at sample 1234.
        for (field, d) in [("layout", &spec.layout), ("terrain", &spec.terrain)] {
            for v in law_values(d) {
                let ok = match field {
                    "layout" => ["coast", "islands", "harbour"].contains(&v.as_str().unwrap_or("")),
                    _ => xbandsim::land::Terrain::ALL
                        .iter()
                        .any(|t| Some(t.as_str()) == v.as_str()),
                };
                if !ok {
                    return Err(DatasetError::spec(
                        format!("coast.{field}"),
                        format!("{v} is not a {field} this generator knows"),
                    ));
                }
            }
        }
        for (field, d, lo, hi) in [
            ("distance_fraction", &spec.distance_fraction, 0.1, 2.0),
            ("height_m", &spec.height_m, 0.0, 9000.0),
            ("roughness", &spec.roughness, 0.0, 1.0),
            ("islands", &spec.islands, 1.0, 20.0),
            ("entrance_m", &spec.entrance_m, 20.0, 1000.0),
            ("hills", &spec.hills, 0.0, 10.0),
            ("buildings", &spec.buildings, 0.0, 40.0),
        ] {
            for v in law_values(d) {
                let x = crate::dist::as_f64(&v).unwrap_or(f64::NAN);
                if !(lo..=hi).contains(&x) {
                    return Err(DatasetError::spec(
                        format!("coast.{field}"),
                        format!("can draw {x}; must stay within {lo}..{hi}"),
                    ));
                }
            }
        }
        Ok(spec)
    }
}

/// The values a law can draw at its ends (every value of a choice).
fn law_values(d: &Dist) -> Vec<toml::Value> {
    match d {
        Dist::Fixed(v) => vec![v.clone()],
        Dist::Uniform { low, high } | Dist::LogUniform { low, high } => {
            vec![toml::Value::Float(*low), toml::Value::Float(*high)]
        }
        Dist::Normal { min, max, .. } => vec![toml::Value::Float(*min), toml::Value::Float(*max)],
        Dist::UniformInt { low, high } => {
            vec![toml::Value::Integer(*low), toml::Value::Integer(*high)]
        }
        Dist::Choice { values, .. } => values.clone(),
    }
}

/// A sample's land: the `[[land]]` tables and what placement needs.
#[derive(Debug, Clone, Default)]
pub struct SampleCoast {
    /// The `[[land]]` tables.
    pub tables: Vec<toml::Table>,
    /// The `[[structure]]` tables (a harbour's buildings).
    pub structures: Vec<toml::Table>,
    /// Every polygon's ring, m (for placing targets on the water).
    pub rings: Vec<Vec<(f64, f64)>>,
    /// A harbour's channel.
    pub channel: Option<Channel>,
    /// A harbour's quay.
    pub quay: Option<Quay>,
}

/// A point on the ground, m (x east, y north).
pub type Point = (f64, f64);

/// A harbour's channel: its axis from the entrance toward the antenna, and how far off the
/// axis its buoys stand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Channel {
    /// Where it starts, off the entrance.
    pub start: Point,
    /// Where it ends, toward the antenna.
    pub end: Point,
    /// Its buoys' distance from the axis, m.
    pub half_width_m: f64,
}

/// A harbour's quay wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quay {
    /// One end.
    pub from: Point,
    /// The other end.
    pub to: Point,
    /// Unit vector from the wall toward the water.
    pub water: Point,
}

impl SampleCoast {
    /// Whether `p` is on land.
    pub fn on_land(&self, p: (f64, f64)) -> bool {
        self.rings.iter().any(|r| ring_contains(r, p))
    }

    /// Distance from `p` to the nearest coast, m (infinite without land).
    pub fn distance_to_coast_m(&self, p: (f64, f64)) -> f64 {
        let mut best = f64::INFINITY;
        for r in &self.rings {
            for i in 0..r.len() {
                best = best.min(segment_distance(p, r[i], r[(i + 1) % r.len()]));
            }
        }
        best
    }

    /// Whether a target of extent `extent_m` may stand at `p`: on the water, at least its
    /// extent and 10 m from the coast.
    pub fn clear(&self, p: (f64, f64), extent_m: f64) -> bool {
        !self.on_land(p) && self.distance_to_coast_m(p) >= extent_m + 10.0
    }
}

fn ring_contains(ring: &[(f64, f64)], (x, y): (f64, f64)) -> bool {
    let mut inside = false;
    let n = ring.len();
    for i in 0..n {
        let ((ax, ay), (bx, by)) = (ring[i], ring[(i + 1) % n]);
        if (ay > y) != (by > y) && x < ax + (y - ay) / (by - ay) * (bx - ax) {
            inside = !inside;
        }
    }
    inside
}

fn segment_distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (abx, aby) = (b.0 - a.0, b.1 - a.1);
    let len2 = abx * abx + aby * aby;
    let t = if len2 > 0.0 {
        (((p.0 - a.0) * abx + (p.1 - a.1) * aby) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a.0 + abx * t - p.0).hypot(a.1 + aby * t - p.1)
}

/// Midpoint displacement over `2^levels + 1` points with zero ends: level L displaces by
/// `amplitude·2^{−0.7·L}·u`, u uniform in [−1, 1).
fn fractal_line(rng: &mut Pcg64Mcg, levels: u32, amplitude: f64) -> Vec<f64> {
    let n = (1usize << levels) + 1;
    let mut v = vec![0.0; n];
    let mut step = n - 1;
    let mut level = 0;
    while step > 1 {
        let half = step / 2;
        let a = amplitude * 2f64.powf(-0.7 * level as f64);
        let mut i = half;
        while i < n {
            v[i] = 0.5 * (v[i - half] + v[i + half]) + a * (2.0 * unit_draw(rng) - 1.0);
            i += step;
        }
        step = half;
        level += 1;
    }
    v
}

/// A land table of one ring.
fn land_table(name: &str, ring: &[(f64, f64)], height_m: f64, terrain: &str) -> toml::Table {
    let mut t = toml::Table::new();
    t.insert("name".into(), name.into());
    t.insert(
        "polygon_m".into(),
        toml::Value::Array(
            ring.iter()
                .map(|&(x, y)| toml::Value::Array(vec![round_cm(x).into(), round_cm(y).into()]))
                .collect(),
        ),
    );
    t.insert("height_m".into(), round_cm(height_m).into());
    t.insert("terrain".into(), terrain.into());
    t
}

fn round_cm(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

/// Draws a sample's land about `origin` for a radar recording `max_range_m`, or None when
/// the sample has none. Draws, in order: whether it has land; the layout, distance fraction,
/// bearing, height, terrain and roughness; then the layout's own draws.
pub fn draw(
    spec: &CoastSpec,
    rng: &mut Pcg64Mcg,
    origin: (f64, f64),
    max_range_m: f64,
) -> Result<Option<SampleCoast>> {
    if unit_draw(rng) >= spec.probability {
        return Ok(None);
    }
    let layout = spec.layout.sample(rng);
    let layout = layout.as_str().unwrap_or("coast").to_string();
    let d = spec
        .distance_fraction
        .sample_f64("coast.distance_fraction", rng)?
        * max_range_m;
    let bearing = spec
        .bearing_deg
        .sample_f64("coast.bearing_deg", rng)?
        .to_radians();
    let height = spec.height_m.sample_f64("coast.height_m", rng)?;
    let terrain_value = spec.terrain.sample(rng);
    let terrain = terrain_value.as_str().unwrap_or("rock").to_string();
    let rough = spec.roughness.sample_f64("coast.roughness", rng)?;
    // The coast's frame: v toward the land, u along the coast.
    let v_hat = (bearing.sin(), bearing.cos());
    let u_hat = (bearing.cos(), -bearing.sin());
    let at = |u: f64, v: f64| {
        (
            origin.0 + u * u_hat.0 + v * v_hat.0,
            origin.1 + u * u_hat.1 + v * v_hat.1,
        )
    };
    let mut coast = SampleCoast::default();
    let mut harbour_buildings: Option<(f64, f64)> = None;
    let far = 2.5 * max_range_m;
    let shore = |rng: &mut Pcg64Mcg, quay_half_m: f64| -> Vec<(f64, f64)> {
        let v = fractal_line(rng, 7, rough * d);
        let n = v.len();
        let mut ring: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let u = -far + 2.0 * far * i as f64 / (n - 1) as f64;
                // A straight quay in the middle, blended into the fractal shore.
                let blend = ((u.abs() - quay_half_m) / (0.3 * d).max(1.0)).clamp(0.0, 1.0);
                let off = if quay_half_m > 0.0 {
                    v[i] * blend
                } else {
                    v[i]
                };
                (u, (d + off).max(0.4 * d))
            })
            .collect();
        ring.push((far, far + d));
        ring.push((-far, far + d));
        ring.into_iter().map(|(u, v)| at(u, v)).collect()
    };
    match layout.as_str() {
        "coast" => {
            let ring = shore(rng, 0.0);
            coast
                .tables
                .push(land_table("coast", &ring, height, &terrain));
            coast.rings.push(ring);
        }
        "islands" => {
            let count = spec.islands.sample_f64("coast.islands", rng)?.round() as usize;
            for k in 0..count.max(1) {
                let r0 = (0.03 + 0.07 * unit_draw(rng)) * max_range_m;
                let dist = d + (unit_draw(rng) - 0.3) * 0.5 * max_range_m;
                let dist = dist.max(1.6 * r0 + 100.0);
                let b = bearing + (unit_draw(rng) - 0.5) * std::f64::consts::PI;
                let centre = (origin.0 + dist * b.sin(), origin.1 + dist * b.cos());
                let harmonics: Vec<(f64, f64)> = (1..=6)
                    .map(|h| {
                        (
                            rough * (2.0 * unit_draw(rng) - 1.0) / h as f64,
                            std::f64::consts::TAU * unit_draw(rng),
                        )
                    })
                    .collect();
                let h_island = height * (0.5 + unit_draw(rng));
                let ring: Vec<(f64, f64)> = (0..48)
                    .map(|i| {
                        let a = std::f64::consts::TAU * i as f64 / 48.0;
                        let wobble: f64 = harmonics
                            .iter()
                            .enumerate()
                            .map(|(h, (amp, phase))| amp * ((h + 1) as f64 * a + phase).sin())
                            .sum();
                        let r = r0 * (1.0 + wobble).clamp(0.3, 1.6);
                        (centre.0 + r * a.sin(), centre.1 + r * a.cos())
                    })
                    .collect();
                coast.tables.push(land_table(
                    &format!("island-{k}"),
                    &ring,
                    h_island,
                    &terrain,
                ));
                coast.rings.push(ring);
            }
        }
        _ => {
            // Harbour: a straight quay 2·B long at distance d, two breakwaters from it whose
            // heads leave an entrance, a channel from the entrance toward the antenna.
            let entrance = spec.entrance_m.sample_f64("coast.entrance_m", rng)?;
            let half_quay = (0.25 + 0.15 * unit_draw(rng)) * d;
            let reach = (0.2 + 0.1 * unit_draw(rng)) * d;
            let ring = shore(rng, half_quay + 0.3 * d);
            coast
                .tables
                .push(land_table("quay", &ring, height, "urban"));
            coast.rings.push(ring);
            let width = 15.0;
            let rect = |u0: f64, v0: f64, u1: f64, v1: f64| {
                vec![at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1)]
            };
            for (k, side) in [-1.0f64, 1.0].iter().enumerate() {
                // The stem out from the quay at the basin's end, then the head along it.
                let u_stem = side * half_quay;
                let stem = if *side < 0.0 {
                    rect(u_stem, d - reach, u_stem + width, d + 20.0)
                } else {
                    rect(u_stem - width, d - reach, u_stem, d + 20.0)
                };
                let head_end = side * entrance / 2.0;
                let head = if *side < 0.0 {
                    rect(u_stem, d - reach, head_end, d - reach + width)
                } else {
                    rect(head_end, d - reach, u_stem, d - reach + width)
                };
                for (j, r) in [stem, head].into_iter().enumerate() {
                    coast
                        .tables
                        .push(land_table(&format!("breakwater-{k}-{j}"), &r, 4.0, "rock"));
                    coast.rings.push(r);
                }
            }
            coast.channel = Some(Channel {
                start: at(0.0, d - reach - 20.0),
                end: at(0.0, 0.25 * d),
                half_width_m: entrance / 2.0 + 15.0,
            });
            coast.quay = Some(Quay {
                from: at(-half_quay + 30.0, d),
                to: at(half_quay - 30.0, d),
                water: (-v_hat.0, -v_hat.1),
            });
            harbour_buildings = Some((half_quay, height));
        }
    }
    // Hills and buildings draw from a stream of their own (the sample's, jumped ahead), so
    // that adding them leaves every other draw of the sample as it was.
    let mut extra = rng.clone();
    extra.advance(1 << 64);
    if layout != "islands" {
        let count = spec.hills.sample_f64("coast.hills", &mut extra)?.round() as usize;
        let land = coast.rings[0].clone();
        // Inland of the shore's farthest reach, and past a harbour's town.
        let inland = (d * (1.0 + rough)).max(d + 160.0);
        for k in 0..count {
            let radius = (0.08 + 0.12 * unit_draw(&mut extra)) * d;
            let centre = at(
                (2.0 * unit_draw(&mut extra) - 1.0) * 1.5 * d,
                inland + radius * (1.3 + unit_draw(&mut extra)),
            );
            let top = height * (1.5 + 1.5 * unit_draw(&mut extra));
            // Three terraces (cliff-edged rings at a third, two thirds and all of the rise
            // over the land), so that the hill rises from the land's height, not the sea's.
            let terraces: Vec<(Vec<(f64, f64)>, f64)> = (1..=3)
                .map(|t| {
                    let r_t = radius * (4 - t) as f64 / 3.0;
                    let ring = (0..32)
                        .map(|i| {
                            let a = std::f64::consts::TAU * i as f64 / 32.0;
                            let r = r_t * (1.0 + 0.2 * (3.0 * a + 7.0 * k as f64).sin());
                            (centre.0 + r * a.sin(), centre.1 + r * a.cos())
                        })
                        .collect();
                    (ring, height + (top - height) * t as f64 / 3.0)
                })
                .collect();
            // Only a hill wholly on the land (the shore may reach inland that far).
            if terraces[0].0.iter().all(|&p| ring_contains(&land, p)) {
                for (t, (ring, z)) in terraces.into_iter().enumerate() {
                    coast
                        .tables
                        .push(land_table(&format!("hill-{k}-{t}"), &ring, z, "forest"));
                    coast.rings.push(ring);
                }
            }
        }
    }
    if let Some((half_quay, ground_m)) = harbour_buildings {
        let count = spec
            .buildings
            .sample_f64("coast.buildings", &mut extra)?
            .round() as usize;
        let yaw_deg = (u_hat.0.atan2(u_hat.1)).to_degrees().rem_euclid(360.0);
        // The kept buildings' centres (as written, to the centimetre).
        let mut placed: Vec<(f64, f64)> = Vec::new();
        for k in 0..count {
            let length = 20.0 + 40.0 * unit_draw(&mut extra);
            let width = 12.0 + 18.0 * unit_draw(&mut extra);
            let tall = 6.0 + 14.0 * unit_draw(&mut extra);
            let u =
                (2.0 * unit_draw(&mut extra) - 1.0) * (half_quay - 0.5 * length - 20.0).max(0.0);
            let v = d + 25.0 + 0.5 * width + 60.0 * unit_draw(&mut extra);
            let centre = at(u, v);
            let mut t = toml::Table::new();
            t.insert("name".into(), format!("building-{k}").into());
            t.insert("kind".into(), "building".into());
            t.insert(
                "position_m".into(),
                toml::Value::Array(vec![round_cm(centre.0).into(), round_cm(centre.1).into()]),
            );
            t.insert(
                "size_m".into(),
                toml::Value::Array(vec![round_cm(length).into(), round_cm(width).into()]),
            );
            t.insert("yaw_deg".into(), round_cm(yaw_deg).into());
            t.insert("height_m".into(), round_cm(tall).into());
            t.insert("base_m".into(), round_cm(ground_m).into());
            // Buildings that would overlap are left out (the structures' checks allow it, a
            // town does not).
            let at_cm = (round_cm(centre.0), round_cm(centre.1));
            let clear = placed
                .iter()
                .all(|p: &(f64, f64)| (p.0 - at_cm.0).hypot(p.1 - at_cm.1) > 0.5 * length + 45.0);
            if clear {
                placed.push(at_cm);
                coast.structures.push(t);
            }
        }
    }
    Ok(Some(coast))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn spec(layout: &str) -> CoastSpec {
        let text = format!("layout = \"{layout}\"\nroughness = {{ uniform = [0.0, 1.0] }}\n");
        CoastSpec::parse(&toml::from_str(&text).unwrap()).unwrap()
    }

    /// Every layout, over 300 draws each: every ring passes the scene loader's checks
    /// (closed, simple, no crossing edges), the antenna is on the water at least 50 m from
    /// the coast, and a harbour's channel and quay lie on the water with an entrance of the
    /// drawn width between its breakwaters.
    #[test]
    fn every_layout_gives_simple_rings_and_leaves_the_antenna_at_sea() {
        for layout in ["coast", "islands", "harbour"] {
            let s = spec(layout);
            for k in 0..300u64 {
                let mut rng = Pcg64Mcg::seed_from_u64(k);
                let origin = (100.0 * k as f64, -50.0);
                let range = [750.0, 1500.0, 6000.0][k as usize % 3];
                let c = draw(&s, &mut rng, origin, range)
                    .unwrap()
                    .expect("probability 1");
                assert_eq!(c.tables.len(), c.rings.len());
                for (i, r) in c.rings.iter().enumerate() {
                    let ring: Vec<glam::DVec2> =
                        r.iter().map(|&(x, y)| glam::DVec2::new(x, y)).collect();
                    xbandsim::land::check_rings(
                        "coast",
                        &format!("{layout} {k} ring {i}"),
                        &[ring],
                    )
                    .unwrap_or_else(|e| panic!("{e}"));
                }
                assert!(!c.on_land(origin), "{layout} {k}: the antenna is on land");
                assert!(c.distance_to_coast_m(origin) >= 50.0, "{layout} {k}");
                if layout == "harbour" {
                    let ch = c.channel.unwrap();
                    assert!(
                        !c.on_land(ch.start) && !c.on_land(ch.end),
                        "{k}: channel on land"
                    );
                    let quay = c.quay.unwrap();
                    let w = quay.water;
                    for q in [quay.from, quay.to] {
                        assert!(!c.on_land((q.0 + 5.0 * w.0, q.1 + 5.0 * w.1)), "{k}: quay");
                        assert!(c.on_land((q.0 - 5.0 * w.0, q.1 - 5.0 * w.1)), "{k}: quay");
                    }
                }
            }
        }
    }

    #[test]
    fn the_probability_and_bad_fields_are_honoured() {
        let never = CoastSpec::parse(&toml::from_str("probability = 0.0").unwrap()).unwrap();
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        assert!(draw(&never, &mut rng, (0.0, 0.0), 1500.0)
            .unwrap()
            .is_none());
        for (text, field) in [
            ("probability = 1.5", "coast.probability"),
            ("layout = \"fjord\"", "coast.layout"),
            ("terrain = \"lava\"", "coast.terrain"),
            ("roughness = 2.0", "coast.roughness"),
            (
                "distance_fraction = { uniform = [0.0, 0.5] }",
                "coast.distance_fraction",
            ),
            ("islands = 0", "coast.islands"),
            ("shore = 1", "coast.shore"),
        ] {
            let e = CoastSpec::parse(&toml::from_str(text).unwrap()).unwrap_err();
            assert!(e.to_string().contains(field), "{text}: {e}");
        }
    }
}
