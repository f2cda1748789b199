//! Robot targets as cells write them: pose tables and robot programs.
//! One reader per layout, used by the import (a pose log: where the robot
//! was when each profile was taken) and by target compensation (the
//! targets of a program, rewritten in place). Every reader keeps, for
//! each target, the byte range of each of its numbers in the text, so a
//! program can be rewritten with every other byte kept.
//!
//! | layout | what is read | a pose is |
//! |---|---|---|
//! | [`PoseFormat::Table`] | rows of numbers, a header optional, separated by `,` `;` tabs or spaces | the convention's columns (by name, or in order without a header) |
//! | [`PoseFormat::Json`] | a list of poses (RobCalibrator's `.rob`: key `RobPoses`) | a list of the convention's numbers |
//! | [`PoseFormat::FanucLs`] | a FANUC TP program's `/POS` section (`P[n]{ GP1: … }`, GP1 only) | `X Y Z` mm, `W P R` deg, or `J1…Jn` deg |
//! | [`PoseFormat::Rapid`] | ABB RAPID `robtarget` / `jointtarget` declarations and literals | `[[x,y,z],[q1..q4],[cf…],[eax…]]`, or `[[j1..j6],[eax…]]` |
//! | [`PoseFormat::Krl`] | KUKA `.dat`/`.src`: `E6POS`, `POS`, `FRAME`, `E6AXIS`, `AXIS` aggregates | `{X …,Y …,Z …,A …,B …,C …}` or `{A1 …,…}` |
//! | [`PoseFormat::UrScript`] | URScript `p[x,y,z,rx,ry,rz]` and the joint lists of `movej`/`movel`/`movep` | m and rad |
//!
//! The layout is detected from the content ([`detect`]); a program's
//! poses are in the order its motion instructions first move to them
//! when it has any ([`PoseFile::order`], with [`PoseFile::order_note`]
//! saying which order was used), else in the order they are written.

mod fanuc;
mod json;
mod krl;
mod rapid;
mod lex;
pub mod style;
mod table;
mod urscript;

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::base::session::Use;
use crate::engine::files::format::{Cap, read_bytes, read_text};

pub use self::lex::{MAX_SHOWN_CHARS, name_list};
pub use self::table::Row;

/// The layout of a pose file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoseFormat {
    /// A table: rows of numbers, header optional.
    Table,
    /// JSON: a list of poses, top level or under a key.
    Json,
    /// A FANUC TP program (`.ls`).
    FanucLs,
    /// An ABB RAPID module (`.mod`, `.modx`, `.prg`).
    Rapid,
    /// A KUKA KRL data or source file (`.dat`, `.src`).
    Krl,
    /// A URScript program (`.script`, `.urscript`).
    UrScript,
}

impl PoseFormat {
    /// Every layout, in the order `--pose-format` lists them.
    pub const ALL: [Self; 6] = [
        Self::Table,
        Self::Json,
        Self::FanucLs,
        Self::Rapid,
        Self::Krl,
        Self::UrScript,
    ];

    /// The name [`Self::parse`] reads.
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::Table => "table",
            Self::Json => "json",
            Self::FanucLs => "fanuc-ls",
            Self::Rapid => "rapid",
            Self::Krl => "krl",
            Self::UrScript => "urscript",
        }
    }

    /// Parses a key of [`Self::key`] (also `ls`, `kuka`, `ur`, `csv`, any case).
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "table" | "csv" | "txt" => Some(Self::Table),
            "json" | "rob" => Some(Self::Json),
            "fanuc-ls" | "fanuc" | "ls" | "tp" => Some(Self::FanucLs),
            "rapid" | "abb" | "mod" => Some(Self::Rapid),
            "krl" | "kuka" | "dat" | "src" => Some(Self::Krl),
            "urscript" | "ur" | "script" => Some(Self::UrScript),
            _ => None,
        }
    }

    /// For people: "FANUC TP program (.ls)".
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Self::Table => "pose table",
            Self::Json => "JSON pose list",
            Self::FanucLs => "FANUC TP program (.ls)",
            Self::Rapid => "ABB RAPID module",
            Self::Krl => "KUKA KRL file",
            Self::UrScript => "URScript program",
        }
    }

    /// The flange-pose convention the layout itself fixes (a program's
    /// language), or `None` for tables and JSON, whose convention the
    /// user gives.
    #[must_use]
    pub fn convention(self) -> Option<FlangeConvention> {
        match self {
            Self::FanucLs => Some(FlangeConvention::FanucWpr),
            Self::Rapid => Some(FlangeConvention::AbbQuaternion),
            Self::Krl => Some(FlangeConvention::KukaAbc),
            Self::UrScript => Some(FlangeConvention::UrRotationVector),
            Self::Table | Self::Json => None,
        }
    }
}

impl fmt::Display for PoseFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.key())
    }
}

/// The layout of `text` (the content of a file named `path`), from its
/// content; the extension only breaks ties.
#[must_use]
pub fn detect(text: &str, path: &Path) -> PoseFormat {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let body = text.trim_start_matches('\u{feff}').trim_start();
    let upper_head: String = body.chars().take(4096).collect::<String>().to_uppercase();
    if body.starts_with('{') || body.starts_with('[') {
        return PoseFormat::Json;
    }
    if upper_head.starts_with("/PROG") || text.contains("\n/POS") || ext == "ls" {
        return PoseFormat::FanucLs;
    }
    // URScript's `def name():` would read as KRL's `DEF name( )`: the
    // colon that ends a Python-like header tells them apart.
    let first_line = body.lines().next().unwrap_or("").trim();
    if first_line.to_ascii_lowercase().starts_with("def ") && first_line.ends_with(':') {
        return PoseFormat::UrScript;
    }
    let upper = text.to_uppercase();
    if upper.contains("ROBTARGET")
        || upper.contains("JOINTTARGET")
        || upper_head.contains("MODULE ")
    {
        return PoseFormat::Rapid;
    }
    // URScript by its pose literals or move calls (before KRL, whose
    // programs have neither).
    if lex::contains_ur_pose(text)
        || text.contains("movej(")
        || text.contains("movel(")
        || ext == "script"
        || ext == "urscript"
    {
        return PoseFormat::UrScript;
    }
    if upper.contains("DEFDAT")
        || upper.contains("E6POS")
        || upper.contains("E6AXIS")
        || upper_head.starts_with("DEF ")
        || upper_head.starts_with("&ACCESS")
        || ext == "dat"
        || ext == "src"
    {
        return PoseFormat::Krl;
    }
    PoseFormat::Table
}

/// The last number in a target's name (`P[3]` → 3, `XP12` → 12).
#[must_use]
pub fn number_in(name: &str) -> Option<u64> {
    lex::last_number(name)
}

/// A target's value as written.
#[derive(Debug, Clone, PartialEq)]
pub enum TargetValue {
    /// A Cartesian pose in `convention` (the convention's numbers, file
    /// units: mm and deg, or m and rad for UR).
    Pose {
        /// The numbers, in the convention's order.
        values: Vec<f64>,
        /// How they make a pose.
        convention: FlangeConvention,
    },
    /// Joint positions, deg (converted from rad for URScript).
    Joints {
        /// One per joint, deg.
        deg: Vec<f64>,
        /// True when the file writes radians (URScript).
        radians: bool,
    },
}

/// One target of a pose file.
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// Its name: `P[3]`, `p10`, `XP1`, or `line 12` for a literal.
    pub name: String,
    /// The number in its name (`P[3]` → 3, `XP12` → 12), for pairing
    /// with numbered profiles.
    pub number: Option<u64>,
    /// 1-based line where it starts.
    pub line: usize,
    /// The value.
    pub value: TargetValue,
    /// Byte range in the text of each number of `value`, in order.
    pub spans: Vec<Range<usize>>,
    /// The configuration as written (FANUC `CONFIG`, RAPID `[cf1,cf4,cf6,cfx]`,
    /// KUKA `S`/`T`), with its byte range, when the layout has one.
    pub config: Option<(String, Range<usize>)>,
    /// A table's `id` column.
    pub id: Option<String>,
    /// A table's `station` column.
    pub station: Option<String>,
    /// A table's `use` column.
    pub usage: Option<Use>,
    /// A table's `side` column, when it has a value.
    pub side: Option<i8>,
    /// User frame and tool numbers (FANUC `UF`/`UT`, KUKA `BASE_NO`/`TOOL_NO`), when written.
    pub frames: Option<(i64, i64)>,
}

impl Target {
    fn new(name: String, line: usize, value: TargetValue, spans: Vec<Range<usize>>) -> Self {
        let number = lex::last_number(&name);
        Self {
            name,
            number,
            line,
            value,
            spans,
            config: None,
            id: None,
            station: None,
            usage: None,
            side: None,
            frames: None,
        }
    }
}

/// A pose file as read.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseFile {
    /// The file.
    pub path: PathBuf,
    /// Its layout.
    pub format: PoseFormat,
    /// Whether the layout was detected (not forced).
    pub detected: bool,
    /// Every target, in the order written.
    pub targets: Vec<Target>,
    /// Indices into `targets` in the order the robot went to them.
    pub order: Vec<usize>,
    /// Which order `order` is, in words.
    pub order_note: String,
    /// What the reader noticed (a non-zero user frame, extended axes,
    /// targets never moved to), in words.
    pub warnings: Vec<String>,
    /// The file's text, for rewriting.
    pub text: String,
}

impl PoseFile {
    /// The targets in the order the robot went to them.
    pub fn ordered(&self) -> impl Iterator<Item = &Target> {
        self.order.iter().filter_map(|&i| self.targets.get(i))
    }

    /// The text with the numbers of `edits` replaced: each edit is a
    /// target index and its new numbers, already formatted, one per span
    /// of [`Target::spans`]. Every other byte is kept.
    ///
    /// # Errors
    /// A target index out of range or a count of numbers that does not
    /// match the target's spans.
    pub fn rewritten(&self, edits: &[(usize, Vec<String>)]) -> Result<String, RewriteError> {
        self.rewritten_with_config(edits, &[])
    }

    /// As [`Self::rewritten`], and each target of `configs` with its
    /// configuration ([`Target::config`], its byte range) replaced by the
    /// text given. Every other byte is kept.
    ///
    /// # Errors
    /// As [`Self::rewritten`], and a target without a configuration in
    /// `configs`.
    pub fn rewritten_with_config(
        &self,
        edits: &[(usize, Vec<String>)],
        configs: &[(usize, String)],
    ) -> Result<String, RewriteError> {
        let mut replacements: Vec<(Range<usize>, &str)> = Vec::new();
        for (index, numbers) in edits {
            let target = self
                .targets
                .get(*index)
                .ok_or(RewriteError::NoTarget(*index))?;
            if numbers.len() != target.spans.len() {
                return Err(RewriteError::Count {
                    target: target.name.clone(),
                    numbers: numbers.len(),
                    places: target.spans.len(),
                });
            }
            for (span, n) in target.spans.iter().zip(numbers) {
                replacements.push((span.clone(), n.as_str()));
            }
        }
        for (index, text) in configs {
            let (_, range) = self
                .targets
                .get(*index)
                .and_then(|t| t.config.as_ref())
                .ok_or(RewriteError::NoConfiguration(*index))?;
            replacements.push((range.clone(), text.as_str()));
        }
        Ok(lex::replace_ranges(&self.text, replacements))
    }
}

/// Edits that do not fit the file's targets (an internal error of the
/// caller).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RewriteError {
    /// A target index out of range.
    #[error("no target {0}")]
    NoTarget(usize),
    /// Another count of numbers than the target has places.
    #[error("{target}: {numbers} numbers for {places} places")]
    Count {
        /// The target's name.
        target: String,
        /// Numbers given.
        numbers: usize,
        /// Its places.
        places: usize,
    },
    /// A configuration edit of a target without one.
    #[error("target {0} has no configuration")]
    NoConfiguration(usize),
}

/// A pose file could not be read: the line and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}{message} ({})", if *line > 0 { format!("line {line}: ") } else { String::new() }, path.display())]
pub struct ProgramError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line (0 when the file as a whole is wrong).
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// How to read a pose file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadSpec {
    /// The layout; `None`: detected.
    pub format: Option<PoseFormat>,
    /// The convention of a table's or JSON list's numbers (a program's
    /// language fixes its own).
    pub convention: Option<FlangeConvention>,
    /// A table's pose columns by name, in the convention's order; `None`:
    /// the convention's default names, or the columns in order without a
    /// header.
    pub columns: Option<Vec<String>>,
}

/// Reads a pose file: the layout detected from the content (or forced),
/// every target with the byte range of its numbers, and the order the
/// robot went to them.
///
/// # Errors
/// An unreadable file, a layout that holds no target, a target whose
/// numbers cannot be read (naming the line), a convention that contradicts
/// the program's language.
pub fn read_pose_file(path: &Path, spec: &ReadSpec) -> Result<PoseFile, ProgramError> {
    let fail = |line: usize, message: String| ProgramError {
        path: path.to_path_buf(),
        line,
        message,
    };
    let bytes =
        read_bytes(path, Cap::POSE_FILE).map_err(|e| fail(0, format!("cannot be read: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        #[allow(
            clippy::naive_bytecount,
            reason = "once, on an error path: not worth a crate"
        )]
        let line = 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        fail(line, "not UTF-8 text".to_string())
    })?;
    parse_pose_text(text, path, spec)
}

/// [`read_pose_file`] on text already read.
///
/// # Errors
/// As [`read_pose_file`].
pub fn parse_pose_text(
    text: String,
    path: &Path,
    spec: &ReadSpec,
) -> Result<PoseFile, ProgramError> {
    let fail = |line: usize, message: String| ProgramError {
        path: path.to_path_buf(),
        line,
        message,
    };
    // Lines ended by CR alone (an old Mac editor) read as one line: every
    // reader would then miss what it looks for and say something else.
    if text.contains('\r') && !text.contains('\n') && text.trim_end().contains('\r') {
        return Err(fail(
            0,
            "its lines end with CR alone (no line feed): save it with LF or CRLF line ends"
                .to_string(),
        ));
    }
    let (format, detected) = match spec.format {
        Some(f) => (f, false),
        None => (detect(&text, path), true),
    };
    if let (Some(fixed), Some(given)) = (format.convention(), spec.convention)
        && fixed != given
    {
        return Err(fail(
            0,
            format!(
                "{} {} writes its poses as {}, but --pose-convention says {}: leave it out or give `{}`",
                if format == PoseFormat::Rapid {
                    "an"
                } else {
                    "a"
                },
                format.describe(),
                fixed.describe(),
                given.key(),
                fixed.key()
            ),
        ));
    }
    let parsed = match format {
        PoseFormat::Table => {
            let convention = spec.convention.ok_or_else(|| {
                fail(
                    0,
                    "a pose table needs its convention (--pose-convention abb, kuka, fanuc, ur or matrix)"
                        .to_string(),
                )
            })?;
            table::read(&text, convention, spec.columns.as_deref())
        }
        PoseFormat::Json => {
            let convention = spec.convention.ok_or_else(|| {
                fail(
                    0,
                    "a JSON pose list needs its convention (--pose-convention abb, kuka, fanuc, ur or matrix)"
                        .to_string(),
                )
            })?;
            json::read(&text, convention)
        }
        PoseFormat::FanucLs => fanuc::read(&text),
        PoseFormat::Rapid => rapid::read(&text),
        PoseFormat::Krl => krl::read(&text),
        PoseFormat::UrScript => urscript::read(&text),
    }
    .map_err(|(line, message)| fail(line, message))?;
    if parsed.targets.is_empty() {
        return Err(fail(
            0,
            format!(
                "no pose found in this {}{}",
                format.describe(),
                if detected {
                    " (the layout was detected from the content: --pose-format forces one)"
                } else {
                    ""
                }
            ),
        ));
    }
    let (order, order_note, mut warnings) = lex::motion_order(&parsed.targets, &parsed.visits);
    warnings.splice(0..0, parsed.warnings);
    Ok(PoseFile {
        path: path.to_path_buf(),
        format,
        detected,
        targets: parsed.targets,
        order,
        order_note,
        warnings,
        text,
    })
}

/// Reads a table of numbers from `path` (a header optional, any
/// separator; see the pose tables): the columns `names` (by name under a
/// header, in order without one) and optionally `id`, `station`, `use`,
/// `side`. `what` describes the numbers for messages, `hint` how to say
/// which reading a headerless table with one number more means (any
/// numbers fit these values, so such a table needs a header). Used for tables
/// that are not poses, such as sphere centres reported by a sensor.
///
/// # Errors
/// An unreadable file, no rows, a missing column, a bad cell: naming the
/// line.
pub fn read_number_table(
    path: &Path,
    names: &[String],
    names_given: bool,
    what: &str,
    hint: &str,
) -> Result<Vec<Row>, ProgramError> {
    let fail = |line: usize, message: String| ProgramError {
        path: path.to_path_buf(),
        line,
        message,
    };
    let text = read_text(path, Cap::TABLE).map_err(|e| fail(0, format!("cannot be read: {e}")))?;
    table::read_rows(&text, names, names_given, what, &|_| true, hint)
        .map_err(|(line, message)| fail(line, message))
}

/// What a layout's reader returns: the targets, the motion instructions'
/// references to them in program order (indices into `targets`), and
/// what it noticed.
#[derive(Debug)]
struct Parsed {
    targets: Vec<Target>,
    visits: Vec<usize>,
    warnings: Vec<String>,
}

/// A reader's failure: the 1-based line and what is wrong.
type ParseError = (usize, String);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urscript_def_is_not_krl_def() {
        let ur = "def path():\n  movel(p[0.4, 0, 0.3, 3.14, 0, 0], a=1.2, v=0.25)\nend\n";
        assert_eq!(detect(ur, Path::new("a.txt")), PoseFormat::UrScript);
        let krl = "DEF calib( )\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 0,A6 0}\nEND\n";
        assert_eq!(detect(krl, Path::new("a.txt")), PoseFormat::Krl);
    }
}
