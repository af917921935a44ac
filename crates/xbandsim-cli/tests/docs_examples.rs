#![cfg(unix)]
//! Every `xbandsim` command the README and docs give as an example runs as written, with its
//! defaults: each inline code span or shell-block line that starts with `xbandsim ` (or
//! `target/release/xbandsim `) and names no placeholder (`SPEC`, `DIR`, `[--opt]`, `<…>`) is
//! run from a stand-in for the repository root (its scenes, datasets and meshes; `out/` its
//! own), and must succeed. Left out: benchmarks (`xbandsim bench`, minutes of measuring;
//! bench/run.sh runs them) and `xbandsim validate [--json]`, which other tests run as written
//! (cli.rs `validate_passes_and_prints_a_table`, golden.rs), each seconds of physics checks.

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The example commands of a markdown text: code spans (which may run over a line break)
/// and shell-block lines.
fn commands(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut prose = String::new();
    let mut fence: Option<bool> = None; // inside a fenced block: whether it is a shell one
    for line in text.lines() {
        let trimmed = line.trim_start();
        if let Some(lang) = trimmed.strip_prefix("```") {
            fence = match fence {
                Some(_) => None,
                None => Some(["sh", "bash", "shell", "console"].contains(&lang.trim())),
            };
            continue;
        }
        match fence {
            Some(true) => found.push(trimmed.split(" #").next().unwrap_or("").trim().to_string()),
            Some(false) => {}
            None => {
                prose.push_str(line);
                prose.push('\n');
            }
        }
    }
    for (k, span) in prose.split('`').enumerate() {
        if k % 2 == 1 {
            found.push(span.split_whitespace().collect::<Vec<_>>().join(" "));
        }
    }
    found
        .into_iter()
        .filter_map(|c| {
            let rest = c
                .strip_prefix("xbandsim ")
                .or_else(|| c.strip_prefix("target/release/xbandsim "))?;
            Some(rest.to_string())
        })
        .filter(|args| {
            let placeholder = args.contains('[')
                || args.contains('<')
                || args.contains('…')
                || args.contains("...")
                || args.split_whitespace().any(|w| {
                    let w = w.split('=').next_back().unwrap_or(w);
                    w.len() >= 2
                        && w.chars()
                            .all(|c| c.is_ascii_uppercase() || c == '_' || c == '.')
                        && w.chars().any(|c| c.is_ascii_uppercase())
                });
            !placeholder
        })
        .collect()
}

/// Whether `args` is a complete command (not a lone option such as `dataset --jobs 2` that
/// the text quotes from a longer one): a subcommand with what it needs.
fn complete(args: &str) -> bool {
    let words: Vec<&str> = args.split_whitespace().collect();
    match words.first() {
        Some(&"render") | Some(&"dataset") | Some(&"rcs") => {
            words.get(1).is_some_and(|w| !w.starts_with('-'))
                && (words[1] == "schema"
                    || words[1] == "verify"
                    || words[1] == "stats"
                    || words.contains(&"--out")
                    || words[0] == "rcs")
        }
        Some(&"detect") | Some(&"track") | Some(&"nmea") | Some(&"serve") | Some(&"replay") => {
            words.get(1).is_some_and(|w| !w.starts_with('-'))
        }
        Some(&"validate") | Some(&"schema") => true,
        Some(&"figures") | Some(&"make-vessel") => words.contains(&"--out"),
        _ => false,
    }
}

#[test]
fn the_readme_and_docs_commands_run_as_written() {
    let root = repo_root();
    let mut docs = vec![root.join("README.md")];
    for e in std::fs::read_dir(root.join("docs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            docs.push(p);
        }
    }
    docs.sort();
    let stand_in = tempfile::tempdir().unwrap();
    for name in ["scenes", "datasets", "crates", "docs"] {
        std::os::unix::fs::symlink(
            root.join(name).canonicalize().unwrap(),
            stand_in.path().join(name),
        )
        .unwrap();
    }
    let mut ran = Vec::new();
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        for args in commands(&text) {
            let first = args.split_whitespace().next().unwrap_or("");
            if ["bench", "validate"].contains(&first) || !complete(&args) || ran.contains(&args) {
                continue;
            }
            if ["serve", "replay"].contains(&first) {
                run_server(stand_in.path(), &args, doc);
                eprintln!("ran `xbandsim {args}` ({})", doc.display());
                ran.push(args);
                continue;
            }
            let out = Command::new(env!("CARGO_BIN_EXE_xbandsim"))
                .current_dir(stand_in.path())
                .args(args.split_whitespace())
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{}: `xbandsim {args}` failed: {}",
                doc.display(),
                String::from_utf8_lossy(&out.stderr)
            );
            eprintln!("ran `xbandsim {args}` ({})", doc.display());
            ran.push(args);
        }
    }
    // The README's two examples and the docs' are among them.
    for wanted in [
        "dataset datasets/detection.toml --count 100 --out out/detection/",
        "render scenes/crossing.toml --frames 8",
        "detect scenes/sea-state-4-rain.toml",
        "track scenes/crossing.toml",
        "nmea scenes/crossing.toml --duration-s 400 --out out/crossing.nmea --truth out/crossing-nmea-truth.jsonl",
        "serve scenes/harbour-departure.toml",
        "replay out/harbour.xbsrec",
    ] {
        assert!(
            ran.iter().any(|r| r.starts_with(wanted)),
            "`xbandsim {wanted}` not found among {ran:?}"
        );
    }
}

/// Runs a server example (`serve`, `replay`) as a person would: starts it, opens its page
/// once it says where it listens, lets it send for a few seconds, then presses Ctrl-C; it
/// must stop cleanly (a replay may end by itself first, when its recording does).
fn run_server(dir: &Path, args: &str, doc: &Path) {
    use std::io::{BufRead, Read, Write};
    let mut child = Command::new(env!("CARGO_BIN_EXE_xbandsim"))
        .current_dir(dir)
        .args(args.split_whitespace())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::inherit())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufReader::new(child.stdout.take().unwrap()).lines();
    let mut addr = None;
    for line in lines.by_ref() {
        let line = line.unwrap();
        if let Some(rest) = line.split(" on http://").nth(1) {
            addr = rest.split('/').next().map(str::to_string);
        }
        if line.starts_with("Ctrl-C stops") {
            break;
        }
    }
    let addr = addr.unwrap_or_else(|| panic!("{}: `xbandsim {args}` did not start", doc.display()));
    let mut page = String::new();
    let mut s = std::net::TcpStream::connect(&addr).unwrap();
    write!(
        s,
        "GET / HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    s.read_to_string(&mut page).unwrap();
    assert!(
        page.starts_with("HTTP/1.1 200") && page.contains("<canvas"),
        "{}: `xbandsim {args}`'s page: {page}",
        doc.display()
    );
    std::thread::sleep(std::time::Duration::from_secs(4));
    let _ = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status();
    let rest: Vec<String> = lines.map_while(|l| l.ok()).collect();
    let status = child.wait().unwrap();
    assert!(
        status.success() && rest.iter().any(|l| l.starts_with("stopped at")),
        "{}: `xbandsim {args}` did not stop cleanly: {status}, {rest:?}",
        doc.display()
    );
}

/// Every TOML block of the README and docs is a scene file the loader builds as written.
#[test]
fn the_docs_toml_blocks_are_valid_scenes() {
    let root = repo_root();
    let mut files = vec![root.join("README.md")];
    for e in std::fs::read_dir(root.join("docs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            files.push(p);
        }
    }
    let mut blocks = 0;
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let mut block: Option<String> = None;
        for line in text.lines() {
            let trimmed = line.trim_start();
            match (&mut block, trimmed.strip_prefix("```")) {
                (None, Some(lang)) if lang.trim() == "toml" => block = Some(String::new()),
                (Some(b), Some(_)) => {
                    let name = path.display().to_string();
                    xbandsim::LoadedSpec::from_toml(b, &name, &root)
                        .and_then(|s| s.build())
                        .unwrap_or_else(|e| panic!("{name}: a TOML block is refused: {e}"));
                    blocks += 1;
                    block = None;
                }
                (Some(b), None) => {
                    b.push_str(line);
                    b.push('\n');
                }
                (None, _) => {}
            }
        }
    }
    assert!(blocks >= 2, "{blocks} TOML blocks");
}
