//! The history of a cell: a library over a folder of session and result
//! files ([`read_library`]), and for one robot the drift of the hand-eye and of
//! its main kinematic deviations over time, with every change between
//! consecutive results that exceeds `k` times their combined 1σ flagged
//! ([`drift`]).
//!
//! # The library
//!
//! [`read_library`] walks a folder (subfolders to [`MAX_DEPTH`] levels; hidden
//! entries such as `.git` or the temporary files of
//! [`write_atomic`](crate::engine::files::format::write_atomic) and symbolic links to
//! folders are skipped). Every `*.json` file is classified by its
//! `"format"` key, not by its name: `spherecal-session` and
//! `spherecal-result` files are loaded by the strict loaders of
//! [`session`](crate::engine::files::format); JSON files of other formats (truth files,
//! anything else) are listed as ignored. A file that cannot be read, is
//! not JSON, or breaks a rule of its format is a [`Problem`] with its path
//! and message, and the walk goes on. Only a folder that cannot be read at
//! all fails the walk ([`HistoryError`]).
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
//! **Checks.** A `spherecal-check` file (the record `spherecal check`
//! writes beside its session) is a [`CheckEntry`], dated by its `date`
//! key (else its file's modification time), listed with its verdict and
//! what moved.
//!
//! # Parameters and their uncertainty
//!
//! Every entry holds 6 hand-eye values and the `5·n` kinematic deviations
//! as [`ParamValue`]s, each with its 1σ when the result's `solver` block
//! has a covariance (the `ml` method; the paper's method reports none):
//!
//! - **Hand-eye**: the calibrated `eT_s` as translation `hand_eye.x/y/z`
//!   (mm, flange frame) and `hand_eye.roll/pitch/yaw` (deg; the crate's
//!   roll/pitch/yaw convention, see the crate docs). `ml` reports the
//!   covariance of the hand-eye perturbation (the crate's convention: a
//!   right twist in the sensor frame, [`HAND_EYE_LABELS`](crate::engine::calibrate::solve::estimate::HAND_EYE_LABELS)); it is carried to
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
//! 17.45 mm), the paper's own scaling ([`ANGLE_SCALE_MM`](crate::engine::calibrate::solve::estimate::ANGLE_SCALE_MM)).
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

mod csv;
mod date;
mod drift;
mod entry;
mod walk;

pub use csv::drift_csv;
pub use date::{DateSource, Timestamp, date_in_name};
pub use drift::{Drift, DriftOptions, JumpCheck, Point, Series, SeriesKind, Verdict, drift};
pub use walk::read_library;

use std::fmt;
use std::io;
use std::path::PathBuf;

use nalgebra::{Isometry3, UnitQuaternion};

use crate::engine::base::geometry::rotation_from_rpy_deg;
use crate::engine::base::robot::Joint;
pub use crate::engine::base::session::Mount;
use crate::engine::calibrate::validate::Stats;
use crate::engine::tools::result_view::HandEyeView;

/// Deepest subfolder level [`read_library`] enters (the folder itself is level 0).
/// A library is a folder of cells, robots or dates; 8 levels is far beyond
/// any such layout and still stops a walk into an unrelated tree.
pub const MAX_DEPTH: usize = 8;
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
/// The six values of a fixed sensor's `base_from_sensor` (`bT_s`: mm in
/// the base frame, roll, pitch, yaw in deg), what [`HAND_EYE_NAMES`] are
/// for a sensor on the flange.
pub const BASE_FROM_SENSOR_NAMES: [&str; 6] = [
    "base_from_sensor.x",
    "base_from_sensor.y",
    "base_from_sensor.z",
    "base_from_sensor.roll",
    "base_from_sensor.pitch",
    "base_from_sensor.yaw",
];

/// The names of the six sensor values of a result of `mount`: the
/// hand-eye's for a sensor on the flange, `base_from_sensor`'s for a
/// fixed sensor.
#[must_use]
pub fn hand_eye_names(mount: Mount) -> [&'static str; 6] {
    match mount {
        Mount::Flange => HAND_EYE_NAMES,
        Mount::Fixed => BASE_FROM_SENSOR_NAMES,
    }
}

/// What the six sensor values of results of `mounts` are called: the
/// hand-eye (sensors on the flange), `base_from_sensor` (fixed sensors),
/// or both named when they mix.
#[must_use]
pub fn sensor_name(mounts: impl IntoIterator<Item = Mount>) -> &'static str {
    let (mut flange, mut fixed) = (false, false);
    for m in mounts {
        match m {
            Mount::Flange => flange = true,
            Mount::Fixed => fixed = true,
        }
    }
    match (flange, fixed) {
        (true, true) => "hand-eye or base_from_sensor",
        (false, true) => "base_from_sensor",
        _ => "hand-eye",
    }
}

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

/// A file the walk could not use, and why.
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
    /// hand-eye twist labels [`HAND_EYE_LABELS`](crate::engine::calibrate::solve::estimate::HAND_EYE_LABELS) or kinematic labels);
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
    /// Where the sensor stood: says whether [`Entry::hand_eye`] is the
    /// hand-eye `eT_s` or a fixed sensor's `base_from_sensor` `bT_s`.
    pub mount: Mount,
    /// The calibrated hand-eye (`bT_s` for a fixed sensor).
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

/// A re-check's record of the library (`spherecal check`).
#[derive(Debug, Clone, PartialEq)]
pub struct CheckEntry {
    /// The record file.
    pub path: PathBuf,
    /// When the check was made (the record's `date`; else its file time).
    pub date: Timestamp,
    /// The record.
    pub record: crate::engine::files::format::CheckRecord,
}

/// What [`read_library`] found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Library {
    /// Re-check records, in date order (then by path).
    pub checks: Vec<CheckEntry>,
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
// ---------------------------------------------------------------------------
// Reading a result's parameters
// ---------------------------------------------------------------------------
// ---------------------------------------------------------------------------
// Drift and jumps
// ---------------------------------------------------------------------------
// ---------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------
#[cfg(test)]
mod tests {
    use std::path::Path;
    use std::time::UNIX_EPOCH;

    use nalgebra::{Matrix3, Vector3};

    use super::entry::{hand_eye_jacobians, roll_pitch_yaw_deg};
    use super::walk::result_stem;
    use super::*;

    #[test]
    fn the_sensor_values_are_named_by_mount() {
        assert_eq!(hand_eye_names(Mount::Flange)[0], "hand_eye.x");
        assert_eq!(hand_eye_names(Mount::Fixed)[5], "base_from_sensor.yaw");
        assert_eq!(sensor_name([Mount::Flange, Mount::Flange]), "hand-eye");
        assert_eq!(sensor_name([Mount::Fixed]), "base_from_sensor");
        assert_eq!(
            sensor_name([Mount::Fixed, Mount::Flange]),
            "hand-eye or base_from_sensor"
        );
        assert_eq!(sensor_name([]), "hand-eye");
        assert_eq!(SeriesKind::HandEye.label(Mount::Fixed), "base from sensor");
        assert_eq!(SeriesKind::HandEye.label(Mount::Flange), "hand-eye");
    }
    use crate::engine::base::geometry::wrap_deg;

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
