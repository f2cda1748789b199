//! `spherecal history FOLDER`: the library table of a folder of sessions
//! and results, then per robot the drift of the hand-eye and of the main
//! kinematic deviations, and the jumps beyond `k` combined σ. A thin caller
//! of [`crate::engine::tools::history`]; it prints, the engine does not.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::engine::base::numeric::plural;
use crate::engine::files::format;
use crate::engine::tools::history::{
    self, CheckEntry, DEFAULT_K, DEFAULT_TOP, Drift, DriftOptions, Entry, Library, Series,
    SeriesKind, Verdict,
};

use super::CliError;

/// Longest session name shown in the library table; longer ones are cut
/// with an ellipsis (the CSV has them whole).
const NAME_WIDTH: usize = 36;
/// Drift columns per table: six keep a line near 130 characters.
const COLUMNS: usize = 6;

/// `spherecal history`.
#[derive(Debug, Clone, clap::Args)]
pub struct HistoryArgs {
    /// Folder to scan for session and result files (subfolders too, 8 levels deep).
    pub folder: PathBuf,
    /// Only this robot: its name in the result files, or a unique part of it (case-insensitive).
    #[arg(long)]
    pub robot: Option<String>,
    /// Flag a change between consecutive results larger than k × sqrt(σ₁² + σ₂²).
    #[arg(long, default_value_t = DEFAULT_K, value_parser = parse_k)]
    pub k: f64,
    /// Number of main kinematic deviations to show (largest median |value|/σ).
    #[arg(long, default_value_t = DEFAULT_TOP)]
    pub top: usize,
    /// Kinematic parameters to show as well, comma-separated (e.g. theta3,d4).
    #[arg(long, value_delimiter = ',')]
    pub param: Vec<String>,
    /// Also write every parameter of every result shown, with σ, as CSV (one row per result and parameter).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// With --csv: print nothing but errors (without it the tables are the command's output).
    #[arg(long, short, requires = "csv")]
    pub quiet: bool,
}

/// Largest `--k`: a change beyond 1000 combined σ is no test at all (no
/// jump could ever be flagged), so a larger k is a typo.
const MAX_K: f64 = 1000.0;

fn parse_k(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(k) if k.is_finite() && k > 0.0 && k <= MAX_K => Ok(k),
        Ok(k) if k > MAX_K => Err(format!(
            "k = {} would flag no jump at all: give at most {MAX_K} (σ)",
            crate::engine::base::numeric::show(k)
        )),
        _ => Err(format!("expected a positive number, got `{s}`")),
    }
}

/// Runs `spherecal history`.
///
/// # Errors
/// Status 2 when the folder cannot be read, the robot or a parameter is
/// unknown, or the CSV is refused or cannot be written.
pub fn run(args: &HistoryArgs) -> Result<(), CliError> {
    if let Some(path) = &args.csv {
        super::check_outputs(&[path], format::Folders::Existing)?;
    }
    let library =
        history::read_library(&args.folder).map_err(|e| CliError::input(e.to_string()))?;
    let robots: Vec<String> = match &args.robot {
        Some(query) => vec![
            library
                .find_robot(query)
                .map_err(|e| CliError::input(format!("{e} ({})", args.folder.display())))?,
        ],
        None => library.robots().into_iter().map(|(n, _)| n).collect(),
    };
    let options = DriftOptions {
        k: args.k,
        top: args.top,
        extra: args.param.clone(),
    };
    let drifts = robots
        .iter()
        .map(|r| history::drift(&library, r, &options))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| CliError::input(e.to_string()))?;
    let shown: Vec<usize> = match &args.robot {
        Some(_) => drifts.iter().flat_map(|d| d.entries.clone()).collect(),
        None => (0..library.entries.len()).collect(),
    };
    let checks: Vec<&CheckEntry> = library
        .checks
        .iter()
        .filter(|c| args.robot.is_none() || robots.contains(&c.record.robot))
        .collect();
    if !args.quiet {
        say!("{}", library_text(&library, &shown));
        say!("{}", checks_text(&checks));
        for d in &drifts {
            say!("{}", drift_text(&library, d));
        }
    }
    if let Some(path) = &args.csv {
        let inputs: Vec<&Path> = library
            .entries
            .iter()
            .map(|e| e.path.as_path())
            .chain(library.sessions.iter().map(|s| s.path.as_path()))
            .chain(library.problems.iter().map(|p| p.path.as_path()))
            .chain(library.ignored.iter().map(|(p, _)| p.as_path()))
            .chain(library.checks.iter().map(|c| c.path.as_path()))
            .collect();
        CliError::guard_output(path, &inputs)?;
        format::write_atomic(path, history::drift_csv(&library, &drifts).as_bytes())
            .map_err(|e| CliError::from_file(&e, false))?;
        if !args.quiet {
            sayln!("\nwrote {}", path.display());
        }
    }
    Ok(())
}

/// The re-checks (`spherecal check`'s records), oldest first: date,
/// verdict, robot, the calibration checked, the statistics and what moved.
fn checks_text(checks: &[&CheckEntry]) -> String {
    let mut s = String::new();
    if checks.is_empty() {
        return s;
    }
    let _ = writeln!(s, "\nchecks (spherecal check):");
    for c in checks {
        let r = &c.record;
        let _ = writeln!(
            s,
            "  {}  {}  {}  {:?} against {:?}: T {:.1} / {:.1}, T_d {:.1} / {} ({} sightings, α {}){}",
            c.date,
            if r.holds { "HOLDS" } else { "FAILS" },
            cut(&r.robot, 16),
            cut(&r.session, NAME_WIDTH),
            r.result_session,
            r.statistic,
            r.threshold,
            r.directed,
            r.directed_threshold
                .map_or_else(|| "-".into(), |t| format!("{t:.1}")),
            r.sightings,
            r.alpha,
            if r.hand_eye_only {
                ", hand-eye only"
            } else {
                ""
            }
        );
        if let Some(moved) = &r.moved {
            let _ = writeln!(s, "      {moved}");
        }
        let _ = writeln!(s, "      ({})", c.path.display());
    }
    s
}

fn cut(s: &str, width: usize) -> String {
    if s.chars().count() <= width {
        s.to_string()
    } else {
        let mut out: String = s.chars().take(width - 1).collect();
        out.push('…');
        out
    }
}

fn opt(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.decimals$}"))
}

/// The library table and what could not be used.
fn library_text(library: &Library, shown: &[usize]) -> String {
    let mut s = String::new();
    let without = library.sessions_without_result().count();
    let _ = writeln!(
        s,
        "library {}: {} ({}), {} ({} without a result), {}, {} of other formats ignored",
        library.root.display(),
        plural(library.entries.len(), "result", "results"),
        plural(library.robots().len(), "robot", "robots"),
        plural(library.sessions.len(), "session file", "session files"),
        without,
        plural(library.problems.len(), "problem", "problems"),
        plural(library.ignored.len(), "JSON file", "JSON files"),
    );
    if !shown.is_empty() {
        let dw = date_width(library, shown);
        let _ = writeln!(
            s,
            "\n{:<dw$}  {:<17}  {:<16}  {:<NAME_WIDTH$}  {:<6}  {:>10}  {:>10}  {} x, y, z mm; roll, pitch, yaw deg",
            "date",
            "date from",
            "robot",
            "session",
            "method",
            "std before",
            "std after",
            history::sensor_name(shown.iter().map(|&i| library.entries[i].mount))
        );
        for &i in shown {
            let e = &library.entries[i];
            let _ = writeln!(
                s,
                "{:<dw$}  {:<17}  {:<16}  {:<NAME_WIDTH$}  {:<6}  {:>10}  {:>10}  {}",
                e.date.to_string(),
                e.date_source.as_str(),
                cut(&e.robot, 16),
                cut(&e.session, NAME_WIDTH),
                e.method,
                opt(e.validation_before.map(|v| v.std), 3),
                opt(e.validation_std_after(), 4),
                hand_eye_text(e),
            );
        }
    }
    if without > 0 {
        let _ = writeln!(s, "\nsessions without a result:");
        for x in library.sessions_without_result() {
            let _ = writeln!(
                s,
                "  {} ({}): {:?}, {}, {} measurements ({})",
                x.date,
                x.date_source.as_str(),
                x.name,
                x.robot,
                x.measurements,
                x.path.display()
            );
        }
    }
    if !library.problems.is_empty() {
        let _ = writeln!(s, "\nproblems (files not used):");
        for p in &library.problems {
            let _ = writeln!(s, "  {p}");
        }
    }
    for &i in shown {
        let e = &library.entries[i];
        for n in &e.notes {
            let _ = writeln!(s, "  note, {}: {n}", e.path.display());
        }
        if e.session_path.is_none() {
            let _ = writeln!(
                s,
                "  note, {}: no session file found for {:?}",
                e.path.display(),
                e.session
            );
        }
    }
    s
}

/// Width of the date column: 10 for dates, 19 when one has a time.
fn date_width(library: &Library, shown: &[usize]) -> usize {
    if shown.iter().any(|&i| library.entries[i].date.has_time) {
        19
    } else {
        10
    }
}

fn hand_eye_text(e: &Entry) -> String {
    let t = e.hand_eye.translation;
    let r = e.hand_eye.rpy_deg;
    format!(
        "{:.3}, {:.3}, {:.3}; {:.3}, {:.3}, {:.3}",
        t[0], t[1], t[2], r[0], r[1], r[2]
    )
}

/// One robot: drift tables, jumps, checks not possible, notes.
fn drift_text(library: &Library, d: &Drift) -> String {
    let mut s = String::new();
    let first = d.entries.first().map(|&i| library.entries[i].date);
    let last = d.entries.last().map(|&i| library.entries[i].date);
    let _ = writeln!(
        s,
        "\n== {}: {}{}",
        d.robot,
        plural(d.entries.len(), "result", "results"),
        match (first, last) {
            (Some(a), Some(b)) if d.entries.len() > 1 => format!(", {a} to {b}"),
            _ => String::new(),
        }
    );
    let hand_eye: Vec<&Series> = d
        .series
        .iter()
        .filter(|x| x.kind == SeriesKind::HandEye)
        .collect();
    let kinematic: Vec<&Series> = d
        .series
        .iter()
        .filter(|x| x.kind != SeriesKind::HandEye)
        .collect();
    s.push_str(&series_table(
        library,
        d,
        match d.mount {
            history::Mount::Flange => {
                "hand-eye eT_s (translation mm in the flange frame, roll/pitch/yaw deg), ± 1σ:"
            }
            history::Mount::Fixed => {
                "base_from_sensor bT_s, a fixed sensor (translation mm in the base frame, roll/pitch/yaw deg), ± 1σ:"
            }
        },
        &hand_eye,
    ));
    let by_sigma = kinematic
        .iter()
        .any(|x| matches!(x.kind, SeriesKind::Main { by_sigma: true, .. }));
    let title = format!(
        "kinematic deviations (calibrated − nominal, deg and mm), ± 1σ; main ones by median {}{}:",
        if by_sigma {
            "|value|/σ"
        } else {
            "|value| (no σ in these results; 1° counted as 17.45 mm)"
        },
        if kinematic
            .iter()
            .any(|x| x.kind != SeriesKind::HandEye && !matches!(x.kind, SeriesKind::Main { .. }))
        {
            ", then chosen (c) and jumped (j) ones"
        } else {
            ""
        }
    );
    s.push_str(&series_table(library, d, &title, &kinematic));

    let date = |i: usize| library.entries[i].date.to_string();
    let jumps: Vec<_> = d.jumps().collect();
    let _ = writeln!(
        s,
        "\njumps (|change| > k·sqrt(σ₁² + σ₂²), k = {}): {}",
        crate::engine::base::numeric::show(d.k),
        if jumps.is_empty() {
            "none".to_string()
        } else {
            jumps.len().to_string()
        }
    );
    for c in &jumps {
        let _ = writeln!(
            s,
            "  {} → {}  {:<14}  {:.4} → {:.4} {}  change {:+.4}  σ {} / {}  combined {}  ratio {:.1}",
            date(c.from),
            date(c.to),
            c.parameter,
            c.before,
            c.after,
            c.unit.as_str(),
            c.change,
            opt(c.sigma_before, 4),
            opt(c.sigma_after, 4),
            opt(c.combined, 4),
            c.ratio.unwrap_or(f64::NAN),
        );
        for n in &c.notes {
            let _ = writeln!(s, "      {n}");
        }
    }
    // Checks not possible, grouped by pair and reason.
    let mut groups: Vec<(usize, usize, String, Vec<&str>)> = Vec::new();
    for c in &d.checks {
        if let Verdict::NotChecked(reason) = &c.verdict {
            match groups
                .iter_mut()
                .find(|g| g.0 == c.from && g.1 == c.to && g.2 == *reason)
            {
                Some(g) => g.3.push(&c.parameter),
                None => groups.push((c.from, c.to, reason.clone(), vec![&c.parameter])),
            }
        }
    }
    if !groups.is_empty() {
        let _ = writeln!(s, "not checked:");
        for (from, to, reason, params) in &groups {
            let _ = writeln!(
                s,
                "  {} → {}: {}: {}",
                date(*from),
                date(*to),
                plural(params.len(), "parameter", "parameters"),
                reason
            );
        }
    }
    let steady = d
        .checks
        .iter()
        .filter(|c| c.verdict == Verdict::Steady)
        .count();
    let _ = writeln!(
        s,
        "checked: {} over {}: {} steady, {} jumps",
        plural(
            d.checks
                .iter()
                .filter(|c| !matches!(c.verdict, Verdict::NotChecked(_)))
                .count(),
            "value",
            "values"
        ),
        plural(d.entries.len(), "result", "results"),
        steady,
        jumps.len()
    );
    for n in &d.notes {
        let _ = writeln!(s, "note: {n}");
    }
    s
}

fn series_table(library: &Library, d: &Drift, title: &str, series: &[&Series]) -> String {
    let mut s = String::new();
    if series.is_empty() {
        return s;
    }
    let _ = writeln!(s, "\n{title}");
    let dw = date_width(library, &d.entries);
    for chunk in series.chunks(COLUMNS) {
        let _ = write!(s, "{:<dw$}", "date");
        for x in chunk {
            let mark = match x.kind {
                SeriesKind::Chosen => " (c)",
                SeriesKind::Jumped => " (j)",
                _ => "",
            };
            let name = x.name.strip_prefix("hand_eye.").unwrap_or(&x.name);
            let _ = write!(s, "  {:>19}", format!("{name} {}{mark}", x.unit.as_str()));
        }
        let _ = writeln!(s);
        for &e in &d.entries {
            let _ = write!(s, "{:<dw$}", library.entries[e].date.to_string());
            for x in chunk {
                let cell = x.points.iter().find(|p| p.entry == e).map_or_else(
                    || "-".to_string(),
                    |p| {
                        let flag = match p.status {
                            history::Status::Fixed => " fixed",
                            _ if p.prior_held => " (p)",
                            _ => "",
                        };
                        match p.sigma {
                            Some(sigma) => format!("{:.4} ±{sigma:.4}{flag}", p.value),
                            None => format!("{:.4}{flag}", p.value),
                        }
                    },
                );
                let _ = write!(s, "  {cell:>19}");
            }
            let _ = writeln!(s);
        }
    }
    if series.iter().any(|x| x.points.iter().any(|p| p.prior_held)) {
        let _ = writeln!(
            s,
            "(p): held near nominal by the ml prior (σ ≥ {} × prior σ)",
            history::PRIOR_HELD_FRACTION
        );
    }
    s
}
