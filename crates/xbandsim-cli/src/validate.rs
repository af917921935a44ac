//! `xbandsim validate`: the physics checks of `xbandsim_validate`, printed as a table.

use anyhow::{bail, Result};
use xbandsim_validate::{run_all_with, CheckResult};

/// Runs every check; prints a table (or JSON) and fails if any check fails.
pub fn run(json: bool) -> Result<()> {
    let t0 = std::time::Instant::now();
    let progress = crate::progress::spinner("validate: checks");
    let results: Vec<CheckResult> = run_all_with(&mut |c| {
        progress.inc(1);
        progress.set_message(c.name.clone());
    });
    progress.finish_and_clear();
    if json {
        crate::say!("{}", serde_json::to_string_pretty(&results)?);
    } else {
        crate::say!(
            "{:<62} {:>12} {:>12} {:>12}  {}",
            "check",
            "expected",
            "measured",
            "tolerance",
            "result"
        );
        for r in &results {
            crate::say!(
                "{:<62} {:>12} {:>12} {:>12}  {}",
                r.name,
                format!("{:.3} {}", r.expected, r.unit),
                format!("{:.3} {}", r.measured, r.unit),
                r.tolerance.describe(&r.unit),
                if r.pass { "pass" } else { "FAIL" }
            );
        }
        let passed = results.iter().filter(|r| r.pass).count();
        crate::say!(
            "{} passed, {} failed ({:.1} s)",
            passed,
            results.len() - passed,
            t0.elapsed().as_secs_f64()
        );
    }
    let failed: Vec<&str> = results
        .iter()
        .filter(|r| !r.pass)
        .map(|r| r.name.as_str())
        .collect();
    if !failed.is_empty() {
        bail!(
            "{} physics check(s) failed: {}",
            failed.len(),
            failed.join("; ")
        );
    }
    Ok(())
}
