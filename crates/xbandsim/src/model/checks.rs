//! Small checks shared by the model's validating constructors: each returns the value or an
//! [`Error`] naming the field, the value and what is wrong with it.

use crate::error::{Error, Problem, Result};
use glam::DVec3;

pub(crate) fn fmt_vec(v: DVec3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}

/// A finite number, else an error naming the field.
pub(crate) fn finite(field: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::invalid(
            Problem::NotFinite,
            field,
            v,
            "must be a finite number",
        ))
    }
}

/// A finite number > 0.
pub(crate) fn positive(field: &str, v: f64) -> Result<f64> {
    finite(field, v)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(Error::invalid(
            Problem::OutOfRange,
            field,
            v,
            "must be greater than zero",
        ))
    }
}

pub(crate) fn finite_vec(field: &str, v: [f64; 3]) -> Result<DVec3> {
    for (k, x) in v.iter().enumerate() {
        if !x.is_finite() {
            return Err(Error::invalid(
                Problem::NotFinite,
                field,
                format!("{v:?}"),
                format!("component {k} must be a finite number"),
            ));
        }
    }
    Ok(DVec3::from_array(v))
}
