//! Distributions of a dataset spec: every randomised field is a plain value (fixed) or a
//! one-key table naming its law (docs/formats.md, "Dataset spec"):
//! `{ uniform = [a, b] }` (a ≤ x < b), `{ normal = [mean, std] }` (optionally clipped with
//! `min`/`max`), `{ log_uniform = [a, b] }` (`ln x` uniform, 0 < a ≤ b), `{ uniform_int =
//! [a, b] }` (whole numbers a..=b) and `{ choice = [v, ...], weights = [w, ...] }` (any TOML
//! values, equal weights when `weights` is left out).

use crate::error::{DatasetError, Result};
use rand::Rng;
use rand_distr::{Distribution as _, StandardNormal};
use rand_pcg::Pcg64Mcg;

/// A TOML number (float or integer) as f64.
pub fn as_f64(v: &toml::Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// A draw uniform in [0, 1) from the top 53 bits of the generator's next word.
pub fn unit_draw(rng: &mut Pcg64Mcg) -> f64 {
    xbandsim::rng::unit_f64(rand::RngCore::next_u64(rng))
}

/// One randomised field.
#[derive(Debug, Clone, PartialEq)]
pub enum Dist {
    /// Always this value.
    Fixed(toml::Value),
    /// `a + (b − a)·u`, u uniform in [0, 1).
    Uniform { low: f64, high: f64 },
    /// `mean + std·z`, z standard normal, clipped to `[min, max]`.
    Normal {
        mean: f64,
        std: f64,
        min: f64,
        max: f64,
    },
    /// `exp(ln a + (ln b − ln a)·u)`.
    LogUniform { low: f64, high: f64 },
    /// A whole number from `low` to `high` inclusive, each equally likely.
    UniformInt { low: i64, high: i64 },
    /// One of `values`, value i with probability `weights[i]/Σweights`.
    Choice {
        values: Vec<toml::Value>,
        weights: Vec<f64>,
    },
}

impl Dist {
    /// Reads a field's value: a table with one of the laws' keys is a distribution (checked:
    /// finite bounds in order, a positive spread, non-empty choices, non-negative weights
    /// that do not all vanish), anything else a fixed value. Errors name `field`.
    pub fn parse(field: &str, value: &toml::Value) -> Result<Dist> {
        let Some(table) = value.as_table() else {
            return Ok(Dist::Fixed(value.clone()));
        };
        let laws = ["uniform", "normal", "log_uniform", "uniform_int", "choice"];
        let named: Vec<&str> = laws
            .iter()
            .copied()
            .filter(|k| table.contains_key(*k))
            .collect();
        let bad = |key: &str, why: String| DatasetError::spec(format!("{field}.{key}"), why);
        match named.as_slice() {
            [] => Ok(Dist::Fixed(value.clone())),
            [law] => {
                let allowed: &[&str] = match *law {
                    "normal" => &["normal", "min", "max"],
                    "choice" => &["choice", "weights"],
                    other => &[other][..],
                };
                if let Some(extra) = table.keys().find(|k| !allowed.contains(&k.as_str())) {
                    return Err(bad(
                        extra,
                        format!(
                            "not a key of a `{law}` distribution (it takes {})",
                            allowed.join(", ")
                        ),
                    ));
                }
                Dist::parse_law(field, law, table)
            }
            several => Err(DatasetError::spec(
                field,
                format!(
                    "names {} laws ({}); a distribution names exactly one",
                    several.len(),
                    several.join(", ")
                ),
            )),
        }
    }

    fn parse_law(field: &str, law: &str, table: &toml::Table) -> Result<Dist> {
        let name = format!("{field}.{law}");
        let pair = || -> Result<(f64, f64)> {
            let arr = table[law]
                .as_array()
                .filter(|a| a.len() == 2)
                .ok_or_else(|| {
                    DatasetError::spec(&name, "must be a pair of numbers [a, b]".into())
                })?;
            let num = |v: &toml::Value| {
                as_f64(v)
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| DatasetError::spec(&name, format!("{v} is not a finite number")))
            };
            Ok((num(&arr[0])?, num(&arr[1])?))
        };
        let bound = |key: &str, default: f64| -> Result<f64> {
            match table.get(key) {
                None => Ok(default),
                Some(v) => as_f64(v).filter(|x| !x.is_nan()).ok_or_else(|| {
                    DatasetError::spec(format!("{field}.{key}"), format!("{v} is not a number"))
                }),
            }
        };
        match law {
            "uniform" => {
                let (low, high) = pair()?;
                if low > high {
                    return Err(DatasetError::spec(
                        &name,
                        format!(
                            "[{low}, {high}] is empty: the first bound must not exceed the second"
                        ),
                    ));
                }
                Ok(Dist::Uniform { low, high })
            }
            "log_uniform" => {
                let (low, high) = pair()?;
                if !(low > 0.0 && low <= high) {
                    return Err(DatasetError::spec(
                        &name,
                        format!("[{low}, {high}]: a log-uniform law needs 0 < a ≤ b"),
                    ));
                }
                Ok(Dist::LogUniform { low, high })
            }
            "normal" => {
                let (mean, std) = pair()?;
                if std < 0.0 {
                    return Err(DatasetError::spec(
                        &name,
                        format!("standard deviation {std} is negative"),
                    ));
                }
                let (min, max) = (
                    bound("min", f64::NEG_INFINITY)?,
                    bound("max", f64::INFINITY)?,
                );
                if min > max {
                    return Err(DatasetError::spec(
                        format!("{field}.min"),
                        format!("{min} is above max = {max}"),
                    ));
                }
                Ok(Dist::Normal {
                    mean,
                    std,
                    min,
                    max,
                })
            }
            "uniform_int" => {
                let arr = table[law]
                    .as_array()
                    .filter(|a| a.len() == 2)
                    .and_then(|a| Some((a[0].as_integer()?, a[1].as_integer()?)))
                    .ok_or_else(|| {
                        DatasetError::spec(&name, "must be a pair of whole numbers [a, b]".into())
                    })?;
                if arr.0 > arr.1 {
                    return Err(DatasetError::spec(
                        &name,
                        format!(
                            "[{}, {}] is empty: the first bound must not exceed the second",
                            arr.0, arr.1
                        ),
                    ));
                }
                Ok(Dist::UniformInt {
                    low: arr.0,
                    high: arr.1,
                })
            }
            _ => {
                let values = table[law]
                    .as_array()
                    .cloned()
                    .ok_or_else(|| DatasetError::spec(&name, "must be a list of values".into()))?;
                if values.is_empty() {
                    return Err(DatasetError::spec(
                        &name,
                        "is empty: a choice needs at least one value".into(),
                    ));
                }
                let weights = match table.get("weights") {
                    None => vec![1.0; values.len()],
                    Some(w) => {
                        let w: Vec<f64> = w
                            .as_array()
                            .and_then(|a| a.iter().map(as_f64).collect::<Option<Vec<f64>>>())
                            .ok_or_else(|| {
                                DatasetError::spec(
                                    format!("{field}.weights"),
                                    "must be a list of numbers".into(),
                                )
                            })?;
                        if w.len() != values.len() {
                            return Err(DatasetError::spec(
                                format!("{field}.weights"),
                                format!("has {} weights for {} choices", w.len(), values.len()),
                            ));
                        }
                        if w.iter().any(|x| !x.is_finite() || *x < 0.0)
                            || w.iter().sum::<f64>() <= 0.0
                        {
                            return Err(DatasetError::spec(
                                format!("{field}.weights"),
                                "weights must be finite, 0 or more, and not all 0".into(),
                            ));
                        }
                        w
                    }
                };
                Ok(Dist::Choice { values, weights })
            }
        }
    }

    /// A number drawn from this distribution (fixed values must be numbers). Every law takes
    /// the same number of generator steps whatever its parameters, so the draws that follow
    /// do not depend on them.
    pub fn sample_f64(&self, field: &str, rng: &mut Pcg64Mcg) -> Result<f64> {
        let v = self.sample(rng);
        as_f64(&v).ok_or_else(|| DatasetError::spec(field, format!("{v} is not a number")))
    }

    /// A TOML value drawn from this distribution.
    pub fn sample(&self, rng: &mut Pcg64Mcg) -> toml::Value {
        match self {
            Dist::Fixed(v) => v.clone(),
            Dist::Uniform { low, high } => {
                let u: f64 = rng.random();
                toml::Value::Float(low + (high - low) * u)
            }
            Dist::LogUniform { low, high } => {
                let u: f64 = rng.random();
                toml::Value::Float((low.ln() + (high.ln() - low.ln()) * u).exp())
            }
            Dist::Normal {
                mean,
                std,
                min,
                max,
            } => {
                let z: f64 = StandardNormal.sample(rng);
                toml::Value::Float((mean + std * z).clamp(*min, *max))
            }
            Dist::UniformInt { low, high } => {
                let u: f64 = rng.random();
                let span = (high - low + 1) as f64;
                toml::Value::Integer(low + ((u * span).floor() as i64).min(high - low))
            }
            Dist::Choice { values, weights } => {
                let total: f64 = weights.iter().sum();
                let mut u: f64 = rng.random::<f64>() * total;
                for (v, w) in values.iter().zip(weights) {
                    if u < *w {
                        return v.clone();
                    }
                    u -= w;
                }
                // Rounding left u at the top: the last value with weight.
                values
                    .iter()
                    .zip(weights)
                    .rev()
                    .find(|(_, w)| **w > 0.0)
                    .map_or_else(|| values[0].clone(), |(v, _)| v.clone())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn dist(text: &str) -> Result<Dist> {
        let t: toml::Table = toml::from_str(&format!("v = {text}")).unwrap();
        Dist::parse("f", &t["v"])
    }

    /// Sample means and spreads of each law against their closed forms (10⁵ draws; the
    /// tolerances are about 5 standard errors).
    #[test]
    fn laws_have_their_moments() {
        let mut rng = Pcg64Mcg::seed_from_u64(7);
        let n = 100_000;
        let draws = |d: &Dist, rng: &mut Pcg64Mcg| -> Vec<f64> {
            (0..n).map(|_| d.sample_f64("f", rng).unwrap()).collect()
        };
        let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
        let var = |x: &[f64]| {
            let m = mean(x);
            x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / x.len() as f64
        };
        let u = draws(&dist("{ uniform = [2.0, 6.0] }").unwrap(), &mut rng);
        assert!((mean(&u) - 4.0).abs() < 0.02 && (var(&u) - 16.0 / 12.0).abs() < 0.02);
        assert!(u.iter().all(|x| (2.0..6.0).contains(x)));
        let g = draws(&dist("{ normal = [1.0, 0.5] }").unwrap(), &mut rng);
        assert!((mean(&g) - 1.0).abs() < 0.01 && (var(&g) - 0.25).abs() < 0.01);
        let l = draws(&dist("{ log_uniform = [1.0, 100.0] }").unwrap(), &mut rng);
        let logs: Vec<f64> = l.iter().map(|x| x.log10()).collect();
        assert!((mean(&logs) - 1.0).abs() < 0.01);
        let k = draws(&dist("{ uniform_int = [0, 9] }").unwrap(), &mut rng);
        assert!((mean(&k) - 4.5).abs() < 0.05);
        assert!(k
            .iter()
            .all(|x| x.fract() == 0.0 && (0.0..=9.0).contains(x)));
        let c = draws(
            &dist("{ choice = [1, 2], weights = [3, 1] }").unwrap(),
            &mut rng,
        );
        let ones = c.iter().filter(|x| **x == 1.0).count() as f64 / n as f64;
        assert!((ones - 0.75).abs() < 0.01, "{ones}");
        let clipped = draws(
            &dist("{ normal = [0.0, 1.0], min = 0.0 }").unwrap(),
            &mut rng,
        );
        assert!(clipped.iter().all(|x| *x >= 0.0));
    }

    #[test]
    fn bad_distributions_name_the_field() {
        for (text, key) in [
            ("{ uniform = [3.0, 1.0] }", "f.uniform"),
            ("{ uniform = [1.0] }", "f.uniform"),
            ("{ log_uniform = [0.0, 1.0] }", "f.log_uniform"),
            ("{ normal = [0.0, -1.0] }", "f.normal"),
            ("{ uniform_int = [5, 2] }", "f.uniform_int"),
            ("{ choice = [] }", "f.choice"),
            ("{ choice = [1, 2], weights = [1] }", "f.weights"),
            ("{ choice = [1, 2], weights = [0, 0] }", "f.weights"),
            ("{ uniform = [0, 1], normal = [0, 1] }", "f"),
            ("{ uniform = [0, 1], mean = 3 }", "f.mean"),
        ] {
            let err = dist(text).unwrap_err().to_string();
            assert!(err.contains(key), "{text}: {err}");
        }
        assert_eq!(
            dist("[1.0, 2.0]").unwrap(),
            Dist::Fixed(toml::Value::Array(vec![1.0.into(), 2.0.into()]))
        );
    }
}
