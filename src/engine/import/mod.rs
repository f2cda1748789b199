//! Import of real data (issue 5): a joint log CSV plus stripe profiles
//! become a [`Session`], validated by a round trip through the session
//! loader so every FORMAT.md rule is enforced with its own messages.
//!
//! Optional flange poses from the robot controller are checked against the
//! nominal model's forward kinematics; a pose further off than the
//! tolerance is flagged with a hint at the likely cause (joints in the
//! wrong unit, two joint columns swapped, wrong robot or base frame).
//!
//! CSV files: comma or semicolon separated (the header decides), fields
//! trimmed and stripped of surrounding quotes, blank lines and lines
//! starting with `#` ignored, the first other line is the header. Column
//! names match case-insensitively. Line numbers in messages are 1-based
//! lines of the file.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use crate::engine::format::FileError;
use crate::engine::format::{parse_result, parse_session, session_to_json};
use crate::engine::robot::{self, Robot};
use crate::engine::session::{
    Measurement, Observation, ReferenceDistance, Session, SolverSettings, Use,
};

/// The side column read when the mapping names none.
pub const DEFAULT_SIDE_COLUMN: &str = "side";
/// Default sphere diameter, mm: the 1.5 inch sphere of the paper.
pub const DEFAULT_SPHERE_DIAMETER: f64 = 38.1;
/// Default position tolerance of the flange-pose check, mm: a few mm, far
/// above the nominal model's errors (< 1 mm) and far below the effect of a
/// unit or joint-order mistake (tens to hundreds of mm).
pub const DEFAULT_POSITION_TOLERANCE_MM: f64 = 3.0;
/// Default rotation tolerance of the flange-pose check, deg.
pub const DEFAULT_ROTATION_TOLERANCE_DEG: f64 = 0.5;
/// Largest accepted deviation of an ABB quaternion's norm from 1.
const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// Unit of the joint readings in the log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleUnit {
    /// Degrees (the session's unit).
    Deg,
    /// Radians.
    Rad,
}

impl AngleUnit {
    /// The value in degrees.
    #[must_use]
    pub fn to_deg(self, v: f64) -> f64 {
        match self {
            Self::Deg => v,
            Self::Rad => v.to_degrees(),
        }
    }

    /// Short name, `deg` or `rad`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Deg => "deg",
            Self::Rad => "rad",
        }
    }

    /// Parses `deg` or `rad`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "deg" => Some(Self::Deg),
            "rad" => Some(Self::Rad),
            _ => None,
        }
    }
}

/// Unit of the stripe profile coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    /// Millimetres (the session's unit).
    Mm,
    /// Micrometres.
    Um,
    /// Metres.
    M,
}

impl LengthUnit {
    /// The value in millimetres.
    #[must_use]
    pub fn to_mm(self, v: f64) -> f64 {
        match self {
            Self::Mm => v,
            Self::Um => v / 1000.0,
            Self::M => v * 1000.0,
        }
    }

    /// Short name, `mm`, `um` or `m`.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mm => "mm",
            Self::Um => "um",
            Self::M => "m",
        }
    }

    /// Parses `mm`, `um` or `m`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "mm" => Some(Self::Mm),
            "um" => Some(Self::Um),
            "m" => Some(Self::M),
            _ => None,
        }
    }
}

/// Where the stripe profiles are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ProfileSource {
    /// A folder with one CSV per pose named `<id>.csv`, columns `y`, `z`.
    Folder(PathBuf),
    /// One CSV with columns `<pose_column>`, `y`, `z`.
    File {
        /// The file.
        path: PathBuf,
        /// Name of the column holding the pose id.
        pose_column: String,
    },
}

/// Where the nominal robot model comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RobotSource {
    /// A preset key of [`robot::preset`] (`irb2400`, `irb120`, `ur5e`).
    Preset(String),
    /// The `robot` block of a session or result file.
    File(PathBuf),
}

/// Column names of the joint log.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnMap {
    /// Measurement id.
    pub id: String,
    /// Station id.
    pub station: String,
    /// Use (`translation`, `rotation`, `identify`, `validate`).
    pub usage: String,
    /// Side (+1 or −1). `None`: the column named [`DEFAULT_SIDE_COLUMN`]
    /// when the log has one, else every side is +1.
    pub side: Option<String>,
    /// The joint columns, joint 1 first; one per robot joint.
    pub joints: Vec<String>,
}

/// How a controller writes the flange pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlangeConvention {
    /// ABB: x, y, z (mm), q1..q4 = w, x, y, z of a unit quaternion.
    AbbQuaternion,
    /// KUKA: x, y, z (mm), A, B, C (deg), `R = Rz(A)·Ry(B)·Rx(C)`.
    KukaAbc,
    /// Fanuc: x, y, z (mm), W, P, R (deg), `R = Rz(R)·Ry(P)·Rx(W)`.
    FanucWpr,
    /// Universal Robots: x, y, z (m), rx, ry, rz (rad) rotation vector.
    UrRotationVector,
}

impl FlangeConvention {
    /// Number of columns a pose takes (7 for ABB, 6 otherwise).
    #[must_use]
    pub fn n_columns(self) -> usize {
        match self {
            Self::AbbQuaternion => 7,
            _ => 6,
        }
    }

    /// Default column names.
    #[must_use]
    pub fn default_columns(self) -> Vec<String> {
        let names: &[&str] = match self {
            Self::AbbQuaternion => &["x", "y", "z", "q1", "q2", "q3", "q4"],
            Self::KukaAbc => &["x", "y", "z", "a", "b", "c"],
            Self::FanucWpr => &["x", "y", "z", "w", "p", "r"],
            Self::UrRotationVector => &["x", "y", "z", "rx", "ry", "rz"],
        };
        names.iter().map(|s| (*s).to_string()).collect()
    }

    /// Parses `ABB`, `KUKA`, `FANUC` or `UR` (any case).
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s.to_ascii_lowercase().as_str() {
            "abb" => Some(Self::AbbQuaternion),
            "kuka" => Some(Self::KukaAbc),
            "fanuc" => Some(Self::FanucWpr),
            "ur" => Some(Self::UrRotationVector),
            _ => None,
        }
    }

    /// The flange pose `bT_e` (mm) from the controller's values, or what
    /// is wrong with them.
    ///
    /// # Errors
    /// A message when the count is wrong or an ABB quaternion is not unit.
    pub fn pose_from_values(self, v: &[f64]) -> Result<Isometry3<f64>, String> {
        if v.len() != self.n_columns() {
            return Err(format!(
                "{} values given, the convention needs {}",
                v.len(),
                self.n_columns()
            ));
        }
        let (t, r) = match self {
            Self::AbbQuaternion => {
                let q = Quaternion::new(v[3], v[4], v[5], v[6]);
                if (q.norm() - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
                    return Err(format!("quaternion norm {:.6} is not 1", q.norm()));
                }
                (
                    Vector3::new(v[0], v[1], v[2]),
                    UnitQuaternion::from_quaternion(q),
                )
            }
            Self::KukaAbc => (
                Vector3::new(v[0], v[1], v[2]),
                UnitQuaternion::from_euler_angles(
                    v[5].to_radians(),
                    v[4].to_radians(),
                    v[3].to_radians(),
                ),
            ),
            Self::FanucWpr => (
                Vector3::new(v[0], v[1], v[2]),
                UnitQuaternion::from_euler_angles(
                    v[3].to_radians(),
                    v[4].to_radians(),
                    v[5].to_radians(),
                ),
            ),
            Self::UrRotationVector => (
                Vector3::new(v[0], v[1], v[2]) * 1000.0,
                UnitQuaternion::from_scaled_axis(Vector3::new(v[3], v[4], v[5])),
            ),
        };
        Ok(Isometry3::from_parts(Translation3::from(t), r))
    }

    /// The controller's values for a flange pose `bT_e` (mm): the inverse
    /// of [`Self::pose_from_values`] (for tests and simulated logs).
    #[must_use]
    pub fn values_from_pose(self, pose: &Isometry3<f64>) -> Vec<f64> {
        let t = pose.translation.vector;
        let r = pose.rotation;
        match self {
            Self::AbbQuaternion => vec![t.x, t.y, t.z, r.w, r.i, r.j, r.k],
            Self::KukaAbc => {
                let (roll, pitch, yaw) = r.euler_angles();
                vec![
                    t.x,
                    t.y,
                    t.z,
                    yaw.to_degrees(),
                    pitch.to_degrees(),
                    roll.to_degrees(),
                ]
            }
            Self::FanucWpr => {
                let (roll, pitch, yaw) = r.euler_angles();
                vec![
                    t.x,
                    t.y,
                    t.z,
                    roll.to_degrees(),
                    pitch.to_degrees(),
                    yaw.to_degrees(),
                ]
            }
            Self::UrRotationVector => {
                let s = r.scaled_axis();
                vec![t.x / 1000.0, t.y / 1000.0, t.z / 1000.0, s.x, s.y, s.z]
            }
        }
    }
}

/// The optional flange-pose check.
#[derive(Debug, Clone, PartialEq)]
pub struct FlangeCheck {
    /// How the controller writes the pose.
    pub convention: FlangeConvention,
    /// The pose columns of the joint log, in the convention's order.
    pub columns: Vec<String>,
    /// Largest accepted position mismatch, mm.
    pub tolerance_mm: f64,
    /// Largest accepted rotation mismatch, deg.
    pub tolerance_deg: f64,
}

impl FlangeCheck {
    /// A check with the convention's default columns and tolerances.
    #[must_use]
    pub fn new(convention: FlangeConvention) -> Self {
        Self {
            convention,
            columns: convention.default_columns(),
            tolerance_mm: DEFAULT_POSITION_TOLERANCE_MM,
            tolerance_deg: DEFAULT_ROTATION_TOLERANCE_DEG,
        }
    }
}

/// Everything the import needs.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportSpec {
    /// The joint log CSV.
    pub joint_log: PathBuf,
    /// Its column names.
    pub columns: ColumnMap,
    /// Unit of its joint columns.
    pub joint_unit: AngleUnit,
    /// The stripe profiles.
    pub profiles: ProfileSource,
    /// Unit of the profile coordinates.
    pub profile_unit: LengthUnit,
    /// The nominal robot model.
    pub robot: RobotSource,
    /// Sphere diameter, mm.
    pub sphere_diameter: f64,
    /// Session name; `None` gives the joint log's file stem.
    pub name: Option<String>,
    /// Optional flange-pose check.
    pub flange: Option<FlangeCheck>,
    /// Optional laser-tracker reference distances: a CSV with columns
    /// `from`, `to`, `distance` (station ids, mm).
    pub references: Option<PathBuf>,
}

/// The flange-pose check of one pose.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseCheck {
    /// Measurement id.
    pub id: String,
    /// Distance between the controller's and the nominal FK flange
    /// position, mm.
    pub position_error_mm: f64,
    /// Angle between the two flange orientations, deg.
    pub rotation_error_deg: f64,
    /// Whether either error is above its tolerance.
    pub flagged: bool,
    /// The likely cause when flagged, else empty.
    pub hint: String,
}

/// An import failed; every message names the file and, where it applies,
/// the line, column or pose id.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// A file could not be read.
    #[error("reading failed: {source} ({path})")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A CSV problem at a line.
    #[error("line {line}: {message} ({path})")]
    Csv {
        /// The file.
        path: PathBuf,
        /// 1-based line of the file.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A problem with the file as a whole (no header, missing column).
    #[error("{message} ({path})")]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A pose of the joint log has no profile.
    #[error("pose {id}: no stripe profile ({path})")]
    MissingProfile {
        /// The pose id.
        id: String,
        /// The file that was expected, or the single profile file.
        path: PathBuf,
    },
    /// The specification itself is inconsistent.
    #[error("{0}")]
    Spec(String),
    /// The built session breaks a FORMAT.md rule (the loader's message).
    #[error("{0}")]
    Session(#[from] FileError),
}

/// A parsed CSV: header and data rows with their line numbers.
struct Csv {
    path: PathBuf,
    header: Vec<String>,
    rows: Vec<(usize, Vec<String>)>,
}

fn clean(field: &str) -> String {
    let f = field.trim();
    let f = f
        .strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(f);
    f.trim().to_string()
}

impl Csv {
    fn read(path: &Path) -> Result<Self, ImportError> {
        let text = fs::read_to_string(path).map_err(|source| ImportError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l))
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let Some((_, header_line)) = lines.next() else {
            return Err(ImportError::File {
                path: path.to_path_buf(),
                message: "no header row".into(),
            });
        };
        let sep = if header_line.contains(';') { ';' } else { ',' };
        let header: Vec<String> = header_line.split(sep).map(clean).collect();
        let mut rows = Vec::new();
        for (line, l) in lines {
            let fields: Vec<String> = l.split(sep).map(clean).collect();
            if fields.len() != header.len() {
                return Err(ImportError::Csv {
                    path: path.to_path_buf(),
                    line,
                    message: format!("{} fields, the header has {}", fields.len(), header.len()),
                });
            }
            rows.push((line, fields));
        }
        Ok(Self {
            path: path.to_path_buf(),
            header,
            rows,
        })
    }

    fn column(&self, name: &str) -> Result<usize, ImportError> {
        self.header
            .iter()
            .position(|h| h.eq_ignore_ascii_case(name))
            .ok_or_else(|| ImportError::File {
                path: self.path.clone(),
                message: format!(
                    "no column `{name}` (the header has: {})",
                    self.header.join(", ")
                ),
            })
    }

    fn number(&self, line: usize, row: &[String], col: usize) -> Result<f64, ImportError> {
        let s = &row[col];
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(ImportError::Csv {
                path: self.path.clone(),
                line,
                message: format!(
                    "column `{}`: `{s}` is not a finite number",
                    self.header[col]
                ),
            }),
        }
    }
}

/// Column indices of the joint log.
struct LogColumns {
    id: usize,
    station: usize,
    usage: usize,
    side: Option<usize>,
    joints: Vec<usize>,
    flange: Vec<usize>,
}

fn log_columns(spec: &ImportSpec, log: &Csv, dof: usize) -> Result<LogColumns, ImportError> {
    if spec.columns.joints.len() != dof {
        return Err(ImportError::Spec(format!(
            "{} joint columns mapped, the robot has {dof} joints",
            spec.columns.joints.len()
        )));
    }
    let flange = match &spec.flange {
        Some(f) => {
            if f.columns.len() != f.convention.n_columns() {
                return Err(ImportError::Spec(format!(
                    "{} flange columns given, the convention needs {}",
                    f.columns.len(),
                    f.convention.n_columns()
                )));
            }
            f.columns
                .iter()
                .map(|c| log.column(c))
                .collect::<Result<_, _>>()?
        }
        None => Vec::new(),
    };
    Ok(LogColumns {
        id: log.column(&spec.columns.id)?,
        station: log.column(&spec.columns.station)?,
        usage: log.column(&spec.columns.usage)?,
        side: match &spec.columns.side {
            Some(s) => Some(log.column(s)?),
            None => log
                .header
                .iter()
                .position(|h| h.eq_ignore_ascii_case(DEFAULT_SIDE_COLUMN)),
        },
        joints: spec
            .columns
            .joints
            .iter()
            .map(|c| log.column(c))
            .collect::<Result<_, _>>()?,
        flange,
    })
}

/// The nominal robot model of the spec.
///
/// # Errors
/// [`ImportError::Spec`] for an unknown preset, the loader's error for a
/// file that is neither a valid session nor a valid result file.
pub fn load_robot(source: &RobotSource) -> Result<Robot, ImportError> {
    match source {
        RobotSource::Preset(key) => robot::preset(key).map(|p| p.robot).ok_or_else(|| {
            let keys: Vec<&str> = robot::presets().iter().map(|p| p.key).collect();
            ImportError::Spec(format!(
                "unknown robot `{key}`, expected one of: {} or a session/result file",
                keys.join(", ")
            ))
        }),
        RobotSource::File(path) => {
            let text = fs::read_to_string(path).map_err(|source| ImportError::Io {
                path: path.clone(),
                source,
            })?;
            let no_robot = || ImportError::File {
                path: path.clone(),
                message: "the file has no robot model (a pose-only session or result)".into(),
            };
            match parse_session(&text, path) {
                Ok(s) if s.robot_given => Ok(s.robot),
                Ok(_) => Err(no_robot()),
                Err(session_error) => match parse_result(&text, path) {
                    Ok(r) => r.robot.ok_or_else(no_robot),
                    Err(_) => Err(ImportError::Session(session_error)),
                },
            }
        }
    }
}

/// The column names of a CSV file's header (for a mapping form).
///
/// # Errors
/// The file cannot be read or has no header row.
pub fn header(path: &Path) -> Result<Vec<String>, ImportError> {
    Ok(Csv::read(path)?.header)
}

/// The first `rows` rows of the joint log with the mapping applied, as a
/// text table: id, station, use, side and the joints converted to deg (the
/// declared unit in the header).
///
/// # Errors
/// As [`import`] for the joint log: unreadable file, missing column,
/// malformed number.
pub fn preview(spec: &ImportSpec, rows: usize) -> Result<String, ImportError> {
    let robot = load_robot(&spec.robot)?;
    let log = Csv::read(&spec.joint_log)?;
    let cols = log_columns(spec, &log, robot.dof())?;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{} ({} rows), robot {}, joints read as {} and shown in deg",
        spec.joint_log.display(),
        log.rows.len(),
        robot.name,
        spec.joint_unit.as_str()
    );
    match cols.side {
        Some(c) => {
            let _ = writeln!(out, "side from column `{}`", log.header[c]);
        }
        None => {
            let _ = writeln!(out, "no side column: every side is +1");
        }
    }
    let mut header = format!("{:<10} {:<8} {:<12} {:>4}", "id", "station", "use", "side");
    for (k, c) in spec.columns.joints.iter().enumerate() {
        let _ = write!(header, " {:>12}", format!("j{}={c}", k + 1));
    }
    let _ = writeln!(out, "{header}");
    for (line, row) in log.rows.iter().take(rows) {
        let side = cols.side.map_or("-", |c| row[c].as_str());
        let _ = write!(
            out,
            "{:<10} {:<8} {:<12} {:>4}",
            row[cols.id], row[cols.station], row[cols.usage], side
        );
        for &c in &cols.joints {
            let v = spec.joint_unit.to_deg(log.number(*line, row, c)?);
            let _ = write!(out, " {v:>12.4}");
        }
        let _ = writeln!(out);
    }
    Ok(out)
}

/// Stripe points (mm) of every pose id that has a profile.
fn read_profiles(
    spec: &ImportSpec,
    ids: &[String],
) -> Result<HashMap<String, Vec<[f64; 2]>>, ImportError> {
    let unit = spec.profile_unit;
    let points_of = |csv: &Csv, rows: &[&(usize, Vec<String>)]| -> Result<_, ImportError> {
        let y = csv.column("y")?;
        let z = csv.column("z")?;
        rows.iter()
            .map(|(line, row)| {
                Ok([
                    unit.to_mm(csv.number(*line, row, y)?),
                    unit.to_mm(csv.number(*line, row, z)?),
                ])
            })
            .collect::<Result<Vec<_>, _>>()
    };
    let mut out = HashMap::new();
    match &spec.profiles {
        ProfileSource::Folder(dir) => {
            for id in ids {
                let path = dir.join(format!("{id}.csv"));
                if !path.is_file() {
                    return Err(ImportError::MissingProfile {
                        id: id.clone(),
                        path,
                    });
                }
                let csv = Csv::read(&path)?;
                let rows: Vec<_> = csv.rows.iter().collect();
                out.insert(id.clone(), points_of(&csv, &rows)?);
            }
        }
        ProfileSource::File { path, pose_column } => {
            let csv = Csv::read(path)?;
            let pose = csv.column(pose_column)?;
            for (line, row) in &csv.rows {
                if !ids.contains(&row[pose]) {
                    return Err(ImportError::Csv {
                        path: path.clone(),
                        line: *line,
                        message: format!("pose `{}` is not in the joint log", row[pose]),
                    });
                }
            }
            for id in ids {
                let rows: Vec<_> = csv.rows.iter().filter(|(_, r)| r[pose] == *id).collect();
                if rows.is_empty() {
                    return Err(ImportError::MissingProfile {
                        id: id.clone(),
                        path: path.clone(),
                    });
                }
                out.insert(id.clone(), points_of(&csv, &rows)?);
            }
        }
    }
    Ok(out)
}

/// Builds the session of the spec and checks the flange poses, if given.
/// The session is validated by writing it as FORMAT.md JSON and loading it
/// back, so every FORMAT.md rule is enforced with the loader's messages.
///
/// # Errors
/// [`ImportError`] naming the file, the line, the column or the pose id.
pub fn import(spec: &ImportSpec) -> Result<(Session, Vec<PoseCheck>), ImportError> {
    let robot = load_robot(&spec.robot)?;
    let log = Csv::read(&spec.joint_log)?;
    let cols = log_columns(spec, &log, robot.dof())?;
    let ids: Vec<String> = log.rows.iter().map(|(_, r)| r[cols.id].clone()).collect();
    let mut profiles = read_profiles(spec, &ids)?;
    let mut measurements = Vec::with_capacity(log.rows.len());
    let mut checks = Vec::new();
    for (line, row) in &log.rows {
        let id = row[cols.id].clone();
        let csv_error = |message: String| ImportError::Csv {
            path: log.path.clone(),
            line: *line,
            message: format!("pose {id}: {message}"),
        };
        let usage = Use::parse(&row[cols.usage]).ok_or_else(|| {
            csv_error(format!(
                "column `{}`: `{}` is not translation, rotation, identify or validate",
                log.header[cols.usage], row[cols.usage]
            ))
        })?;
        let side_given = match cols.side {
            None => None,
            Some(c) => match row[c].as_str() {
                "1" | "+1" => Some(1),
                "-1" => Some(-1),
                other => {
                    return Err(csv_error(format!(
                        "column `{}`: side `{other}` is not +1 or -1",
                        log.header[c]
                    )));
                }
            },
        };
        let raw: Vec<f64> = cols
            .joints
            .iter()
            .map(|&c| log.number(*line, row, c))
            .collect::<Result<_, _>>()?;
        let joints: Vec<f64> = raw.iter().map(|&v| spec.joint_unit.to_deg(v)).collect();
        if let Some(f) = &spec.flange {
            let values: Vec<f64> = cols
                .flange
                .iter()
                .map(|&c| log.number(*line, row, c))
                .collect::<Result<_, _>>()?;
            let pose = f
                .convention
                .pose_from_values(&values)
                .map_err(|m| csv_error(format!("flange pose: {m}")))?;
            checks.push(check_pose(&robot, f, spec.joint_unit, &id, &raw, &pose));
        }
        let points = profiles
            .remove(&id)
            .ok_or_else(|| ImportError::MissingProfile {
                id: id.clone(),
                path: log.path.clone(),
            })?;
        measurements.push(Measurement {
            id,
            station: row[cols.station].clone(),
            usage,
            side_given,
            side: side_given.unwrap_or(1),
            joints,
            flange: None,
            observation: Observation::Stripe(points),
        });
    }
    let name = spec.name.clone().unwrap_or_else(|| {
        spec.joint_log
            .file_stem()
            .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned())
    });
    let session = Session {
        name,
        name_given: true,
        base_given: robot.base != Isometry3::identity(),
        flange_given: robot.flange != Isometry3::identity(),
        robot,
        robot_given: true,
        sphere_diameter: spec.sphere_diameter,
        default_side: 1,
        sensor_given: false,
        hand_eye: None,
        solver: SolverSettings::default(),
        solver_given: false,
        reference_distances: match &spec.references {
            Some(path) => read_references(path)?,
            None => Vec::new(),
        },
        measurements,
    };
    let session = parse_session(&session_to_json(&session), &spec.joint_log)?;
    Ok((session, checks))
}

/// The reference distances of a CSV with columns `from`, `to`, `distance`
/// (mm). Whether the stations exist and have validate measurements is
/// the session loader's check.
///
/// # Errors
/// Unreadable file, missing column, a distance that is not a positive
/// finite number, an empty station id or no rows at all.
pub fn read_references(path: &Path) -> Result<Vec<ReferenceDistance>, ImportError> {
    let csv = Csv::read(path)?;
    let from = csv.column("from")?;
    let to = csv.column("to")?;
    let distance = csv.column("distance")?;
    let mut out = Vec::with_capacity(csv.rows.len());
    for (line, row) in &csv.rows {
        let d = csv.number(*line, row, distance)?;
        let fail = |message: String| ImportError::Csv {
            path: path.to_path_buf(),
            line: *line,
            message,
        };
        if d <= 0.0 {
            return Err(fail(format!("distance {d} mm is not positive")));
        }
        if row[from].is_empty() || row[to].is_empty() {
            return Err(fail("empty station id".into()));
        }
        if row[from] == row[to] {
            return Err(fail(format!("from and to are both `{}`", row[from])));
        }
        out.push(ReferenceDistance {
            from: row[from].clone(),
            to: row[to].clone(),
            distance: d,
        });
    }
    if out.is_empty() {
        return Err(ImportError::File {
            path: path.to_path_buf(),
            message: "no reference distances (only a header)".into(),
        });
    }
    Ok(out)
}

/// Position (mm) and rotation (deg) mismatch of FK at `q_deg` and `pose`.
fn mismatch(robot: &Robot, q_deg: &[f64], pose: &Isometry3<f64>) -> (f64, f64) {
    let fk = robot.base_from_flange(q_deg);
    (
        (fk.translation.vector - pose.translation.vector).norm(),
        fk.rotation.angle_to(&pose.rotation).to_degrees(),
    )
}

fn check_pose(
    robot: &Robot,
    f: &FlangeCheck,
    unit: AngleUnit,
    id: &str,
    raw: &[f64],
    pose: &Isometry3<f64>,
) -> PoseCheck {
    let within = |(p, r): (f64, f64)| p <= f.tolerance_mm && r <= f.tolerance_deg;
    let q: Vec<f64> = raw.iter().map(|&v| unit.to_deg(v)).collect();
    let (position_error_mm, rotation_error_deg) = mismatch(robot, &q, pose);
    let flagged = !within((position_error_mm, rotation_error_deg));
    let mut hint = String::new();
    if flagged {
        let (other, other_q): (AngleUnit, Vec<f64>) = match unit {
            AngleUnit::Deg => (AngleUnit::Rad, raw.iter().map(|v| v.to_degrees()).collect()),
            AngleUnit::Rad => (AngleUnit::Deg, raw.to_vec()),
        };
        if within(mismatch(robot, &other_q, pose)) {
            hint = format!(
                "joints look like {}: reading them as {} brings FK within tolerance (--joint-unit {})",
                other.as_str(),
                other.as_str(),
                other.as_str()
            );
        } else {
            'swap: for i in 0..q.len() {
                for j in i + 1..q.len() {
                    let mut s = q.clone();
                    s.swap(i, j);
                    if within(mismatch(robot, &s, pose)) {
                        hint = format!(
                            "joint columns {} and {} look swapped: swapping them brings FK within tolerance",
                            i + 1,
                            j + 1
                        );
                        break 'swap;
                    }
                }
            }
        }
        if hint.is_empty() {
            hint = "wrong robot model or base frame?".into();
        }
    }
    PoseCheck {
        id: id.to_string(),
        position_error_mm,
        rotation_error_deg,
        flagged,
        hint,
    }
}
