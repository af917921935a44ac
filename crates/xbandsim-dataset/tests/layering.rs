//! The crate's modules are in layers (docs/architecture.md, "The dataset crate's layers"):
//! each imports only the modules before it in [`ORDER`], so no two import each other,
//! directly or round a circle.

use std::path::Path;

/// The modules from the bottom: each may use only those before it.
const ORDER: [&str; 18] = [
    "error",
    "layout",
    "dist",
    "obb",
    "owner",
    "baseline",
    "coast",
    "spec",
    "labels",
    "sample",
    "render",
    "check",
    "webdataset",
    "assemble",
    "generate",
    "stats",
    "verify",
    "lib",
];

/// The modules that `source` refers to as `crate::<module>` outside comments.
fn uses(source: &str) -> Vec<String> {
    let mut found = Vec::new();
    for line in source.lines() {
        let code = line.split("//").next().unwrap_or_default();
        for (at, _) in code.match_indices("crate::") {
            let name: String = code[at + "crate::".len()..]
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                .collect();
            if !name.is_empty() && !found.contains(&name) {
                found.push(name);
            }
        }
    }
    found
}

#[test]
fn each_module_uses_only_the_layers_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut seen = Vec::new();
    for entry in std::fs::read_dir(&src).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "rs") {
            let module = path.file_stem().unwrap().to_string_lossy().to_string();
            let rank = ORDER
                .iter()
                .position(|m| *m == module)
                .unwrap_or_else(|| panic!("src/{module}.rs: add it to ORDER, above what it uses"));
            let source = std::fs::read_to_string(&path).unwrap();
            for used in uses(&source) {
                if used == module {
                    continue;
                }
                let below = ORDER[..rank].contains(&used.as_str());
                assert!(
                    below,
                    "src/{module}.rs uses crate::{used}, which is not below it in the layers"
                );
            }
            seen.push(module);
        }
    }
    assert_eq!(seen.len(), ORDER.len(), "{seen:?}");
}

#[test]
fn the_layout_module_imports_nothing_above_the_errors() {
    let source =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/layout.rs"))
            .unwrap();
    assert_eq!(uses(&source), ["error"]);
}
