//! The result file of FORMAT.md: what a calibration gives, in memory as
//! [`ResultFile`] and on disk as `spherecal-result` JSON. Written from a
//! finished run and read back here, and only here.

use std::path::Path;

use serde::de::IgnoredAny;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use nalgebra::Isometry3;

use super::json::{Ctx, UniqueValue, join, read_text, render, render_lossy, settle, some};
pub use super::result_check::implausible_number;
use super::result_check::{first_non_finite, has_bare_null};
use super::stations::{StationRecord, mount_of};
use super::{FORMAT_VERSION, FileError, RESULT_FORMAT, write_atomic};
use crate::engine::base::geometry::{isometry_from_rows, rigid_from_rows, rows_from_isometry};
use crate::engine::base::records::solver::{Direction, PaperReport, SolverReport};
use crate::engine::base::records::{HeldOut, MlReport, Validation};
use crate::engine::base::robot::{Joint, Robot};
use crate::engine::base::session::{Mount, Use};

/// A result (FORMAT.md "Result file") as the engine holds it: transforms
/// as [`Isometry3`], the robot as a [`Robot`], the method's report typed.
/// Made from a run by [`ResultFile::from_calibration`] or read from a file
/// by [`parse_result`]; [`result_to_json`] writes it (4×4 matrices
/// row-major in mm, joints in deg and mm) and `format` and `version` are
/// added on writing and checked on reading. Two results are equal when
/// they write the same file: transforms compare as their written 4×4
/// matrices, to the few ulps by which a computed transform and the one
/// read back from its file may differ.
#[derive(Debug, Clone)]
pub struct ResultFile {
    /// Name of the session the result was computed from.
    pub session: String,
    /// Initial hand-eye, before identification: `eT_s`
    /// (`flange_from_sensor`), or `bT_s` (`base_from_sensor`) for a fixed
    /// sensor ([`ResultFile::mount`]).
    pub hand_eye_initial: Isometry3<f64>,
    /// Calibrated hand-eye, as `hand_eye_initial`.
    pub hand_eye: Isometry3<f64>,
    /// The calibrated robot model; `None` for a pose-only session without
    /// a robot (FORMAT.md "Additions to version 1": `robot: null`). A
    /// pose-only session's given robot is written back unchanged.
    pub robot: Option<Robot>,
    /// Calibrated minus nominal joint parameters (deg, mm), one per joint
    /// (paper Table 1); empty for a pose-only session (no kinematic
    /// parameter is identified).
    pub joint_errors: Vec<Joint>,
    /// How the result was obtained: the method's report.
    pub solver: SolverReport,
    /// ε (mm) after 0, 1, … updates; at least the starting ε.
    pub iterations: Vec<IterationRecord>,
    /// ε (mm) before identification, equal to the first `iterations` entry.
    pub epsilon_before: f64,
    /// ε (mm) after identification, equal to the last `iterations` entry.
    pub epsilon_after: f64,
    /// Every measurement's sphere centre in the sensor and base frames.
    pub centres: Vec<CentreRecord>,
    /// Present when the session has validate measurements.
    pub validation: Option<Validation>,
    /// Each identify measurement predicted by a calibration made without
    /// it (the top-level `held_out` key, README "Held-out figure"); absent
    /// from results written before it existed.
    pub held_out: Option<HeldOut>,
    /// The joint readings (deg) of each identify and validate measurement
    /// that has them, by id, in `centres` order: where the calibration saw
    /// the robot (`pose_joints`, a key of the engine's own; target
    /// compensation takes the branch and the calibrated region from it).
    /// Empty for a pose-only session and for results written before it.
    pub pose_joints: Vec<(String, Vec<f64>)>,
    /// Every station's calibrated point and its frame (FORMAT.md
    /// 2026-11-27); empty in results written before it.
    pub stations: Vec<StationRecord>,
}

impl PartialEq for ResultFile {
    fn eq(&self, other: &Self) -> bool {
        self.session == other.session
            && same_transform(&self.hand_eye_initial, &other.hand_eye_initial)
            && same_transform(&self.hand_eye, &other.hand_eye)
            && match (&self.robot, &other.robot) {
                (Some(a), Some(b)) => {
                    a.name == b.name
                        && a.joints == b.joints
                        && same_transform(&a.base, &b.base)
                        && same_transform(&a.flange, &b.flange)
                }
                (None, None) => true,
                _ => false,
            }
            && self.joint_errors == other.joint_errors
            && self.solver == other.solver
            && self.iterations == other.iterations
            && self.epsilon_before == other.epsilon_before
            && self.epsilon_after == other.epsilon_after
            && self.centres == other.centres
            && self.validation == other.validation
            && self.held_out == other.held_out
            && self.pose_joints == other.pose_joints
            && self.stations == other.stations
    }
}

impl ResultFile {
    /// Where the sensor stood: fixed when the stations are points on the
    /// flange (FORMAT.md 2026-11-27), else on the flange.
    #[must_use]
    pub fn mount(&self) -> Mount {
        mount_of(&self.stations)
    }

    /// The session's nominal model: the calibrated one minus the joint
    /// errors (base and flange as calibrated; sphere data do not move them).
    /// `None` when the result has no robot (pose-only).
    #[must_use]
    pub fn nominal(&self) -> Option<Robot> {
        let robot = self.robot.as_ref()?;
        Some(Robot {
            joints: robot
                .joints
                .iter()
                .zip(&self.joint_errors)
                .map(|(c, e)| c.minus(e))
                .collect(),
            ..robot.clone()
        })
    }

    /// The warning when the loop made no update (ε started within the
    /// threshold: one `iterations` entry), from the one wording
    /// ([`no_update_warning`](crate::engine::base::records::solver::no_update_warning)).
    #[must_use]
    pub fn no_update_warning(&self) -> Option<String> {
        crate::engine::base::records::solver::no_update_warning(
            self.iterations.len().saturating_sub(1),
            self.epsilon_before,
            self.solver.threshold(),
        )
    }

    /// The robot's name, or [`NO_ROBOT`] for a pose-only result without
    /// a robot (what history groups such results under).
    #[must_use]
    pub fn robot_name(&self) -> &str {
        self.robot.as_ref().map_or(NO_ROBOT, |r| r.name.as_str())
    }

    /// True when no kinematic parameter was identified (a pose-only
    /// session): the result calibrates the hand-eye only.
    #[must_use]
    pub fn hand_eye_only(&self) -> bool {
        self.joint_errors.is_empty()
    }
}

/// What a pose-only result without a robot is called where a robot name
/// is expected (history's grouping, the workbench).
pub const NO_ROBOT: &str = "(no robot: pose-only)";

/// One entry of the result's `iterations`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IterationRecord {
    /// ε (paper eq. 20, pooled over identify stations), mm.
    pub epsilon: f64,
}

/// One entry of the result's `centres`: a measurement's sphere centre.
#[derive(Debug, Clone, PartialEq)]
pub struct CentreRecord {
    /// Measurement id.
    pub measurement: String,
    /// Station id.
    pub station: String,
    /// The measurement's `use`.
    pub usage: Use,
    /// Centre in the sensor frame **S**, mm.
    pub sensor: [f64; 3],
    /// Centre in the base frame **B**, nominal model and initial hand-eye, mm.
    pub before: [f64; 3],
    /// Centre in the base frame **B**, calibrated model and hand-eye, mm.
    pub after: [f64; 3],
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
}

/// A centre as the file holds it (`use` spelled out).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CentreWire {
    measurement: String,
    station: String,
    #[serde(rename = "use")]
    usage: String,
    sensor: [f64; 3],
    before: [f64; 3],
    after: [f64; 3],
}

/// The `solver` block of `report`: what [`result_to_json`] writes (with
/// `method` first). Keys in the block are sorted, as serde_json's maps are.
#[must_use]
pub fn solver_block(report: &SolverReport) -> Map<String, Value> {
    let (method, mut block) = match report {
        SolverReport::Paper(r) => ("paper", paper_block(r)),
        SolverReport::Ml(r) => (
            "ml",
            match serde_json::to_value(r.as_ref()) {
                Ok(Value::Object(m)) => m,
                _ => Map::new(),
            },
        ),
        SolverReport::Other { method, block } => (method.as_str(), block.clone()),
    };
    block.insert("method".into(), Value::String(method.to_string()));
    block
}

/// The paper's block: the keys the report holds, and its extra ones.
fn paper_block(r: &PaperReport) -> Map<String, Value> {
    let mut m = r.extra.clone();
    let mut put = |key: &str, value: Option<Value>| {
        if let Some(v) = value {
            m.insert(key.into(), v);
        }
    };
    put("pairs", r.pairs.clone().map(Value::String));
    put("svd_tolerance", r.svd_tolerance.map(Value::from));
    put(
        "column_scaling",
        r.column_scaling.clone().map(Value::String),
    );
    put("threshold", r.threshold.map(Value::from));
    put("max_iterations", r.max_iterations.map(Value::from));
    put("stop", r.stop.clone().map(Value::String));
    put("stop_reason", r.stop_reason.clone().map(Value::String));
    put("kept_directions", r.kept_directions.map(Value::from));
    put("equations", r.equations.map(Value::from));
    put(
        "singular_values",
        r.singular_values.as_ref().map(|v| Value::from(v.clone())),
    );
    put(
        "dropped_directions",
        r.dropped_directions
            .as_ref()
            .map(|d| d.iter().map(|x| Value::String(x.to_string())).collect()),
    );
    put(
        "unknowns",
        r.unknowns.as_ref().map(|u| Value::from(u.clone())),
    );
    m
}

/// The report of a `solver` block read from a file (`method` checked to be
/// a non-empty string before): the paper's and `ml`'s typed, any other
/// method kept as read. A key of the paper's block that does not read as
/// its type stays among the extra keys; an `ml` block that does not read
/// is kept as another method's.
fn solver_report(mut block: Map<String, Value>) -> SolverReport {
    let method = match block.remove("method") {
        Some(Value::String(m)) => m,
        _ => String::new(),
    };
    match method.as_str() {
        "paper" => SolverReport::Paper(Box::new(paper_report(block))),
        "ml" => match serde_json::from_value::<MlReport>(Value::Object(block.clone())) {
            Ok(r) => SolverReport::Ml(Box::new(r)),
            Err(_) => SolverReport::Other { method, block },
        },
        _ => SolverReport::Other { method, block },
    }
}

/// The paper's block, key by key.
fn paper_report(mut block: Map<String, Value>) -> PaperReport {
    fn take<T: serde::de::DeserializeOwned>(
        block: &mut Map<String, Value>,
        key: &str,
    ) -> Option<T> {
        let value = block.get(key)?;
        let parsed = serde_json::from_value(value.clone()).ok()?;
        block.remove(key);
        Some(parsed)
    }
    let dropped: Option<Vec<String>> = block
        .get("dropped_directions")
        .and_then(|v| serde_json::from_value::<Vec<String>>(v.clone()).ok());
    let dropped_directions = dropped.and_then(|d| {
        d.iter()
            .map(|t| t.parse::<Direction>().ok())
            .collect::<Option<Vec<_>>>()
    });
    if dropped_directions.is_some() {
        block.remove("dropped_directions");
    }
    PaperReport {
        pairs: take(&mut block, "pairs"),
        svd_tolerance: take(&mut block, "svd_tolerance"),
        column_scaling: take(&mut block, "column_scaling"),
        threshold: take(&mut block, "threshold"),
        max_iterations: take(&mut block, "max_iterations"),
        stop: take(&mut block, "stop"),
        stop_reason: take(&mut block, "stop_reason"),
        kept_directions: take(&mut block, "kept_directions"),
        equations: take(&mut block, "equations"),
        singular_values: take(&mut block, "singular_values"),
        dropped_directions,
        unknowns: take(&mut block, "unknowns"),
        extra: block,
    }
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
    ctx.check_result(&keys)?;
    let result = keys.into_result();
    if let Some(message) = implausible_number(&result) {
        return Err(ctx.invalid(None, message));
    }
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
    let text = result_text_checked(result, path)?;
    write_atomic(path, text.as_bytes())
}

/// The text of the result file, refused unless every number in it is
/// finite (JSON has no NaN or infinity; serde_json would write `null`,
/// and the file would not load). The text is scanned for a bare `null`
/// (microseconds); only a result that has one is walked key by key to
/// tell a legal `null` from a number that is not finite. That every
/// result written this way loads in `report`, `export-model` and
/// `history` is a property test (`tests/engine/fuzz.rs`).
///
/// # Errors
/// [`FileError::Invalid`] naming the first non-finite number by its key
/// path; nothing is written.
pub fn result_text_checked(result: &ResultFile, path: &Path) -> Result<String, FileError> {
    if let Some(message) = implausible_number(result) {
        return Err(FileError::Invalid {
            path: path.to_path_buf(),
            measurement: None,
            message: format!(
                "the result is not written: {message} (the calibration diverged or an input is out of range)"
            ),
        });
    }
    let out = ResultOut::new(result);
    let text = render(&out, path)?;
    if has_bare_null(&text)
        && let Ok(tree) = serde_json::to_value(&out)
        && let Some(key) = first_non_finite(&tree, "")
    {
        return Err(FileError::Invalid {
            path: path.to_path_buf(),
            measurement: None,
            message: format!(
                "the result is not written: `{key}` is not a finite number (the calibration diverged or an input is out of range)"
            ),
        });
    }
    Ok(text)
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
    "held_out",
    "held_out.measurements[]",
    "stations[]",
];

/// The result file as read: [`ResultFile`] plus `format` and `version`
/// (checked by [`Ctx::header`] before). Converting it to [`ResultFile`] names
/// every field, so the two cannot drift apart.
///
/// Unknown top-level keys are ignored (FORMAT.md "Additions to version
/// 1": a result may carry further keys of the engine's own); the records
/// inside stay strict.
#[derive(Deserialize)]
#[serde(expecting = "a result object")]
struct ResultKeys {
    #[allow(dead_code, reason = "checked by the header pass")]
    format: IgnoredAny,
    #[allow(dead_code, reason = "checked by the header pass")]
    version: IgnoredAny,
    session: String,
    hand_eye_initial: [[f64; 4]; 4],
    hand_eye: [[f64; 4]; 4],
    robot: Option<RobotRecord>,
    joint_errors: Vec<Joint>,
    solver: Map<String, Value>,
    iterations: Vec<IterationRecord>,
    epsilon_before: f64,
    epsilon_after: f64,
    centres: Vec<CentreWire>,
    #[serde(default, deserialize_with = "some")]
    validation: Option<Validation>,
    #[serde(default, deserialize_with = "some")]
    held_out: Option<HeldOut>,
    #[serde(default)]
    pose_joints: Option<Map<String, Value>>,
    #[serde(default)]
    stations: Vec<StationRecord>,
}

/// The transform of checked file rows, settled so that it survives its
/// own save and load bit for bit (see [`settle`]).
fn transform(rows: &[[f64; 4]; 4]) -> Isometry3<f64> {
    let iso = isometry_from_rows(rows).unwrap_or_else(|_| rigid_from_rows(rows));
    settle(rows, iso)
}

/// Whether two transforms write the same 4×4 matrix, to the rounding of
/// a matrix read and settled (a few ulps of its rotation entries).
fn same_transform(a: &Isometry3<f64>, b: &Isometry3<f64>) -> bool {
    /// Rotation entries are at most 1; settling moves them by a few ulps.
    const ROUNDING: f64 = 8.0 * f64::EPSILON;
    let (ra, rb) = (rows_from_isometry(a), rows_from_isometry(b));
    ra.iter().zip(&rb).all(|(x, y)| {
        x.iter()
            .zip(y)
            .all(|(u, v)| (u - v).abs() <= ROUNDING * u.abs().max(1.0))
    })
}

/// The `pose_joints` read, in `centres` order (`ids`): entries that are
/// not lists of finite numbers are left out (the key is the engine's own
/// and optional; a reader that cannot use an entry does without it).
fn pose_joints(map: Option<&Map<String, Value>>, ids: &[String]) -> Vec<(String, Vec<f64>)> {
    let Some(map) = map else {
        return Vec::new();
    };
    ids.iter()
        .filter_map(|id| {
            let q: Vec<f64> = serde_json::from_value(map.get(id)?.clone()).ok()?;
            q.iter().all(|v| v.is_finite()).then(|| (id.clone(), q))
        })
        .collect()
}

impl ResultKeys {
    /// The typed result of keys that passed [`Ctx::check_result`].
    fn into_result(self) -> ResultFile {
        let ids: Vec<String> = self.centres.iter().map(|c| c.measurement.clone()).collect();
        ResultFile {
            session: self.session,
            hand_eye_initial: transform(&self.hand_eye_initial),
            hand_eye: transform(&self.hand_eye),
            robot: self.robot.map(|r| Robot {
                name: r.name,
                joints: r.joints,
                base: transform(&r.base),
                flange: transform(&r.flange),
            }),
            joint_errors: self.joint_errors,
            solver: solver_report(self.solver),
            iterations: self.iterations,
            epsilon_before: self.epsilon_before,
            epsilon_after: self.epsilon_after,
            centres: self
                .centres
                .into_iter()
                .map(|c| CentreRecord {
                    usage: Use::parse(&c.usage).unwrap_or(Use::Identify),
                    measurement: c.measurement,
                    station: c.station,
                    sensor: c.sensor,
                    before: c.before,
                    after: c.after,
                })
                .collect(),
            validation: self.validation,
            held_out: self.held_out,
            pose_joints: pose_joints(self.pose_joints.as_ref(), &ids),
            stations: self.stations,
        }
    }
}

impl Ctx<'_> {
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
                // A pose-only result without a robot has `robot: null`.
                if path == "robot" && node.is_null() {
                    continue;
                }
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

    fn check_result(&self, r: &ResultKeys) -> Result<(), FileError> {
        let mut matrices = vec![
            ("hand_eye_initial", &r.hand_eye_initial),
            ("hand_eye", &r.hand_eye),
        ];
        if let Some(robot) = &r.robot {
            matrices.push(("robot.base", &robot.base));
            matrices.push(("robot.flange", &robot.flange));
        }
        for (key, rows) in matrices {
            isometry_from_rows(rows).map_err(|e| self.invalid(None, format!("{key}: {e}")))?;
        }
        match &r.robot {
            Some(robot) if robot.joints.is_empty() => {
                return Err(
                    self.invalid(None, "robot.joints is empty: at least one joint is needed")
                );
            }
            // A pose-only result identifies no kinematic parameter.
            Some(_) | None if r.joint_errors.is_empty() => {}
            Some(robot) if r.joint_errors.len() != robot.joints.len() => {
                return Err(self.invalid(
                    None,
                    format!(
                        "joint_errors has {} entries, robot.joints has {}; one is needed per joint (or none, for a pose-only result)",
                        r.joint_errors.len(),
                        robot.joints.len()
                    ),
                ));
            }
            Some(_) => {}
            None => {
                return Err(self.invalid(
                    None,
                    format!(
                        "joint_errors has {} entries but robot is null; a result without a robot (pose-only) has none",
                        r.joint_errors.len()
                    ),
                ));
            }
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
        for (i, st) in r.stations.iter().enumerate() {
            if st.frame != "base" && st.frame != "flange" {
                return Err(self.invalid(
                    None,
                    format!(
                        "stations[{i}].frame must be \"base\" or \"flange\"; found \"{}\"",
                        st.frame
                    ),
                ));
            }
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

/// The result as written: `format` and `version`, then every key of
/// FORMAT.md in its order, transforms as row-major 4×4 matrices.
#[derive(Serialize)]
struct ResultOut<'a> {
    format: &'static str,
    version: u32,
    session: &'a str,
    hand_eye_initial: [[f64; 4]; 4],
    hand_eye: [[f64; 4]; 4],
    robot: Option<RobotRecord>,
    joint_errors: &'a [Joint],
    #[serde(serialize_with = "method_first")]
    solver: Map<String, Value>,
    iterations: &'a [IterationRecord],
    epsilon_before: f64,
    epsilon_after: f64,
    centres: Vec<CentreWire>,
    #[serde(skip_serializing_if = "Option::is_none")]
    validation: Option<&'a Validation>,
    #[serde(skip_serializing_if = "Option::is_none")]
    held_out: Option<&'a HeldOut>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pose_joints: Option<Map<String, Value>>,
    #[serde(skip_serializing_if = "<[StationRecord]>::is_empty")]
    stations: &'a [StationRecord],
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

impl<'a> ResultOut<'a> {
    fn new(r: &'a ResultFile) -> Self {
        Self {
            format: RESULT_FORMAT,
            version: FORMAT_VERSION,
            session: &r.session,
            hand_eye_initial: rows_from_isometry(&r.hand_eye_initial),
            hand_eye: rows_from_isometry(&r.hand_eye),
            robot: r.robot.as_ref().map(RobotRecord::from_robot),
            joint_errors: &r.joint_errors,
            solver: solver_block(&r.solver),
            iterations: &r.iterations,
            epsilon_before: r.epsilon_before,
            epsilon_after: r.epsilon_after,
            centres: r
                .centres
                .iter()
                .map(|c| CentreWire {
                    measurement: c.measurement.clone(),
                    station: c.station.clone(),
                    usage: c.usage.as_str().to_string(),
                    sensor: c.sensor,
                    before: c.before,
                    after: c.after,
                })
                .collect(),
            validation: r.validation.as_ref(),
            held_out: r.held_out.as_ref(),
            pose_joints: (!r.pose_joints.is_empty()).then(|| {
                r.pose_joints
                    .iter()
                    .map(|(id, q)| (id.clone(), Value::from(q.clone())))
                    .collect()
            }),
            stations: &r.stations,
        }
    }
}
