//! Robot import from a DH table in CSV, standard or modified convention,
//! converted to the modified-DH model of [`kinematics`](super::kinematics).
//!
//! # The file
//!
//! One header line naming the columns, then one row per joint, base to
//! flange:
//!
//! ```text
//! # UR5e, Universal Robots' published standard DH table
//! joint, a,      alpha, d,     theta
//! 1,     0,      90,    162.5, 0
//! 2,     -425,   0,     0,     0
//! ```
//!
//! - Columns (case-insensitive, any order): `a`, `alpha`, `d`, `theta`, and
//!   for the modified convention optionally `beta` (Hayati's angle about y,
//!   0 when absent). Lengths are **mm** and angles **degrees**; a unit
//!   suffix overrides this per column: `a_m`/`d_m` (metres), `a_mm`/`d_mm`,
//!   `alpha_rad`/`theta_rad`/`beta_rad` (radians), `alpha_deg` etc. A
//!   `joint`, `name` or `link` column is a label; any other column is an
//!   error.
//! - Rows are joints base to flange in file order. When a label column
//!   numbers them (`1`, `J2`, `joint_3`, …), the numbers must run up by
//!   one from the first row, so that a table sorted otherwise is an error
//!   rather than another robot.
//! - Angles without a unit suffix are degrees; a table whose angles all lie
//!   within ±2π while an `alpha` is π/2 or π to 0.01 (1.5708, 3.1416: a
//!   table in radians) is an error that names the suffix to use.
//! - Every value must be finite and within the session file's plausibility
//!   limits (lengths 100 m, angles 36,000°); the file at most
//!   [`MAX_DH_BYTES`].
//! - Lines starting with `#` are comments, blank lines are skipped, cells
//!   are trimmed, a UTF-8 byte-order mark is dropped.
//! - Errors name the file and the 1-based line.
//!
//! # The conventions
//!
//! A **modified** (Craig) row `i` is the model's joint `i` as it stands:
//! `T_i = Rx(alpha)·Tx(a)·Ry(beta)·Rz(q_i + theta)·Tz(d)`, base and flange
//! transforms the identity.
//!
//! A **standard** (Denavit-Hartenberg) row `i` is the link
//! `Rz(q_i + theta_i)·Tz(d_i)·Tx(a_i)·Rx(alpha_i)`. Regrouping the product
//! (and using that `Tx` and `Rx` commute) gives the model exactly: joint 1
//! gets `alpha = a = 0`, joint `i ≥ 2` gets `(alpha, a)` of standard row
//! `i−1`, `theta` and `d` stay with their joint, `beta = 0`, and the last
//! row's `Tx(a_n)·Rx(alpha_n)` becomes the flange transform `F` (base the
//! identity). A standard table has no `beta` column.

use std::path::Path;

use nalgebra::Isometry3;

use super::error::RobotImportError;
use crate::engine::base::geometry::{rot_x, trans};
use crate::engine::base::limits;
use crate::engine::base::numeric::show;
use crate::engine::base::robot::kinematics::{Joint, Robot};
use crate::engine::files::table::{Table, excerpt, parse_number, separator};

/// Largest DH table read, bytes (1 MiB): a table has a row per joint.
pub const MAX_DH_BYTES: u64 = 1 << 20;

/// How near π/2 or π (rad) an `alpha` without a unit must be to be taken
/// for a table in radians: 1.5708 and 3.1416 as tables print them; no
/// nominal DH table in degrees has an alpha of 1.57° or 3.14°.
const RADIAN_ALPHA_TOLERANCE: f64 = 0.01;

/// Which DH convention the rows of a table follow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DhConvention {
    /// Denavit-Hartenberg: `Rz(theta)·Tz(d)·Tx(a)·Rx(alpha)` per row.
    Standard,
    /// Craig's modified DH (with Hayati's optional `beta`):
    /// `Rx(alpha)·Tx(a)·Ry(beta)·Rz(theta)·Tz(d)` per row, the model's own.
    Modified,
}

/// The robot of a DH table in CSV (module docs), named after the file.
/// `source` names the file in errors.
///
/// # Errors
/// [`RobotImportError::DhLine`] for a bad header (unknown, repeated or
/// missing column, `beta` in a standard table) or row (wrong number of
/// cells, a cell that is not a finite number), with its line;
/// [`RobotImportError::DhTable`] for a file without header or rows.
pub fn robot_from_dh_csv(
    text: &str,
    source: &Path,
    convention: DhConvention,
) -> Result<Robot, RobotImportError> {
    let rows = read_rows(text, source, convention)?;
    let name = source
        .file_stem()
        .map_or_else(|| "robot".to_owned(), |s| s.to_string_lossy().into_owned());
    Ok(match convention {
        DhConvention::Modified => Robot::new(name, rows),
        DhConvention::Standard => {
            let (joints, flange) = standard_to_model(&rows);
            Robot {
                flange,
                ..Robot::new(name, joints)
            }
        }
    })
}

/// Standard DH rows (in [`Joint`]'s fields, `beta` 0) as model joints plus
/// the flange transform `Tx(a_n)·Rx(alpha_n)` (module docs).
fn standard_to_model(rows: &[Joint]) -> (Vec<Joint>, Isometry3<f64>) {
    let mut carried = (0.0, 0.0);
    let mut joints = Vec::with_capacity(rows.len());
    for row in rows {
        joints.push(Joint {
            alpha: carried.0,
            a: carried.1,
            beta: 0.0,
            theta: row.theta,
            d: row.d,
        });
        carried = (row.alpha, row.a);
    }
    let flange = trans(carried.1, 0.0, 0.0) * rot_x(carried.0.to_radians());
    (joints, flange)
}

/// A DH parameter a column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Param {
    /// `alpha`.
    Alpha,
    /// `a`.
    A,
    /// `beta`.
    Beta,
    /// `theta`.
    Theta,
    /// `d`.
    D,
}

impl Param {
    /// The parameters a table must have.
    const REQUIRED: [Self; 4] = [Self::A, Self::Alpha, Self::D, Self::Theta];

    /// The parameter of a column name without unit suffix.
    fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "alpha" => Self::Alpha,
            "a" => Self::A,
            "beta" => Self::Beta,
            "theta" => Self::Theta,
            "d" => Self::D,
            _ => return None,
        })
    }

    /// The column name without suffix.
    fn name(self) -> &'static str {
        match self {
            Self::Alpha => "alpha",
            Self::A => "a",
            Self::Beta => "beta",
            Self::Theta => "theta",
            Self::D => "d",
        }
    }

    /// Whether the parameter is a length (mm) rather than an angle (deg).
    fn is_length(self) -> bool {
        matches!(self, Self::A | Self::D)
    }

    /// The factor to file units (mm, deg) for a unit suffix, if allowed.
    fn unit_factor(self, unit: &str) -> Option<f64> {
        match (self.is_length(), unit) {
            (true, "" | "mm") | (false, "" | "deg") => Some(1.0),
            (true, "m") => Some(1000.0),
            (false, "rad") => Some(1.0_f64.to_degrees()),
            _ => None,
        }
    }

    /// Stores `value` (file units) into the joint.
    fn set(self, joint: &mut Joint, value: f64) {
        match self {
            Self::Alpha => joint.alpha = value,
            Self::A => joint.a = value,
            Self::Beta => joint.beta = value,
            Self::Theta => joint.theta = value,
            Self::D => joint.d = value,
        }
    }
}

/// One header column: the parameter, the factor to mm/deg and whether
/// the header names the unit, or `None` for a label column.
type Column = Option<(Param, f64, bool)>;

/// The parsed header: one entry per CSV column.
struct Header {
    /// Column meanings, in file order.
    columns: Vec<Column>,
    /// The header's cells, for messages.
    names: Vec<String>,
}

/// The rows of the table as joints in file units (convention not applied).
fn read_rows(
    text: &str,
    path: &Path,
    convention: DhConvention,
) -> Result<Vec<Joint>, RobotImportError> {
    let table = Table::parse(text).map_err(|e| {
        if e.message == "no header row" {
            table_error(
                path,
                "the file is empty: expected a header line naming the columns a, alpha, d, theta",
            )
        } else {
            line_error(path, e.line, e.message)
        }
    })?;
    let header = Some(parse_header(
        &table.header,
        path,
        table.header_line,
        convention,
    )?);
    // Fields separated by `;` or tabs may write decimal commas (`0,5`).
    let decimal_commas = separator(text) != b',';
    let kept: Vec<&(usize, Vec<String>)> = table
        .rows
        .iter()
        .filter(|(_, fields)| !fields.iter().all(String::is_empty))
        .collect();
    let rows = kept
        .iter()
        .map(|(line, fields)| match &header {
            Some(h) => parse_row(fields, h, path, *line, decimal_commas),
            None => Err(table_error(path, "no header")),
        })
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(h) = &header {
        check_labels(&kept, h, path)?;
        check_radians(&kept, &rows, h, path)?;
    }
    match (header, rows.is_empty()) {
        (None, _) => Err(table_error(
            path,
            "the file is empty: expected a header line naming the columns a, alpha, d, theta",
        )),
        (Some(_), true) => Err(table_error(path, "no joint rows after the header")),
        (Some(_), false) => Ok(rows),
    }
}

/// A whole-table error.
fn table_error(path: &Path, message: &str) -> RobotImportError {
    RobotImportError::DhTable {
        path: path.to_path_buf(),
        message: message.to_owned(),
    }
}

/// An error on one line.
fn line_error(path: &Path, line: usize, message: String) -> RobotImportError {
    RobotImportError::DhLine {
        path: path.to_path_buf(),
        line,
        message,
    }
}

/// The header line: every column known, none twice, all required present,
/// `beta` only in a modified table.
fn parse_header(
    record: &[String],
    path: &Path,
    line: usize,
    convention: DhConvention,
) -> Result<Header, RobotImportError> {
    let err = |message: String| line_error(path, line, message);
    let mut columns: Vec<Column> = Vec::with_capacity(record.len());
    for cell in record {
        let column = parse_column(cell).map_err(err)?;
        if let Some((param, _, _)) = column {
            if columns.iter().flatten().any(|(p, _, _)| *p == param) {
                return Err(err(format!("column `{}` is given twice", param.name())));
            }
            if param == Param::Beta && convention == DhConvention::Standard {
                return Err(err(
                    "a `beta` column belongs to the modified convention (Hayati's angle); \
                     a standard DH table has none"
                        .into(),
                ));
            }
        }
        columns.push(column);
    }
    let missing: Vec<&str> = Param::REQUIRED
        .iter()
        .filter(|p| !columns.iter().flatten().any(|(q, _, _)| q == *p))
        .map(|p| p.name())
        .collect();
    if !missing.is_empty() {
        return Err(err(format!(
            "the header lacks the column(s) {}; expected a, alpha, d, theta",
            missing.join(", ")
        )));
    }
    Ok(Header {
        columns,
        names: record.to_vec(),
    })
}

/// One header cell: a parameter with optional unit suffix, or a label.
fn parse_column(cell: &str) -> Result<Column, String> {
    let name = cell.to_ascii_lowercase();
    if matches!(name.as_str(), "joint" | "name" | "link") {
        return Ok(None);
    }
    let (base, unit) = match name.split_once('_') {
        Some((base, unit)) => (base, unit),
        None => (name.as_str(), ""),
    };
    let unknown = || {
        format!(
            "unknown column `{}`: expected a, alpha, d, theta (beta in a modified table), \
             optionally with a unit suffix _mm/_m (lengths) or _deg/_rad (angles), \
             and an optional joint label column",
            excerpt(cell)
        )
    };
    let param = Param::from_name(base).ok_or_else(unknown)?;
    let factor = param.unit_factor(unit).ok_or_else(unknown)?;
    Ok(Some((param, factor, !unit.is_empty())))
}

/// One table row as a joint in file units.
fn parse_row(
    record: &[String],
    header: &Header,
    path: &Path,
    line: usize,
    decimal_commas: bool,
) -> Result<Joint, RobotImportError> {
    if record.len() != header.columns.len() {
        return Err(line_error(
            path,
            line,
            format!(
                "the row has {} cells, the header has {} ({})",
                record.len(),
                header.columns.len(),
                header.names.join(", ")
            ),
        ));
    }
    let mut joint = Joint::default();
    for ((cell, column), name) in record.iter().zip(&header.columns).zip(&header.names) {
        let Some((param, factor, _)) = column else {
            continue;
        };
        let value = parse_number(cell, decimal_commas)
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                line_error(
                    path,
                    line,
                    format!(
                        "column `{}`: `{}` is not a finite number",
                        excerpt(name),
                        excerpt(cell)
                    ),
                )
            })?;
        let value = value * factor;
        let (limit, unit) = if param.is_length() {
            (limits::LENGTH_MM, "mm")
        } else {
            (limits::ANGLE_DEG, "deg")
        };
        if value.abs() > limit {
            return Err(line_error(
                path,
                line,
                format!(
                    "column `{}`: {} {unit} is not plausible for a robot (at most {limit} {unit})",
                    excerpt(name),
                    show(value)
                ),
            ));
        }
        param.set(&mut joint, value);
    }
    Ok(joint)
}

/// The number a joint label ends with (`3`, `J3`, `joint_3`), if any.
fn label_number(label: &str) -> Option<u64> {
    let digits = label.len() - label.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    label[label.len() - digits..].parse().ok()
}

/// Refuses rows whose label column numbers them out of order: the rows
/// are the joints in file order, and a label saying otherwise means the
/// table is not what it looks like.
fn check_labels(
    rows: &[&(usize, Vec<String>)],
    header: &Header,
    path: &Path,
) -> Result<(), RobotImportError> {
    for (col, name) in header
        .columns
        .iter()
        .zip(&header.names)
        .enumerate()
        .filter_map(|(k, (c, name))| c.is_none().then_some((k, name)))
    {
        let numbers: Option<Vec<u64>> = rows
            .iter()
            .map(|(_, fields)| fields.get(col).and_then(|l| label_number(l)))
            .collect();
        let Some(numbers) = numbers else {
            continue;
        };
        for (k, pair) in numbers.windows(2).enumerate() {
            if pair[1] != pair[0] + 1 {
                let (line, fields) = rows[k + 1];
                return Err(line_error(
                    path,
                    *line,
                    format!(
                        "column `{}` labels this row `{}` after `{}`: the rows are read as joints base to flange in file order; sort them by joint",
                        excerpt(name),
                        excerpt(&fields[col]),
                        excerpt(&rows[k].1[col])
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Refuses a table whose angles (columns without a unit suffix) look like
/// radians: all within ±2π, with an `alpha` at π/2 or π.
fn check_radians(
    rows: &[&(usize, Vec<String>)],
    joints: &[Joint],
    header: &Header,
    path: &Path,
) -> Result<(), RobotImportError> {
    let implicit = |p: Param| {
        header
            .columns
            .iter()
            .flatten()
            .any(|(q, _, explicit)| *q == p && !explicit)
    };
    if !implicit(Param::Alpha) {
        return Ok(());
    }
    let tau = std::f64::consts::TAU;
    let angles_small = joints.iter().all(|j| {
        j.alpha.abs() <= tau
            && (!implicit(Param::Theta) || j.theta.abs() <= tau)
            && (!implicit(Param::Beta) || j.beta.abs() <= tau)
    });
    let radian_like = |a: f64| {
        [std::f64::consts::FRAC_PI_2, std::f64::consts::PI]
            .iter()
            .any(|r| (a.abs() - r).abs() <= RADIAN_ALPHA_TOLERANCE)
    };
    let Some((row, joint)) = rows
        .iter()
        .zip(joints)
        .find(|(_, j)| radian_like(j.alpha))
        .filter(|_| angles_small)
    else {
        return Ok(());
    };
    Err(line_error(
        path,
        row.0,
        format!(
            "alpha = {} looks like radians (π/2 or π), and every angle lies within ±2π: a DH table is read in degrees; name the columns alpha_rad, theta_rad (or alpha_deg, theta_deg if these really are degrees)",
            show(joint.alpha)
        ),
    ))
}
