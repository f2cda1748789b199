//! The history of a cell: a library over a folder of session and result
//! files ([`scan`]), and for one robot the drift of the hand-eye and of
//! its main kinematic deviations over time, with every change between
//! consecutive results that exceeds `k` times their combined 1σ flagged
//! ([`drift`]).
//!
//! # The library
//!
//! [`scan`] walks a folder (subfolders to [`MAX_DEPTH`] levels; hidden
//! entries such as `.git` or the temporary files of
//! [`write_atomic`](crate::engine::format::write_atomic) and symbolic links to
//! folders are skipped). Every `*.json` file is classified by its
//! `"format"` key, not by its name: `spherecal-session` and
//! `spherecal-result` files are loaded by the strict loaders of
//! [`session`](crate::engine::format); JSON files of other formats (truth files,
//! anything else) are listed as ignored. A file that cannot be read, is
//! not JSON, or breaks a rule of its format is a [`Problem`] with its path
//! and message, and the scan goes on. Only a folder that cannot be read at
//! all fails the scan ([`HistoryError`]).
//!
//! **One [`Entry`] per result file.** Its session file is found, in order:
//! by name, `X.result.json` (the `--out` name of the README) or
//! `X-result.json` / `X_result.json` next to `X.json`; else the one
//! session file in the library whose `name` is the result's `session`
//! (one in the same folder first).
//!
//! **Date.** FORMAT.md version 1 has no date key, and the formats are not
//! changed for this, so the date is found, in order ([`DateSource`]): an
//! ISO 8601 date `YYYY-MM-DD`, optionally followed by `THH:MM[:SS]` (or a
//! space or `_` instead of `T`), in the session name (FORMAT.md's example
//! is "IRB2400 cell 3, 2026-11-20"); the same in the result's or the
//! session's file name; the modification time of the session file; that
//! of the result file (UTC). The source is recorded so a view can show it:
//! a modification time changes when a file is copied.
//!
//! # Parameters and their uncertainty
//!
//! Every entry holds 6 hand-eye values and the `5·n` kinematic deviations
//! as [`ParamValue`]s, each with its 1σ when the result's `solver` block
//! has a covariance (the `ml` method; the paper's method reports none):
//!
//! - **Hand-eye**: the calibrated `eT_s` as translation `hand_eye.x/y/z`
//!   (mm, flange frame) and `hand_eye.roll/pitch/yaw` (deg, `R = Rz(yaw) ·
//!   Ry(pitch) · Rx(roll)`, the workbench's convention). `ml` reports the
//!   covariance of a twist applied on the right of the calibrated hand-eye
//!   (`eT_s · exp(Δ)`, sensor frame, [`HAND_EYE_LABELS`]); it is carried to
//!   these six numbers by their Jacobian (the rotation for the
//!   translation, central differences for roll, pitch and yaw). The values
//!   are absolute, not `ml`'s change from the session's initial hand-eye,
//!   which differs from session to session.
//! - **Kinematic**: calibrated minus nominal (`theta3`, `d4`, … deg and
//!   mm). Across a drift they are measured from one nominal model, the
//!   earliest result's, so that a session whose nominal model is an
//!   earlier calibration (the README's `export-model` workflow) stays
//!   comparable.
//! - **Identifiability**: `ml` lists the parameters it estimated and the
//!   ones it fixed at their start ([`Status`]), and names each fixed
//!   parameter's combination (`d6 ~ he_z`: a change of `d6` appears as a
//!   change of the hand-eye z). These are kept as [`Combination`]s.
//! - **σ scaling.** When the result's variance factor (Σ r² per degree of
//!   freedom of the whitened residuals) exceeds 1 the noise model was
//!   optimistic; every σ is then multiplied by its square root (Birge's
//!   ratio), so that a cell whose real noise exceeds the model does not
//!   flag every repeat. Below 1 the σ is kept.
//! - **Prior-held.** With `ml`'s prior on, a kinematic parameter whose σ is
//!   at least [`PRIOR_HELD_FRACTION`] of its prior σ is barely seen by the
//!   data: the prior holds it near nominal, so a real change in it is
//!   shrunk and the jump check on it is weak. It is marked.
//!
//! # Drift and jumps
//!
//! [`drift`] takes one robot's results (by the `robot.name` of the result
//! files) in date order and builds [`Series`]: the six hand-eye values,
//! the `top` **main kinematic deviations**, the parameters the user
//! chose, and every parameter with a flagged jump. The main deviations
//! are the kinematic parameters estimated in at least one result, ranked
//! by the median over the results of `|value| / σ` (how many σ the
//! deviation from nominal is: the errors the data show most clearly);
//! when no result of the series has a σ (paper method only), by the
//! median `|value|` with angles taken as their effect at 1 m (1° ≈
//! 17.45 mm), the paper's own scaling ([`ANGLE_SCALE_MM`]).
//!
//! Between every two consecutive results each parameter is checked
//! ([`JumpCheck`]): a jump when `|b − a| > k · sqrt(σa² + σb²)` (angle
//! differences wrapped to ±180°), [`DEFAULT_K`] = 3. It is not checked,
//! with the reason given, when
//!
//! - a σ is missing (a `paper` result): there is no uncertainty to judge
//!   the change against, and none is guessed;
//! - the parameter was estimated in one result and fixed in the other;
//! - the two results fixed different parameters and this one belongs to a
//!   combination that differs: its value then carries different things.
//!
//! A parameter fixed in both results is not identifiable and is not
//! checked at all. A checked parameter that carries fixed ones (`he_z`
//! carries `d6`) gets a note naming them: its jump may be theirs.
//!
//! With about 30 parameters checked per pair of results and Gaussian
//! noise, a 3σ threshold flags a false jump in about 8 % of pairs; the
//! ratio tells a marginal flag (3-5) from a clear change.

use std::collections::{HashMap, HashSet};
use std::fmt;
use std::fmt::Write as _;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use nalgebra::{Isometry3, Matrix3, UnitQuaternion, Vector3};
use serde::Deserialize;
use serde::de::IgnoredAny;
use serde_json::Value;

use crate::engine::format::FileError;
use crate::engine::format::{self, RESULT_FORMAT, ResultFile, SESSION_FORMAT};
use crate::engine::geometry::{rotation_from_rpy_deg, wrap_deg};
use crate::engine::result_view::HandEyeView;
use crate::engine::robot::{Joint, PARAM_IS_ANGLE, PARAMS_PER_JOINT, Robot};
use crate::engine::solve::SolverReport;
use crate::engine::solve::estimate::{ANGLE_SCALE_MM, HAND_EYE_LABELS};
use crate::engine::validate::Stats;

/// Deepest subfolder level [`scan`] enters (the folder itself is level 0).
/// A library is a folder of cells, robots or dates; 8 levels is far beyond
/// any such layout and still stops a walk into an unrelated tree.
pub const MAX_DEPTH: usize = 8;
/// Largest file [`scan`] reads, bytes. A stripe session of 124
/// measurements is 240 KB; 64 MiB leaves room for sessions a hundred
/// times larger and keeps a stray data dump from filling memory.
pub const MAX_FILE_BYTES: u64 = 64 * 1024 * 1024;
/// Default `k` of the jump check: a change beyond 3 combined σ. Under
/// Gaussian noise one parameter passes it by chance in 0.27 % of checks.
pub const DEFAULT_K: f64 = 3.0;
/// Default number of main kinematic deviations a drift shows: the largest
/// Table 1 errors of the paper's robot that sphere data identify are about
/// six (theta3, beta3, alpha4, alpha3, a4, a2).
pub const DEFAULT_TOP: usize = 6;
/// A kinematic parameter whose σ is at least this fraction of its prior σ
/// is "prior-held": the data shrink its prior variance by less than 4×, so
/// the prior, not the data, keeps it near nominal.
pub const PRIOR_HELD_FRACTION: f64 = 0.5;
/// The six hand-eye values of an entry: translation of `eT_s` (mm, flange
/// frame) and roll, pitch, yaw (deg, `R = Rz(yaw)·Ry(pitch)·Rx(roll)`).
pub const HAND_EYE_NAMES: [&str; 6] = [
    "hand_eye.x",
    "hand_eye.y",
    "hand_eye.z",
    "hand_eye.roll",
    "hand_eye.pitch",
    "hand_eye.yaw",
];
/// Step of the central differences of roll, pitch and yaw with respect to
/// the hand-eye rotation twist, deg: small against the curvature, large
/// against rounding (error ~1e-9 relative).
const RPY_STEP_DEG: f64 = 1e-4;
/// A hand-eye twist component counts as part of a hand-eye value when its
/// Jacobian entry is at least this fraction of the row's largest. The
/// paper's sensor z axis is 1.3° off the flange's −z, which couples the
/// sensor z twist into the flange x translation at 1 %: a change of `d6`
/// (carried by `he_z`) would have to be 100 mm to move x by 1 mm, so such
/// a coupling is misalignment, not a dependence worth naming.
const COUPLING_REL: f64 = 0.1;
/// Suffixes of a result file's stem that name its session `X.json`:
/// `X.result.json` is the README's `--out` name.
const RESULT_SUFFIXES: [&str; 3] = [".result", "-result", "_result"];

// ---------------------------------------------------------------------------
// Errors and problems
// ---------------------------------------------------------------------------

/// Why the history of a folder could not be built. A bad file is never one
/// of these: it is a [`Problem`] of the [`Library`].
#[derive(Debug, thiserror::Error)]
pub enum HistoryError {
    /// The folder cannot be read (missing, no permission).
    #[error("cannot read the folder: {source} ({})", path.display())]
    Folder {
        /// The folder.
        path: PathBuf,
        /// The I/O error.
        source: io::Error,
    },
    /// The path is not a folder.
    #[error("not a folder ({})", path.display())]
    NotAFolder {
        /// The path given.
        path: PathBuf,
    },
    /// No result of the library is of this robot.
    #[error(
        "no result of a robot named {query:?}; the library has {}",
        list_or_none(known)
    )]
    UnknownRobot {
        /// The name asked for.
        query: String,
        /// Robot names in the library.
        known: Vec<String>,
    },
    /// The name is part of several robot names.
    #[error("{query:?} matches several robots: {}; give the full name", candidates.join(", "))]
    AmbiguousRobot {
        /// The name asked for.
        query: String,
        /// The robot names containing it.
        candidates: Vec<String>,
    },
    /// A chosen parameter is not a parameter of the robot.
    #[error(
        "unknown parameter {name:?}: expected a kinematic parameter such as theta3 or d4 ({robot} has {count})"
    )]
    UnknownParameter {
        /// The name given.
        name: String,
        /// Robot name.
        robot: String,
        /// How many kinematic parameters it has.
        count: usize,
    },
    /// `k` of the jump check is not a positive finite number.
    #[error("k must be a positive finite number, got {k}")]
    InvalidK {
        /// The value given.
        k: f64,
    },
}

fn list_or_none(names: &[String]) -> String {
    if names.is_empty() {
        "no results".into()
    } else {
        names.join(", ")
    }
}

/// A file the scan could not use, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// The file (or folder).
    pub path: PathBuf,
    /// What is wrong, without the path.
    pub message: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.message, self.path.display())
    }
}

// ---------------------------------------------------------------------------
// Dates
// ---------------------------------------------------------------------------

/// A calendar date with an optional time of day (no time zone: a date in a
/// session name is local to the cell, a file time is UTC). Orders
/// chronologically; a date without a time sorts as midnight.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Timestamp {
    /// Year.
    pub year: i32,
    /// Month, 1-12.
    pub month: u32,
    /// Day of the month, 1-31.
    pub day: u32,
    /// Hour, 0-23 (0 without a time).
    pub hour: u32,
    /// Minute, 0-59.
    pub minute: u32,
    /// Second, 0-59.
    pub second: u32,
    /// Whether a time of day was given.
    pub has_time: bool,
}

impl Timestamp {
    /// A date without a time of day; `None` when it is not a calendar date.
    #[must_use]
    pub fn date(year: i32, month: u32, day: u32) -> Option<Self> {
        ((1..=12).contains(&month) && day >= 1 && day <= days_in_month(year, month)).then_some(
            Self {
                year,
                month,
                day,
                hour: 0,
                minute: 0,
                second: 0,
                has_time: false,
            },
        )
    }

    /// The same date at a time of day; `None` when the time is invalid.
    #[must_use]
    pub fn at(self, hour: u32, minute: u32, second: u32) -> Option<Self> {
        (hour < 24 && minute < 60 && second < 60).then_some(Self {
            hour,
            minute,
            second,
            has_time: true,
            ..self
        })
    }

    /// A file time as a UTC date and time; `None` before 1970 or after
    /// 9999 (the calendar is `humantime`'s RFC 3339 formatter).
    #[must_use]
    pub fn from_system_time(t: SystemTime) -> Option<Self> {
        // humantime formats the years 1970..=9999 (it panics outside them).
        const YEAR_10000: u64 = 253_402_300_800;
        let secs = t.duration_since(UNIX_EPOCH).ok()?.as_secs();
        if secs >= YEAR_10000 {
            return None;
        }
        // `YYYY-MM-DDThh:mm:ssZ`
        let text = humantime::format_rfc3339_seconds(t).to_string();
        let field = |range: std::ops::Range<usize>| text.get(range)?.parse::<u32>().ok();
        let year = i32::try_from(field(0..4)?).ok()?;
        Self::date(year, field(5..7)?, field(8..10)?)?.at(
            field(11..13)?,
            field(14..16)?,
            field(17..19)?,
        )
    }
}

impl fmt::Display for Timestamp {
    /// ISO 8601: `2026-11-20`, or `2026-11-20 14:30:00` with a time.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:04}-{:02}-{:02}", self.year, self.month, self.day)?;
        if self.has_time {
            write!(f, " {:02}:{:02}:{:02}", self.hour, self.minute, self.second)?;
        }
        Ok(())
    }
}

fn is_leap(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

fn days_in_month(year: i32, month: u32) -> u32 {
    match month {
        2 if is_leap(year) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Years accepted in a name: a four-digit number outside this range is a
/// serial or part number, not a date.
const NAME_YEARS: std::ops::RangeInclusive<i32> = 1900..=2999;

/// The first ISO 8601 date in `text` (`YYYY-MM-DD`, not inside a longer
/// number), with its time of day when `THH:MM[:SS]` follows (a space or
/// `_` may stand for the `T`). Invalid dates (`2026-02-30`) are skipped.
#[must_use]
pub fn date_in_name(text: &str) -> Option<Timestamp> {
    let b = text.as_bytes();
    let digits = |from: usize, n: usize| -> Option<u32> {
        let s = b.get(from..from + n)?;
        s.iter().all(u8::is_ascii_digit).then(|| {
            s.iter()
                .fold(0_u32, |acc, &c| acc * 10 + u32::from(c - b'0'))
        })
    };
    let is_digit_at = |i: usize| b.get(i).is_some_and(u8::is_ascii_digit);
    for i in 0..b.len() {
        if i > 0 && is_digit_at(i - 1) {
            continue;
        }
        let (Some(y), Some(m), Some(d)) = (digits(i, 4), digits(i + 5, 2), digits(i + 8, 2)) else {
            continue;
        };
        if b.get(i + 4) != Some(&b'-') || b.get(i + 7) != Some(&b'-') || is_digit_at(i + 10) {
            continue;
        }
        let Ok(year) = i32::try_from(y) else { continue };
        if !NAME_YEARS.contains(&year) {
            continue;
        }
        let Some(date) = Timestamp::date(year, m, d) else {
            continue;
        };
        let t = i + 10;
        let time = if matches!(b.get(t), Some(b'T' | b' ' | b'_')) {
            match (digits(t + 1, 2), b.get(t + 3), digits(t + 4, 2)) {
                (Some(h), Some(b':'), Some(min)) => {
                    let sec = if b.get(t + 6) == Some(&b':') {
                        digits(t + 7, 2)
                    } else {
                        Some(0)
                    };
                    let end = if b.get(t + 6) == Some(&b':') {
                        t + 9
                    } else {
                        t + 6
                    };
                    sec.filter(|_| !is_digit_at(end))
                        .and_then(|s| date.at(h, min, s))
                }
                _ => None,
            }
        } else {
            None
        };
        return Some(time.unwrap_or(date));
    }
    None
}

/// Where an entry's date came from (see the module docs for the order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DateSource {
    /// An ISO date in the session name (the result's `session`).
    SessionName,
    /// An ISO date in the result's or its session's file name.
    FileName,
    /// The modification time of the session file (UTC).
    SessionModified,
    /// The modification time of the result file (UTC).
    ResultModified,
    /// None of these could be read; the date is 1970-01-01.
    Unknown,
}

impl DateSource {
    /// In words, for tables.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::SessionName => "session name",
            Self::FileName => "file name",
            Self::SessionModified => "session file time",
            Self::ResultModified => "result file time",
            Self::Unknown => "unknown",
        }
    }

    /// Whether the date was written by a person (a name) rather than
    /// taken from the file system, which changes on a copy.
    #[must_use]
    pub fn is_from_name(self) -> bool {
        matches!(self, Self::SessionName | Self::FileName)
    }
}

// ---------------------------------------------------------------------------
// Library types
// ---------------------------------------------------------------------------

/// Unit of a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Unit {
    /// Millimetres.
    Mm,
    /// Degrees.
    Deg,
}

impl Unit {
    /// `"mm"` or `"deg"`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mm => "mm",
            Self::Deg => "deg",
        }
    }
}

/// Whether the method estimated a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Status {
    /// Estimated from the data (`ml`'s identifiable set).
    Estimated,
    /// Held at its start (nominal, or the initial hand-eye): the data
    /// cannot tell it from other parameters.
    Fixed,
    /// The method does not say (the paper's truncated SVD keeps directions,
    /// not parameters).
    Unknown,
}

impl Status {
    /// In words.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Estimated => "estimated",
            Self::Fixed => "fixed",
            Self::Unknown => "unknown",
        }
    }
}

/// One parameter of a result.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamValue {
    /// `hand_eye.x` … `hand_eye.yaw` ([`HAND_EYE_NAMES`]) or a kinematic
    /// label (`alpha1` … `d6`).
    pub name: String,
    /// Unit of `value` and `sigma`.
    pub unit: Unit,
    /// Hand-eye: the calibrated value. Kinematic: calibrated minus this
    /// result's nominal (the result's `joint_errors`).
    pub value: f64,
    /// 1σ, scaled by [`Entry::sigma_scale`]; `None` when the result has no
    /// covariance (paper method) or the parameter was fixed.
    pub sigma: Option<f64>,
    /// Estimated, fixed or unknown.
    pub status: Status,
    /// Kinematic parameter held near nominal by `ml`'s prior (see
    /// [`PRIOR_HELD_FRACTION`]).
    pub prior_held: bool,
}

/// A combination `ml` could not separate: the fixed parameters, the
/// estimated ones that carry their effect, and `ml`'s sentence.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Combination {
    /// Fixed parameters (`d6`; several for "no effect" groups).
    pub fixed: Vec<String>,
    /// Estimated parameters that undo their effect (`he_z`; `ml`'s
    /// hand-eye twist labels [`HAND_EYE_LABELS`] or kinematic labels);
    /// empty when the fixed ones move no distance at all.
    pub partners: Vec<String>,
    /// `ml`'s sentence, e.g. `d6 ~ he_z: d6 +1 mm is undone by he_z +0.999 mm`.
    pub text: String,
}

/// The calibrated hand-eye `eT_s` in numbers people read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandEye {
    /// Translation, mm, flange frame.
    pub translation: [f64; 3],
    /// Roll, pitch, yaw, deg (`R = Rz(yaw)·Ry(pitch)·Rx(roll)`).
    pub rpy_deg: [f64; 3],
}

impl HandEye {
    /// The rotation of `eT_s`.
    #[must_use]
    pub fn rotation(&self) -> UnitQuaternion<f64> {
        rotation_from_rpy_deg(self.rpy_deg)
    }

    /// The hand-eye `flange_from_sensor` in these numbers.
    #[must_use]
    pub fn new(flange_from_sensor: &Isometry3<f64>) -> Self {
        let v = HandEyeView::new(flange_from_sensor);
        Self {
            translation: v.translation,
            rpy_deg: v.rpy_deg,
        }
    }
}

/// How a result's session file was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PairedBy {
    /// `X.result.json` (or `-result`, `_result`) next to `X.json`.
    FileName,
    /// The session file whose `name` is the result's `session`.
    SessionName,
}

/// One result file of the library.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// The result file.
    pub path: PathBuf,
    /// Its session file, when found.
    pub session_path: Option<PathBuf>,
    /// How the session file was found.
    pub paired_by: Option<PairedBy>,
    /// The date of the calibration (see [`DateSource`]).
    pub date: Timestamp,
    /// Where `date` came from.
    pub date_source: DateSource,
    /// Robot name (`robot.name` of the result): what [`drift`] groups by.
    pub robot: String,
    /// Session name (the result's `session`).
    pub session: String,
    /// Identification method (`solver.method`: `ml`, `paper`, …).
    pub method: String,
    /// ε before identification, mm.
    pub epsilon_before: f64,
    /// ε after identification, mm.
    pub epsilon_after: f64,
    /// Reference-distance errors before (nominal model), mm; `None` without
    /// validate measurements.
    pub validation_before: Option<Stats>,
    /// Reference-distance errors after calibration, mm.
    pub validation_after: Option<Stats>,
    /// Within-station distances of the validate stations, before, mm.
    pub within_station_before: Option<Stats>,
    /// Within-station distances of the validate stations, after, mm.
    pub within_station_after: Option<Stats>,
    /// The calibrated hand-eye.
    pub hand_eye: HandEye,
    /// The initial hand-eye (before identification).
    pub hand_eye_initial: HandEye,
    /// The session's nominal model (calibrated minus the joint errors),
    /// deg and mm.
    pub nominal: Vec<Joint>,
    /// The calibrated model, deg and mm.
    pub calibrated: Vec<Joint>,
    /// Calibrated minus nominal (the result's `joint_errors`).
    pub joint_errors: Vec<Joint>,
    /// The six hand-eye values ([`HAND_EYE_NAMES`]), then the `5·n`
    /// kinematic deviations in parameter order.
    pub params: Vec<ParamValue>,
    /// Parameters the method estimated, its own labels (`he_x`, `theta3`);
    /// empty when it does not say.
    pub estimated: Vec<String>,
    /// Parameters the method fixed at their start.
    pub fixed: Vec<String>,
    /// Combinations the method could not separate.
    pub combinations: Vec<Combination>,
    /// Paper method: SVD directions kept.
    pub kept_directions: Option<usize>,
    /// `ml`: Σ r² / degrees of freedom of the whitened residuals.
    pub variance_factor: Option<f64>,
    /// Factor applied to the reported σ: `sqrt(max(1, variance factor))`.
    pub sigma_scale: f64,
    /// Anything odd found while pairing or reading, one sentence each.
    pub notes: Vec<String>,
}

impl Entry {
    /// A parameter by name ([`HAND_EYE_NAMES`] or a kinematic label).
    #[must_use]
    pub fn param(&self, name: &str) -> Option<&ParamValue> {
        self.params.iter().find(|p| p.name == name)
    }

    /// Validation std after calibration, mm (the headline figure).
    #[must_use]
    pub fn validation_std_after(&self) -> Option<f64> {
        self.validation_after.map(|s| s.std)
    }
}

/// A session file of the library.
#[derive(Debug, Clone, PartialEq)]
pub struct SessionInfo {
    /// The file.
    pub path: PathBuf,
    /// Its name.
    pub name: String,
    /// Robot name.
    pub robot: String,
    /// Number of measurements.
    pub measurements: usize,
    /// Date (from the name, the file name or the file time).
    pub date: Timestamp,
    /// Where `date` came from.
    pub date_source: DateSource,
    /// Indices into [`Library::entries`] of the results paired with it.
    pub results: Vec<usize>,
}

/// What [`scan`] found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Library {
    /// The folder scanned.
    pub root: PathBuf,
    /// One entry per result file, in date order (then by path).
    pub entries: Vec<Entry>,
    /// Every session file, by path.
    pub sessions: Vec<SessionInfo>,
    /// Files that could not be used, by path.
    pub problems: Vec<Problem>,
    /// JSON files of other formats (truth files and the like), with their
    /// `format` when they have one.
    pub ignored: Vec<(PathBuf, Option<String>)>,
}

impl Library {
    /// Robot names with their number of results, by name.
    #[must_use]
    pub fn robots(&self) -> Vec<(String, usize)> {
        let mut out: Vec<(String, usize)> = Vec::new();
        for e in &self.entries {
            match out.iter_mut().find(|(n, _)| *n == e.robot) {
                Some((_, c)) => *c += 1,
                None => out.push((e.robot.clone(), 1)),
            }
        }
        out.sort();
        out
    }

    /// The robot name `query` stands for: an exact name, else the one name
    /// that contains it (case-insensitive).
    ///
    /// # Errors
    /// [`HistoryError::UnknownRobot`] or [`HistoryError::AmbiguousRobot`].
    pub fn find_robot(&self, query: &str) -> Result<String, HistoryError> {
        let names: Vec<String> = self.robots().into_iter().map(|(n, _)| n).collect();
        if names.iter().any(|n| n == query) {
            return Ok(query.to_string());
        }
        let q = query.to_lowercase();
        let found: Vec<String> = names
            .iter()
            .filter(|n| n.to_lowercase().contains(&q))
            .cloned()
            .collect();
        match found.len() {
            1 => Ok(found.into_iter().next().unwrap_or_default()),
            0 => Err(HistoryError::UnknownRobot {
                query: query.to_string(),
                known: names,
            }),
            _ => Err(HistoryError::AmbiguousRobot {
                query: query.to_string(),
                candidates: found,
            }),
        }
    }

    /// Session files no result was paired with (not calibrated yet).
    pub fn sessions_without_result(&self) -> impl Iterator<Item = &SessionInfo> {
        self.sessions.iter().filter(|s| s.results.is_empty())
    }
}

// ---------------------------------------------------------------------------
// Scanning
// ---------------------------------------------------------------------------

/// Scans `folder` for session and result files (see the module docs).
///
/// # Errors
/// [`HistoryError::Folder`] when the folder cannot be read,
/// [`HistoryError::NotAFolder`] when it is a file. Bad files are
/// [`Library::problems`], never an error.
pub fn scan(folder: &Path) -> Result<Library, HistoryError> {
    let meta = fs::metadata(folder).map_err(|source| HistoryError::Folder {
        path: folder.to_path_buf(),
        source,
    })?;
    if !meta.is_dir() {
        return Err(HistoryError::NotAFolder {
            path: folder.to_path_buf(),
        });
    }
    let mut files = Vec::new();
    let mut problems = Vec::new();
    let top = fs::read_dir(folder).map_err(|source| HistoryError::Folder {
        path: folder.to_path_buf(),
        source,
    })?;
    walk(top, folder, 0, &mut files, &mut problems);
    files.sort();

    let mut results: Vec<(PathBuf, ResultFile, Option<SystemTime>)> = Vec::new();
    let mut sessions: Vec<(SessionInfo, Option<SystemTime>)> = Vec::new();
    let mut ignored = Vec::new();
    for path in files {
        match read_file(&path) {
            Ok(Found::Session {
                name,
                robot,
                measurements,
                modified,
            }) => {
                let (date, date_source) = session_date(&name, &path, modified);
                sessions.push((
                    SessionInfo {
                        path,
                        name,
                        robot,
                        measurements,
                        date,
                        date_source,
                        results: Vec::new(),
                    },
                    modified,
                ));
            }
            Ok(Found::Result { result, modified }) => results.push((path, *result, modified)),
            Ok(Found::Other(format)) => ignored.push((path, format)),
            Err(message) => problems.push(Problem { path, message }),
        }
    }

    let mut entries = Vec::new();
    for (path, result, modified) in results {
        let (session_index, paired_by, mut notes) = pair(&path, &result, &sessions);
        let session = session_index.map(|i| &sessions[i]);
        let (date, date_source) = entry_date(&result, &path, modified, session);
        if let Some((s, _)) = session {
            if s.robot != result.robot.name {
                notes.push(format!(
                    "the session file's robot is {:?}, the result's {:?}",
                    s.robot, result.robot.name
                ));
            }
            if paired_by == Some(PairedBy::FileName) && s.name != result.session {
                notes.push(format!(
                    "the session file is named {:?}, the result says {:?}",
                    s.name, result.session
                ));
            }
        }
        match build_entry(
            path.clone(),
            &result,
            session.map(|(s, _)| s.path.clone()),
            paired_by,
            date,
            date_source,
            notes,
        ) {
            Ok(entry) => entries.push((entry, session_index)),
            Err(message) => problems.push(Problem { path, message }),
        }
    }
    entries.sort_by(|(a, _), (b, _)| a.date.cmp(&b.date).then_with(|| a.path.cmp(&b.path)));
    let mut sessions: Vec<SessionInfo> = sessions.into_iter().map(|(s, _)| s).collect();
    for (i, (_, s)) in entries.iter().enumerate() {
        if let Some(s) = s {
            sessions[*s].results.push(i);
        }
    }
    problems.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(Library {
        root: folder.to_path_buf(),
        entries: entries.into_iter().map(|(e, _)| e).collect(),
        sessions,
        problems,
        ignored,
    })
}

/// Collects `*.json` files below `dir` (already opened), depth-first.
fn walk(
    read: fs::ReadDir,
    dir: &Path,
    depth: usize,
    files: &mut Vec<PathBuf>,
    problems: &mut Vec<Problem>,
) {
    for item in read {
        let item = match item {
            Ok(i) => i,
            Err(e) => {
                problems.push(Problem {
                    path: dir.to_path_buf(),
                    message: format!("cannot list the folder: {e}"),
                });
                continue;
            }
        };
        let path = item.path();
        let name = item.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') {
            continue;
        }
        // `file_type` does not follow symbolic links: a linked folder is
        // not entered (no cycles), a linked file is read.
        let Ok(kind) = item.file_type() else {
            problems.push(Problem {
                path,
                message: "cannot read the file type".into(),
            });
            continue;
        };
        if kind.is_dir() {
            if depth + 1 > MAX_DEPTH {
                problems.push(Problem {
                    path,
                    message: format!("not scanned: deeper than {MAX_DEPTH} folder levels"),
                });
                continue;
            }
            match fs::read_dir(&path) {
                Ok(sub) => walk(sub, &path, depth + 1, files, problems),
                Err(e) => problems.push(Problem {
                    path,
                    message: format!("cannot read the folder: {e}"),
                }),
            }
        } else if name.to_ascii_lowercase().ends_with(".json") && !kind.is_dir() {
            files.push(path);
        }
    }
}

/// What one file is.
enum Found {
    Session {
        name: String,
        robot: String,
        measurements: usize,
        modified: Option<SystemTime>,
    },
    Result {
        result: Box<ResultFile>,
        modified: Option<SystemTime>,
    },
    Other(Option<String>),
}

/// Only the `format` key; everything else is skipped unparsed.
#[derive(Deserialize)]
struct Header {
    #[serde(default)]
    format: Option<Value>,
}

fn read_file(path: &Path) -> Result<Found, String> {
    let meta = fs::metadata(path).map_err(|e| format!("cannot read the file: {e}"))?;
    if meta.is_dir() {
        return Ok(Found::Other(None));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!(
            "not read: {} bytes, more than the {MAX_FILE_BYTES} a session or result file may have",
            meta.len()
        ));
    }
    let modified = meta.modified().ok();
    let text = fs::read_to_string(path).map_err(|e| format!("cannot read the file: {e}"))?;
    let format = if text.trim_start().starts_with('{') {
        serde_json::from_str::<Header>(&text)
            .map_err(|e| format!("not valid JSON: {e}"))?
            .format
    } else {
        // Valid JSON that is not an object (an array, a number) is not ours.
        serde_json::from_str::<IgnoredAny>(&text).map_err(|e| format!("not valid JSON: {e}"))?;
        None
    };
    match format.as_ref().and_then(Value::as_str) {
        Some(SESSION_FORMAT) => {
            let s = format::parse_session(&text, path).map_err(|e| file_error_message(&e))?;
            Ok(Found::Session {
                name: s.name,
                robot: s.robot.name,
                measurements: s.measurements.len(),
                modified,
            })
        }
        Some(RESULT_FORMAT) => {
            let result = format::parse_result(&text, path).map_err(|e| file_error_message(&e))?;
            Ok(Found::Result {
                result: Box::new(result),
                modified,
            })
        }
        Some(other) => Ok(Found::Other(Some(other.to_string()))),
        None => Ok(Found::Other(None)),
    }
}

/// A file error's message without its path (a [`Problem`] has the path).
fn file_error_message(e: &FileError) -> String {
    match e {
        FileError::Io { action, source, .. } => format!("{action} failed: {source}"),
        FileError::Invalid {
            measurement,
            message,
            ..
        } => match measurement {
            Some(m) => format!("measurement {m}: {message}"),
            None => message.clone(),
        },
    }
}

/// `X` for a result file `X.result.json` (also `-result`, `_result`).
fn result_stem(path: &Path) -> Option<String> {
    let name = path.file_name()?.to_string_lossy().into_owned();
    let stem = strip_json(&name)?;
    RESULT_SUFFIXES
        .iter()
        .find_map(|s| stem.strip_suffix(s))
        .map(str::to_string)
}

fn strip_json(name: &str) -> Option<&str> {
    let n = name.len();
    (n >= 5 && name.is_char_boundary(n - 5) && name[n - 5..].eq_ignore_ascii_case(".json"))
        .then(|| &name[..n - 5])
}

/// The session of a result: by file name, else by session name.
fn pair(
    path: &Path,
    result: &ResultFile,
    sessions: &[(SessionInfo, Option<SystemTime>)],
) -> (Option<usize>, Option<PairedBy>, Vec<String>) {
    let dir = path.parent();
    if let Some(stem) = result_stem(path) {
        let found = sessions.iter().position(|(s, _)| {
            s.path.parent() == dir
                && s.path
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .as_deref()
                    .and_then(strip_json)
                    == Some(stem.as_str())
        });
        if let Some(i) = found {
            return (Some(i), Some(PairedBy::FileName), Vec::new());
        }
    }
    let named: Vec<usize> = sessions
        .iter()
        .enumerate()
        .filter(|(_, (s, _))| s.name == result.session)
        .map(|(i, _)| i)
        .collect();
    let here: Vec<usize> = named
        .iter()
        .copied()
        .filter(|&i| sessions[i].0.path.parent() == dir)
        .collect();
    let chosen = match (here.as_slice(), named.as_slice()) {
        ([one], _) | ([], [one]) => Some(*one),
        _ => None,
    };
    match chosen {
        Some(i) => (Some(i), Some(PairedBy::SessionName), Vec::new()),
        None if named.len() > 1 => (
            None,
            None,
            vec![format!(
                "{} session files are named {:?}; none was chosen",
                named.len(),
                result.session
            )],
        ),
        None => (None, None, Vec::new()),
    }
}

fn file_name_date(path: &Path) -> Option<Timestamp> {
    date_in_name(&path.file_name()?.to_string_lossy())
}

fn session_date(name: &str, path: &Path, modified: Option<SystemTime>) -> (Timestamp, DateSource) {
    if let Some(d) = date_in_name(name) {
        return (d, DateSource::SessionName);
    }
    if let Some(d) = file_name_date(path) {
        return (d, DateSource::FileName);
    }
    match modified.and_then(Timestamp::from_system_time) {
        Some(d) => (d, DateSource::SessionModified),
        None => (epoch(), DateSource::Unknown),
    }
}

fn epoch() -> Timestamp {
    Timestamp {
        year: 1970,
        month: 1,
        day: 1,
        hour: 0,
        minute: 0,
        second: 0,
        has_time: false,
    }
}

fn entry_date(
    result: &ResultFile,
    path: &Path,
    modified: Option<SystemTime>,
    session: Option<&(SessionInfo, Option<SystemTime>)>,
) -> (Timestamp, DateSource) {
    if let Some(d) = date_in_name(&result.session) {
        return (d, DateSource::SessionName);
    }
    if let Some(d) =
        file_name_date(path).or_else(|| session.and_then(|(s, _)| file_name_date(&s.path)))
    {
        return (d, DateSource::FileName);
    }
    if let Some(d) = session
        .and_then(|(_, m)| *m)
        .and_then(Timestamp::from_system_time)
    {
        return (d, DateSource::SessionModified);
    }
    match modified.and_then(Timestamp::from_system_time) {
        Some(d) => (d, DateSource::ResultModified),
        None => (epoch(), DateSource::Unknown),
    }
}

// ---------------------------------------------------------------------------
// Reading a result's parameters
// ---------------------------------------------------------------------------

/// What a result's method says about its parameters.
#[derive(Debug, Default)]
struct SolverInfo {
    estimated: Vec<String>,
    fixed: Vec<String>,
    combinations: Vec<Combination>,
    covariance: Option<(Vec<String>, Vec<Vec<f64>>)>,
    stds: HashMap<String, f64>,
    /// Prior σ (angle deg, length mm) when the prior was on.
    prior: Option<(f64, f64)>,
    variance_factor: Option<f64>,
    kept_directions: Option<usize>,
}

fn solver_info(report: &SolverReport) -> SolverInfo {
    match report {
        SolverReport::Ml(r) => {
            let c = &r.covariance;
            let square = c.matrix.len() == c.labels.len()
                && c.matrix.iter().all(|row| row.len() == c.labels.len());
            SolverInfo {
                estimated: r.estimated.clone(),
                fixed: r.fixed.clone(),
                combinations: r
                    .inseparable
                    .iter()
                    .map(|i| Combination {
                        fixed: i.fixed().into_iter().map(str::to_string).collect(),
                        partners: i.partners().into_iter().map(str::to_string).collect(),
                        text: i.to_string(),
                    })
                    .collect(),
                covariance: square.then(|| (c.labels.clone(), c.matrix.clone())),
                stds: r
                    .parameters
                    .iter()
                    .map(|p| (p.parameter.clone(), p.std))
                    .collect(),
                prior: r
                    .prior
                    .enabled
                    .then_some((r.prior.angle_sigma_deg, r.prior.length_sigma_mm)),
                variance_factor: Some(r.variance_factor),
                kept_directions: None,
            }
        }
        SolverReport::Paper(p) => SolverInfo {
            kept_directions: p.kept_directions,
            ..SolverInfo::default()
        },
        SolverReport::Other { .. } => SolverInfo::default(),
    }
}

/// The hand-eye twist labels a hand-eye value depends on (its block).
fn twist_block(index: usize) -> &'static [&'static str] {
    if index < 3 {
        &HAND_EYE_LABELS[..3]
    } else {
        &HAND_EYE_LABELS[3..]
    }
}

fn roll_pitch_yaw_deg(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    Vector3::from(crate::engine::geometry::roll_pitch_yaw_deg(q))
}

/// Jacobians of the hand-eye translation (mm / mm) and roll-pitch-yaw
/// (deg / deg) with respect to the right twist `eT_s · exp(Δ)`.
fn hand_eye_jacobians(rotation: &UnitQuaternion<f64>) -> (Matrix3<f64>, Matrix3<f64>) {
    let jt = rotation.to_rotation_matrix().into_inner();
    let mut jr = Matrix3::zeros();
    for i in 0..3 {
        let mut axis = Vector3::zeros();
        axis[i] = RPY_STEP_DEG.to_radians();
        let plus = roll_pitch_yaw_deg(&(rotation * UnitQuaternion::from_scaled_axis(axis)));
        let minus = roll_pitch_yaw_deg(&(rotation * UnitQuaternion::from_scaled_axis(-axis)));
        for r in 0..3 {
            jr[(r, i)] = wrap_deg(plus[r] - minus[r]) / (2.0 * RPY_STEP_DEG);
        }
    }
    (jt, jr)
}

/// The twist labels ([`HAND_EYE_LABELS`]) hand-eye value `index` depends
/// on (see [`COUPLING_REL`]).
fn coupled_twist(rotation: &UnitQuaternion<f64>, index: usize) -> Vec<&'static str> {
    let (jt, jr) = hand_eye_jacobians(rotation);
    let (jac, row) = if index < 3 {
        (jt, index)
    } else {
        (jr, index - 3)
    };
    let biggest = (0..3).map(|c| jac[(row, c)].abs()).fold(0.0, f64::max);
    let block = twist_block(index);
    (0..3)
        .filter(|&c| jac[(row, c)].abs() >= COUPLING_REL * biggest)
        .map(|c| block[c])
        .collect()
}

fn build_entry(
    path: PathBuf,
    result: &ResultFile,
    session_path: Option<PathBuf>,
    paired_by: Option<PairedBy>,
    date: Timestamp,
    date_source: DateSource,
    notes: Vec<String>,
) -> Result<Entry, String> {
    let he_iso = result.hand_eye;
    let hand_eye = HandEye::new(&result.hand_eye);
    let hand_eye_initial = HandEye::new(&result.hand_eye_initial);
    let method = result.solver.method().to_string();
    let info = solver_info(&result.solver);
    let sigma_scale = info.variance_factor.map_or(1.0, |v| v.max(1.0).sqrt());
    let estimated: HashSet<&str> = info.estimated.iter().map(String::as_str).collect();
    let fixed: HashSet<&str> = info.fixed.iter().map(String::as_str).collect();
    let status_of = |label: &str| {
        if estimated.contains(label) {
            Status::Estimated
        } else if fixed.contains(label) {
            Status::Fixed
        } else {
            Status::Unknown
        }
    };
    let cov = |a: &str, b: &str| -> Option<f64> {
        let (labels, m) = info.covariance.as_ref()?;
        let i = labels.iter().position(|l| l == a)?;
        let j = labels.iter().position(|l| l == b)?;
        Some(m[i][j])
    };
    let std_of = |label: &str| -> Option<f64> {
        info.stds
            .get(label)
            .copied()
            .or_else(|| cov(label, label).map(|v| v.max(0.0).sqrt()))
            .filter(|s| s.is_finite())
    };

    let mut params = Vec::with_capacity(6 + PARAMS_PER_JOINT * result.joint_errors.len());
    // Hand-eye: the twist covariance carried through the Jacobians.
    let (jt, jr) = hand_eye_jacobians(&he_iso.rotation);
    let has_cov = info.covariance.is_some();
    for (i, name) in HAND_EYE_NAMES.iter().enumerate() {
        let block = twist_block(i);
        let (jac, row) = if i < 3 { (&jt, i) } else { (&jr, i - 3) };
        let statuses: Vec<Status> = coupled_twist(&he_iso.rotation, i)
            .into_iter()
            .map(status_of)
            .collect();
        let status = if statuses.iter().all(|s| *s == Status::Estimated) {
            Status::Estimated
        } else if statuses.contains(&Status::Fixed) {
            Status::Fixed
        } else {
            Status::Unknown
        };
        let sigma = (has_cov && status == Status::Estimated).then(|| {
            // A fixed twist component has no variance; its entries are 0.
            let mut var = 0.0;
            for a in 0..3 {
                for b in 0..3 {
                    var += jac[(row, a)] * jac[(row, b)] * cov(block[a], block[b]).unwrap_or(0.0);
                }
            }
            var.max(0.0).sqrt() * sigma_scale
        });
        let value = if i < 3 {
            hand_eye.translation[i]
        } else {
            hand_eye.rpy_deg[i - 3]
        };
        params.push(ParamValue {
            name: (*name).to_string(),
            unit: if i < 3 { Unit::Mm } else { Unit::Deg },
            value,
            sigma: sigma.filter(|s| s.is_finite()),
            status,
            prior_held: false,
        });
    }
    for (k, err) in result
        .joint_errors
        .iter()
        .flat_map(|j| (0..PARAMS_PER_JOINT).map(move |p| j.get(p)))
        .enumerate()
    {
        let label = Robot::param_label(k);
        let is_angle = PARAM_IS_ANGLE[k % PARAMS_PER_JOINT];
        let status = status_of(&label);
        let sigma = (status != Status::Fixed)
            .then(|| std_of(&label))
            .flatten()
            .map(|s| s * sigma_scale);
        let prior_held = match (info.prior, sigma) {
            (Some((angle, length)), Some(s)) => {
                let prior = if is_angle { angle } else { length };
                prior > 0.0 && s / sigma_scale >= PRIOR_HELD_FRACTION * prior
            }
            _ => false,
        };
        params.push(ParamValue {
            name: label,
            unit: if is_angle { Unit::Deg } else { Unit::Mm },
            value: err,
            sigma,
            status,
            prior_held,
        });
    }
    let nominal: Vec<Joint> = result
        .robot
        .joints
        .iter()
        .zip(&result.joint_errors)
        .map(|(c, e)| c.minus(e))
        .collect();
    let validation = result.validation.as_ref();
    Ok(Entry {
        path,
        session_path,
        paired_by,
        date,
        date_source,
        robot: result.robot.name.clone(),
        session: result.session.clone(),
        method,
        epsilon_before: result.epsilon_before,
        epsilon_after: result.epsilon_after,
        validation_before: validation.map(|v| v.before),
        validation_after: validation.map(|v| v.after),
        within_station_before: validation.map(|v| v.within_station.before),
        within_station_after: validation.map(|v| v.within_station.after),
        hand_eye,
        hand_eye_initial,
        nominal,
        calibrated: result.robot.joints.clone(),
        joint_errors: result.joint_errors.clone(),
        params,
        estimated: info.estimated,
        fixed: info.fixed,
        combinations: info.combinations,
        kept_directions: info.kept_directions,
        variance_factor: info.variance_factor,
        sigma_scale,
        notes,
    })
}

// ---------------------------------------------------------------------------
// Drift and jumps
// ---------------------------------------------------------------------------

/// Settings of [`drift`].
#[derive(Debug, Clone, PartialEq)]
pub struct DriftOptions {
    /// Flag a change beyond `k` combined σ ([`DEFAULT_K`]).
    pub k: f64,
    /// Number of main kinematic deviations shown ([`DEFAULT_TOP`]).
    pub top: usize,
    /// Kinematic parameters to show as well (`theta3`, `d4`).
    pub extra: Vec<String>,
}

impl Default for DriftOptions {
    fn default() -> Self {
        Self {
            k: DEFAULT_K,
            top: DEFAULT_TOP,
            extra: Vec::new(),
        }
    }
}

/// Why a series is shown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SeriesKind {
    /// One of the six hand-eye values.
    HandEye,
    /// A main kinematic deviation: `rank` 1 is the largest, `score` the
    /// median `|value| / σ` (or the median `|value|` in mm of effect when
    /// no result has a σ, see `by_sigma`).
    Main {
        /// 1-based rank.
        rank: usize,
        /// Ranking score.
        score: f64,
        /// Whether `score` is in σ (else mm of effect).
        by_sigma: bool,
    },
    /// Chosen by the caller ([`DriftOptions::extra`]).
    Chosen,
    /// Not among the above, but a jump was flagged in it.
    Jumped,
}

impl SeriesKind {
    /// In words, for tables and CSV.
    #[must_use]
    pub fn label(&self) -> String {
        match self {
            Self::HandEye => "hand-eye".into(),
            Self::Main { rank, .. } => format!("main {rank}"),
            Self::Chosen => "chosen".into(),
            Self::Jumped => "jumped".into(),
        }
    }
}

/// One value of a series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Index into [`Library::entries`].
    pub entry: usize,
    /// The entry's date.
    pub date: Timestamp,
    /// Hand-eye: the calibrated value (angles unwrapped along the series,
    /// so a roll near ±180° does not leap by 360°). Kinematic: calibrated
    /// minus [`Drift::reference`].
    pub value: f64,
    /// 1σ when the result has one.
    pub sigma: Option<f64>,
    /// Estimated, fixed or unknown in this result.
    pub status: Status,
    /// Held near nominal by the prior in this result.
    pub prior_held: bool,
}

/// One parameter over time.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// [`HAND_EYE_NAMES`] or a kinematic label.
    pub name: String,
    /// Unit of the values.
    pub unit: Unit,
    /// Why it is shown.
    pub kind: SeriesKind,
    /// One point per result, in date order.
    pub points: Vec<Point>,
}

/// The outcome of one check.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// `|change| > k · combined σ`.
    Jump,
    /// Within `k · combined σ`.
    Steady,
    /// No check was possible; the reason.
    NotChecked(String),
}

/// One parameter between two consecutive results.
#[derive(Debug, Clone, PartialEq)]
pub struct JumpCheck {
    /// Parameter name.
    pub parameter: String,
    /// Unit of the values.
    pub unit: Unit,
    /// Index into [`Library::entries`] of the earlier result.
    pub from: usize,
    /// Index of the later result.
    pub to: usize,
    /// Value in the earlier result (as in the series).
    pub before: f64,
    /// Value in the later result.
    pub after: f64,
    /// `after − before` (angles wrapped to ±180°).
    pub change: f64,
    /// 1σ of the earlier value.
    pub sigma_before: Option<f64>,
    /// 1σ of the later value.
    pub sigma_after: Option<f64>,
    /// `sqrt(σ_before² + σ_after²)`.
    pub combined: Option<f64>,
    /// `|change| / combined`.
    pub ratio: Option<f64>,
    /// Jump, steady or not checked.
    pub verdict: Verdict,
    /// Cautions: prior-held, fixed parameters it carries.
    pub notes: Vec<String>,
}

impl JumpCheck {
    /// Whether a jump was flagged.
    #[must_use]
    pub fn is_jump(&self) -> bool {
        self.verdict == Verdict::Jump
    }
}

/// One robot's results over time (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Drift {
    /// Robot name.
    pub robot: String,
    /// Indices into [`Library::entries`], in date order.
    pub entries: Vec<usize>,
    /// Nominal model the kinematic deviations are measured from: the
    /// earliest result's (deg, mm).
    pub reference: Vec<Joint>,
    /// `k` of the jump check.
    pub k: f64,
    /// Hand-eye series, then main, chosen and jumped kinematic ones.
    pub series: Vec<Series>,
    /// Every check between consecutive results, in date order, hand-eye
    /// first; parameters fixed in both results are not listed.
    pub checks: Vec<JumpCheck>,
    /// Cautions about the whole series (nominal models that differ,
    /// results on the same date, dates from file times).
    pub notes: Vec<String>,
}

impl Drift {
    /// The flagged jumps.
    pub fn jumps(&self) -> impl Iterator<Item = &JumpCheck> {
        self.checks.iter().filter(|c| c.is_jump())
    }

    /// A series by parameter name.
    #[must_use]
    pub fn series(&self, name: &str) -> Option<&Series> {
        self.series.iter().find(|s| s.name == name)
    }
}

/// Value, σ, status and prior flag of parameter `index` of an entry, the
/// kinematic ones measured from `reference`.
fn value_from(entry: &Entry, index: usize, reference: &[Joint]) -> Option<ParamValue> {
    let p = entry.params.get(index)?;
    if index < 6 {
        return Some(p.clone());
    }
    let k = index - 6;
    let joint = k / PARAMS_PER_JOINT;
    let which = k % PARAMS_PER_JOINT;
    let value = entry.calibrated.get(joint)?.get(which) - reference.get(joint)?.get(which);
    Some(ParamValue {
        value: if p.unit == Unit::Deg {
            wrap_deg(value)
        } else {
            value
        },
        ..p.clone()
    })
}

/// The labels (`ml`'s, e.g. `he_z`, `theta3`) a parameter goes by in
/// combinations.
fn method_labels<'a>(index: usize, name: &'a str, entry: &Entry) -> Vec<&'a str> {
    if index < 6 {
        coupled_twist(&entry.hand_eye.rotation(), index)
    } else {
        vec![name]
    }
}

/// One robot's drift: its results in date order, the series to show and
/// every jump check (see the module docs).
///
/// # Errors
/// [`HistoryError::UnknownRobot`] when no result has this robot name
/// (exact; use [`Library::find_robot`] for a partial name),
/// [`HistoryError::InvalidK`], [`HistoryError::UnknownParameter`] for an
/// `extra` name that is not a kinematic parameter of the robot.
pub fn drift(
    library: &Library,
    robot: &str,
    options: &DriftOptions,
) -> Result<Drift, HistoryError> {
    if !(options.k.is_finite() && options.k > 0.0) {
        return Err(HistoryError::InvalidK { k: options.k });
    }
    let entries: Vec<usize> = (0..library.entries.len())
        .filter(|&i| library.entries[i].robot == robot)
        .collect();
    let Some(&first) = entries.first() else {
        return Err(HistoryError::UnknownRobot {
            query: robot.to_string(),
            known: library.robots().into_iter().map(|(n, _)| n).collect(),
        });
    };
    let reference = library.entries[first].nominal.clone();
    let n_params = 6 + PARAMS_PER_JOINT * reference.len();
    let names: Vec<String> = (0..n_params)
        .map(|i| {
            if i < 6 {
                HAND_EYE_NAMES[i].to_string()
            } else {
                Robot::param_label(i - 6)
            }
        })
        .collect();
    for extra in &options.extra {
        if !names.iter().skip(6).any(|n| n == extra) {
            return Err(HistoryError::UnknownParameter {
                name: extra.clone(),
                robot: robot.to_string(),
                count: n_params - 6,
            });
        }
    }
    let mut notes = drift_notes(library, &entries, &reference);

    // Values of every parameter at every entry.
    let values: Vec<Vec<Option<ParamValue>>> = (0..n_params)
        .map(|i| {
            entries
                .iter()
                .map(|&e| value_from(&library.entries[e], i, &reference))
                .collect()
        })
        .collect();

    let checks = jump_checks(library, &entries, &names, &values, options.k);

    // Main kinematic deviations.
    let any_sigma = (6..n_params).any(|i| {
        values[i]
            .iter()
            .flatten()
            .any(|p| p.sigma.is_some() && p.status == Status::Estimated)
    });
    let mut ranked: Vec<(usize, f64)> = (6..n_params)
        .filter_map(|i| {
            let vals = values[i]
                .iter()
                .flatten()
                .filter(|p| p.status != Status::Fixed);
            let scores: Vec<f64> = if any_sigma {
                vals.filter_map(|p| p.sigma.filter(|s| *s > 0.0).map(|s| p.value.abs() / s))
                    .collect()
            } else {
                vals.map(|p| {
                    if p.unit == Unit::Deg {
                        p.value.abs().to_radians() * ANGLE_SCALE_MM
                    } else {
                        p.value.abs()
                    }
                })
                .collect()
            };
            median(scores).map(|m| (i, m))
        })
        .collect();
    ranked.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));

    let mut chosen: Vec<(usize, SeriesKind)> = (0..6).map(|i| (i, SeriesKind::HandEye)).collect();
    for (rank, &(i, score)) in ranked.iter().take(options.top).enumerate() {
        chosen.push((
            i,
            SeriesKind::Main {
                rank: rank + 1,
                score,
                by_sigma: any_sigma,
            },
        ));
    }
    for extra in &options.extra {
        if let Some(i) = names.iter().position(|n| n == extra)
            && !chosen.iter().any(|(c, _)| *c == i)
        {
            chosen.push((i, SeriesKind::Chosen));
        }
    }
    for c in checks.iter().filter(|c| c.is_jump()) {
        if let Some(i) = names.iter().position(|n| *n == c.parameter)
            && !chosen.iter().any(|(x, _)| *x == i)
        {
            chosen.push((i, SeriesKind::Jumped));
        }
    }
    let series = chosen
        .into_iter()
        .map(|(i, kind)| Series {
            name: names[i].clone(),
            unit: if i < 3 || (i >= 6 && !PARAM_IS_ANGLE[(i - 6) % PARAMS_PER_JOINT]) {
                Unit::Mm
            } else {
                Unit::Deg
            },
            kind,
            points: series_points(library, &entries, &values[i]),
        })
        .collect();
    if entries.len() < 2 {
        notes.push("one result only: nothing to compare yet".into());
    }
    Ok(Drift {
        robot: robot.to_string(),
        entries,
        reference,
        k: options.k,
        series,
        checks,
        notes,
    })
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        f64::midpoint(v[n / 2 - 1], v[n / 2])
    })
}

fn series_points(
    library: &Library,
    entries: &[usize],
    values: &[Option<ParamValue>],
) -> Vec<Point> {
    let mut out: Vec<Point> = Vec::with_capacity(entries.len());
    for (&e, v) in entries.iter().zip(values) {
        let Some(v) = v else { continue };
        let value = match (v.unit, out.last()) {
            (Unit::Deg, Some(prev)) => prev.value + wrap_deg(v.value - prev.value),
            _ => v.value,
        };
        out.push(Point {
            entry: e,
            date: library.entries[e].date,
            value,
            sigma: v.sigma,
            status: v.status,
            prior_held: v.prior_held,
        });
    }
    out
}

fn drift_notes(library: &Library, entries: &[usize], reference: &[Joint]) -> Vec<String> {
    let mut notes = Vec::new();
    let differs: Vec<String> = entries
        .iter()
        .map(|&e| &library.entries[e])
        .filter(|e| {
            e.nominal.len() != reference.len()
                || e.nominal
                    .iter()
                    .zip(reference)
                    .any(|(a, b)| (0..PARAMS_PER_JOINT).any(|k| (a.get(k) - b.get(k)).abs() > 1e-9))
        })
        .map(|e| e.date.to_string())
        .collect();
    if !differs.is_empty() {
        notes.push(format!(
            "the nominal model differs in the results of {}: kinematic deviations are measured from the earliest result's nominal model",
            differs.join(", ")
        ));
    }
    let from_files = entries
        .iter()
        .filter(|&&e| !library.entries[e].date_source.is_from_name())
        .count();
    if from_files > 0 {
        notes.push(format!(
            "{from_files} of {} dates come from file times, which change when files are copied; put the date in the session name (YYYY-MM-DD)",
            entries.len()
        ));
    }
    let mut shared: Vec<String> = entries
        .windows(2)
        .map(|w| (&library.entries[w[0]], &library.entries[w[1]]))
        .filter(|(a, b)| a.date == b.date)
        .map(|(a, _)| a.date.to_string())
        .collect();
    shared.dedup();
    if !shared.is_empty() {
        notes.push(format!(
            "several results share a date ({}): among themselves they are in file path order",
            shared.join(", ")
        ));
    }
    notes
}

/// Fixed parameters that differ between two results, and every label that
/// belongs to a combination with one of them.
fn differing_fixed(a: &Entry, b: &Entry) -> (Vec<String>, HashSet<String>) {
    if a.estimated.is_empty() || b.estimated.is_empty() {
        // A method that does not say what it estimated: nothing to compare.
        return (Vec::new(), HashSet::new());
    }
    let fa: HashSet<&String> = a.fixed.iter().collect();
    let fb: HashSet<&String> = b.fixed.iter().collect();
    let mut diff: Vec<String> = fa.symmetric_difference(&fb).map(|s| (*s).clone()).collect();
    diff.sort();
    let mut involved: HashSet<String> = diff.iter().cloned().collect();
    for c in a.combinations.iter().chain(&b.combinations) {
        if c.fixed.iter().any(|f| diff.contains(f)) {
            involved.extend(c.partners.iter().cloned());
            involved.extend(c.fixed.iter().cloned());
        }
    }
    (diff, involved)
}

/// Whether a value can be judged against another: estimated, with a σ.
fn comparable(p: &ParamValue) -> bool {
    p.status != Status::Fixed && p.sigma.is_some()
}

/// Every check of every parameter: each result against the latest earlier
/// result in which the parameter is comparable (so a `paper` result in
/// between does not break the chain of `ml` results), or, when the result
/// itself is not comparable, against the result just before it (a "not
/// checked" row). Sorted by the later result, then parameter order.
fn jump_checks(
    library: &Library,
    entries: &[usize],
    names: &[String],
    values: &[Vec<Option<ParamValue>>],
    k: f64,
) -> Vec<JumpCheck> {
    let mut out: Vec<(usize, usize, JumpCheck)> = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let mut last: Option<usize> = None;
        let mut prev: Option<usize> = None;
        for (w, v) in values[i].iter().enumerate() {
            let Some(b) = v else { continue };
            let from = if comparable(b) { last.or(prev) } else { prev };
            // Nothing identifiable to compare: fixed in one result and not
            // estimated in the other (fixed too, or a method that does not say).
            let identifiable = |p: &ParamValue| p.status == Status::Estimated;
            if let Some(wa) = from
                && let Some(a) = &values[i][wa]
                && !((a.status == Status::Fixed || b.status == Status::Fixed)
                    && !(identifiable(a) || identifiable(b)))
            {
                let between = (wa + 1..w).filter(|&x| values[i][x].is_some()).count();
                let pair = (&library.entries[entries[wa]], &library.entries[entries[w]]);
                let mut c = check(pair, (entries[wa], entries[w]), name, i, (a, b), k);
                if between > 0 {
                    c.notes.push(format!(
                        "compared with the result of {}: the {} between have no σ for it",
                        pair.0.date,
                        if between == 1 {
                            "result".to_string()
                        } else {
                            format!("{between} results")
                        }
                    ));
                }
                out.push((w, i, c));
            }
            if comparable(b) {
                last = Some(w);
            }
            prev = Some(w);
        }
    }
    out.sort_by_key(|(w, i, _)| (*w, *i));
    out.into_iter().map(|(_, _, c)| c).collect()
}

/// One check of parameter `name` (index `i`) from result `a` to `b`.
fn check(
    (ea, eb): (&Entry, &Entry),
    (ia, ib): (usize, usize),
    name: &str,
    i: usize,
    (a, b): (&ParamValue, &ParamValue),
    k: f64,
) -> JumpCheck {
    let change = if a.unit == Unit::Deg {
        wrap_deg(b.value - a.value)
    } else {
        b.value - a.value
    };
    let labels = method_labels(i, name, ea);
    let (diff, involved) = differing_fixed(ea, eb);
    let mut notes = Vec::new();
    if a.prior_held || b.prior_held {
        notes.push(format!(
            "held near nominal by the ml prior (σ ≥ {PRIOR_HELD_FRACTION} × prior σ): the data barely see it, so a real change is shrunk"
        ));
    }
    let mut carried: Vec<&Combination> = eb
        .combinations
        .iter()
        .filter(|c| c.partners.iter().any(|p| labels.contains(&p.as_str())))
        .collect();
    carried.dedup_by(|x, y| x.text == y.text);
    for c in carried {
        notes.push(format!(
            "may also be a change of {} (fixed; {})",
            c.fixed.join(", "),
            c.text
        ));
    }
    let not_checked = if a.status == Status::Fixed || b.status == Status::Fixed {
        Some("estimated in one result, fixed in the other".to_string())
    } else if a.sigma.is_none() || b.sigma.is_none() {
        let mut methods: Vec<&str> = [(ea, a), (eb, b)]
            .iter()
            .filter(|(_, p)| p.sigma.is_none())
            .map(|(e, _)| e.method.as_str())
            .collect();
        methods.dedup();
        Some(format!(
            "no uncertainty in the result ({} method): a change cannot be judged",
            methods.join(" and ")
        ))
    } else if !diff.is_empty() && labels.iter().any(|l| involved.contains(*l)) {
        Some(format!(
            "the results fixed different parameters ({}), so this value carries different combinations",
            diff.join(", ")
        ))
    } else {
        None
    };
    let combined = match (a.sigma, b.sigma) {
        (Some(sa), Some(sb)) => Some(sa.hypot(sb)),
        _ => None,
    };
    let ratio = combined.filter(|c| *c > 0.0).map(|c| change.abs() / c);
    let verdict = match (not_checked, ratio) {
        (Some(reason), _) => Verdict::NotChecked(reason),
        (None, Some(r)) if r > k => Verdict::Jump,
        (None, Some(_)) => Verdict::Steady,
        (None, None) => Verdict::NotChecked("zero uncertainty".into()),
    };
    JumpCheck {
        parameter: name.to_string(),
        unit: a.unit,
        from: ia,
        to: ib,
        before: a.value,
        after: a.value + change,
        change,
        sigma_before: a.sigma,
        sigma_after: b.sigma,
        combined,
        ratio,
        verdict,
        notes,
    }
}

// ---------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The drifts as CSV, one row per result and parameter (every hand-eye and
/// kinematic parameter, not only the shown series), values at full
/// precision: `robot, date, date_source, result, session, method,
/// parameter, unit, value, sigma, status, prior_held, series`. `value` is
/// as in the series (kinematic: calibrated minus the drift's reference
/// nominal); `sigma` is empty when the result has none; `series` says why
/// the drift shows the parameter (`hand-eye`, `main 1`, `chosen`,
/// `jumped`) and is empty when it does not.
#[must_use]
pub fn drift_csv(library: &Library, drifts: &[Drift]) -> String {
    let mut s = String::from(
        "robot,date,date_source,result,session,method,parameter,unit,value,sigma,status,prior_held,series\n",
    );
    for d in drifts {
        let n_params = 6 + PARAMS_PER_JOINT * d.reference.len();
        for &e in &d.entries {
            let entry = &library.entries[e];
            for i in 0..n_params {
                let Some(v) = value_from(entry, i, &d.reference) else {
                    continue;
                };
                let (value, kind) = match d.series(&v.name) {
                    Some(series) => (
                        series
                            .points
                            .iter()
                            .find(|p| p.entry == e)
                            .map_or(v.value, |p| p.value),
                        series.kind.label(),
                    ),
                    None => (v.value, String::new()),
                };
                let _ = writeln!(
                    s,
                    "{},{},{},{},{},{},{},{},{},{},{},{},{}",
                    csv_field(&d.robot),
                    entry.date,
                    entry.date_source.as_str(),
                    csv_field(&entry.path.display().to_string()),
                    csv_field(&entry.session),
                    csv_field(&entry.method),
                    v.name,
                    v.unit.as_str(),
                    value,
                    v.sigma.map(|x| x.to_string()).unwrap_or_default(),
                    v.status.as_str(),
                    v.prior_held,
                    kind
                );
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_in_names() {
        let d = |y, m, day| Timestamp::date(y, m, day).unwrap();
        assert_eq!(
            date_in_name("IRB2400 cell 3, 2026-11-20"),
            Some(d(2026, 11, 20))
        );
        assert_eq!(
            date_in_name("cell 3 2026-11-20T14:05"),
            Some(d(2026, 11, 20).at(14, 5, 0).unwrap())
        );
        assert_eq!(
            date_in_name("2026-11-20 14:05:09 after the crash"),
            Some(d(2026, 11, 20).at(14, 5, 9).unwrap())
        );
        assert_eq!(
            date_in_name("x_2024-02-29_08:00.json"),
            Some(d(2024, 2, 29).at(8, 0, 0).unwrap())
        );
        // A bad time keeps the date.
        assert_eq!(date_in_name("2026-11-20T25:00"), Some(d(2026, 11, 20)));
        // Not dates: February 30, a longer number, a year out of range,
        // no date at all. The first valid date wins.
        assert_eq!(date_in_name("2026-02-30"), None);
        assert_eq!(date_in_name("2025-02-29"), None);
        assert_eq!(date_in_name("SN 12026-11-20"), None);
        assert_eq!(date_in_name("2026-11-201"), None);
        assert_eq!(date_in_name("0815-01-01"), None);
        assert_eq!(date_in_name("simulated ABB IRB 2400/16, seed 7"), None);
        assert_eq!(
            date_in_name("2026-13-01 then 2027-01-02"),
            Some(d(2027, 1, 2))
        );
        assert_eq!(date_in_name("été 2026-07-14"), Some(d(2026, 7, 14)));
        assert_eq!(d(2026, 11, 20).to_string(), "2026-11-20");
        assert_eq!(
            d(2026, 11, 20).at(9, 3, 0).unwrap().to_string(),
            "2026-11-20 09:03:00"
        );
        assert!(d(2026, 11, 20) < d(2026, 11, 20).at(0, 0, 1).unwrap());
    }

    #[test]
    fn file_times_are_utc_dates() {
        let t = |s: u64| UNIX_EPOCH + std::time::Duration::from_secs(s);
        assert_eq!(
            Timestamp::from_system_time(t(0)).unwrap().to_string(),
            "1970-01-01 00:00:00"
        );
        // 2000-02-29 12:34:56 UTC (a leap day of a century leap year).
        assert_eq!(
            Timestamp::from_system_time(t(951_827_696))
                .unwrap()
                .to_string(),
            "2000-02-29 12:34:56"
        );
        // 2026-11-20 00:00:00 UTC.
        assert_eq!(
            Timestamp::from_system_time(t(1_795_132_800))
                .unwrap()
                .to_string(),
            "2026-11-20 00:00:00"
        );
    }

    #[test]
    fn wrapping_and_result_stems() {
        assert!((wrap_deg(359.0) + 1.0).abs() < 1e-12);
        assert!((wrap_deg(-181.0) - 179.0).abs() < 1e-12);
        assert_eq!(wrap_deg(180.0), 180.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(
            result_stem(Path::new("a/cell3.result.json")).as_deref(),
            Some("cell3")
        );
        assert_eq!(
            result_stem(Path::new("a/cell3_result.JSON")).as_deref(),
            Some("cell3")
        );
        assert_eq!(result_stem(Path::new("a/cell3.json")), None);
    }

    #[test]
    fn hand_eye_jacobian_matches_a_finite_step() {
        // The paper's hand-eye rotation: roll near 180°, where a naive
        // difference of Euler angles would leap by 360°.
        let rows = [
            [0.8703, 0.4925, -0.0108, -7.442],
            [0.4921, -0.8702, -0.0227, -1.012],
            [-0.0205, 0.0144, -0.9997, 287.804],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let r = Matrix3::from_fn(|i, j| rows[i][j]);
        let q = UnitQuaternion::from_matrix(&r);
        let (jt, jr) = hand_eye_jacobians(&q);
        assert!((jt - q.to_rotation_matrix().into_inner()).norm() < 1e-12);
        let step = Vector3::new(0.01, -0.02, 0.015); // deg
        let moved =
            roll_pitch_yaw_deg(&(q * UnitQuaternion::from_scaled_axis(step.map(f64::to_radians))));
        let base = roll_pitch_yaw_deg(&q);
        let predicted = jr * step;
        for i in 0..3 {
            let actual = wrap_deg(moved[i] - base[i]);
            assert!(
                (actual - predicted[i]).abs() < 1e-5,
                "component {i}: {actual} vs {predicted}"
            );
        }
    }
}
