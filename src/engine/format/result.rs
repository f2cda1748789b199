//! The result file of FORMAT.md: what a calibration gives, in memory as
//! [`ResultFile`] and on disk as `spherecal-result` JSON. Written from a
//! finished run and read back here, and only here.

use std::path::Path;

use serde::de::IgnoredAny;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::json::{Ctx, UniqueValue, join, read_text, render, render_lossy, some};
use super::{FORMAT_VERSION, FileError, RESULT_FORMAT, write_atomic};
use crate::engine::geometry::{isometry_from_rows, rows_from_isometry};
use crate::engine::robot::{Joint, Robot};
use crate::engine::session::Use;
use crate::engine::validate::Validation;

/// A result file (FORMAT.md "Result file"), field for field; `format` and
/// `version` are added on writing and checked on reading. Matrices are
/// row-major 4×4 (mm), joints in deg and mm.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResultFile {
    /// Name of the session the result was computed from.
    pub session: String,
    /// Initial hand-eye `eT_s` (sensor to flange), before identification.
    pub hand_eye_initial: [[f64; 4]; 4],
    /// Calibrated hand-eye `eT_s` (sensor to flange).
    pub hand_eye: [[f64; 4]; 4],
    /// The calibrated robot model.
    pub robot: RobotRecord,
    /// Calibrated minus nominal joint parameters (deg, mm), one per joint
    /// (paper Table 1).
    pub joint_errors: Vec<Joint>,
    /// How the result was obtained: `method` (required, a string) and the
    /// method's own settings and diagnostics. Written with `method` first.
    #[serde(serialize_with = "method_first")]
    pub solver: Map<String, Value>,
    /// ε (mm) after 0, 1, … updates; at least the starting ε.
    pub iterations: Vec<IterationRecord>,
    /// ε (mm) before identification, equal to the first `iterations` entry.
    pub epsilon_before: f64,
    /// ε (mm) after identification, equal to the last `iterations` entry.
    pub epsilon_after: f64,
    /// Every measurement's sphere centre in the sensor and base frames.
    pub centres: Vec<CentreRecord>,
    /// Present when the session has validate measurements.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validation: Option<Validation>,
}

/// The result's `robot` block: the calibrated model in file units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotRecord {
    /// Display name.
    pub name: String,
    /// MDH joints (deg, mm), base to flange.
    pub joints: Vec<Joint>,
    /// `B`, row-major 4×4 (mm): base frame to joint-1 frame.
    pub base: [[f64; 4]; 4],
    /// `F`, row-major 4×4 (mm): last joint frame to flange.
    pub flange: [[f64; 4]; 4],
}

impl RobotRecord {
    /// The record of a robot model.
    #[must_use]
    pub fn from_robot(robot: &Robot) -> Self {
        Self {
            name: robot.name.clone(),
            joints: robot.joints.clone(),
            base: rows_from_isometry(&robot.base),
            flange: rows_from_isometry(&robot.flange),
        }
    }

    /// The robot model of this record.
    ///
    /// # Errors
    /// [`crate::engine::geometry::MatrixError`] when `base` or `flange` is not a
    /// rigid transform ([`parse_result`] has already checked both).
    pub fn to_robot(&self) -> Result<Robot, crate::engine::geometry::MatrixError> {
        Ok(Robot {
            name: self.name.clone(),
            joints: self.joints.clone(),
            base: isometry_from_rows(&self.base)?,
            flange: isometry_from_rows(&self.flange)?,
        })
    }
}

/// One entry of the result's `iterations`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IterationRecord {
    /// ε (paper eq. 20, pooled over identify stations), mm.
    pub epsilon: f64,
}

/// One entry of the result's `centres`: a measurement's sphere centre.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CentreRecord {
    /// Measurement id.
    pub measurement: String,
    /// Station id.
    pub station: String,
    /// The measurement's `use` (FORMAT.md spelling, see [`Use::as_str`]).
    #[serde(rename = "use")]
    pub usage: String,
    /// Centre in the sensor frame **S**, mm.
    pub sensor: [f64; 3],
    /// Centre in the base frame **B**, nominal model and initial hand-eye, mm.
    pub before: [f64; 3],
    /// Centre in the base frame **B**, calibrated model and hand-eye, mm.
    pub after: [f64; 3],
}

/// Serialises the `solver` block with `method` first, then the other keys.
fn method_first<S: serde::Serializer>(
    solver: &Map<String, Value>,
    s: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap as _;
    let mut map = s.serialize_map(Some(solver.len()))?;
    if let Some(method) = solver.get("method") {
        map.serialize_entry("method", method)?;
    }
    for (key, value) in solver.iter().filter(|(k, _)| *k != "method") {
        map.serialize_entry(key, value)?;
    }
    map.end()
}

/// The result as FORMAT.md version 1 JSON, pretty-printed, with a trailing
/// newline; [`parse_result`] reads it back to an equal [`ResultFile`].
/// Non-finite numbers (which JSON cannot hold) are written as `null` and
/// would then fail to load.
#[must_use]
pub fn result_to_json(result: &ResultFile) -> String {
    render_lossy(&ResultOut::new(result))
}

/// Parses and checks the text of a result file: `format`, `version`, every
/// key (unknown keys are rejected everywhere except inside `solver`; a key
/// given twice is rejected everywhere), rigid 4×4 matrices, `solver.method`,
/// one joint error per joint, each centre's `use`, and `epsilon_before` /
/// `epsilon_after` equal to the first and last `iterations`.
///
/// # Errors
/// [`FileError::Invalid`] naming what is wrong and where.
pub fn parse_result(text: &str, path: &Path) -> Result<ResultFile, FileError> {
    let ctx = Ctx::new(text, path);
    let top = ctx.document()?;
    ctx.header(top, RESULT_FORMAT)?;
    // Keys given twice anywhere (also inside `solver`), and objects where
    // objects belong; then the strict typed parse.
    let tree: UniqueValue = ctx.parse(top, "", None)?;
    ctx.result_objects(&tree.0)?;
    let keys: ResultKeys = ctx.parse(top, "", None)?;
    let result = keys.into_result();
    ctx.check_result(&result)?;
    Ok(result)
}

/// Reads and checks a result file (see [`parse_result`]).
///
/// # Errors
/// [`FileError::Io`] when the file cannot be read, else as [`parse_result`].
pub fn load_result(path: &Path) -> Result<ResultFile, FileError> {
    let text = read_text(path)?;
    parse_result(&text, path)
}

/// Writes the result to `path` atomically (see [`write_atomic`]).
///
/// # Errors
/// [`FileError::Io`] when the file cannot be written; the old file, if any,
/// is then unchanged.
pub fn save_result(result: &ResultFile, path: &Path) -> Result<(), FileError> {
    let text = render(&ResultOut::new(result), path)?;
    write_atomic(path, text.as_bytes())
}

/// Where the result file holds objects (`[]`: every element of an array).
const RESULT_OBJECTS: &[&str] = &[
    "robot",
    "robot.joints[]",
    "joint_errors[]",
    "solver",
    "iterations[]",
    "centres[]",
    "validation",
    "validation.distances[]",
    "validation.before",
    "validation.after",
    "validation.within_station",
    "validation.within_station.before",
    "validation.within_station.after",
];

/// The result file as read: [`ResultFile`] plus `format` and `version`
/// (checked by [`Ctx::header`] before). Converting it to [`ResultFile`] names
/// every field, so the two cannot drift apart.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a result object")]
struct ResultKeys {
    #[allow(dead_code, reason = "checked by the header pass")]
    format: IgnoredAny,
    #[allow(dead_code, reason = "checked by the header pass")]
    version: IgnoredAny,
    session: String,
    hand_eye_initial: [[f64; 4]; 4],
    hand_eye: [[f64; 4]; 4],
    robot: RobotRecord,
    joint_errors: Vec<Joint>,
    solver: Map<String, Value>,
    iterations: Vec<IterationRecord>,
    epsilon_before: f64,
    epsilon_after: f64,
    centres: Vec<CentreRecord>,
    #[serde(default, deserialize_with = "some")]
    validation: Option<Validation>,
}

impl ResultKeys {
    fn into_result(self) -> ResultFile {
        ResultFile {
            session: self.session,
            hand_eye_initial: self.hand_eye_initial,
            hand_eye: self.hand_eye,
            robot: self.robot,
            joint_errors: self.joint_errors,
            solver: self.solver,
            iterations: self.iterations,
            epsilon_before: self.epsilon_before,
            epsilon_after: self.epsilon_after,
            centres: self.centres,
            validation: self.validation,
        }
    }
}

impl<'a> Ctx<'a> {
    /// Checks that the result's records are JSON objects (serde's derive
    /// would also take an array of the values in field order).
    fn result_objects(&self, top: &Value) -> Result<(), FileError> {
        for pattern in RESULT_OBJECTS {
            let mut nodes: Vec<(String, &Value)> = vec![(String::new(), top)];
            for segment in pattern.split('.') {
                let (name, each) = match segment.strip_suffix("[]") {
                    Some(name) => (name, true),
                    None => (segment, false),
                };
                let mut next = Vec::new();
                for (path, node) in nodes {
                    let Some(child) = node.get(name) else {
                        continue;
                    };
                    let path = join(&path, name);
                    match (each, child) {
                        (false, _) => next.push((path, child)),
                        (true, Value::Array(items)) => {
                            for (i, item) in items.iter().enumerate() {
                                next.push((format!("{path}[{i}]"), item));
                            }
                        }
                        // Not an array: the typed parse reports it.
                        (true, _) => {}
                    }
                }
                nodes = next;
            }
            for (path, node) in nodes {
                if !node.is_object() {
                    let found = match node {
                        Value::Array(_) => "an array",
                        Value::String(_) => "a string",
                        Value::Null => "null",
                        Value::Bool(_) => "a boolean",
                        _ => "a number",
                    };
                    return Err(
                        self.invalid(None, format!("{path}: expected an object, found {found}"))
                    );
                }
            }
        }
        Ok(())
    }

    fn check_result(&self, r: &ResultFile) -> Result<(), FileError> {
        for (key, rows) in [
            ("hand_eye_initial", &r.hand_eye_initial),
            ("hand_eye", &r.hand_eye),
            ("robot.base", &r.robot.base),
            ("robot.flange", &r.robot.flange),
        ] {
            isometry_from_rows(rows).map_err(|e| self.invalid(None, format!("{key}: {e}")))?;
        }
        if r.robot.joints.is_empty() {
            return Err(self.invalid(None, "robot.joints is empty: at least one joint is needed"));
        }
        if r.joint_errors.len() != r.robot.joints.len() {
            return Err(self.invalid(
                None,
                format!(
                    "joint_errors has {} entries, robot.joints has {}; one is needed per joint",
                    r.joint_errors.len(),
                    r.robot.joints.len()
                ),
            ));
        }
        match r.solver.get("method") {
            Some(Value::String(m)) if !m.is_empty() => {}
            Some(other) => {
                return Err(self.invalid(
                    None,
                    format!("solver.method must be a non-empty string, found {other}"),
                ));
            }
            None => return Err(self.invalid(None, "solver: missing key `method`")),
        }
        let (Some(first), Some(last)) = (r.iterations.first(), r.iterations.last()) else {
            return Err(self.invalid(
                None,
                "iterations is empty: it holds at least the starting ε",
            ));
        };
        if r.epsilon_before != first.epsilon {
            return Err(self.invalid(
                None,
                format!(
                    "epsilon_before ({}) differs from the first iterations entry ({})",
                    r.epsilon_before, first.epsilon
                ),
            ));
        }
        if r.epsilon_after != last.epsilon {
            return Err(self.invalid(
                None,
                format!(
                    "epsilon_after ({}) differs from the last iterations entry ({})",
                    r.epsilon_after, last.epsilon
                ),
            ));
        }
        for (i, c) in r.centres.iter().enumerate() {
            if Use::parse(&c.usage).is_none() {
                return Err(self.invalid(
                    Some(&c.measurement),
                    format!(
                        "centres[{i}].use must be one of translation, rotation, identify, validate; found \"{}\"",
                        c.usage
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[derive(Serialize)]
struct ResultOut<'a> {
    format: &'static str,
    version: u32,
    #[serde(flatten)]
    result: &'a ResultFile,
}

impl<'a> ResultOut<'a> {
    fn new(result: &'a ResultFile) -> Self {
        Self {
            format: RESULT_FORMAT,
            version: FORMAT_VERSION,
            result,
        }
    }
}
