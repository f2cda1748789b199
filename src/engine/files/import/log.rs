//! The joint log: one CSV row a pose with its id, station, use, side and
//! joint readings (the column names mapped by [`ColumnMap`]), and optional
//! flange-pose columns for the check. [`header`] and [`preview`] serve a
//! mapping form (the workbench's import wizard).

use std::fmt::Write as _;
use std::path::Path;

use super::csv_file::CsvFile;
use super::{ImportError, ImportSpec, load_robot};

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

/// Column indices of the joint log.
pub(super) struct LogColumns {
    pub id: usize,
    pub station: usize,
    pub usage: usize,
    pub side: Option<usize>,
    pub joints: Vec<usize>,
    pub flange: Vec<usize>,
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
                .map(|h| format!("`{}`", crate::engine::base::table::excerpt(h)))
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

/// A side cell: `+1`, `1`, `-1`, or blank (not given).
///
/// # Errors
/// Anything else, in words.
pub(super) fn side_cell(cell: &str) -> Result<Option<i8>, String> {
    match cell.trim() {
        "" => Ok(None),
        "1" | "+1" | "1.0" | "+1.0" => Ok(Some(1)),
        "-1" | "-1.0" => Ok(Some(-1)),
        other => Err(format!(
            "side `{}` is not +1, -1 or blank",
            crate::engine::base::table::excerpt(other)
        )),
    }
}
