//! The command line's own description, held to the code: every `--help`
//! and value list as the engine has it, `-q` meaning "nothing printed but
//! errors" on every command that writes files, option errors naming the
//! flag and its unit (never a number of 309 digits), defaults shown one
//! way, the workbench without a display, and the guide's reference
//! chapter (`docs/src/reference/cli.md`) generated from the clap
//! definitions (`UPDATE_DOCS=1 cargo test --test cli cli_help` rewrites it).

// Test helpers may panic: a panic is a test failure with its message.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use crate::support::bin::{outcome, spherecal};
use spherecal::cli;

/// The repository root (the tests run from it; the paths say so).
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// (status, stdout, stderr) of `spherecal args…` run from the repository root.
fn run(args: &[&OsStr]) -> (i32, String, String) {
    outcome(&spherecal().current_dir(root()).args(args).output().unwrap())
}

fn run_str(args: &[&str]) -> (i32, String, String) {
    let args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
    run(&args)
}

/// The subcommands, built (bin names, propagated settings), without
/// clap's own `help`.
fn subcommands() -> Vec<clap::Command> {
    let mut cmd = cli::command();
    cmd.build();
    cmd.get_subcommands()
        .filter(|s| s.get_name() != "help")
        .cloned()
        .collect()
}

/// The options through which a command writes a file.
const OUTPUT_OPTIONS: [&str; 6] = ["out", "truth", "csv", "csv-out", "rapid", "program"];

/// Commands that write no file (they print, or open a window).
const WRITE_NO_FILE: [&str; 3] = ["gui", "evaluate", "check"];

/// A run of every command that writes files, on the repository's
/// examples, its outputs in `dir`; `calibrate` first (the others read its
/// result).
fn writing_runs(dir: &Path) -> Vec<(&'static str, Vec<PathBuf>)> {
    let p = |s: &str| PathBuf::from(s);
    let out = |s: &str| dir.join(s);
    vec![
        (
            "calibrate",
            vec![
                p("calibrate"),
                p("sessions/demo-irb2400.json"),
                p("-o"),
                out("r.json"),
            ],
        ),
        (
            "simulate",
            vec![
                p("simulate"),
                p("--seed"),
                p("3"),
                p("-o"),
                out("s.json"),
                p("--csv-out"),
                out("sim"),
            ],
        ),
        (
            "import",
            [
                "import",
                "--joints",
                "examples/log/log.csv",
                "--map",
                "id=Pose,station=Sphere,use=Use,side=Side,j1=A1,j2=A2,j3=A3,j4=A4,j5=A5,j6=A6",
                "--joint-unit",
                "rad",
                "--profiles",
                "examples/log/profiles",
                "--profile-unit",
                "um",
                "--robot",
                "irb2400",
                "--flange-poses",
                "kuka",
                "--flange-columns",
                "X,Y,Z,A,B,C",
                "--references",
                "examples/log/references.csv",
                "-o",
            ]
            .into_iter()
            .map(p)
            .chain([out("i.json")])
            .collect(),
        ),
        (
            "plan",
            vec![
                p("plan"),
                p("--sphere"),
                p("1050,0,475"),
                p("--predict"),
                p("1"),
                p("--csv"),
                out("plan.csv"),
                p("--program"),
                PathBuf::from(format!("urscript={}", out("plan.script").display())),
            ],
        ),
        (
            "report",
            vec![
                p("report"),
                p("sessions/demo-irb2400.json"),
                p("--result"),
                out("r.json"),
                p("--tolerance"),
                p("0.01,0.02"),
                p("-o"),
                out("r.html"),
            ],
        ),
        // The demo's validate poses lie outside the identify poses' joint
        // range: warnings that -q silences.
        (
            "measure",
            vec![
                p("measure"),
                p("sessions/demo-irb2400.json"),
                p("--result"),
                out("r.json"),
                p("-o"),
                out("cloud.csv"),
            ],
        ),
        (
            "export-model",
            vec![
                p("export-model"),
                out("r.json"),
                p("--format"),
                p("urdf"),
                p("-o"),
                out("m.urdf"),
            ],
        ),
        (
            "history",
            vec![
                p("history"),
                p("sessions/history"),
                p("--csv"),
                out("history.csv"),
            ],
        ),
        (
            "compensate",
            vec![
                p("compensate"),
                p("--result"),
                out("r.json"),
                p("--targets"),
                p("examples/path.mod"),
                p("-o"),
                out("path.mod"),
            ],
        ),
    ]
}

/// Issue 29: `-q` means "nothing printed but errors" on every command
/// that writes files (`measure -q` printed warnings, `history --csv`
/// refused `-q`). Every subcommand is either one that writes (then it has
/// `-q`, and a run of it with `-q` prints nothing at all) or one that
/// writes no file.
#[test]
fn quiet_prints_nothing_on_every_command_that_writes_files() {
    let dir = tempfile::tempdir().unwrap();
    let runs = writing_runs(dir.path());
    for sub in subcommands() {
        let name = sub.get_name();
        let outputs: Vec<&str> = sub
            .get_arguments()
            .filter_map(clap::Arg::get_long)
            .filter(|l| OUTPUT_OPTIONS.contains(l))
            .collect();
        let writes = runs.iter().any(|(n, _)| *n == name);
        assert!(
            writes != WRITE_NO_FILE.contains(&name),
            "`spherecal {name}`: add a run with -q to writing_runs, or list it in WRITE_NO_FILE"
        );
        assert_eq!(
            !outputs.is_empty(),
            writes,
            "`spherecal {name}`: output options {outputs:?}"
        );
        if writes {
            let quiet = sub
                .get_arguments()
                .find(|a| a.get_long() == Some("quiet"))
                .unwrap_or_else(|| panic!("`spherecal {name}` writes files but has no --quiet"));
            assert_eq!(quiet.get_short(), Some('q'), "{name}");
        }
    }
    for (name, args) in &runs {
        let mut args: Vec<&OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        let (status, out, err) = run(&args);
        assert_eq!(status, 0, "`spherecal {name}` without -q failed: {err}");
        assert!(
            !out.is_empty(),
            "`spherecal {name}` says what it did without -q"
        );
        args.push(OsStr::new("-q"));
        let (status, out, err) = run(&args);
        assert_eq!(status, 0, "`spherecal {name} -q`: {err}");
        assert_eq!(out, "", "`spherecal {name} -q` printed on stdout");
        assert_eq!(err, "", "`spherecal {name} -q` printed on stderr");
    }
    // The runs wrote what they say.
    for file in [
        "r.json",
        "s.json",
        "i.json",
        "plan.csv",
        "plan.script",
        "r.html",
    ] {
        assert!(dir.path().join(file).is_file(), "{file}");
    }
    for file in [
        "cloud.csv",
        "m.urdf",
        "history.csv",
        "path.mod",
        "sim/joints.csv",
    ] {
        assert!(dir.path().join(file).is_file(), "{file}");
    }
    // Without --csv, -q would silence the whole output: refused.
    let (status, _, err) = run_str(&["history", "sessions/history", "-q"]);
    assert_eq!(status, 2, "{err}");
    assert!(err.contains("--csv"), "{err}");
}

/// Every value that a flag's help lists is one its parser takes: the
/// lists come from the engine, and cannot fall behind it. (clap parses
/// each value as it reads it, before it checks what else is missing.)
#[test]
fn every_listed_value_is_accepted() {
    use clap::error::ErrorKind;
    let mut checked = 0;
    for sub in subcommands() {
        for arg in sub.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            for value in arg.get_possible_values() {
                let flag = format!("--{long}");
                let argv = ["spherecal", sub.get_name(), flag.as_str(), value.get_name()];
                if let Err(e) = cli::command().try_get_matches_from(argv) {
                    assert!(
                        !matches!(
                            e.kind(),
                            ErrorKind::InvalidValue | ErrorKind::ValueValidation
                        ),
                        "{argv:?}: listed value refused: {e}"
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(checked > 40, "{checked} values");
}

fn values_of(sub: &str, long: &str) -> Vec<String> {
    let subs = subcommands();
    let cmd = subs.iter().find(|s| s.get_name() == sub).unwrap();
    let arg = cmd
        .get_arguments()
        .find(|a| a.get_long() == Some(long))
        .unwrap_or_else(|| panic!("spherecal {sub} --{long}"));
    arg.get_possible_values()
        .iter()
        .map(|v| v.get_name().to_owned())
        .collect()
}

fn help_of(sub: &str, long: &str) -> String {
    let subs = subcommands();
    let cmd = subs.iter().find(|s| s.get_name() == sub).unwrap();
    let arg = cmd
        .get_arguments()
        .find(|a| a.get_long() == Some(long))
        .unwrap_or_else(|| panic!("spherecal {sub} --{long}"));
    arg.get_help().map(ToString::to_string).unwrap_or_default()
}

/// Issue 29: `--flange-poses` omitted `matrix`, `evaluate --scenario`
/// omitted `stations-30-spread`. The lists are the engine's, in full.
#[test]
fn value_lists_are_the_engines() {
    use spherecal::engine::base::robot::RobotChoice;
    use spherecal::engine::base::robot::controller::FlangeConvention;
    use spherecal::engine::calibrate::solve::Method;
    use spherecal::engine::files::program::PoseFormat;
    use spherecal::engine::tools::evaluate::study::SCENARIOS;

    let conventions: Vec<String> = FlangeConvention::ALL
        .iter()
        .map(|c| c.key().to_owned())
        .collect();
    assert!(conventions.contains(&"matrix".to_owned()));
    for (sub, long) in [
        ("import", "flange-poses"),
        ("import", "pose-convention"),
        ("measure", "pose-convention"),
        ("compensate", "pose-convention"),
    ] {
        assert_eq!(values_of(sub, long), conventions, "{sub} --{long}");
    }
    let formats: Vec<String> = PoseFormat::ALL.iter().map(|f| f.key().to_owned()).collect();
    for sub in ["import", "measure", "compensate"] {
        assert_eq!(values_of(sub, "pose-format"), formats, "{sub}");
    }
    let mut scenarios = vec!["all".to_owned()];
    scenarios.extend(SCENARIOS.iter().map(|s| s.key.to_owned()));
    assert!(scenarios.contains(&"stations-30-spread".to_owned()));
    assert_eq!(values_of("evaluate", "scenario"), scenarios);
    let methods: Vec<String> = Method::ALL.iter().map(|m| m.as_str().to_owned()).collect();
    assert_eq!(values_of("calibrate", "method"), methods);
    assert_eq!(values_of("report", "method"), methods);
    let presets: Vec<String> = RobotChoice::ALL
        .iter()
        .map(|r| r.key().to_owned())
        .collect();
    assert_eq!(values_of("simulate", "robot"), presets);
    for (sub, long) in [("import", "robot"), ("plan", "robot"), ("measure", "robot")] {
        let help = help_of(sub, long);
        for key in &presets {
            assert!(
                help.contains(key.as_str()),
                "{sub} --{long} omits {key}: {help}"
            );
        }
    }
    let program = help_of("plan", "program");
    for key in ["rapid", "urscript"] {
        assert!(program.contains(key), "{program}");
    }
}

/// Issue 29: `import`'s summary said "a joint log CSV and stripe profile
/// files" only; it takes pose files of every layout and centres tables.
#[test]
fn summaries_say_what_each_command_takes() {
    let subs = subcommands();
    let about = |name: &str| {
        let sub = subs.iter().find(|s| s.get_name() == name).unwrap();
        format!(
            "{} {}",
            sub.get_about().map(ToString::to_string).unwrap_or_default(),
            sub.get_long_about()
                .map(ToString::to_string)
                .unwrap_or_default()
        )
    };
    let import = about("import");
    for word in [
        "--joints",
        "--poses",
        "--profiles",
        "--centres",
        "FANUC",
        "RAPID",
        "KUKA",
        "URScript",
    ] {
        assert!(
            import.contains(word),
            "import's summary omits {word}: {import}"
        );
    }
    for sub in &subs {
        let short = sub.get_about().map(ToString::to_string).unwrap_or_default();
        assert!(!short.is_empty(), "{} has no summary", sub.get_name());
        // The list of `spherecal --help` stays a list: one line each at 100 columns.
        assert!(short.chars().count() <= 110, "{}: {short}", sub.get_name());
    }
    // The scatter beyond which a calibration is refused is the engine's.
    let limit = format!(
        "beyond {} mm",
        spherecal::engine::calibrate::solve::plausible::MAX_PLAUSIBLE_SCATTER_MM
    );
    assert!(
        about("calibrate").contains(&limit),
        "{}",
        about("calibrate")
    );
    for sub in ["calibrate", "report"] {
        let help = help_of(sub, "accept-implausible");
        assert!(help.contains(&limit), "{sub}: {help}");
    }
    let gui = about("gui");
    assert!(
        gui.contains("DISPLAY") && gui.contains("WAYLAND_DISPLAY"),
        "{gui}"
    );
}

/// Issue 29: defaults were written three ways ("(default 5)", "default:
/// …", clap's `[default: …]`); every one reads `[default: …]` now.
#[test]
fn defaults_are_shown_one_way() {
    for sub in subcommands() {
        for arg in sub.get_arguments() {
            let texts = [arg.get_help(), arg.get_long_help()];
            for text in texts.into_iter().flatten() {
                let text = text.to_string();
                let lower = text.to_lowercase();
                for bad in ["(default", "by default", "default)"] {
                    assert!(
                        !lower.contains(bad),
                        "spherecal {} --{}: `{bad}` in {text:?}",
                        sub.get_name(),
                        arg.get_id()
                    );
                }
                for (at, _) in lower.match_indices("default:") {
                    assert!(
                        at > 0 && &lower[at - 1..at] == "[",
                        "spherecal {} --{}: write [default: …] in {text:?}",
                        sub.get_name(),
                        arg.get_id()
                    );
                }
            }
        }
    }
}

/// True when `text` holds a run of more than 18 digits (a number printed
/// in full: `1e308` as 309 digits).
fn has_long_number(text: &str) -> bool {
    let mut run = 0;
    for c in text.chars() {
        run = if c.is_ascii_digit() { run + 1 } else { 0 };
        if run > 18 {
            return true;
        }
    }
    false
}

/// Words of `text` that look like an engine's field name (`stripe_noise`,
/// `n_identify`): lower-case letters joined by underscores.
fn field_names(text: &str) -> Vec<String> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.'))
        .filter(|w| {
            w.contains('_')
                && !w.starts_with('-')
                && w.chars().all(|c| c.is_ascii_lowercase() || c == '_')
        })
        .map(str::to_owned)
        .collect()
}

/// The option errors to check: the arguments (`{plan}` and `{he}` stand
/// for a plan CSV and a hand-eye file with a translation of 1e308 mm;
/// commands that write get `-o` into the scratch folder) and what the
/// message must say.
const OPTION_ERRORS: [(&str, &[&str]); 21] = [
    (
        "simulate --stripe-noise 100",
        &["--stripe-noise", "mm", "10"],
    ),
    ("simulate --stripe-noise -1e308", &["--stripe-noise", "mm"]),
    (
        "simulate --identify-stations 9000 --validate-stations 9000",
        &["--identify-stations + --validate-stations", "10000"],
    ),
    ("simulate --error-scale 1e308", &["--error-scale", "1e308"]),
    ("simulate --point-spacing 100", &["--point-spacing"]),
    (
        "simulate --plan {plan} --hand-eye {he}",
        &["--hand-eye", "1e308 mm", "he.json"],
    ),
    (
        "calibrate D --rank-tolerance 1e308",
        &["--rank-tolerance", "(0, 1)"],
    ),
    (
        "calibrate D --svd-tolerance 1e308",
        &["--svd-tolerance", "(0, 1)"],
    ),
    ("calibrate D --joint-sigma -1", &["--joint-sigma", "deg"]),
    ("calibrate D --threshold 1e308", &["--threshold", "mm"]),
    ("calibrate D --max-iterations 1e308", &["--max-iterations"]),
    (
        "measure D --result r.json --sensor-noise 1e308",
        &["--sensor-noise", "mm"],
    ),
    (
        "measure D --result r.json --sphere-diameter 1e308",
        &["--sphere-diameter", "mm"],
    ),
    ("report D --tolerance 1e308,0.5", &["--tolerance", "mm"]),
    (
        "plan --sphere 1050,0,475 --cone 1e308",
        &["--cone", "deg", "1e308"],
    ),
    ("plan --sphere 1050,0,475 --angle 90", &["--angle", "deg"]),
    (
        "plan --sphere 1050,0,475 --diameter 1e308",
        &["--diameter", "mm"],
    ),
    (
        "plan --sphere 1050,0,475 --identify-stations 400 --validate-stations 200",
        &["--identify-stations + --validate-stations", "500"],
    ),
    (
        "plan --sphere 1050,0,475 --predict 100000 --hand-eye {he}",
        &["--predict"],
    ),
    (
        "import --poses p.txt --profiles d --sphere-diameter 0",
        &["--sphere-diameter", "mm"],
    ),
    ("evaluate --seeds 0", &["--seeds"]),
];

/// Issues 29 and 31: option errors named internal fields
/// (`stripe_noise`, `n_identify + n_validate`) and printed `1e308` as 309
/// digits. Each is refused with status 2, naming the flag (and its unit
/// where it has one), the number as people write it, nothing written.
#[test]
fn option_errors_name_the_flag_and_its_unit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let hand_eye = d.join("he.json");
    std::fs::write(&hand_eye, "[[1,0,0,1e308],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n").unwrap();
    let plan_csv = d.join("plan.csv");
    let plan = format!(
        "plan --sphere 1050,0,475 --predict 0 -q --csv {}",
        plan_csv.display()
    );
    let (status, _, err) = run_str(&plan.split_whitespace().collect::<Vec<_>>());
    assert_eq!(status, 0, "{err}");
    let x = d.join("x.json");
    for (args, needles) in OPTION_ERRORS {
        let mut argv: Vec<String> = args
            .split_whitespace()
            .map(|a| match a {
                "D" => "sessions/demo-irb2400.json".to_owned(),
                "{plan}" => plan_csv.display().to_string(),
                "{he}" => hand_eye.display().to_string(),
                other => other.to_owned(),
            })
            .collect();
        if ["simulate", "calibrate", "report", "measure", "import"].contains(&argv[0].as_str()) {
            argv.extend(["-o".to_owned(), x.display().to_string()]);
        }
        let argv: Vec<&str> = argv.iter().map(String::as_str).collect();
        let (status, stdout, err) = run_str(&argv);
        assert_eq!(status, 2, "{args}: {stdout}{err}");
        assert!(err.starts_with("error: "), "{args}: {err}");
        for needle in needles {
            assert!(
                err.contains(needle),
                "{args}: `{needle}` missing from {err}"
            );
        }
        assert!(!has_long_number(&err), "{args}: a number in full: {err}");
        assert_eq!(field_names(&err), Vec::<String>::new(), "{args}: {err}");
        assert!(!x.exists(), "{args}: written");
    }
}

/// Issue 31: `gui` without a display exited 1 with a panic-like text.
/// Now: status 2, one sentence naming DISPLAY and WAYLAND_DISPLAY and the
/// commands that need no display; `spherecal` alone the same.
#[cfg(all(feature = "gui", target_os = "linux"))]
#[test]
fn the_workbench_without_a_display_says_so_in_one_sentence() {
    for args in [
        vec!["gui"],
        vec![],
        vec!["gui", "sessions/demo-irb2400.json"],
    ] {
        let o = spherecal()
            .current_dir(root())
            .args(&args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(o.stdout.is_empty(), "{args:?}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("error: the workbench needs a display"),
            "{err}"
        );
        for needle in [
            "DISPLAY",
            "WAYLAND_DISPLAY",
            "spherecal calibrate",
            "spherecal --help",
        ] {
            assert!(err.contains(needle), "{args:?}: {needle}: {err}");
        }
        assert!(!err.to_lowercase().contains("panic"), "{err}");
    }
}

/// `spherecal --help` and each `spherecal <command> --help`, as the guide's
/// reference chapter shows them: at 100 columns, trailing spaces removed.
fn rendered_help() -> Vec<(String, String)> {
    let mut cmd = cli::command()
        .term_width(100)
        .mut_subcommands(|s| s.term_width(100));
    cmd.build();
    let tidy = |text: String| -> String {
        let lines: Vec<&str> = text.lines().map(str::trim_end).collect();
        format!("{}\n", lines.join("\n").trim_end())
    };
    // The top level has no long help of its own: `--help` prints the
    // short form there (`the_binary_prints_the_rendered_help` holds both
    // to the binary).
    let mut out = vec![("spherecal".to_owned(), tidy(cmd.render_help().to_string()))];
    for sub in cmd.get_subcommands_mut() {
        if sub.get_name() == "help" {
            continue;
        }
        let name = format!("spherecal {}", sub.get_name());
        out.push((name, tidy(sub.render_long_help().to_string())));
    }
    out
}

/// The chapter of the guide that shows each command at work.
const CHAPTERS: [(&str, &str, &str); 12] = [
    ("calibrate", "Calibrating", "../workflows/calibrating.md"),
    ("simulate", "A quick tour", "../getting-started/tour.md"),
    ("gui", "The workbench", "../workflows/workbench.md"),
    ("evaluate", "The ml method", "../evidence/ml.md"),
    (
        "export-model",
        "Reports, export and history",
        "../workflows/reports.md",
    ),
    ("import", "Importing data", "../workflows/importing.md"),
    ("plan", "Planning poses", "../workflows/planning.md"),
    (
        "report",
        "Reports, export and history",
        "../workflows/reports.md",
    ),
    ("measure", "Measuring parts", "../workflows/measuring.md"),
    (
        "history",
        "Reports, export and history",
        "../workflows/reports.md",
    ),
    (
        "compensate",
        "Compensating programs",
        "../workflows/compensating.md",
    ),
    ("check", "A five-minute re-check", "../workflows/recheck.md"),
];

/// The reference chapter: an intro with a table of the commands (their
/// summary, a link to their help below and to the chapter that shows
/// them at work), then every help in a `text` block.
fn reference_markdown() -> String {
    let mut md = String::from(
        "# The command line\n\n\
         <!-- Generated by tests/cli/cli_help.rs from the command line's own definitions \
         (src/cli); do not edit by hand. After changing a help text run \
         `UPDATE_DOCS=1 cargo test --test cli cli_help`. -->\n\n\
         Every `spherecal` command's `--help`, exactly as the program prints it \
         (here at 100 columns). `spherecal <command> -h` prints the short form. \
         Exit statuses and what each reader refuses are in \
         [Limits, exit codes and what readers refuse](limits.md).\n\n\
         | command | what it does | shown at work in |\n|---|---|---|\n",
    );
    let subs = subcommands();
    for sub in &subs {
        let name = sub.get_name();
        let (_, title, link) = CHAPTERS
            .iter()
            .find(|(n, _, _)| *n == name)
            .unwrap_or_else(|| panic!("add `spherecal {name}` to CHAPTERS"));
        let about = sub.get_about().map(ToString::to_string).unwrap_or_default();
        md.push_str(&format!(
            "| [`{name}`](#spherecal-{name}) | {} | [{title}]({link}) |\n",
            about.replace('|', "\\|")
        ));
    }
    for (name, help) in rendered_help() {
        md.push_str(&format!("\n## {name}\n\n```text\n{help}```\n"));
    }
    md
}

/// The guide's reference chapter is the help, generated: when a help text
/// changes, this fails until the chapter is regenerated.
#[test]
fn the_reference_chapter_is_the_help() {
    let path = root().join("docs/src/reference/cli.md");
    let expected = reference_markdown();
    if std::env::var_os("UPDATE_DOCS").is_some() {
        std::fs::write(&path, &expected).unwrap();
        return;
    }
    let found = std::fs::read_to_string(&path).unwrap_or_default();
    if found != expected {
        let first = found
            .lines()
            .zip(expected.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| found.lines().count().min(expected.lines().count()));
        panic!(
            "docs/src/reference/cli.md is not the command line's help (first difference at line {}); \
             run `UPDATE_DOCS=1 cargo test --test cli cli_help` to regenerate it",
            first + 1
        );
    }
}

/// The help shown in the chapter is the help the binary prints.
#[test]
fn the_binary_prints_the_rendered_help() {
    for (name, help) in rendered_help() {
        let mut args: Vec<&str> = name.split(' ').skip(1).collect();
        args.push("--help");
        let o = spherecal()
            .args(&args)
            .env("COLUMNS", "100")
            .output()
            .unwrap();
        assert!(o.status.success(), "{name}");
        let printed = String::from_utf8_lossy(&o.stdout);
        let printed: Vec<&str> = printed.lines().map(str::trim_end).collect();
        assert_eq!(
            format!("{}\n", printed.join("\n").trim_end()),
            help,
            "{name}"
        );
    }
}
