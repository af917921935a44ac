//! # xbandsim-validate
//!
//! Physics checks of the whole pipeline against closed forms (docs/validation.md), run by
//! `xbandsim validate` and by the test suite. Each check builds a scene, runs the real
//! pipeline (scattering → echoes → noise → matched filter → polar output, or the RCS tool)
//! and compares one measured number with its closed form. The checks are grouped by area,
//! one module each; docs/validation.md lists their sources.

pub mod antenna;
pub mod combined;
pub mod detection;
pub mod doppler;
pub mod environment;
pub mod harness;
pub mod land;
pub mod motion;
pub mod multipath;
pub mod rcs;
pub mod receiver;
pub mod signal_chain;

// The measuring helpers, for the library's tests that measure the same way.
pub use antenna::*;
pub use doppler::*;
pub use environment::*;
pub use harness::*;
pub use motion::*;
pub use multipath::*;
pub use rcs::*;
pub use signal_chain::*;

use serde::Serialize;

/// How far a measurement may be from its expected value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", content = "value", rename_all = "snake_case")]
pub enum Tolerance {
    /// |measured − expected| ≤ value.
    Absolute(f64),
    /// |measured/expected − 1| ≤ value.
    Relative(f64),
    /// measured ≤ value (expected is the theoretical figure).
    AtMost(f64),
    /// measured ≥ value.
    AtLeast(f64),
}

impl Tolerance {
    /// Whether `measured` is acceptable against `expected`.
    pub fn accepts(&self, expected: f64, measured: f64) -> bool {
        if !measured.is_finite() {
            return false;
        }
        match *self {
            Tolerance::Absolute(t) => (measured - expected).abs() <= t,
            Tolerance::Relative(t) => (measured / expected - 1.0).abs() <= t,
            Tolerance::AtMost(t) => measured <= t,
            Tolerance::AtLeast(t) => measured >= t,
        }
    }

    /// Human-readable form, with `unit`.
    pub fn describe(&self, unit: &str) -> String {
        match *self {
            Tolerance::Absolute(t) => format!("±{t} {unit}"),
            // Rounded to 10⁻⁶ %: 0.07 is not 7 % exactly in binary.
            Tolerance::Relative(t) => format!("±{}%", (t * 1e8).round() / 1e6),
            Tolerance::AtMost(t) => format!("≤ {t} {unit}"),
            Tolerance::AtLeast(t) => format!("≥ {t} {unit}"),
        }
    }
}

/// The outcome of one check.
#[derive(Debug, Clone, Serialize)]
pub struct CheckResult {
    /// What is checked.
    pub name: String,
    /// Closed-form value.
    pub expected: f64,
    /// Value measured through the pipeline.
    pub measured: f64,
    /// Unit of both.
    pub unit: String,
    /// Allowed deviation.
    pub tolerance: Tolerance,
    /// Whether it passed.
    pub pass: bool,
    /// Source of the closed form.
    pub source: String,
}

pub(crate) fn check(
    name: &str,
    expected: f64,
    measured: f64,
    unit: &str,
    tolerance: Tolerance,
    source: &str,
) -> CheckResult {
    CheckResult {
        name: name.into(),
        expected,
        measured,
        unit: unit.into(),
        pass: tolerance.accepts(expected, measured),
        tolerance,
        source: source.into(),
    }
}

/// The checks as they are made, told to an observer (for progress).
pub(crate) struct Checks<'a> {
    done: Vec<CheckResult>,
    on_check: &'a mut dyn FnMut(&CheckResult),
}

impl Checks<'_> {
    fn push(&mut self, c: CheckResult) {
        (self.on_check)(&c);
        self.done.push(c);
    }
}

/// Runs every check.
pub fn run_all() -> Vec<CheckResult> {
    run_all_with(&mut |_| {})
}

/// Runs every check, telling `on_check` about each as it completes.
pub fn run_all_with(on_check: &mut dyn FnMut(&CheckResult)) -> Vec<CheckResult> {
    let mut out = Checks {
        done: Vec::new(),
        on_check,
    };
    signal_chain::checks(&mut out);
    multipath::checks(&mut out);
    environment::checks(&mut out);
    antenna::checks(&mut out);
    rcs::checks(&mut out);
    motion::checks(&mut out);
    doppler::checks(&mut out);
    combined::checks(&mut out);
    receiver::checks(&mut out);
    land::checks(&mut out);
    detection::checks(&mut out);
    out.done
}
