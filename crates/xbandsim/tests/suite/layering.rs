//! The library's modules are in layers (docs/architecture.md, "Layers"): each imports only
//! the modules before it in [`ORDER`], outside its tests, with one exception — the loader
//! (`scene/load.rs`) turns a file into the model and the display settings, so it names
//! both. Choices a file names live in the leaf `choice`.

use std::path::{Path, PathBuf};

/// The modules from the bottom: each may use only those before it.
const ORDER: [&str; 23] = [
    "error",
    "constants",
    "special",
    "rng",
    "cache",
    "choice",
    "waveform",
    "geometry",
    "antenna",
    "environment",
    "propagation",
    "land",
    "scene",
    "model",
    "targets",
    "scattering",
    "echo",
    "schedule",
    "signal",
    "receiver",
    "processing",
    "products",
    "engine",
];

/// The one file allowed to import above its module, and what it may import.
const LOADER: (&str, [&str; 2]) = ("scene/load.rs", ["model", "products"]);

/// The modules `source` refers to as `crate::<module>` outside comments and `#[cfg(test)]`
/// items.
fn uses(source: &str) -> Vec<String> {
    let mut found = Vec::new();
    for line in source.lines() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            break;
        }
        let code = line.split("//").next().unwrap_or_default();
        for (at, _) in code.match_indices("crate::") {
            let rest = &code[at + "crate::".len()..];
            // `crate::{a, b::c}`: every name in the braces (on this line).
            let names: Vec<&str> = match rest.strip_prefix('{') {
                Some(group) => group
                    .split([',', '}'])
                    .map(|n| n.trim())
                    .take_while(|n| !n.is_empty())
                    .collect(),
                None => vec![rest],
            };
            for n in names {
                let name: String = n
                    .chars()
                    .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                    .collect();
                if !name.is_empty() && !found.contains(&name) {
                    found.push(name);
                }
            }
        }
    }
    found
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn each_module_uses_only_the_layers_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let mut checked = 0;
    for path in files {
        let relative = path
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if relative == "lib.rs" {
            continue;
        }
        let module = relative
            .split('/')
            .next()
            .unwrap()
            .trim_end_matches(".rs")
            .to_string();
        let rank = ORDER.iter().position(|m| *m == module).unwrap_or_else(|| {
            panic!("src/{relative}: add `{module}` to ORDER, above what it uses")
        });
        let source = std::fs::read_to_string(&path).unwrap();
        for used in uses(&source) {
            if used == module {
                continue;
            }
            let used_rank = ORDER.iter().position(|m| *m == used).unwrap_or_else(|| {
                panic!("src/{relative} uses crate::{used}, which is not in ORDER")
            });
            let allowed = relative == LOADER.0 && LOADER.1.contains(&used.as_str());
            assert!(
                used_rank < rank || allowed,
                "src/{relative} ({module}) uses crate::{used}, a layer above it"
            );
            checked += 1;
        }
    }
    assert!(
        checked > 100,
        "only {checked} imports seen: is the source tree there?"
    );
}

/// The check sees an upward import when there is one.
#[test]
fn an_upward_import_is_seen() {
    let found = uses(
        "use crate::engine::Simulation; // crate::nothing\n#[cfg(test)]\nuse crate::products;",
    );
    assert_eq!(found, vec!["engine".to_string()]);
}
