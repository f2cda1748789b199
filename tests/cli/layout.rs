//! The layout as the guide describes it: every repository path the guide
//! names exists (above all the paper → code map of
//! `docs/src/architecture.md`, which names every engine unit), and the
//! engine's layers and units import only those declared before them
//! (`src/engine/mod.rs` and each layer's `mod.rs` give the order), whether
//! the import is spelled `crate::engine::…` or `super::…`.

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

/// The folders a repository path the guide names starts with.
const ROOTS: [&str; 9] = [
    "src/",
    "tests/",
    "benches/",
    "sessions/",
    "assets/",
    "examples/",
    "data/",
    "docs/",
    ".ci/",
];

/// The repository paths a Markdown text names in backticks (`src/…`,
/// `tests/…`, …; a command names its path first) or as a link or image
/// target written from the repository root, with their line numbers.
fn named_paths(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        for (k, piece) in line.split('`').enumerate() {
            // Odd pieces are inside backticks.
            if k % 2 == 1 && ROOTS.iter().any(|r| piece.starts_with(r)) {
                let path = piece.split_whitespace().next().unwrap_or(piece);
                out.push((n + 1, path.to_string()));
            }
        }
        for part in line.split("](").skip(1) {
            let target = part.split(')').next().unwrap_or("");
            if ROOTS.iter().any(|r| target.starts_with(r)) {
                out.push((n + 1, target.to_string()));
            }
        }
    }
    out
}

/// The named paths of `text` (file `name`, relative to the root) that do
/// not exist, from the root or from the file's own folder (`docs/README.md`
/// names `src/SUMMARY.md`).
fn missing_paths(name: &str, text: &str) -> Vec<String> {
    let folder = root().join(name);
    let folder = folder.parent().unwrap_or(&folder);
    let exists = |p: &str| {
        let p = p.trim_end_matches('/');
        root().join(p).exists() || folder.join(p).exists()
    };
    named_paths(text)
        .iter()
        // A glob (`src/engine/*`) names a pattern, not a path.
        .filter(|(_, p)| !p.contains('*') && !exists(p))
        .map(|(n, p)| format!("{name} line {n}: `{p}`"))
        .collect()
}

/// Every Markdown file of the guide (`docs/`) and README.md, as (path
/// relative to the root, text).
fn documents() -> Vec<(String, String)> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in fs::read_dir(dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|e| e == "md") {
                out.push(p);
            }
        }
    }
    let mut paths = Vec::new();
    walk(&root().join("docs/src"), &mut paths);
    paths.push(root().join("docs/README.md"));
    paths.push(root().join("README.md"));
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            let rel = p
                .strip_prefix(root())
                .unwrap()
                .to_string_lossy()
                .into_owned();
            (rel, fs::read_to_string(&p).unwrap())
        })
        .collect()
}

#[test]
fn every_path_the_guide_names_exists() {
    let docs = documents();
    let architecture = docs
        .iter()
        .find(|(name, _)| name == "docs/src/architecture.md")
        .expect("docs/src/architecture.md, the paper → code map");
    let mapped = named_paths(&architecture.1).len();
    assert!(
        mapped > 60,
        "architecture.md names {mapped} paths: the scan missed the map"
    );
    let missing: Vec<String> = docs
        .iter()
        .flat_map(|(name, text)| missing_paths(name, text))
        .collect();
    assert!(
        missing.is_empty(),
        "paths that do not exist:\n{}",
        missing.join("\n")
    );
}

/// Each unit of each engine layer (`src/engine/LAYER/UNIT`), as the
/// layers' `mod.rs` declare them.
fn engine_units() -> Vec<(String, String)> {
    let engine = root().join("src/engine");
    declared(&engine.join("mod.rs"))
        .into_iter()
        .flat_map(|layer| {
            declared(&engine.join(&layer).join("mod.rs"))
                .into_iter()
                .map(move |unit| (layer.clone(), unit))
        })
        .collect()
}

#[test]
fn the_map_names_every_engine_unit() {
    let text = fs::read_to_string(root().join("docs/src/architecture.md")).unwrap();
    let named: Vec<String> = named_paths(&text).into_iter().map(|(_, p)| p).collect();
    let units = engine_units();
    assert!(units.len() >= 20, "{} units", units.len());
    let unnamed: Vec<String> = units
        .iter()
        .filter(|(layer, unit)| {
            let folder = format!("src/engine/{layer}/{unit}/");
            let file = format!("src/engine/{layer}/{unit}.rs");
            !named
                .iter()
                .any(|p| p.starts_with(&folder) || *p == file || *p == folder.trim_end_matches('/'))
        })
        .map(|(layer, unit)| format!("{layer}::{unit}"))
        .collect();
    assert!(
        unnamed.is_empty(),
        "engine units the map of docs/src/architecture.md does not name: {}",
        unnamed.join(", ")
    );
}

#[test]
fn the_scan_finds_a_missing_path() {
    let text =
        "| eq. 21 | `src/engine/calibrate/stripe/segment.rs` (`find_arc`) |\n![x](assets/none.png)";
    let found = named_paths(text);
    assert_eq!(
        found,
        [
            (1, "src/engine/calibrate/stripe/segment.rs".to_string()),
            (2, "assets/none.png".to_string())
        ]
    );
    assert_eq!(
        missing_paths("t.md", text),
        [
            "t.md line 1: `src/engine/calibrate/stripe/segment.rs`",
            "t.md line 2: `assets/none.png`"
        ]
    );
    assert!(
        missing_paths(
            "t.md",
            "`src/engine/mod.rs`, `tests/cli/layout.rs` and `src/*`"
        )
        .is_empty()
    );
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

/// Rust source with comments dropped and the contents of string and
/// character literals emptied, so that braces and paths in them count
/// for nothing.
fn code_only(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < chars.len() {
                if chars[i] == '/' && chars.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if chars[i] == '*' && chars.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if c == 'r'
            && (next == Some('"') || next == Some('#'))
            && !chars[..i]
                .last()
                .is_some_and(|p| p.is_alphanumeric() || *p == '_')
        {
            // A raw string r"…", r#"…"#: it ends at `"` and as many `#`.
            let mut j = i + 1;
            let mut hashes = 0;
            while chars.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if chars.get(j) == Some(&'"') {
                j += 1;
                while j < chars.len() {
                    if chars[j] == '"' && (1..=hashes).all(|h| chars.get(j + h) == Some(&'#')) {
                        j += 1 + hashes;
                        break;
                    }
                    j += 1;
                }
                out.push_str("\"\"");
                i = j;
            } else {
                out.push(c);
                i += 1;
            }
        } else if c == '"' {
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                i += if chars[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == '\'' && (next == Some('\\') || chars.get(i + 2) == Some(&'\'')) {
            // A character literal ('{', '\n', '\''); a lifetime has no
            // closing quote.
            i += if next == Some('\\') { 2 } else { 1 };
            while i < chars.len() && chars[i] != '\'' {
                i += 1;
            }
            i += 1;
            out.push_str("' '");
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

/// The paths a use tree names, from its start (`a::b::{c, d::e}` gives
/// `a::b::c` and `a::b::d::e`), and how many bytes it takes. `self` in a
/// group names the path before it; a glob names nothing.
fn use_tree(s: &str) -> (Vec<Vec<String>>, usize) {
    let s0 = s.len();
    let mut rest = s.trim_start();
    if let Some(inner) = rest.strip_prefix('{') {
        let mut out = Vec::new();
        rest = inner;
        loop {
            rest = rest.trim_start();
            if let Some(r) = rest.strip_prefix('}') {
                rest = r;
                break;
            }
            if let Some(r) = rest.strip_prefix(',') {
                rest = r;
                continue;
            }
            let (paths, used) = use_tree(rest);
            if used == 0 {
                break;
            }
            out.extend(paths);
            rest = &rest[used..];
        }
        return (out, s0 - rest.len());
    }
    let ident: String = rest
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    if ident.is_empty() {
        // A glob or the end of the path.
        let skip = usize::from(rest.starts_with('*'));
        return (Vec::new(), s0 - rest.len() + skip);
    }
    rest = &rest[ident.len()..];
    if let Some(after) = rest.strip_prefix("::") {
        let (paths, used) = use_tree(after);
        rest = &after[used..];
        let paths = if paths.is_empty() {
            // `a::*`: the path up to the glob.
            vec![vec![ident]]
        } else {
            paths
                .into_iter()
                .map(|p| {
                    let mut full = vec![ident.clone()];
                    full.extend(p.into_iter().filter(|n| n != "self"));
                    full
                })
                .collect()
        };
        return (paths, s0 - rest.len());
    }
    (vec![vec![ident]], s0 - rest.len())
}

/// The engine units (layer, unit) a file's code uses, through
/// `crate::engine::LAYER::UNIT` paths and `super::` paths resolved from
/// `module`, the file's module path below `engine` (`src/engine/calibrate/
/// solve/ml/problem.rs` is `calibrate::solve::ml::problem`); inline modules
/// (`mod tests { … }`) are followed.
fn engine_uses(text: &str, module: &[String]) -> Vec<(String, String)> {
    let code = code_only(text);
    let bytes = code.as_bytes();
    let mut out = Vec::new();
    // The open braces: Some(name) for an inline module's.
    let mut braces: Vec<Option<String>> = Vec::new();
    let mut i = 0;
    while i < code.len() {
        let rest = &code[i..];
        let after_ident = i > 0 && {
            let p = bytes[i - 1];
            p.is_ascii_alphanumeric() || p == b'_' || p == b':'
        };
        if rest.starts_with('{') {
            // `mod NAME {` opens an inline module.
            let before = code[..i].trim_end();
            let name: String = before
                .chars()
                .rev()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect();
            let head = before[..before.len() - name.len()].trim_end();
            let is_mod = !name.is_empty()
                && head
                    .strip_suffix("mod")
                    .is_some_and(|h| !h.ends_with(|c: char| c.is_alphanumeric() || c == '_'));
            braces.push(is_mod.then_some(name));
            i += 1;
        } else if rest.starts_with('}') {
            braces.pop();
            i += 1;
        } else if !after_ident && rest.starts_with("crate::engine::") {
            let start = "crate::engine::".len();
            let (paths, used) = use_tree(&rest[start..]);
            out.extend(paths);
            i += start + used.max(1);
        } else if !after_ident && rest.starts_with("super::") {
            let mut here: Vec<String> = module.to_vec();
            here.extend(braces.iter().flatten().cloned());
            let mut j = 0;
            while rest[j..].starts_with("super::") {
                here.pop();
                j += "super::".len();
            }
            let (paths, used) = use_tree(&rest[j..]);
            if paths.is_empty() {
                // `super::*`: the module itself.
                out.push(here.clone());
            }
            for p in paths {
                let mut full = here.clone();
                full.extend(p.into_iter().filter(|n| n != "self"));
                out.push(full);
            }
            i += j + used.max(1);
        } else {
            i += rest.chars().next().map_or(1, char::len_utf8);
        }
    }
    out.into_iter()
        .filter(|p| p.len() >= 2)
        .map(|p| (p[0].clone(), p[1].clone()))
        .collect()
}

/// The module path below `engine` of a file under `src/engine`.
fn module_of(rel: &Path) -> Vec<String> {
    let mut names: Vec<String> = rel
        .components()
        .map(|c| {
            c.as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string()
        })
        .collect();
    if names.last().is_some_and(|n| n == "mod") {
        names.pop();
    }
    names
}

#[test]
fn engine_units_use_only_those_before_them() {
    let engine = root().join("src/engine");
    let layers = declared(&engine.join("mod.rs"));
    assert_eq!(
        layers,
        ["base", "files", "calibrate", "assemble", "tools", "uses"]
    );
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
    let mut seen = 0;
    for layer in &layers {
        let mut files = Vec::new();
        rust_files(&engine.join(layer), &mut files);
        for file in files {
            let module = module_of(file.strip_prefix(&engine).unwrap());
            let Some(&mine) = module
                .get(1)
                .and_then(|unit| rank.get(&(layer.clone(), unit.clone())))
            else {
                // The layer's own mod.rs.
                continue;
            };
            for used in engine_uses(&fs::read_to_string(&file).unwrap(), &module) {
                seen += 1;
                match rank.get(&used) {
                    Some(&theirs) if theirs <= mine => {}
                    Some(_) => wrong.push(format!(
                        "{}: {} uses {}::{} declared after it",
                        file.display(),
                        module[..2].join("::"),
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
    assert!(seen > 500, "only {seen} uses read: the scan missed them");
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

fn pairs(v: &[(&str, &str)]) -> Vec<(String, String)> {
    v.iter()
        .map(|(a, b)| ((*a).to_string(), (*b).to_string()))
        .collect()
}

fn module(path: &str) -> Vec<String> {
    path.split("::").map(str::to_string).collect()
}

#[test]
fn the_order_check_reads_uses() {
    let text = "use crate::engine::base::robot::Robot; // crate::engine::uses::measure\n\
                let x = crate::engine::calibrate::solve::run(a);\n\
                let s = \"crate::engine::uses::measure\";";
    assert_eq!(
        engine_uses(text, &module("tools::plan::select")),
        pairs(&[("base", "robot"), ("calibrate", "solve")])
    );
}

#[test]
fn the_order_check_reads_groups_and_super_paths() {
    // A unit of the layer `calibrate` (`solve/ml/problem.rs`) naming a
    // sibling unit through `super::`, and a group of `crate::engine` paths.
    let text = "use super::super::super::{stripe::fit_circle, handeye};\n\
                use super::Estimate;\n\
                use crate::engine::{base::{geometry, numeric::show}, files::format};\n\
                fn f() { let c = '{'; let s = r#\"super::x {\"#; }";
    assert_eq!(
        engine_uses(text, &module("calibrate::solve::ml::problem")),
        pairs(&[
            ("calibrate", "stripe"),
            ("calibrate", "handeye"),
            ("calibrate", "solve"),
            ("base", "geometry"),
            ("base", "numeric"),
            ("files", "format"),
        ])
    );
}

#[test]
fn super_in_an_inline_module_is_the_file_itself() {
    let text = "use super::validate;\n\
                #[cfg(test)]\n\
                mod tests {\n    use super::*;\n    use super::super::solve;\n}\n\
                fn after() { super::stripe::f(); }";
    assert_eq!(
        engine_uses(text, &module("calibrate::handeye")),
        pairs(&[
            ("calibrate", "validate"),
            ("calibrate", "handeye"),
            ("calibrate", "solve"),
            ("calibrate", "stripe"),
        ])
    );
}

#[test]
fn a_super_path_to_a_later_unit_is_caught() {
    // `stripe` (unit 0 of calibrate) naming `solve` (unit 3) through
    // `super::`: the kind of import the check exists to refuse.
    let uses = engine_uses(
        "use super::super::solve::run;",
        &module("calibrate::stripe::circle"),
    );
    assert_eq!(uses, pairs(&[("calibrate", "solve")]));
    let engine = root().join("src/engine");
    let calibrate = declared(&engine.join("calibrate/mod.rs"));
    let at = |u: &str| calibrate.iter().position(|x| x == u).unwrap();
    assert!(at("solve") > at("stripe"));
}
