//! Helpers shared by the dataset's test binaries.

use std::path::Path;

/// A sample's render seed (from its scene.toml header's `--seed S`) and its loaded scene.
pub fn sample_scene(sample_dir: &Path) -> (u64, xbandsim::LoadedSpec) {
    let text = std::fs::read_to_string(sample_dir.join("scene.toml")).unwrap();
    let seed: u64 = text
        .lines()
        .find_map(|l| l.split("--seed ").nth(1))
        .and_then(|s| s.trim().parse().ok())
        .unwrap();
    let loaded = xbandsim::LoadedSpec::from_toml(&text, "scene.toml", Path::new(".")).unwrap();
    (seed, loaded)
}
