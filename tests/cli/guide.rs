//! The user guide (`docs/`) and README.md as a user meets them: every
//! command of a `console` block runs as written and prints what the guide
//! quotes, every link and image points at a file that exists, every
//! chapter SUMMARY.md lists is there, and README.md stays a two-screen
//! front door. The block conventions are in `docs/README.md`.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "tests fail by panicking"
)]

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

/// README.md at most this many bytes: two screens a newcomer reads in a
/// few minutes (issue 29); the rest lives once in the guide.
const README_MAX_BYTES: usize = 10_000;

/// The repository folders a chapter's commands may read, copied into the
/// chapter's scratch folder so that nothing a command writes lands in the
/// repository.
const DATA_FOLDERS: [&str; 5] = ["sessions", "examples", "data", "tests/data", "benches"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One fenced block of a Markdown file.
#[derive(Debug, Clone, PartialEq)]
struct Block {
    /// The info string after the opening fence (`console`, `bash norun`, …).
    info: String,
    /// 1-based line of the opening fence.
    line: usize,
    lines: Vec<String>,
}

/// The fenced blocks of a Markdown text (``` or ```` fences).
fn blocks(text: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<(String, Block)> = None;
    for (n, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        match &mut open {
            None => {
                if trimmed.starts_with("```") {
                    let fence: String = trimmed.chars().take_while(|&c| c == '`').collect();
                    let info = trimmed[fence.len()..].trim().to_string();
                    open = Some((
                        fence,
                        Block {
                            info,
                            line: n + 1,
                            lines: Vec::new(),
                        },
                    ));
                }
            }
            Some((fence, block)) => {
                if trimmed.starts_with(fence.as_str())
                    && trimmed.trim_start_matches('`').trim().is_empty()
                {
                    out.push(block.clone());
                    open = None;
                } else {
                    block.lines.push(line.to_string());
                }
            }
        }
    }
    out
}

/// One command of a console block and the output the guide quotes.
#[derive(Debug, Clone, PartialEq)]
struct Step {
    command: String,
    expected: Vec<String>,
    exit: i32,
    /// Where it stands: `file:line`.
    place: String,
}

fn steps(file: &str, block: &Block) -> Vec<Step> {
    let mut out: Vec<Step> = Vec::new();
    for (k, line) in block.lines.iter().enumerate() {
        if let Some(command) = line.strip_prefix("$ ") {
            out.push(Step {
                command: command.to_string(),
                expected: Vec::new(),
                exit: 0,
                place: format!("{file}:{}", block.line + k + 1),
            });
        } else if let Some(step) = out.last_mut() {
            let t = line.trim();
            if let Some(code) = t.strip_prefix("[exit ").and_then(|c| c.strip_suffix(']')) {
                step.exit = code.parse().expect("[exit N] takes a number");
            } else {
                step.expected.push(line.trim_end().to_string());
            }
        }
    }
    // Trailing blank lines quote nothing.
    for s in &mut out {
        while s.expected.last().is_some_and(String::is_empty) {
            s.expected.pop();
        }
    }
    out
}

/// `pattern` with `[..]` standing for any text matches `line`.
fn line_matches(pattern: &str, line: &str) -> bool {
    let parts: Vec<&str> = pattern.split("[..]").collect();
    if parts.len() == 1 {
        return pattern == line;
    }
    let mut rest = line;
    for (k, part) in parts.iter().enumerate() {
        if k == 0 {
            match rest.strip_prefix(part) {
                Some(r) => rest = r,
                None => return false,
            }
        } else if k == parts.len() - 1 {
            return rest.ends_with(part);
        } else {
            match rest.find(part) {
                Some(i) => rest = &rest[i + part.len()..],
                None => return false,
            }
        }
    }
    true
}

/// The expected lines (with `...` lines and `[..]` wildcards) match the
/// actual lines, every one of them.
fn output_matches(expected: &[String], actual: &[String]) -> bool {
    // Table of "expected[i..] matches actual[j..]", filled from the end.
    let (n, m) = (expected.len(), actual.len());
    let mut ok = vec![vec![false; m + 1]; n + 1];
    ok[n][m] = true;
    for i in (0..n).rev() {
        for j in (0..=m).rev() {
            ok[i][j] = if expected[i].trim() == "..." {
                ok[i + 1][j] || (j < m && ok[i][j + 1])
            } else {
                j < m && line_matches(&expected[i], &actual[j]) && ok[i + 1][j + 1]
            };
        }
    }
    ok[0][0]
}

fn copy_tree(from: &Path, to: &Path) {
    fs::create_dir_all(to).unwrap();
    for entry in fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// A scratch folder with the data folders and `bin/spherecal`.
fn scratch() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for folder in DATA_FOLDERS {
        let from = root().join(folder);
        if from.is_dir() {
            copy_tree(&from, &dir.path().join(folder));
        }
    }
    dir
}

/// Runs every step of one chapter in order; returns the failures.
fn run_chapter(file: &str, text: &str) -> Vec<String> {
    let runnable: Vec<Step> = blocks(text)
        .iter()
        .filter(|b| b.info == "console")
        .flat_map(|b| steps(file, b))
        .collect();
    if runnable.is_empty() {
        return Vec::new();
    }
    let dir = scratch();
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_spherecal"));
    let bin_dir = bin.parent().unwrap().to_path_buf();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut failures = Vec::new();
    for step in runnable {
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!("exec 2>&1; {}", step.command))
            .current_dir(dir.path())
            .env("PATH", &path)
            // No window: a command that would open one says so instead.
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        let actual: Vec<String> = text.lines().map(|l| l.trim_end().to_string()).collect();
        let code = out.status.code().unwrap_or(-1);
        let mut wrong = Vec::new();
        if code != step.exit {
            wrong.push(format!("exit {code}, the guide expects {}", step.exit));
        }
        if !step.expected.is_empty() && !output_matches(&step.expected, &actual) {
            wrong.push(format!(
                "output differs.\n--- the guide quotes:\n{}\n--- it printed:\n{}",
                step.expected.join("\n"),
                actual.join("\n")
            ));
        }
        if !wrong.is_empty() {
            failures.push(format!(
                "{}: `{}`: {}",
                step.place,
                step.command,
                wrong.join("; ")
            ));
        }
    }
    failures
}

/// Every Markdown file of the guide, as (path relative to the root, text).
fn guide_files() -> Vec<(String, String)> {
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
fn every_command_of_the_guide_runs_as_written() {
    let files = guide_files();
    let failures: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = files
            .iter()
            .map(|(file, text)| s.spawn(move || run_chapter(file, text)))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    assert!(
        failures.is_empty(),
        "{} guide command(s) failed:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

#[test]
fn commands_outside_console_blocks_are_marked_norun() {
    let mut unmarked = Vec::new();
    for (file, text) in guide_files() {
        for block in blocks(&text) {
            if block.info == "console" || block.info.split_whitespace().any(|w| w == "norun") {
                continue;
            }
            if block.lines.iter().any(|l| {
                let l = l.trim_start().trim_start_matches("$ ");
                l.starts_with("spherecal ") || l == "spherecal"
            }) {
                unmarked.push(format!(
                    "{file}:{}: a `{}` block runs spherecal",
                    block.line, block.info
                ));
            }
        }
    }
    assert!(
        unmarked.is_empty(),
        "write them as `console` (run by the tests) or mark the block `norun`:\n{}",
        unmarked.join("\n")
    );
}

/// Link and image targets of a Markdown text that are local files.
fn local_targets(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut in_block = false;
    for (n, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            in_block = !in_block;
            continue;
        }
        if in_block {
            continue;
        }
        for part in line.split("](").skip(1) {
            let target = part.split(')').next().unwrap_or("");
            let target = target.split_whitespace().next().unwrap_or("");
            let target = target.split('#').next().unwrap_or("");
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            out.push((n + 1, target.to_string()));
        }
    }
    out
}

/// `path` with `.` and `..` resolved by name, links not followed.
fn lexical(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            std::path::Component::ParentDir => {
                out.pop();
            }
            std::path::Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

#[test]
fn every_link_and_image_points_at_a_file() {
    let mut missing = Vec::new();
    let mut count = 0;
    let book = root().join("docs/src");
    for (file, text) in guide_files() {
        let base = root().join(&file);
        let dir = base.parent().unwrap();
        for (n, target) in local_targets(&text) {
            count += 1;
            let path = dir.join(&target);
            if !path.exists() {
                missing.push(format!("{file}:{n}: {target}"));
            } else if base.starts_with(&book) && !lexical(&path).starts_with(&book) {
                // mdbook copies only what lies under docs/src into the
                // book: screenshots are reached through docs/src/assets
                // (a link to the repository's assets/).
                missing.push(format!(
                    "{file}:{n}: {target} lies outside docs/src (the built book would miss it; use the assets/ link in docs/src)"
                ));
            }
        }
    }
    assert!(count > 20, "only {count} links found: the scan missed them");
    assert!(
        missing.is_empty(),
        "links and images to missing files:\n{}",
        missing.join("\n")
    );
}

#[test]
fn every_chapter_of_the_summary_exists() {
    let summary = fs::read_to_string(root().join("docs/src/SUMMARY.md")).unwrap();
    let chapters = local_targets(&summary);
    assert!(chapters.len() >= 20, "SUMMARY.md lists {}", chapters.len());
    let book = fs::read_to_string(root().join("docs/book.toml")).unwrap();
    assert!(book.contains("src = \"src\""));
    for (n, chapter) in chapters {
        let path = root().join("docs/src").join(&chapter);
        let text = fs::read_to_string(&path)
            .unwrap_or_else(|_| panic!("SUMMARY.md line {n}: {chapter} is missing"));
        assert!(
            text.lines().any(|l| l.starts_with("# ")),
            "{chapter} has no title"
        );
    }
}

#[test]
fn the_readme_is_two_screens() {
    let readme = fs::read(root().join("README.md")).unwrap();
    assert!(
        readme.len() <= README_MAX_BYTES,
        "README.md is {} bytes (at most {README_MAX_BYTES}): move the detail into the guide",
        readme.len()
    );
    let text = String::from_utf8(readme).unwrap();
    for command in ["cargo run --release", "cargo test"] {
        assert!(
            text.contains(command),
            "README.md does not give `{command}`"
        );
    }
}

// The harness itself: each check can fail.

#[test]
fn wildcards_match_and_can_fail() {
    let exp = |v: &[&str]| v.iter().map(ToString::to_string).collect::<Vec<_>>();
    assert!(line_matches("rms [..] mm", "rms 0.083 mm"));
    assert!(!line_matches("rms [..] mm", "rms 0.083 µm"));
    assert!(line_matches("[..]", "anything"));
    assert!(output_matches(
        &exp(&["a", "...", "z"]),
        &exp(&["a", "b", "c", "z"])
    ));
    assert!(output_matches(&exp(&["...", "z"]), &exp(&["z"])));
    assert!(!output_matches(&exp(&["a", "z"]), &exp(&["a", "b", "z"])));
    assert!(!output_matches(&exp(&["a"]), &exp(&["a", "b"])));
}

#[test]
fn steps_read_commands_outputs_and_exit_codes() {
    let text = "```console\n$ spherecal x\nline [..]\n[exit 3]\n$ true\n```\n```bash norun\nspherecal gui\n```\n";
    let b = blocks(text);
    assert_eq!(b.len(), 2);
    let s = steps("f.md", &b[0]);
    assert_eq!(s.len(), 2);
    assert_eq!(s[0].command, "spherecal x");
    assert_eq!(s[0].expected, ["line [..]"]);
    assert_eq!(s[0].exit, 3);
    assert_eq!(s[0].place, "f.md:2");
    assert!(s[1].expected.is_empty());
    assert_eq!(b[1].info, "bash norun");
}

#[test]
fn a_failing_command_is_reported() {
    let text = "```console\n$ spherecal no-such-command\n```\n```console\n$ echo hi\nho\n```\n";
    let failures = run_chapter("t.md", text);
    assert_eq!(failures.len(), 2, "{failures:?}");
    assert!(failures[0].contains("t.md:2") && failures[0].contains("exit 2"));
    assert!(failures[1].contains("output differs"));
}

#[test]
fn a_link_to_a_missing_file_is_found() {
    let t = local_targets(
        "see [a](x.md) and ![b](../assets/n.png \"t\") [c](https://e.org)\n```\n[d](no.md)\n```",
    );
    assert_eq!(
        t,
        [(1, "x.md".to_string()), (1, "../assets/n.png".to_string())]
    );
}
