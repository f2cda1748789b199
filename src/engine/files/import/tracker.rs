//! Import of a fixed sensor's points (FORMAT.md `sensor.mount: "fixed"`):
//! a laser tracker's (or a fixed camera's or scanner's) table of target
//! points per pose, in the sensor frame, beside a joint log.
//!
//! The points table is CSV (`,` `;` or tab, `#` comments), header
//! optional:
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
//! the joint log by id when the table has a pose column, else row k with
//! pose k. The log's `use` column gives each pose's use (default
//! `identify`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use nalgebra::Vector3;

use super::ImportError;
use super::csv_file::CsvFile;
use super::log::JointLog;
use super::units::{AngleUnit, LengthUnit};
use crate::engine::base::robot::Robot;
use crate::engine::base::session::{Measurement, Mount, Observation, Session, Use};
use crate::engine::base::table::parse_number;

/// Names a pose column may have.
const POSE_COLUMNS: [&str; 4] = ["pose", "id", "point", "name"];
/// Names a target column may have.
const TARGET_COLUMNS: [&str; 4] = ["target", "smr", "station", "marker"];
/// The station of a table with one target and no target column.
pub const DEFAULT_TARGET: &str = "T1";

/// What the import of a fixed sensor's points needs.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackerSpec {
    /// The points table.
    pub points: PathBuf,
    /// The joint log: a pose id column and the joint columns.
    pub joint_log: PathBuf,
    /// Name of the log's pose id column.
    pub id_column: String,
    /// The log's joint columns, joint 1 first.
    pub joint_columns: Vec<String>,
    /// Unit of the joints.
    pub angle_unit: AngleUnit,
    /// Unit of the points (`--centre-unit`).
    pub length_unit: LengthUnit,
    /// The nominal robot.
    pub robot: Robot,
    /// Target (sphere, SMR) diameter written to the session, mm.
    pub diameter: f64,
    /// Session name.
    pub name: String,
}

/// One point of the table: pose, target, reading (mm, sensor frame), line.
type Reading = (Option<String>, String, Vector3<f64>, usize);

/// The session of a fixed sensor's table and joint log, and notes for
/// people (the layout read, the averaging and its spread).
///
/// # Errors
/// A file that cannot be read, a missing column, a number that is not one
/// (naming the file, line and column), a pose of the table the log does
/// not have, counts that do not pair, or a session that breaks a rule.
pub fn import_tracker(spec: &TrackerSpec) -> Result<(Session, Vec<String>), ImportError> {
    let mut notes = Vec::new();
    let readings = read_points(&spec.points, spec.length_unit, &mut notes)?;
    let log = JointLog::read_scan(
        &spec.joint_log,
        &spec.id_column,
        &spec.joint_columns,
        "station",
        "use",
    )?;
    let rows = log.rows(spec.angle_unit)?;
    if let Some(r) = rows.iter().find(|r| r.joints.len() != spec.robot.dof()) {
        return Err(ImportError::Csv {
            path: spec.joint_log.clone(),
            line: r.line,
            message: format!(
                "pose {}: {} joints, the robot has {}",
                r.id,
                r.joints.len(),
                spec.robot.dof()
            ),
        });
    }
    let by_id = readings.iter().all(|r| r.0.is_some());
    // Readings grouped by (pose index, target), in table order.
    let mut groups: Vec<(usize, String, Vec<Vector3<f64>>)> = Vec::new();
    let mut group_of: HashMap<(usize, String), usize> = HashMap::new();
    let pose_index: HashMap<&str, usize> = rows
        .iter()
        .enumerate()
        .map(|(i, r)| (r.id.as_str(), i))
        .collect();
    if !by_id && readings.len() != rows.len() {
        return Err(ImportError::File {
            path: spec.points.clone(),
            message: format!(
                "{} points for {} poses of {}: without a pose column, row k is pose k, so the counts must match",
                readings.len(),
                rows.len(),
                spec.joint_log.display()
            ),
        });
    }
    for (k, (pose, target, p, line)) in readings.iter().enumerate() {
        let index = match pose {
            Some(id) => *pose_index
                .get(id.as_str())
                .ok_or_else(|| ImportError::Csv {
                    path: spec.points.clone(),
                    line: *line,
                    message: format!(
                        "pose `{id}` is not in the joint log {}",
                        spec.joint_log.display()
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
    groups.sort_by_key(|g| g.0);
    let mut spreads = Vec::new();
    let mut measurements = Vec::with_capacity(groups.len());
    let targets: std::collections::BTreeSet<&str> = groups.iter().map(|g| g.1.as_str()).collect();
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
            joints: row
                .joints
                .iter()
                .map(|q| spec.angle_unit.to_deg(*q))
                .collect(),
            flange: None,
            observation: Observation::Centre(mean),
        });
    }
    notes.push(format!(
        "{} poses, {} target(s) ({}), {} measurements; a fixed sensor: base_from_sensor, the targets on the flange and the kinematic errors are identified",
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
    let session = Session {
        mount: Mount::Fixed,
        sensor_given: true,
        ..Session::made(
            spec.name.clone(),
            spec.robot.clone(),
            spec.diameter,
            measurements,
        )
    };
    session.validate().map_err(|e| ImportError::File {
        path: spec.points.clone(),
        message: e.to_string(),
    })?;
    Ok((session, notes))
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
