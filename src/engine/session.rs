//! The session and result files of FORMAT.md (version 1): strict loading
//! that enforces every session rule, pretty writing that round-trips
//! exactly, and atomic saves.
//!
//! # Loading
//!
//! A file is checked in layers, so that every error says where it is:
//!
//! 1. the whole text as JSON: a syntax error (`NaN` and `Infinity`
//!    included) reports line and column (a number beyond `f64` is reported
//!    with its key in step 3);
//! 2. the header: `format` and `version`, before anything else, so that a
//!    result file or a newer version is named as such;
//! 3. every JSON object of the session is deserialised into a private
//!    struct with `deny_unknown_fields` whose fields stay raw JSON slices:
//!    serde's derive rejects unknown keys and keys given twice; each field is
//!    then parsed on its own under its key path (`robot.joints[3]`,
//!    `stripe.points[2]`), so a message names the key and, for a problem in
//!    a measurement, the measurement id. Positions are reported as line and
//!    column of the whole file;
//! 4. the rules that span measurements (unique ids, one station for all
//!    translations and one for all rotations, enough measurements for the
//!    initial hand-eye, identify stations of at least 2, reference distances
//!    naming validate stations).
//!
//! Any JSON number is accepted where a number is expected: an integer where
//! a float is stored, and an integer-valued float (`20.0`) where an integer
//! is (`version`, `side`, `max_iterations`). Numbers are parsed exactly
//! (serde_json's `float_roundtrip`) and written in the shortest form that
//! reads back to the same `f64`.
//!
//! # Writing
//!
//! [`session_to_json`] writes only the keys the file had (the `*_given`
//! flags of [`Session`]) plus any value that differs from its default, so a
//! load → save round trip adds nothing. Arrays of numbers stay on one line
//! (a stripe point, a matrix row, joint readings), and so do small objects
//! of scalars (a joint, an iteration); other objects and nested arrays take
//! one line per entry. Saves go through [`write_atomic`]: a crash or a
//! full disk never leaves a partial file.
//!
//! 4×4 matrices are held as [`Isometry3`] (a unit quaternion), which cannot
//! hold the file's 16 numbers bit for bit. The loader checks each matrix with
//! [`isometry_from_rows`] and then settles its rotation on a quaternion, at
//! most a few ulps away, that survives its own write and read unchanged, so a
//! loaded session saves and reloads to an equal [`Session`]. (A transform
//! computed in code may move by those few ulps on its first save.)

use std::collections::HashMap;
use std::fmt;
use std::fs;
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use nalgebra::{Isometry3, Matrix3, Quaternion, Rotation3, Translation3, UnitQuaternion, Vector3};
use serde::de::{self, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;
use serde_json::{Map, Value};

use super::error::{FileError, StripeError};
use super::geometry::{isometry_from_rows, rows_from_isometry};
use super::kinematics::{Joint, Robot};
use super::model::{
    DEFAULT_MAX_ITERATIONS, DEFAULT_THRESHOLD, Measurement, Observation, ReferenceDistance,
    Session, SolverSettings, Use,
};
use super::validate::Validation;

/// The `format` of a session file.
pub const SESSION_FORMAT: &str = "spherecal-session";
/// The `format` of a result file.
pub const RESULT_FORMAT: &str = "spherecal-result";
/// The file-format version this build reads and writes (session and result).
pub const FORMAT_VERSION: u32 = 1;
/// FORMAT.md: "A stripe needs at least 5 points" (a circle has 3 unknowns;
/// 5 leave 2 points to judge the fit). Checked on load.
pub const MIN_STRIPE_POINTS: usize = 5;
/// Largest `max_iterations` accepted: 2^53, the largest integer an `f64`
/// (JSON number) holds exactly. Any real value is far below.
const MAX_ITERATIONS_LIMIT: f64 = 9_007_199_254_740_992.0;
/// Write-and-read rounds [`settle`] tries before searching: about 96 % of
/// rotations reach a fixed point within them.
const SETTLE_ROUNDS: usize = 10;
/// Largest change (ulps per quaternion component) [`settle`] searches for a
/// fixed point; 4 was the most needed in 20 000 random rotations.
const SETTLE_ULPS: i32 = 5;

// ---------------------------------------------------------------------------
// Public API: sessions
// ---------------------------------------------------------------------------

/// Reads and validates a session file (FORMAT.md "Session file").
///
/// # Errors
/// [`FileError::Io`] when the file cannot be read, [`FileError::Invalid`]
/// naming the broken rule (and the measurement, when it is in one).
pub fn load_session(path: &Path) -> Result<Session, FileError> {
    let text = read_text(path)?;
    parse_session(&text, path)
}

/// Parses and validates the text of a session file. `path` is used only in
/// messages and for the default name (the file stem) when the file has no
/// `name`.
///
/// # Errors
/// [`FileError::Invalid`] naming the broken rule, the key path and, for a
/// problem in a measurement, its id.
pub fn parse_session(text: &str, path: &Path) -> Result<Session, FileError> {
    let ctx = Ctx::new(text, path);
    let top = ctx.document()?;
    ctx.header(top, SESSION_FORMAT)?;
    ctx.session(top)
}

/// The session as FORMAT.md version 1 JSON, pretty-printed, with a trailing
/// newline. [`parse_session`] reads it back to an equal [`Session`] (for a
/// session that itself came from [`parse_session`]; see the module doc on
/// matrices).
#[must_use]
pub fn session_to_json(session: &Session) -> String {
    render_lossy(&SessionOut::new(session))
}

/// Writes the session to `path` atomically (see [`write_atomic`]).
///
/// # Errors
/// [`FileError::Io`] when the file cannot be written; the old file, if any,
/// is then unchanged.
pub fn save_session(session: &Session, path: &Path) -> Result<(), FileError> {
    let text = render(&SessionOut::new(session), path)?;
    write_atomic(path, text.as_bytes())
}

/// Replaces `path` with `bytes` atomically: the bytes go to a new temporary
/// file in the same directory, which is flushed to disk and then renamed
/// over `path` (the directory is synced afterwards where the platform
/// allows). On any error the temporary file is removed and `path` is left
/// as it was. An existing target's permissions are kept.
///
/// # Errors
/// [`FileError::Io`] with action "writing" and the target path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    let io_error = |source: io::Error| FileError::Io {
        action: "writing",
        path: path.to_path_buf(),
        source,
    };
    let Some(file_name) = path.file_name() else {
        return Err(io_error(io::Error::new(
            io::ErrorKind::InvalidInput,
            "the path does not name a file",
        )));
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let (temp_path, mut file) = create_temp(dir, file_name).map_err(io_error)?;
    let written = (|| {
        file.write_all(bytes)?;
        if let Ok(meta) = fs::metadata(path) {
            // Best effort: a read-only target stays read-only after a save.
            let _ = file.set_permissions(meta.permissions());
        }
        file.sync_all()?;
        drop(file);
        fs::rename(&temp_path, path)
    })();
    if let Err(source) = written {
        // The temporary file is ours; if even this fails there is nothing
        // better to report than the original error.
        let _ = fs::remove_file(&temp_path);
        return Err(io_error(source));
    }
    sync_dir(dir);
    Ok(())
}

// ---------------------------------------------------------------------------
// Public API: result files
// ---------------------------------------------------------------------------

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
    /// [`super::geometry::MatrixError`] when `base` or `flange` is not a
    /// rigid transform ([`parse_result`] has already checked both).
    pub fn to_robot(&self) -> Result<Robot, super::geometry::MatrixError> {
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

// ---------------------------------------------------------------------------
// Reading: raw key structs
// ---------------------------------------------------------------------------

/// Deserialises a present key as `Some(raw)`, so that `null` is not taken
/// for an absent key (`default` gives `None` for the absent ones).
fn present<'de, D: Deserializer<'de>>(d: D) -> Result<Option<&'de RawValue>, D::Error> {
    <&'de RawValue>::deserialize(d).map(Some)
}

/// A struct of raw JSON slices, one per allowed key: serde's derive rejects
/// unknown keys and keys given twice; the values are parsed one by one.
macro_rules! keys_struct {
    ($name:ident, $expecting:literal {
        $($(#[$attr:meta])* $field:ident $(as $rename:literal)?),* $(,)?
    }) => {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields, expecting = $expecting)]
        struct $name<'a> {
            $(
                $(#[$attr])*
                #[serde(borrow, default, deserialize_with = "present")]
                $(#[serde(rename = $rename)])?
                $field: Option<&'a RawValue>,
            )*
        }
    };
}

keys_struct!(SessionKeys, "a session object" {
    #[allow(dead_code, reason = "checked by the header pass")]
    format,
    #[allow(dead_code, reason = "checked by the header pass")]
    version,
    name, robot, sphere, sensor, hand_eye, solver,
    reference_distances, measurements,
});
keys_struct!(RobotKeys, "an object with name, joints and optionally base and flange" {
    name, joints, base, flange,
});
keys_struct!(SphereKeys, "an object with diameter" { diameter });
keys_struct!(SensorKeys, "an object with side" { side });
keys_struct!(SolverKeys, "an object with threshold and max_iterations" {
    threshold, max_iterations,
});
keys_struct!(ReferenceKeys, "an object with from, to and distance" { from, to, distance });
keys_struct!(MeasurementKeys, "a measurement object" {
    id, station, usage as "use", side, joints, stripe, centre,
});
keys_struct!(StripeKeys, "an object with points" { points });

/// The header of any file: read leniently (other keys ignored) first, so a
/// file of the wrong kind or version is named as such.
#[derive(Deserialize)]
#[serde(expecting = "a JSON object")]
struct Header<'a> {
    #[serde(borrow, default, deserialize_with = "present")]
    format: Option<&'a RawValue>,
    #[serde(borrow, default, deserialize_with = "present")]
    version: Option<&'a RawValue>,
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

/// A present optional key: `null` is an error, not "absent".
fn some<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Option<T>, D::Error> {
    T::deserialize(d).map(Some)
}

/// Builds a [`Value`] like serde_json does, but a key given twice is an
/// error (serde_json's own `Map` keeps the last one silently).
struct UniqueVisitor;

/// A [`Value`] read through [`UniqueVisitor`].
struct UniqueValue(Value);

impl<'de> Deserialize<'de> for UniqueValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UniqueVisitor).map(UniqueValue)
    }
}

impl<'de> Visitor<'de> for UniqueVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E: de::Error>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Value, E> {
        Ok(Value::from(v))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Value, E> {
        Ok(Value::from(v))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Value, E> {
        serde_json::Number::from_f64(v)
            .map(Value::Number)
            .ok_or_else(|| E::custom("a number is not finite"))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_owned()))
    }

    fn visit_string<E: de::Error>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }

    fn visit_unit<E: de::Error>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_none<E: de::Error>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        UniqueValue::deserialize(d).map(|v| v.0)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut out = Vec::new();
        while let Some(UniqueValue(v)) = seq.next_element()? {
            out.push(v);
        }
        Ok(Value::Array(out))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut out = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if out.contains_key(&key) {
                return Err(de::Error::custom(format!("duplicate key `{key}`")));
            }
            let UniqueValue(v) = map.next_value()?;
            out.insert(key, v);
        }
        Ok(Value::Object(out))
    }
}

// ---------------------------------------------------------------------------
// Reading: the checks
// ---------------------------------------------------------------------------

/// The text being read and its path, for messages.
struct Ctx<'a> {
    text: &'a str,
    path: &'a Path,
}

/// `parent: ` or nothing, to start a message about a key of `parent`.
fn prefix(parent: &str) -> String {
    if parent.is_empty() {
        String::new()
    } else {
        format!("{parent}: ")
    }
}

/// The path of key `key` under `parent`.
fn join(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_owned()
    } else {
        format!("{parent}.{key}")
    }
}

/// What kind of JSON value `raw` is, for messages.
fn kind(raw: &RawValue) -> &'static str {
    match raw.get().as_bytes().first() {
        Some(b'{') => "an object",
        Some(b'[') => "an array",
        Some(b'"') => "a string",
        Some(b'n') => "null",
        Some(b't' | b'f') => "a boolean",
        _ => "a number",
    }
}

/// serde_json's message without its position, in FORMAT.md's words.
fn describe(err: &serde_json::Error) -> String {
    let full = err.to_string();
    let position = format!(" at line {} column {}", err.line(), err.column());
    let message = full.strip_suffix(&position).unwrap_or(&full);
    message
        .replace("missing field", "missing key")
        .replace("unknown field", "unknown key")
        .replace("duplicate field", "duplicate key")
        .replace("expected f64", "expected a number")
        .replace(
            "struct Joint",
            "a joint object with alpha, a, beta, theta and d",
        )
}

impl<'a> Ctx<'a> {
    fn new(text: &'a str, path: &'a Path) -> Self {
        // A UTF-8 byte-order mark is not JSON but some editors write one.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        Self { text, path }
    }

    fn invalid(&self, measurement: Option<&str>, message: impl Into<String>) -> FileError {
        FileError::Invalid {
            path: self.path.to_path_buf(),
            measurement: measurement.map(str::to_owned),
            message: message.into(),
        }
    }

    /// Line and column (1-based) of the start of `raw` in the text.
    fn line_column(&self, raw: &RawValue) -> Option<(usize, usize)> {
        let offset = (raw.get().as_ptr() as usize).checked_sub(self.text.as_ptr() as usize)?;
        let before = self.text.get(..offset)?;
        let line = before.bytes().filter(|&b| b == b'\n').count() + 1;
        let column = offset - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        Some((line, column))
    }

    /// ` at line L column C` for the start of `raw`.
    fn at(&self, raw: &RawValue) -> String {
        self.line_column(raw)
            .map(|(l, c)| format!(" at line {l} column {c}"))
            .unwrap_or_default()
    }

    /// The whole text as one JSON value, after a full syntax check.
    fn document(&self) -> Result<&'a RawValue, FileError> {
        if let Err(e) = serde_json::from_str::<IgnoredAny>(self.text) {
            let mut message = format!(
                "not valid JSON: {} at line {} column {}",
                describe(&e),
                e.line(),
                e.column()
            );
            if self.non_finite_literal_at(e.line(), e.column()) {
                message.push_str("; NaN and Infinity are not JSON numbers");
            }
            return Err(self.invalid(None, message));
        }
        serde_json::from_str::<&RawValue>(self.text)
            .map_err(|e| self.invalid(None, format!("not valid JSON: {}", describe(&e))))
    }

    /// Whether a `NaN` or `Infinity` literal sits at the position of a
    /// syntax error (serde_json points at it, or just after a sign).
    fn non_finite_literal_at(&self, line: usize, column: usize) -> bool {
        let Some(text) = self.text.lines().nth(line.saturating_sub(1)) else {
            return false;
        };
        let near = text.get(column.saturating_sub(2)..).unwrap_or("");
        let near = near.trim_start_matches(|c: char| c == '-' || c == '+' || c.is_whitespace());
        ["NaN", "nan", "Infinity", "inf"]
            .iter()
            .any(|w| near.starts_with(w))
    }

    /// Parses `raw` as `T`; an error names `key` and the position in the file.
    fn parse<T: Deserialize<'a>>(
        &self,
        raw: &'a RawValue,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<T, FileError> {
        serde_json::from_str(raw.get()).map_err(|e| {
            let position = match (self.line_column(raw), e.line()) {
                (Some((line, column)), l) if l > 0 => {
                    let (l, c) = if l == 1 {
                        (line, column + e.column() - 1)
                    } else {
                        (line + l - 1, e.column())
                    };
                    format!(" at line {l} column {c}")
                }
                _ => String::new(),
            };
            self.invalid(
                measurement,
                format!("{}{}{position}", prefix(key), describe(&e)),
            )
        })
    }

    /// Parses a JSON object as `T`. serde's derive would also take an array
    /// of the values in field order; FORMAT.md objects must be objects.
    fn object<T: Deserialize<'a>>(
        &self,
        raw: &'a RawValue,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<T, FileError> {
        if !raw.get().starts_with('{') {
            return Err(self.invalid(
                measurement,
                format!(
                    "{}expected an object, found {}{}",
                    prefix(key),
                    kind(raw),
                    self.at(raw)
                ),
            ));
        }
        self.parse(raw, key, measurement)
    }

    /// `raw` or "missing key" naming the key and the object it belongs in.
    fn required(
        &self,
        raw: Option<&'a RawValue>,
        object: &RawValue,
        parent: &str,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<&'a RawValue, FileError> {
        raw.ok_or_else(|| {
            self.invalid(
                measurement,
                format!("{}missing key `{key}`{}", prefix(parent), self.at(object)),
            )
        })
    }

    /// Parses a JSON array element by element, each under `key[i]`.
    fn array<T: Deserialize<'a>>(
        &self,
        raw: &'a RawValue,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<Vec<T>, FileError> {
        let items: Vec<&'a RawValue> = self.parse(raw, key, measurement)?;
        items
            .into_iter()
            .enumerate()
            .map(|(i, item)| self.parse(item, &format!("{key}[{i}]"), measurement))
            .collect()
    }

    /// Exactly `N` numbers (serde's fixed-size arrays report a wrong length
    /// as "trailing characters").
    fn numbers<const N: usize>(
        &self,
        raw: &'a RawValue,
        key: &str,
        what: &str,
        measurement: Option<&str>,
    ) -> Result<[f64; N], FileError> {
        let values: Vec<f64> = self.parse(raw, key, measurement)?;
        <[f64; N]>::try_from(values.as_slice()).map_err(|_| {
            self.invalid(
                measurement,
                format!(
                    "{key} must hold {N} numbers{what}, found {}{}",
                    values.len(),
                    self.at(raw)
                ),
            )
        })
    }

    /// A 4×4 rigid transform (FORMAT.md "Units and frames").
    fn matrix(&self, raw: &'a RawValue, key: &str) -> Result<Isometry3<f64>, FileError> {
        let items: Vec<&'a RawValue> = self.parse(raw, key, None)?;
        if items.len() != 4 {
            return Err(self.invalid(
                None,
                format!(
                    "{key} must be 4 rows of 4 numbers, found {} rows{}",
                    items.len(),
                    self.at(raw)
                ),
            ));
        }
        let mut rows = [[0.0; 4]; 4];
        for (i, (row, item)) in rows.iter_mut().zip(items).enumerate() {
            *row = self.numbers(item, &format!("{key}[{i}]"), "", None)?;
        }
        let iso = isometry_from_rows(&rows)
            .map_err(|e| self.invalid(None, format!("{key}: {e}{}", self.at(raw))))?;
        Ok(settle(&rows, iso))
    }

    /// `side`: +1 or −1, written as any JSON number.
    fn side(
        &self,
        raw: &'a RawValue,
        key: &str,
        measurement: Option<&str>,
    ) -> Result<i8, FileError> {
        let v: f64 = self.parse(raw, key, measurement)?;
        if v == 1.0 {
            Ok(1)
        } else if v == -1.0 {
            Ok(-1)
        } else {
            Err(self.invalid(
                measurement,
                format!("{key} must be 1 or -1, found {v}{}", self.at(raw)),
            ))
        }
    }

    /// `format` and `version` (FORMAT.md: a later version is a new number).
    fn header(&self, top: &'a RawValue, expected: &str) -> Result<(), FileError> {
        let header: Header = self.object(top, "", None)?;
        let kind = if expected == SESSION_FORMAT {
            "session"
        } else {
            "result"
        };
        let Some(format_raw) = header.format else {
            return Err(self.invalid(
                None,
                format!("missing key `format`: not a spherecal {kind} file (expected \"format\": \"{expected}\")"),
            ));
        };
        let format: String = self.parse(format_raw, "format", None)?;
        if format != expected {
            let hint = match format.as_str() {
                SESSION_FORMAT => " (this is a session file, not a result file)",
                RESULT_FORMAT => " (this is a result file, not a session file)",
                _ => "",
            };
            return Err(self.invalid(
                None,
                format!(
                    "format is \"{format}\", expected \"{expected}\"{hint}{}",
                    self.at(format_raw)
                ),
            ));
        }
        let Some(version_raw) = header.version else {
            return Err(self.invalid(None, "missing key `version`"));
        };
        let version: f64 = self.parse(version_raw, "version", None)?;
        if version == f64::from(FORMAT_VERSION) {
            Ok(())
        } else if version.fract() == 0.0 && version > f64::from(FORMAT_VERSION) {
            Err(self.invalid(
                None,
                format!(
                    "version {version} is newer than this build of spherecal reads (it reads version {FORMAT_VERSION}); use a newer spherecal"
                ),
            ))
        } else {
            Err(self.invalid(
                None,
                format!("version {version} is not a {kind} format version; this build reads version {FORMAT_VERSION}"),
            ))
        }
    }

    fn session(&self, top: &'a RawValue) -> Result<Session, FileError> {
        let keys: SessionKeys = self.object(top, "", None)?;
        let name_given = keys.name.is_some();
        let name = match keys.name {
            Some(raw) => self.parse::<String>(raw, "name", None)?,
            None => self.path.file_stem().map_or_else(
                || "session".to_owned(),
                |s| s.to_string_lossy().into_owned(),
            ),
        };
        let robot_raw = self.required(keys.robot, top, "", "robot", None)?;
        let (robot, base_given, flange_given) = self.robot(robot_raw)?;
        let sphere_diameter =
            self.sphere(self.required(keys.sphere, top, "", "sphere", None)?)?;
        let sensor_given = keys.sensor.is_some();
        let default_side = match keys.sensor {
            Some(raw) => {
                let sensor: SensorKeys = self.object(raw, "sensor", None)?;
                match sensor.side {
                    Some(side) => self.side(side, "sensor.side", None)?,
                    None => 1,
                }
            }
            None => 1,
        };
        let hand_eye = match keys.hand_eye {
            Some(raw) => Some(self.matrix(raw, "hand_eye")?),
            None => None,
        };
        let solver_given = keys.solver.is_some();
        let solver = match keys.solver {
            Some(raw) => self.solver(raw)?,
            None => SolverSettings::default(),
        };
        let measurements_raw = self.required(keys.measurements, top, "", "measurements", None)?;
        let items: Vec<&'a RawValue> = self.parse(measurements_raw, "measurements", None)?;
        let mut measurements = Vec::with_capacity(items.len());
        let mut first_index: HashMap<String, usize> = HashMap::new();
        for (index, raw) in items.into_iter().enumerate() {
            let m = self.measurement(index, raw, robot.joints.len(), default_side)?;
            if let Some(&first) = first_index.get(&m.id) {
                return Err(self.invalid(
                    Some(&m.id),
                    format!(
                        "id `{}` is used by measurements[{first}] and measurements[{index}]; ids must be unique{}",
                        m.id,
                        self.at(raw)
                    ),
                ));
            }
            first_index.insert(m.id.clone(), index);
            measurements.push(m);
        }
        let mut session = Session {
            name,
            name_given,
            robot,
            base_given,
            flange_given,
            sphere_diameter,
            default_side,
            sensor_given,
            hand_eye,
            solver,
            solver_given,
            reference_distances: Vec::new(),
            measurements,
        };
        if let Some(raw) = keys.reference_distances {
            session.reference_distances = self.reference_distances(raw, &session)?;
        }
        self.check_uses(&session)?;
        Ok(session)
    }

    fn robot(&self, raw: &'a RawValue) -> Result<(Robot, bool, bool), FileError> {
        let keys: RobotKeys = self.object(raw, "robot", None)?;
        let name: String = self.parse(
            self.required(keys.name, raw, "robot", "name", None)?,
            "robot.name",
            None,
        )?;
        let joints_raw = self.required(keys.joints, raw, "robot", "joints", None)?;
        let items: Vec<&'a RawValue> = self.parse(joints_raw, "robot.joints", None)?;
        let joints = items
            .into_iter()
            .enumerate()
            .map(|(i, item)| self.object::<Joint>(item, &format!("robot.joints[{i}]"), None))
            .collect::<Result<Vec<_>, _>>()?;
        if joints.is_empty() {
            return Err(self.invalid(
                None,
                format!(
                    "robot.joints is empty: at least one joint is needed{}",
                    self.at(joints_raw)
                ),
            ));
        }
        let base = match keys.base {
            Some(b) => Some(self.matrix(b, "robot.base")?),
            None => None,
        };
        let flange = match keys.flange {
            Some(f) => Some(self.matrix(f, "robot.flange")?),
            None => None,
        };
        let robot = Robot {
            name,
            joints,
            base: base.unwrap_or_else(Isometry3::identity),
            flange: flange.unwrap_or_else(Isometry3::identity),
        };
        Ok((robot, base.is_some(), flange.is_some()))
    }

    fn sphere(&self, raw: &'a RawValue) -> Result<f64, FileError> {
        let keys: SphereKeys = self.object(raw, "sphere", None)?;
        let d_raw = self.required(keys.diameter, raw, "sphere", "diameter", None)?;
        let diameter: f64 = self.parse(d_raw, "sphere.diameter", None)?;
        if diameter > 0.0 && diameter.is_finite() {
            Ok(diameter)
        } else {
            Err(self.invalid(
                None,
                format!(
                    "sphere.diameter must be positive (mm), found {diameter}{}",
                    self.at(d_raw)
                ),
            ))
        }
    }

    fn solver(&self, raw: &'a RawValue) -> Result<SolverSettings, FileError> {
        let keys: SolverKeys = self.object(raw, "solver", None)?;
        let mut solver = SolverSettings::default();
        if let Some(t_raw) = keys.threshold {
            let threshold: f64 = self.parse(t_raw, "solver.threshold", None)?;
            if !(threshold >= 0.0 && threshold.is_finite()) {
                return Err(self.invalid(
                    None,
                    format!(
                        "solver.threshold must be zero or positive (mm), found {threshold}{}",
                        self.at(t_raw)
                    ),
                ));
            }
            solver.threshold = threshold;
        }
        if let Some(n_raw) = keys.max_iterations {
            let n: f64 = self.parse(n_raw, "solver.max_iterations", None)?;
            if !(n >= 0.0 && n.fract() == 0.0 && n <= MAX_ITERATIONS_LIMIT) {
                return Err(self.invalid(
                    None,
                    format!(
                        "solver.max_iterations must be a non-negative integer, found {n}{}",
                        self.at(n_raw)
                    ),
                ));
            }
            // Exact: an integer in [0, 2^53].
            solver.max_iterations = n as usize;
        }
        Ok(solver)
    }

    fn measurement(
        &self,
        index: usize,
        raw: &'a RawValue,
        robot_joints: usize,
        default_side: i8,
    ) -> Result<Measurement, FileError> {
        // The id is picked out leniently first so that every later error,
        // even a malformed key, can name the measurement.
        let lenient_id = serde_json::from_str::<Value>(raw.get())
            .ok()
            .and_then(|v| v.get("id")?.as_str().map(str::to_owned))
            .filter(|id| !id.is_empty());
        let m = lenient_id.as_deref();
        let scope = if m.is_some() {
            String::new()
        } else {
            format!("measurements[{index}]")
        };
        let keys: MeasurementKeys = self.object(raw, &scope, m)?;

        let id_raw = self.required(keys.id, raw, &scope, "id", m)?;
        let id: String = self.parse(id_raw, &join(&scope, "id"), m)?;
        if id.is_empty() {
            return Err(self.invalid(
                m,
                format!(
                    "{} must not be empty{}",
                    join(&scope, "id"),
                    self.at(id_raw)
                ),
            ));
        }
        let m = Some(id.as_str());

        let station_raw = self.required(keys.station, raw, &scope, "station", m)?;
        let station: String = self.parse(station_raw, &join(&scope, "station"), m)?;
        if station.is_empty() {
            return Err(self.invalid(
                m,
                format!(
                    "{} must not be empty{}",
                    join(&scope, "station"),
                    self.at(station_raw)
                ),
            ));
        }

        let use_raw = self.required(keys.usage, raw, &scope, "use", m)?;
        let use_text: String = self.parse(use_raw, &join(&scope, "use"), m)?;
        let usage = Use::parse(&use_text).ok_or_else(|| {
            self.invalid(
                m,
                format!(
                    "{} must be one of translation, rotation, identify, validate; found \"{use_text}\"{}",
                    join(&scope, "use"),
                    self.at(use_raw)
                ),
            )
        })?;

        let side_given = match keys.side {
            Some(s) => Some(self.side(s, &join(&scope, "side"), m)?),
            None => None,
        };

        let joints_raw = self.required(keys.joints, raw, &scope, "joints", m)?;
        let joints: Vec<f64> = self.array(joints_raw, &join(&scope, "joints"), m)?;
        if joints.len() != robot_joints {
            return Err(self.invalid(
                m,
                format!(
                    "{} has {} readings, the robot has {robot_joints} joints{}",
                    join(&scope, "joints"),
                    joints.len(),
                    self.at(joints_raw)
                ),
            ));
        }

        let observation = match (keys.stripe, keys.centre) {
            (Some(_), Some(_)) => {
                return Err(self.invalid(
                    m,
                    format!(
                        "{}both `stripe` and `centre` are given; give exactly one{}",
                        prefix(&scope),
                        self.at(raw)
                    ),
                ));
            }
            (None, None) => {
                return Err(self.invalid(
                    m,
                    format!(
                        "{}neither `stripe` nor `centre` is given; give exactly one{}",
                        prefix(&scope),
                        self.at(raw)
                    ),
                ));
            }
            (Some(stripe_raw), None) => {
                let stripe_key = join(&scope, "stripe");
                let stripe: StripeKeys = self.object(stripe_raw, &stripe_key, m)?;
                let points_raw =
                    self.required(stripe.points, stripe_raw, &stripe_key, "points", m)?;
                let points_key = join(&stripe_key, "points");
                let items: Vec<&'a RawValue> = self.parse(points_raw, &points_key, m)?;
                let points = items
                    .into_iter()
                    .enumerate()
                    .map(|(i, item)| {
                        self.numbers::<2>(item, &format!("{points_key}[{i}]"), " [y, z]", m)
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                if points.len() < MIN_STRIPE_POINTS {
                    let problem = StripeError::TooFewPoints {
                        found: points.len(),
                        needed: MIN_STRIPE_POINTS,
                    };
                    return Err(self.invalid(
                        m,
                        format!("{}{problem}{}", prefix(&scope), self.at(points_raw)),
                    ));
                }
                Observation::Stripe(points)
            }
            (None, Some(centre_raw)) => {
                let c = self.numbers::<3>(centre_raw, &join(&scope, "centre"), " [x, y, z]", m)?;
                Observation::Centre(Vector3::from(c))
            }
        };

        Ok(Measurement {
            id,
            station,
            usage,
            side_given,
            side: side_given.unwrap_or(default_side),
            joints,
            observation,
        })
    }

    fn reference_distances(
        &self,
        raw: &'a RawValue,
        session: &Session,
    ) -> Result<Vec<ReferenceDistance>, FileError> {
        let items: Vec<&'a RawValue> = self.parse(raw, "reference_distances", None)?;
        let validate_stations = session.stations(Use::Validate);
        let mut out = Vec::with_capacity(items.len());
        for (i, item) in items.into_iter().enumerate() {
            let key = format!("reference_distances[{i}]");
            let keys: ReferenceKeys = self.object(item, &key, None)?;
            let station = |field: &str, value: Option<&'a RawValue>| -> Result<String, FileError> {
                let v_raw = self.required(value, item, &key, field, None)?;
                let id: String = self.parse(v_raw, &join(&key, field), None)?;
                if validate_stations.iter().any(|(s, _)| *s == id) {
                    return Ok(id);
                }
                let other: Vec<&str> = session
                    .measurements
                    .iter()
                    .filter(|m| m.station == id)
                    .map(|m| m.usage.as_str())
                    .collect();
                let detail = match other.first() {
                    Some(u) => format!(" (it has {u} measurements)"),
                    None => " (no measurement has this station)".to_owned(),
                };
                Err(self.invalid(
                    None,
                    format!(
                        "{}: station `{id}` has no validate measurements{detail}; reference distances may only name validate stations{}",
                        join(&key, field),
                        self.at(v_raw)
                    ),
                ))
            };
            let from = station("from", keys.from)?;
            let to = station("to", keys.to)?;
            if from == to {
                return Err(self.invalid(
                    None,
                    format!(
                        "{key}: from and to are the same station `{from}`{}",
                        self.at(item)
                    ),
                ));
            }
            let d_raw = self.required(keys.distance, item, &key, "distance", None)?;
            let distance: f64 = self.parse(d_raw, &join(&key, "distance"), None)?;
            if !(distance > 0.0 && distance.is_finite()) {
                return Err(self.invalid(
                    None,
                    format!(
                        "{key}.distance must be positive (mm), found {distance}{}",
                        self.at(d_raw)
                    ),
                ));
            }
            out.push(ReferenceDistance { from, to, distance });
        }
        Ok(out)
    }

    /// The rules of FORMAT.md `measurements[].use` and `station` that span
    /// measurements. Whether the translations are collinear and the
    /// rotations too similar is checked by the initial hand-eye itself.
    fn check_uses(&self, session: &Session) -> Result<(), FileError> {
        let ids = |indices: &[usize]| -> String {
            indices
                .iter()
                .map(|&i| session.measurements[i].id.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        for usage in [Use::Translation, Use::Rotation] {
            let stations = session.stations(usage);
            if let [(first, first_ids), (second, second_ids), ..] = stations.as_slice() {
                let offender = &session.measurements[second_ids[0]].id;
                return Err(self.invalid(
                    Some(offender),
                    format!(
                        "all {} measurements must share one station: {} at station {first}, {} at station {second}",
                        usage.as_str(),
                        ids(first_ids),
                        ids(second_ids)
                    ),
                ));
            }
        }
        if session.hand_eye.is_none() {
            for (usage, needed, purpose) in [
                (Use::Translation, 3, "the initial rotation (paper eq. 6-7)"),
                (Use::Rotation, 2, "the initial translation (paper eq. 8-9)"),
            ] {
                let found: Vec<usize> = (0..session.measurements.len())
                    .filter(|&i| session.measurements[i].usage == usage)
                    .collect();
                if found.len() < needed {
                    let list = if found.is_empty() {
                        String::new()
                    } else {
                        format!(" ({})", ids(&found))
                    };
                    return Err(self.invalid(
                        None,
                        format!(
                            "without `hand_eye`, {purpose} needs at least {needed} {} measurements; the session has {}{list}",
                            usage.as_str(),
                            found.len()
                        ),
                    ));
                }
            }
        }
        for (station, indices) in session.stations(Use::Identify) {
            if indices.len() < 2 {
                let id = &session.measurements[indices[0]].id;
                return Err(self.invalid(
                    Some(id),
                    format!(
                        "identify station {station} has only 1 measurement ({id}); an identify station needs at least 2"
                    ),
                ));
            }
        }
        Ok(())
    }

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

/// The rotation of a row-major matrix in closed form (nalgebra's
/// `from_rotation_matrix`, Shepperd's method); deterministic and without
/// the drift of the iterative projection in [`isometry_from_rows`].
fn rotation_from_rows(rows: &[[f64; 4]; 4]) -> UnitQuaternion<f64> {
    let r = Matrix3::from_fn(|i, j| rows[i][j]);
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r))
}

/// The rotation as it reads back after being written (`rows_from_isometry`
/// then [`rotation_from_rows`]).
fn reread(q: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
    rotation_from_rows(&rows_from_isometry(&Isometry3::from_parts(
        Translation3::identity(),
        *q,
    )))
}

/// `v` moved by `n` ulps (toward +∞ for positive `n`).
fn ulps(v: f64, n: i32) -> f64 {
    let mut out = v;
    for _ in 0..n.unsigned_abs() {
        out = if n > 0 {
            out.next_up()
        } else {
            out.next_down()
        };
    }
    out
}

/// The transform of file matrix `rows` (already checked into `iso` by
/// [`isometry_from_rows`]) as a value that survives its own write and read
/// bit for bit. The file holds 16 numbers, the engine a quaternion;
/// converting back and forth may move the last bits.
///
/// A matrix this module wrote reads back exactly in closed form. Otherwise,
/// starting from the checked transform, write and read are repeated until
/// nothing moves; failing that, the quaternions within [`SETTLE_ULPS`] ulps
/// per component are searched for one that reads back to itself. The
/// translation always survives exactly. If no fixed point is found the first
/// reading is kept (a later save and load may then differ by ulps).
fn settle(rows: &[[f64; 4]; 4], iso: Isometry3<f64>) -> Isometry3<f64> {
    let with = |q: UnitQuaternion<f64>| Isometry3::from_parts(iso.translation, q);
    let direct = rotation_from_rows(rows);
    if reread(&direct) == direct {
        return with(direct);
    }
    let start = reread(&iso.rotation);
    let mut q = start;
    for _ in 0..SETTLE_ROUNDS {
        let next = reread(&q);
        if next == q {
            return with(q);
        }
        q = next;
    }
    let c = start.into_inner().coords;
    for k in 1..=SETTLE_ULPS {
        for a in -k..=k {
            for b in -k..=k {
                for d in -k..=k {
                    for e in -k..=k {
                        // Only the shell at distance k; the inside was tried.
                        if a.abs().max(b.abs()).max(d.abs()).max(e.abs()) != k {
                            continue;
                        }
                        let candidate = UnitQuaternion::new_unchecked(Quaternion::new(
                            ulps(c.w, a),
                            ulps(c.x, b),
                            ulps(c.y, d),
                            ulps(c.z, e),
                        ));
                        if reread(&candidate) == candidate {
                            return with(candidate);
                        }
                    }
                }
            }
        }
    }
    with(start)
}

fn read_text(path: &Path) -> Result<String, FileError> {
    fs::read_to_string(path).map_err(|source| FileError::Io {
        action: "reading",
        path: path.to_path_buf(),
        source,
    })
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------

#[derive(Serialize)]
struct SessionOut<'a> {
    format: &'static str,
    version: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    name: Option<&'a str>,
    robot: RobotOut<'a>,
    sphere: SphereOut,
    #[serde(skip_serializing_if = "Option::is_none")]
    sensor: Option<SensorOut>,
    #[serde(skip_serializing_if = "Option::is_none")]
    hand_eye: Option<[[f64; 4]; 4]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    solver: Option<SolverOut>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    reference_distances: Vec<ReferenceOut<'a>>,
    measurements: Vec<MeasurementOut<'a>>,
}

#[derive(Serialize)]
struct RobotOut<'a> {
    name: &'a str,
    joints: &'a [Joint],
    #[serde(skip_serializing_if = "Option::is_none")]
    base: Option<[[f64; 4]; 4]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    flange: Option<[[f64; 4]; 4]>,
}

#[derive(Serialize)]
struct SphereOut {
    diameter: f64,
}

#[derive(Serialize)]
struct SensorOut {
    side: i8,
}

#[derive(Serialize)]
struct SolverOut {
    threshold: f64,
    max_iterations: usize,
}

#[derive(Serialize)]
struct ReferenceOut<'a> {
    from: &'a str,
    to: &'a str,
    distance: f64,
}

#[derive(Serialize)]
struct MeasurementOut<'a> {
    id: &'a str,
    station: &'a str,
    #[serde(rename = "use")]
    usage: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    side: Option<i8>,
    joints: &'a [f64],
    #[serde(skip_serializing_if = "Option::is_none")]
    stripe: Option<StripeOut<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    centre: Option<[f64; 3]>,
}

#[derive(Serialize)]
struct StripeOut<'a> {
    points: &'a [[f64; 2]],
}

impl<'a> SessionOut<'a> {
    /// Keys the file had, plus any value that differs from its default (a
    /// session built in code without the `*_given` flags loses nothing).
    fn new(s: &'a Session) -> Self {
        let matrix = |given: bool, iso: &Isometry3<f64>| {
            (given || *iso != Isometry3::identity()).then(|| rows_from_isometry(iso))
        };
        Self {
            format: SESSION_FORMAT,
            version: FORMAT_VERSION,
            name: s.name_given.then_some(s.name.as_str()),
            robot: RobotOut {
                name: &s.robot.name,
                joints: &s.robot.joints,
                base: matrix(s.base_given, &s.robot.base),
                flange: matrix(s.flange_given, &s.robot.flange),
            },
            sphere: SphereOut {
                diameter: s.sphere_diameter,
            },
            sensor: (s.sensor_given || s.default_side != 1).then_some(SensorOut {
                side: s.default_side,
            }),
            hand_eye: s.hand_eye.as_ref().map(rows_from_isometry),
            solver: (s.solver_given
                || s.solver.threshold != DEFAULT_THRESHOLD
                || s.solver.max_iterations != DEFAULT_MAX_ITERATIONS)
                .then_some(SolverOut {
                    threshold: s.solver.threshold,
                    max_iterations: s.solver.max_iterations,
                }),
            reference_distances: s
                .reference_distances
                .iter()
                .map(|r| ReferenceOut {
                    from: &r.from,
                    to: &r.to,
                    distance: r.distance,
                })
                .collect(),
            measurements: s
                .measurements
                .iter()
                .map(|m| MeasurementOut {
                    id: &m.id,
                    station: &m.station,
                    usage: m.usage.as_str(),
                    // The effective side is kept even if the flags disagree.
                    side: m
                        .side_given
                        .or((m.side != s.default_side).then_some(m.side)),
                    joints: &m.joints,
                    stripe: match &m.observation {
                        Observation::Stripe(points) => Some(StripeOut { points }),
                        Observation::Centre(_) => None,
                    },
                    centre: match &m.observation {
                        Observation::Centre(c) => Some([c.x, c.y, c.z]),
                        Observation::Stripe(_) => None,
                    },
                })
                .collect(),
        }
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

/// Pretty JSON of `value` in the file layout, with a trailing newline.
fn try_render<T: Serialize>(value: &T) -> Result<String, serde_json::Error> {
    let pretty = serde_json::to_string_pretty(value)?;
    let arrays = collapse(&pretty, '[', ']', usize::MAX);
    let mut text = collapse(&arrays, '{', '}', MAX_COLLAPSED_LINE);
    text.push('\n');
    Ok(text)
}

/// [`try_render`] for saving: a failure is reported, never written.
fn render<T: Serialize>(value: &T, path: &Path) -> Result<String, FileError> {
    try_render(value).map_err(|e| FileError::Invalid {
        path: path.to_path_buf(),
        measurement: None,
        message: format!("cannot be written as JSON: {e}"),
    })
}

/// [`try_render`] where no error is possible: the output types hold only
/// strings, numbers and string-keyed maps, serialised to memory. Should it
/// ever fail, the text says so and will not load.
fn render_lossy<T: Serialize>(value: &T) -> String {
    try_render(value).unwrap_or_else(|e| format!("serialisation failed: {e}\n"))
}

/// Longest object line [`collapse`] makes, indent included.
const MAX_COLLAPSED_LINE: usize = 120;

/// Puts each `open … close` container whose entries are all scalars on one
/// line, if the line stays within `max` characters: arrays of numbers
/// (`[y, z]`, a matrix row, joint readings) and flat objects
/// (`{"alpha": 0.0, "a": 0.0, …}`, `{"epsilon": 0.466}`), as FORMAT.md shows
/// them. It works on serde_json's pretty output, where a container that
/// opens a line ends it with `open`, each entry has its own line two spaces
/// deeper, and `close` sits at the opening line's indent; only whitespace
/// changes.
fn collapse(text: &str, open: char, close: char, max: usize) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let mut out: Vec<String> = Vec::with_capacity(lines.len());
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        match flat_container(&lines[i..], open, close, max) {
            Some((collapsed, used)) => {
                out.push(collapsed);
                i += used;
            }
            None => {
                out.push(line.to_owned());
                i += 1;
            }
        }
    }
    out.join("\n")
}

/// Indent of a line of pretty JSON.
fn indent(line: &str) -> usize {
    line.len() - line.trim_start_matches(' ').len()
}

/// The one-line form of the container opened at the end of `lines[0]` and
/// the number of lines it replaces, if its entries are all scalars and it
/// fits in `max` characters.
fn flat_container(lines: &[&str], open: char, close: char, max: usize) -> Option<(String, usize)> {
    let first = lines.first()?;
    if !first.ends_with(open) {
        return None;
    }
    let depth = indent(first);
    let mut entries = Vec::new();
    for (n, line) in lines.iter().enumerate().skip(1) {
        let trimmed = line.trim_start_matches(' ');
        let closing = trimmed
            .strip_prefix(close)
            .is_some_and(|rest| rest.is_empty() || rest == ",");
        if indent(line) == depth && closing {
            let collapsed = format!("{first}{}{trimmed}", entries.join(", "));
            return (!entries.is_empty() && collapsed.len() <= max).then_some((collapsed, n + 1));
        }
        let entry = trimmed.strip_suffix(',').unwrap_or(trimmed);
        let value = if open == '{' {
            object_value(entry)?
        } else {
            entry
        };
        if indent(line) != depth + 2 || value.starts_with(['[', '{']) || value.is_empty() {
            return None;
        }
        entries.push(entry);
    }
    None
}

/// The value of an object entry `"key": value`, minding escapes in the key.
fn object_value(entry: &str) -> Option<&str> {
    let mut escaped = false;
    for (i, c) in entry.char_indices().skip(1) {
        match c {
            '\\' if !escaped => escaped = true,
            '"' if !escaped => return entry.get(i + 1..)?.strip_prefix(": "),
            _ => escaped = false,
        }
    }
    None
}

// ---------------------------------------------------------------------------
// Atomic writes
// ---------------------------------------------------------------------------

/// Distinguishes temporary files of concurrent saves in one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Creates a new, empty temporary file next to the target (same directory,
/// hence same file system, so the rename is atomic).
fn create_temp(dir: &Path, file_name: &std::ffi::OsStr) -> io::Result<(PathBuf, fs::File)> {
    let mut last_error = None;
    for _ in 0..100 {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut name = std::ffi::OsString::from(".");
        name.push(file_name);
        name.push(format!(".{}.{n}.tmp", std::process::id()));
        let temp = dir.join(name);
        match fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp)
        {
            Ok(file) => return Ok((temp, file)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last_error = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last_error.unwrap_or_else(|| io::Error::other("no free temporary file name")))
}

/// Makes the rename durable (Unix); best effort, the file is already in place.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::geometry::isometry_from_twist;

    #[test]
    fn numbers_round_trip_bit_for_bit() {
        // A spread of magnitudes and bit patterns, through the writer and
        // the reader.
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            0.1,
            1e-300,
            5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            615.0,
            38.1,
        ];
        for _ in 0..2000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = f64::from_bits(x);
            if v.is_finite() {
                values.push(v);
            }
        }
        let text = render_lossy(&values);
        let back: Vec<f64> = serde_json::from_str(&text).unwrap_or_default();
        assert_eq!(back.len(), values.len());
        for (a, b) in values.iter().zip(&back) {
            assert!(
                a.to_bits() == b.to_bits() || (*a == 0.0 && *b == 0.0),
                "{a:e} read back as {b:e}"
            );
        }
    }

    #[test]
    fn settled_matrices_survive_write_and_read() {
        let read =
            |rows: &[[f64; 4]; 4]| settle(rows, isometry_from_rows(rows).unwrap_or_default());
        let mut misses = 0;
        for k in 0..2000 {
            let t = f64::from(k);
            let iso = isometry_from_twist(&[
                t,
                -2.0 * t,
                0.5,
                0.013 * t,
                -0.7 + 0.003 * t,
                3.0 * t.sin(),
            ]);
            let settled = read(&rows_from_isometry(&iso));
            if read(&rows_from_isometry(&settled)) != settled {
                misses += 1;
            }
            // Settling moves a transform by rounding only.
            assert!(
                (settled.to_homogeneous() - iso.to_homogeneous())
                    .abs()
                    .max()
                    < 1e-14
            );
        }
        assert_eq!(misses, 0);
    }

    #[test]
    fn layout_keeps_number_arrays_on_one_line() {
        let value = serde_json::json!({
            "a": [[1.0, 2.0], [3.5, -4.0]],
            "b": [],
            "c": {},
            "d": [{"x": 1, "y\\\"{": "}, ["}, {"z": [1]}],
            "e": {"f": {"g": null}}
        });
        let text = render_lossy(&value);
        let expected = r#"{
  "a": [
    [1.0, 2.0],
    [3.5, -4.0]
  ],
  "b": [],
  "c": {},
  "d": [
    {"x": 1, "y\\\"{": "}, ["},
    {
      "z": [1]
    }
  ],
  "e": {
    "f": {"g": null}
  }
}
"#;
        assert_eq!(text, expected);
        assert_eq!(serde_json::from_str::<Value>(&text).ok(), Some(value));
    }
}
