//! Import of a fixed sensor's points (FORMAT.md `sensor.mount: "fixed"`):
//! a laser tracker's (or a fixed camera's) table of target points per
//! pose, in the sensor frame, or a fixed line scanner's stripe profiles
//! of the sphere on the tool, beside a joint log or a pose file.
//!
//! # The poses
//!
//! - a **joint log** (`id`, optional `use`, the joint columns): a session
//!   with joints, which identifies the kinematic errors with
//!   `base_from_sensor` and the targets;
//! - a **pose file** in any layout the eye-in-hand import reads
//!   ([`super::poses::read_pose_log`]: tables, JSON lists, robot
//!   programs): flange poses give a **pose-only** session, which
//!   calibrates `base_from_sensor` and the target points (no kinematic
//!   parameter); joint targets a session with joints (the robot given).
//!
//! # The points table
//!
//! CSV (`,` `;` or tab, `#` comments), header optional:
//!
//! - one point a row: columns `x`, `y`, `z`, a pose column (`pose`, `id`,
//!   `point` or `name`) and optionally a target column (`target`, `smr`,
//!   `station` or `marker`); without a header the columns are `x y z`,
//!   `pose x y z` or `pose target x y z`;
//! - or several targets a row as named columns: `SMR1_x, SMR1_y, SMR1_z,
//!   SMR2_x, …` (`_` `.` or a space before the axis), beside the pose
//!   column.
//!
//! Repeated readings of one target at one pose (rows with the same pose
//! and target) are averaged, and their spread is reported. Poses pair with
//! the table by id when the table has a pose column, else row k with pose
//! k. Every pose needs at least one point (a pose without one is named);
//! a point's pose must be one of the poses. The points' spread is checked
//! against the flange's: a table in metres read as millimetres (or the
//! other way) is refused, naming the unit that fits.
//!
//! # Stripe profiles
//!
//! A fixed line scanner gives one profile a pose (the sphere on the tool
//! cut by the laser plane), read as the flange import reads them (a
//! folder of `<pose id>.<ext>` or one file with a pose column); the
//! calibration fits the circle (eq. 21) in the fixed sensor's frame. One
//! target ([`DEFAULT_TARGET`]); `side` says on which side of the laser
//! plane its centre lies (or the log's `side` column).
//!
//! The log's or pose file's `use` column gives each pose's use (default
//! `identify`).

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Vector3};

use super::csv_file::CsvFile;
use super::log::JointLog;
use super::poses::{PoseValue, read_pose_log, record_id};
use super::profiles::{AxisMap, ProfileFormat, ProfileSource};
use super::progress::{self, ImportProgress, ImportStage};
use super::units::{AngleUnit, LengthUnit};
use super::{FlangeConvention, ImportError, Imported, PoseFormat, ProfileReport};
use crate::engine::base::robot::Robot;
use crate::engine::base::session::{Measurement, Mount, Observation, Session, Use};
use crate::engine::files::table::parse_number;

/// Names a pose column may have.
const POSE_COLUMNS: [&str; 4] = ["pose", "id", "point", "name"];
/// Names a target column may have.
const TARGET_COLUMNS: [&str; 4] = ["target", "smr", "station", "marker"];
/// The station of a table with one target and no target column, and of
/// a line scanner's sphere.
pub const DEFAULT_TARGET: &str = "T1";
/// Smallest rms spread of the flange positions, mm, over which the
/// points' unit is checked against it (a set of pure rotations about one
/// point says nothing about the unit).
const UNIT_CHECK_MIN_SPREAD_MM: f64 = 20.0;
/// The points' spread may differ from the flange's by this factor either
/// way (the targets' offset on the tool turns with the flange) before the
/// unit is called wrong; a wrong unit is a factor of 1000.
const UNIT_CHECK_FACTOR: f64 = 10.0;

/// Where the robot was at each pose.
#[derive(Debug, Clone, PartialEq)]
pub enum FixedPoses {
    /// A joint log: a pose id column, an optional `use` (and `side`)
    /// column, the joint columns.
    Joints {
        /// The log.
        path: PathBuf,
        /// Name of its pose id column.
        id_column: String,
        /// Its joint columns, joint 1 first.
        joint_columns: Vec<String>,
        /// Unit of the joints.
        angle_unit: AngleUnit,
    },
    /// A pose file in any layout [`read_pose_log`] reads.
    File {
        /// The pose file.
        path: PathBuf,
        /// Its layout; `None`: detected from the content.
        format: Option<PoseFormat>,
        /// How a table's numbers make a pose.
        convention: Option<FlangeConvention>,
        /// A table's pose columns; `None`: the convention's names.
        pose_columns: Option<Vec<String>>,
    },
}

impl FixedPoses {
    /// The file the poses are read from.
    #[must_use]
    pub fn path(&self) -> &Path {
        match self {
            Self::Joints { path, .. } | Self::File { path, .. } => path,
        }
    }
}

/// What the fixed sensor gave.
#[derive(Debug, Clone, PartialEq)]
pub enum FixedPoints {
    /// A table of target points (sensor frame) in `unit`.
    Table {
        /// The table.
        path: PathBuf,
        /// Unit of its coordinates (`--centre-unit`).
        unit: LengthUnit,
    },
    /// A fixed line scanner's stripe profiles, one a pose.
    Profiles {
        /// Where they are.
        source: ProfileSource,
        /// How to read them.
        format: ProfileFormat,
        /// Side of the sphere centre (+1: sensor `x > 0`) where the log
        /// gives none; `None`: decided from the data by calibrating both
        /// ([`import_tracker_with`](crate::engine::assemble::side::import_tracker_with)),
        /// read here as +1.
        side: Option<i8>,
    },
}

/// What the import of a fixed sensor's points needs.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackerSpec {
    /// The poses.
    pub poses: FixedPoses,
    /// The sensor's points or profiles.
    pub points: FixedPoints,
    /// The nominal robot: needed for joints; kept in a pose-only session
    /// when given.
    pub robot: Option<Robot>,
    /// Target (sphere, SMR) diameter written to the session, mm.
    pub diameter: f64,
    /// An initial `base_from_sensor` written into the session; `None`:
    /// the calibration's linear start finds it.
    pub hand_eye: Option<Isometry3<f64>>,
    /// Session name.
    pub name: String,
}

/// One point of the table: pose, target, reading (mm, sensor frame), line.
type Reading = (Option<String>, String, Vector3<f64>, usize);

/// One pose as read, from either kind of pose log.
#[derive(Debug, Clone)]
struct PoseRow {
    id: String,
    usage: Option<Use>,
    side: Option<i8>,
    /// Joints, deg (empty for a flange pose).
    joints: Vec<f64>,
    flange: Option<Isometry3<f64>>,
    line: usize,
}

/// The session of a fixed sensor's points and poses, and notes for
/// people (the layout read, the averaging and its spread).
///
/// # Errors
/// A file that cannot be read, a missing column, a number that is not one
/// (naming the file, line and column), a point whose pose is not among
/// the poses, a pose without a point, points in the wrong unit, counts
/// that do not pair, or a session that breaks a rule.
pub fn read_tracker(spec: &TrackerSpec) -> Result<(Session, Vec<String>), ImportError> {
    let imported = read_tracker_with(spec, &mut progress::quiet)?;
    Ok((imported.session, imported.notes))
}

/// [`read_tracker`] as the one import entry runs it
/// ([`import_session`](crate::engine::assemble::import_session)), telling `progress` each profile
/// read and the check.
///
/// # Errors
/// As [`read_tracker`]; [`ImportError::Cancelled`].
pub fn read_tracker_with(
    spec: &TrackerSpec,
    progress: &mut ImportProgress<'_>,
) -> Result<Imported, ImportError> {
    super::check_sphere_diameter(spec.diameter)?;
    let mut notes = Vec::new();
    let rows = read_poses(spec, &mut notes)?;
    let pose_path = spec.poses.path();
    let (measurements, report) = match &spec.points {
        FixedPoints::Table { path, unit } => {
            let readings = read_points(path, *unit, &mut notes)?;
            let measurements = pair_points(spec, path, &rows, &readings, &mut notes)?;
            check_point_unit(spec, path, *unit, &rows, &measurements)?;
            (measurements, empty_report())
        }
        FixedPoints::Profiles {
            source,
            format,
            side,
        } => {
            let side = side.unwrap_or(1);
            let ids: Vec<String> = rows.iter().map(|r| r.id.clone()).collect();
            let (planes, report) = super::read_profiles(source, format, &ids, progress)?;
            super::check_profile_size(&planes, format, spec.diameter)?;
            notes.push(report.summary());
            let measurements = rows
                .iter()
                .zip(planes)
                .map(|(r, plane)| Measurement {
                    id: r.id.clone(),
                    station: DEFAULT_TARGET.to_string(),
                    usage: r.usage.unwrap_or(Use::Identify),
                    side_given: r.side,
                    side: r.side.unwrap_or(side),
                    joints: r.joints.clone(),
                    flange: r.flange,
                    observation: Observation::Stripe(plane.points),
                })
                .collect();
            notes.push(format!(
                "{} poses, one sphere ({DEFAULT_TARGET}) cut by the fixed laser plane, side {side:+}",
                rows.len()
            ));
            (measurements, report)
        }
    };
    progress::report(progress, ImportStage::Checking)?;
    let pose_only = rows.iter().all(|r| r.flange.is_some());
    notes.push(if pose_only {
        "flange poses, pose-only: base_from_sensor and the targets on the flange are calibrated, no kinematic parameter".to_string()
    } else {
        "a fixed sensor: base_from_sensor, the targets on the flange and the kinematic errors are identified".to_string()
    });
    let robot_given = spec.robot.is_some();
    let robot = spec
        .robot
        .clone()
        .unwrap_or_else(|| Robot::new(String::new(), Vec::new()));
    let side = match &spec.points {
        FixedPoints::Profiles { side, .. } => side.unwrap_or(1),
        FixedPoints::Table { .. } => 1,
    };
    let session = Session {
        mount: Mount::Fixed,
        sensor_given: true,
        robot_given,
        default_side: side,
        hand_eye: spec.hand_eye,
        ..Session::made(spec.name.clone(), robot, spec.diameter, measurements)
    };
    let lines: HashMap<&str, usize> = rows.iter().map(|r| (r.id.as_str(), r.line)).collect();
    // A measurement of several targets is `<pose>-<target>`: its pose's line.
    let measurement_lines: Vec<(String, usize)> = session
        .measurements
        .iter()
        .filter_map(|m| {
            let pose = m.id.rsplit_once('-').map_or(m.id.as_str(), |(p, _)| p);
            lines
                .get(m.id.as_str())
                .or_else(|| lines.get(pose))
                .map(|l| (m.id.clone(), *l))
        })
        .collect();
    let lines_of_measurements: HashMap<&str, usize> = measurement_lines
        .iter()
        .map(|(id, l)| (id.as_str(), *l))
        .collect();
    let session = super::recheck(
        session,
        &super::Sources {
            log: pose_path,
            lines: &lines_of_measurements,
            profiles: &report,
            references: None,
        },
    )?;
    Ok(Imported {
        session,
        checks: Vec::new(),
        profiles: report,
        notes,
    })
}

/// The report of an import without profiles.
fn empty_report() -> ProfileReport {
    ProfileReport {
        axes: AxisMap::IDENTITY,
        axes_guessed: false,
        poses: Vec::new(),
        skipped: Vec::new(),
    }
}

/// The poses of a joint log or a pose file, ids unique, joints in deg.
fn read_poses(spec: &TrackerSpec, notes: &mut Vec<String>) -> Result<Vec<PoseRow>, ImportError> {
    let need_robot = |path: &Path, what: &str| {
        ImportError::Spec(format!(
            "{} holds {what}: give the nominal robot (--robot) to place them",
            path.display()
        ))
    };
    let rows = match &spec.poses {
        FixedPoses::Joints {
            path,
            id_column,
            joint_columns,
            angle_unit,
        } => {
            let robot = spec
                .robot
                .as_ref()
                .ok_or_else(|| need_robot(path, "joint readings"))?;
            let log = JointLog::read_scan(path, id_column, joint_columns, "station", "use")?;
            let rows = log.rows(*angle_unit)?;
            let mut out = Vec::with_capacity(rows.len());
            for r in rows {
                if r.joints.len() != robot.dof() {
                    return Err(ImportError::Csv {
                        path: path.clone(),
                        line: r.line,
                        message: format!(
                            "pose {}: {} joints, the robot has {}",
                            r.id,
                            r.joints.len(),
                            robot.dof()
                        ),
                    });
                }
                out.push(PoseRow {
                    joints: r.joints.iter().map(|q| angle_unit.to_deg(*q)).collect(),
                    id: r.id,
                    usage: r.usage,
                    side: r.side,
                    flange: None,
                    line: r.line,
                });
            }
            out
        }
        FixedPoses::File {
            path,
            format,
            convention,
            pose_columns,
        } => {
            let (records, read) =
                read_pose_log(path, *format, *convention, pose_columns.as_deref())?;
            notes.extend(read);
            let mut out = Vec::with_capacity(records.len());
            for (k, r) in records.iter().enumerate() {
                let (joints, flange) = match &r.value {
                    PoseValue::Flange(pose) => (Vec::new(), Some(*pose)),
                    PoseValue::Joints(q) => {
                        let robot = spec.robot.as_ref().ok_or_else(|| {
                            need_robot(
                                path,
                                &format!("joint targets ({} at line {})", r.name, r.line),
                            )
                        })?;
                        if q.len() != robot.dof() {
                            return Err(ImportError::Csv {
                                path: path.clone(),
                                line: r.line,
                                message: format!(
                                    "{}: {} joint values, the robot {} has {} joints",
                                    r.name,
                                    q.len(),
                                    robot.name,
                                    robot.dof()
                                ),
                            });
                        }
                        (q.clone(), None)
                    }
                };
                out.push(PoseRow {
                    id: r.id.clone().unwrap_or_else(|| record_id(r, k + 1)),
                    usage: r.usage,
                    side: r.side,
                    joints,
                    flange,
                    line: r.line,
                });
            }
            let mut first: HashMap<&str, usize> = HashMap::new();
            for r in &out {
                if let Some(line) = first.insert(r.id.as_str(), r.line) {
                    return Err(ImportError::Csv {
                        path: path.clone(),
                        line: r.line,
                        message: format!("pose id `{}` is used twice (first at line {line})", r.id),
                    });
                }
            }
            out
        }
    };
    if rows.is_empty() {
        return Err(ImportError::File {
            path: spec.poses.path().to_path_buf(),
            message: "no poses".into(),
        });
    }
    Ok(rows)
}

/// The measurements of the points table paired with the poses: readings
/// of one target at one pose averaged, poses in their order, targets in
/// the table's order within a pose.
fn pair_points(
    spec: &TrackerSpec,
    points_path: &Path,
    rows: &[PoseRow],
    readings: &[Reading],
    notes: &mut Vec<String>,
) -> Result<Vec<Measurement>, ImportError> {
    let pose_path = spec.poses.path();
    let by_id = readings.iter().all(|r| r.0.is_some());
    let pose_index: HashMap<&str, usize> = rows
        .iter()
        .enumerate()
        .map(|(i, r)| (r.id.as_str(), i))
        .collect();
    if !by_id && readings.len() != rows.len() {
        return Err(ImportError::File {
            path: points_path.to_path_buf(),
            message: format!(
                "{} points for {} poses of {}: without a pose column, row k is pose k, so the counts must match",
                readings.len(),
                rows.len(),
                pose_path.display()
            ),
        });
    }
    // Readings grouped by (pose index, target), in table order.
    let mut groups: Vec<(usize, String, Vec<Vector3<f64>>)> = Vec::new();
    let mut group_of: HashMap<(usize, String), usize> = HashMap::new();
    for (k, (pose, target, p, line)) in readings.iter().enumerate() {
        let index = match pose {
            Some(id) => *pose_index
                .get(id.as_str())
                .ok_or_else(|| ImportError::Csv {
                    path: points_path.to_path_buf(),
                    line: *line,
                    message: format!(
                        "pose `{id}` is not among the poses of {}",
                        pose_path.display()
                    ),
                })?,
            None => k,
        };
        let key = (index, target.clone());
        let g = *group_of.entry(key).or_insert_with(|| {
            groups.push((index, target.clone(), Vec::new()));
            groups.len() - 1
        });
        groups[g].2.push(*p);
    }
    let seen: BTreeSet<usize> = groups.iter().map(|g| g.0).collect();
    if let Some(r) = rows.iter().enumerate().find(|(i, _)| !seen.contains(i)) {
        return Err(ImportError::Csv {
            path: pose_path.to_path_buf(),
            line: r.1.line,
            message: format!(
                "pose `{}` has no point in {}: measure it, or leave the pose out",
                r.1.id,
                points_path.display()
            ),
        });
    }
    groups.sort_by_key(|g| g.0);
    let mut spreads = Vec::new();
    let mut measurements = Vec::with_capacity(groups.len());
    let targets: BTreeSet<&str> = groups.iter().map(|g| g.1.as_str()).collect();
    for (index, target, points) in &groups {
        let row = &rows[*index];
        let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
        if points.len() > 1 {
            let rms = (points
                .iter()
                .map(|p| (p - mean).norm_squared())
                .sum::<f64>()
                / (points.len() - 1) as f64)
                .sqrt();
            spreads.push(rms);
        }
        let id = if targets.len() > 1 {
            format!("{}-{target}", row.id)
        } else {
            row.id.clone()
        };
        measurements.push(Measurement {
            id,
            station: target.clone(),
            usage: row.usage.unwrap_or(Use::Identify),
            side_given: None,
            side: 1,
            joints: row.joints.clone(),
            flange: row.flange,
            observation: Observation::Centre(mean),
        });
    }
    notes.push(format!(
        "{} poses, {} target(s) ({}), {} measurements",
        rows.len(),
        targets.len(),
        targets.iter().copied().collect::<Vec<_>>().join(", "),
        measurements.len()
    ));
    if !spreads.is_empty() {
        let worst = spreads.iter().copied().fold(0.0, f64::max);
        let mean = spreads.iter().sum::<f64>() / spreads.len() as f64;
        notes.push(format!(
            "repeated readings averaged at {} target poses: spread (3-D, sample) mean {mean:.4} mm, largest {worst:.4} mm",
            spreads.len()
        ));
    }
    Ok(measurements)
}

/// The rms distance of `points` from their mean.
fn spread(points: &[Vector3<f64>]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    (points
        .iter()
        .map(|p| (p - mean).norm_squared())
        .sum::<f64>()
        / points.len() as f64)
        .sqrt()
}

/// Refuses points whose spread does not fit the flange's (a table in
/// metres read as millimetres spreads a thousandth of the robot's
/// motion), naming the unit that would fit.
fn check_point_unit(
    spec: &TrackerSpec,
    points_path: &Path,
    unit: LengthUnit,
    rows: &[PoseRow],
    measurements: &[Measurement],
) -> Result<(), ImportError> {
    let flange: Vec<Vector3<f64>> = rows
        .iter()
        .filter_map(|r| match (&r.flange, &spec.robot) {
            (Some(f), _) => Some(f.translation.vector),
            (None, Some(robot)) => Some(robot.base_from_flange(&r.joints).translation.vector),
            (None, None) => None,
        })
        .collect();
    let moved = spread(&flange);
    if moved < UNIT_CHECK_MIN_SPREAD_MM {
        return Ok(());
    }
    let points: Vec<Vector3<f64>> = measurements
        .iter()
        .filter_map(|m| match &m.observation {
            Observation::Centre(c) => Some(*c),
            Observation::Stripe(_) => None,
        })
        .collect();
    let seen = spread(&points);
    let ratio = seen / moved;
    if (1.0 / UNIT_CHECK_FACTOR..=UNIT_CHECK_FACTOR).contains(&ratio) {
        return Ok(());
    }
    let scale = |u: LengthUnit| u.to_mm(1.0) / unit.to_mm(1.0);
    let fits = [LengthUnit::Mm, LengthUnit::M, LengthUnit::Um]
        .into_iter()
        .filter(|u| *u != unit)
        .min_by(|a, b| {
            let off = |u: LengthUnit| (ratio * scale(u)).ln().abs();
            off(*a).total_cmp(&off(*b))
        });
    let hint = fits
        .filter(|u| (1.0 / UNIT_CHECK_FACTOR..=UNIT_CHECK_FACTOR).contains(&(ratio * scale(*u))))
        .map_or_else(String::new, |u| {
            format!(
                "; read as {} they would spread {:.1} mm: import with --centre-unit {}",
                u.symbol(),
                seen * scale(u),
                u.as_str()
            )
        });
    Err(ImportError::File {
        path: points_path.to_path_buf(),
        message: format!(
            "the points spread {seen:.4} mm rms (read as {}) while the target on the flange moves {moved:.1} mm rms: not plausible{hint}",
            unit.symbol()
        ),
    })
}
/// The readings of the points table in mm, with the layout in `notes`.
fn read_points(
    path: &Path,
    unit: LengthUnit,
    notes: &mut Vec<String>,
) -> Result<Vec<Reading>, ImportError> {
    let mut file = CsvFile::read(path)?;
    let numeric = |s: &str| parse_number(s, file.decimal_commas).is_some();
    let headerless = file.header.iter().rev().take(3).all(|h| numeric(h));
    if headerless {
        let width = file.header.len();
        let header = std::mem::take(&mut file.header);
        file.rows.insert(0, (1, header));
        file.header = match width {
            3 => vec!["x", "y", "z"],
            4 => vec!["pose", "x", "y", "z"],
            5 => vec!["pose", "target", "x", "y", "z"],
            _ => {
                return Err(ImportError::File {
                    path: path.to_path_buf(),
                    message: format!(
                        "{width} columns without a header: give `x y z`, `pose x y z` or `pose target x y z`, or a header"
                    ),
                });
            }
        }
        .into_iter()
        .map(String::from)
        .collect();
    }
    let find = |names: &[&str]| names.iter().find_map(|n| file.optional_column(n));
    let pose = find(&POSE_COLUMNS);
    // Named columns: `<target><sep><axis>` for every target.
    let mut named: Vec<(String, [usize; 3])> = Vec::new();
    if file.optional_column("x").is_none() {
        for (c, h) in file.header.iter().enumerate() {
            let lower = h.to_ascii_lowercase();
            for sep in ['_', '.', ' '] {
                if let Some(prefix) = lower.strip_suffix(&format!("{sep}x")) {
                    let col = |axis: &str| file.optional_column(&format!("{prefix}{sep}{axis}"));
                    if let (Some(y), Some(z)) = (col("y"), col("z")) {
                        named.push((h[..prefix.len()].to_string(), [c, y, z]));
                    }
                }
            }
        }
    }
    let mut out = Vec::new();
    let pose_of = |row: &[String]| pose.map(|c| row[c].clone());
    let point =
        |line: usize, row: &[String], cols: [usize; 3]| -> Result<Vector3<f64>, ImportError> {
            let mut v = Vector3::zeros();
            for k in 0..3 {
                v[k] = unit.to_mm(file.number(line, row, cols[k])?);
            }
            Ok(v)
        };
    if named.is_empty() {
        let cols = [file.column("x")?, file.column("y")?, file.column("z")?];
        let target = find(&TARGET_COLUMNS);
        for (line, row) in &file.rows {
            let t = target.map_or_else(|| DEFAULT_TARGET.to_string(), |c| row[c].clone());
            out.push((pose_of(row), t, point(*line, row, cols)?, *line));
        }
        notes.push(format!(
            "points from {} ({}): one point a row{}{}",
            path.display(),
            unit.as_str(),
            if pose.is_some() {
                ", by pose id"
            } else {
                ", row k is pose k"
            },
            if target.is_some() {
                ", a target column"
            } else {
                ", one target"
            }
        ));
    } else {
        for (line, row) in &file.rows {
            for (t, cols) in &named {
                out.push((pose_of(row), t.clone(), point(*line, row, *cols)?, *line));
            }
        }
        notes.push(format!(
            "points from {} ({}): targets as named columns ({})",
            path.display(),
            unit.as_str(),
            named
                .iter()
                .map(|n| n.0.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    if out.is_empty() {
        return Err(ImportError::File {
            path: path.to_path_buf(),
            message: "no points".into(),
        });
    }
    Ok(out)
}
