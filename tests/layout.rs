//! The layout as README.md describes it: every path README names exists,
//! and the engine's layers and units import only those declared before
//! them (`src/engine/mod.rs` and each layer's `mod.rs` give the order).

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "tests fail by panicking"
)]

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The repository paths README names in backticks (`src/…`, `tests/…`,
/// `benches/…`, `sessions/…`, `assets/…`), with their line numbers.
fn readme_paths(readme: &str) -> Vec<(usize, String)> {
    const ROOTS: [&str; 5] = ["src/", "tests/", "benches/", "sessions/", "assets/"];
    let mut out = Vec::new();
    for (n, line) in readme.lines().enumerate() {
        for (k, piece) in line.split('`').enumerate() {
            // Odd pieces are inside backticks.
            if k % 2 == 1 && ROOTS.iter().any(|r| piece.starts_with(r)) {
                // A command line names a path first, then its arguments.
                let path = piece.split_whitespace().next().unwrap_or(piece);
                out.push((n + 1, path.to_string()));
            }
        }
        // Markdown images and links to repository files.
        for part in line.split("](").skip(1) {
            let target = part.split(')').next().unwrap_or("");
            if ROOTS.iter().any(|r| target.starts_with(r)) {
                out.push((n + 1, target.to_string()));
            }
        }
    }
    out
}

#[test]
fn every_path_readme_names_exists() {
    let readme = fs::read_to_string(root().join("README.md")).unwrap();
    let paths = readme_paths(&readme);
    assert!(
        paths.len() > 40,
        "README names {} paths: the scan missed them",
        paths.len()
    );
    let missing: Vec<String> = paths
        .iter()
        // A glob (`src/engine/*`) names a pattern, not a path.
        .filter(|(_, p)| !p.contains('*') && !root().join(p.trim_end_matches('/')).exists())
        .map(|(n, p)| format!("README.md line {n}: `{p}`"))
        .collect();
    assert!(
        missing.is_empty(),
        "paths that do not exist:\n{}",
        missing.join("\n")
    );
}

#[test]
fn the_scan_finds_a_missing_path() {
    let text =
        "| eq. 21 | `src/engine/calibrate/stripe/segment.rs` (`find_arc`) |\n![x](assets/none.png)";
    let found = readme_paths(text);
    assert_eq!(
        found,
        [
            (1, "src/engine/calibrate/stripe/segment.rs".to_string()),
            (2, "assets/none.png".to_string())
        ]
    );
    assert!(!root().join(&found[0].1).exists());
}

/// `pub mod NAME;` declarations of a `mod.rs`, in order.
fn declared(mod_rs: &Path) -> Vec<String> {
    fs::read_to_string(mod_rs)
        .unwrap()
        .lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod "))
        .filter_map(|l| l.strip_suffix(';'))
        .map(str::to_string)
        .collect()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The `crate::engine::LAYER::UNIT` paths of a file's code (comments
/// dropped), as (layer, unit).
fn engine_uses(text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        for part in code.split("crate::engine::").skip(1) {
            let mut names = part
                .split("::")
                .map(|s| s.split(|c: char| !c.is_alphanumeric() && c != '_').next());
            if let (Some(Some(layer)), Some(Some(unit))) = (names.next(), names.next()) {
                out.push((layer.to_string(), unit.to_string()));
            }
        }
    }
    out
}

#[test]
fn engine_units_use_only_those_before_them() {
    let engine = root().join("src/engine");
    let layers = declared(&engine.join("mod.rs"));
    assert_eq!(layers, ["base", "calibrate", "files", "tools", "uses"]);
    // Rank of every unit: (layer index, unit index).
    let mut rank: HashMap<(String, String), (usize, usize)> = HashMap::new();
    for (l, layer) in layers.iter().enumerate() {
        for (u, unit) in declared(&engine.join(layer).join("mod.rs"))
            .into_iter()
            .enumerate()
        {
            rank.insert((layer.clone(), unit), (l, u));
        }
    }
    assert!(rank.len() >= 20, "{} units", rank.len());
    let mut wrong = Vec::new();
    for layer in &layers {
        let mut files = Vec::new();
        rust_files(&engine.join(layer), &mut files);
        for file in files {
            let rel = file.strip_prefix(engine.join(layer)).unwrap();
            let Some(first) = rel.components().next() else {
                continue;
            };
            let unit = first
                .as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string();
            let Some(&mine) = rank.get(&(layer.clone(), unit.clone())) else {
                // The layer's own mod.rs.
                continue;
            };
            for used in engine_uses(&fs::read_to_string(&file).unwrap()) {
                match rank.get(&used) {
                    Some(&theirs) if theirs <= mine => {}
                    Some(_) => wrong.push(format!(
                        "{}: {layer}::{unit} uses {}::{} declared after it",
                        file.display(),
                        used.0,
                        used.1
                    )),
                    None => wrong.push(format!(
                        "{}: uses engine::{}::{}, which no layer declares",
                        file.display(),
                        used.0,
                        used.1
                    )),
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn the_order_check_reads_uses() {
    let text = "use crate::engine::base::robot::Robot; // crate::engine::uses::measure\n\
                let x = crate::engine::calibrate::solve::run(a);";
    assert_eq!(
        engine_uses(text),
        [
            ("base".to_string(), "robot".to_string()),
            ("calibrate".to_string(), "solve".to_string())
        ]
    );
}
