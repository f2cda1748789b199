//! The joint log: one CSV row a pose with its id, station, use, side and
//! joint readings (the column names mapped by [`ColumnMap`]), and optional
//! flange-pose columns for the check. [`JointLog`] is the one reader of
//! joint logs, the import's and a raw scan's (`measure`): the file through
//! the capped reader, the columns found by name, every row's cells read
//! and checked. [`header`] and [`preview`] serve a mapping form (the
//! workbench's import wizard).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use super::csv_file::CsvFile;
use super::units::{self, AngleUnit};
use super::{ImportError, ImportSpec, load_robot};
use crate::engine::base::session::Use;
use crate::engine::files::table::side_cell;

/// The side column read when the mapping names none.
pub const DEFAULT_SIDE_COLUMN: &str = "side";

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

/// Column indices of a joint log: the id and the joints always; station,
/// use and side where the log has them (the import requires station and
/// use); the flange pose when it is checked.
pub(super) struct LogColumns {
    pub id: usize,
    pub station: Option<usize>,
    pub usage: Option<usize>,
    pub side: Option<usize>,
    pub joints: Vec<usize>,
    pub flange: Vec<usize>,
}

impl LogColumns {
    /// The columns of a raw scan's log: `id` and `joints` required,
    /// `station` and `usage` read when the header has them.
    fn of_scan(
        log: &CsvFile,
        id: &str,
        joints: &[String],
        station: &str,
        usage: &str,
    ) -> Result<Self, ImportError> {
        Ok(Self {
            id: log.column(id)?,
            station: log.optional_column(station),
            usage: log.optional_column(usage),
            side: None,
            joints: joints
                .iter()
                .map(|c| log.column(c))
                .collect::<Result<_, _>>()?,
            flange: Vec::new(),
        })
    }
}

/// One pose of a joint log as read.
pub(crate) struct LogRow {
    /// 1-based line.
    pub line: usize,
    /// Pose id.
    pub id: String,
    /// Station; `None` when the log has no station column or the cell is
    /// blank.
    pub station: Option<String>,
    /// Use; `None` when the log has no use column or the cell is blank.
    pub usage: Option<Use>,
    /// Side (+1 or −1); `None` when not given.
    pub side: Option<i8>,
    /// Joint readings as written (the log's unit).
    pub joints: Vec<f64>,
    /// Flange-pose values as written, when checked.
    pub flange: Vec<f64>,
}

/// A joint log: the file and its columns.
pub(crate) struct JointLog {
    /// The file (header and rows).
    pub(super) file: CsvFile,
    /// Its columns.
    pub(super) cols: LogColumns,
}

impl JointLog {
    /// The header of `path` read (through the capped reader) and its
    /// columns found by `columns`.
    ///
    /// # Errors
    /// The file cannot be read or parsed, or `columns` fails.
    pub(super) fn read(
        path: &Path,
        columns: impl FnOnce(&CsvFile) -> Result<LogColumns, ImportError>,
    ) -> Result<Self, ImportError> {
        let file = CsvFile::read(path)?;
        let cols = columns(&file)?;
        Ok(Self { file, cols })
    }

    /// A raw scan's log (`measure`): `id` and the `joints` columns
    /// required, `station` and `usage` read when the header has them.
    ///
    /// # Errors
    /// The file cannot be read or parsed, or a required column is missing
    /// (naming the header).
    pub(crate) fn read_scan(
        path: &Path,
        id: &str,
        joints: &[String],
        station: &str,
        usage: &str,
    ) -> Result<Self, ImportError> {
        Self::read(path, |f| LogColumns::of_scan(f, id, joints, station, usage))
    }

    /// Every row, read and checked: at least one row, no id twice, a use
    /// and a side that are one, finite numbers (decimal commas where the
    /// separator allows them), joint readings plausible in `unit`.
    ///
    /// # Errors
    /// [`ImportError`] naming the file, the line, the pose and the column.
    pub(crate) fn rows(&self, unit: AngleUnit) -> Result<Vec<LogRow>, ImportError> {
        let log = &self.file;
        let cols = &self.cols;
        if log.rows.is_empty() {
            return Err(ImportError::File {
                path: log.path.clone(),
                message: "the joint log has a header but no pose rows".into(),
            });
        }
        let mut seen: HashMap<&str, usize> = HashMap::new();
        for (line, row) in &log.rows {
            let id = row[cols.id].as_str();
            if let Some(first) = seen.insert(id, *line) {
                return Err(ImportError::Csv {
                    path: log.path.clone(),
                    line: *line,
                    message: format!("pose id `{id}` is used twice (first at line {first})"),
                });
            }
        }
        let mut out = Vec::with_capacity(log.rows.len());
        for (line, row) in &log.rows {
            let id = row[cols.id].clone();
            let csv_error = |message: String| ImportError::Csv {
                path: log.path.clone(),
                line: *line,
                message: format!("pose {id}: {message}"),
            };
            let usage = match cols.usage {
                Some(c) if !row[c].is_empty() => Some(
                    Use::parse(&row[c])
                        .ok_or_else(|| csv_error(usage_message(&log.header[c], &row[c])))?,
                ),
                _ => None,
            };
            let side = match cols.side {
                None => None,
                Some(c) => side_cell(&row[c])
                    .map_err(|m| csv_error(format!("column `{}`: {m}", log.header[c])))?,
            };
            let numbers = |columns: &[usize]| -> Result<Vec<f64>, ImportError> {
                columns.iter().map(|&c| log.number(*line, row, c)).collect()
            };
            out.push(LogRow {
                line: *line,
                station: cols
                    .station
                    .map(|c| row[c].clone())
                    .filter(|s| !s.is_empty()),
                usage,
                side,
                joints: numbers(&cols.joints)?,
                flange: numbers(&cols.flange)?,
                id,
            });
        }
        units::check_joint_unit(
            unit,
            out.iter()
                .map(|r| (r.line, r.id.as_str(), r.joints.as_slice())),
        )
        .map_err(|(line, message)| ImportError::Csv {
            path: log.path.clone(),
            line,
            message,
        })?;
        Ok(out)
    }
}

/// "column `use`: `x` is not translation, rotation, identify or validate".
pub(crate) fn usage_message(column: &str, cell: &str) -> String {
    format!(
        "column `{column}`: `{}` is not translation, rotation, identify or validate",
        crate::engine::files::table::excerpt(cell)
    )
}

pub(super) fn log_columns(
    spec: &ImportSpec,
    log: &CsvFile,
    dof: usize,
) -> Result<LogColumns, ImportError> {
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
    check_extra_joints(spec, log, dof)?;
    Ok(LogColumns {
        id: log.column(&spec.columns.id)?,
        station: Some(log.column(&spec.columns.station)?),
        usage: Some(log.column(&spec.columns.usage)?),
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

/// Refuses a log with a joint column beyond the robot's joints (`j7` for
/// a 6-joint robot, `j2` for a 1-joint URDF chain) that no mapping uses:
/// reading only the robot's joints would drop the others silently, and a
/// log with more joints than the model is a wrong model (a URDF tip too
/// near the base) or a wrong log.
fn check_extra_joints(spec: &ImportSpec, log: &CsvFile, dof: usize) -> Result<(), ImportError> {
    let mapped = |h: &str| {
        let c = &spec.columns;
        [&c.id, &c.station, &c.usage]
            .into_iter()
            .chain(c.side.as_ref())
            .chain(&c.joints)
            .any(|m| m.eq_ignore_ascii_case(h))
    };
    let extra: Vec<&String> = log
        .header
        .iter()
        .filter(|h| {
            let n = h
                .strip_prefix(['j', 'J'])
                .and_then(|k| k.parse::<usize>().ok());
            n.is_some_and(|n| n > dof) && !mapped(h)
        })
        .collect();
    if extra.is_empty() {
        return Ok(());
    }
    Err(ImportError::File {
        path: log.path.clone(),
        message: format!(
            "the joint log has the joint column(s) {} but the robot has {dof} joint(s): its readings would be dropped; check the robot model (a URDF's tip link, a DH table's rows) or map the columns with --map",
            extra
                .iter()
                .map(|h| format!("`{}`", crate::engine::files::table::excerpt(h)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    })
}

/// The column names of a CSV file's header (for a mapping form).
///
/// # Errors
/// The file cannot be read or has no header row.
pub fn header(path: &Path) -> Result<Vec<String>, ImportError> {
    Ok(CsvFile::read(path)?.header)
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
    let log = CsvFile::read(&spec.joint_log)?;
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
        let cell = |c: Option<usize>| c.map_or("", |c| row[c].as_str());
        let _ = write!(
            out,
            "{:<10} {:<8} {:<12} {:>4}",
            row[cols.id],
            cell(cols.station),
            cell(cols.usage),
            side
        );
        for &c in &cols.joints {
            let v = spec.joint_unit.to_deg(log.number(*line, row, c)?);
            let _ = write!(out, " {v:>12.4}");
        }
        let _ = writeln!(out);
    }
    Ok(out)
}
