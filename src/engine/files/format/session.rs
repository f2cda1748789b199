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
//! [`isometry_from_rows`](crate::engine::base::geometry::isometry_from_rows) and then settles its rotation on a quaternion, at
//! most a few ulps away, that survives its own write and read unchanged, so a
//! loaded session saves and reloads to an equal [`Session`]. (A transform
//! computed in code may move by those few ulps on its first save.)

use std::collections::HashMap;
use std::path::Path;

use nalgebra::Isometry3;
use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;

use super::FORMAT_VERSION;
use super::json::{Ctx, join, keys_struct, prefix, present, read_text, render, render_lossy};
use super::{FileError, SESSION_FORMAT, write_atomic};
use crate::engine::base::geometry::rows_from_isometry;
use crate::engine::base::robot::{Joint, Robot};
use crate::engine::base::session::{
    DEFAULT_MAX_ITERATIONS, DEFAULT_THRESHOLD, Measurement, Mount, Observation, ReferenceDistance,
    SensorRange, Session, SolverSettings, Use, rules,
};
use nalgebra::Vector3;

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
    // The keys first: when they parse and name a version 1 session, the
    // header pass (a whole scan of the text) is not needed; otherwise it
    // says what the file is before any key is blamed.
    let keys = match ctx.object::<SessionKeys>(top, "", None) {
        Ok(keys) if ctx.is_header(keys.format, keys.version, SESSION_FORMAT) => keys,
        other => {
            ctx.header(top, SESSION_FORMAT)?;
            other?
        }
    };
    ctx.session(top, keys)
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
keys_struct!(SensorKeys, "an object with side, range and/or mount" { side, range, mount });
keys_struct!(SolverKeys, "an object with threshold and max_iterations" {
    threshold, max_iterations,
});
keys_struct!(ReferenceKeys, "an object with from, to and distance" { from, to, distance });
keys_struct!(MeasurementKeys, "a measurement object" {
    id, station, usage as "use", side, joints, flange, stripe, centre,
});
keys_struct!(StripeKeys, "an object with points" { points });

/// The id of a measurement, picked out leniently (other keys skipped
/// unparsed) so that every later error can name the measurement.
#[derive(Deserialize)]
struct IdProbe {
    #[serde(default)]
    id: Option<String>,
}

impl<'a> Ctx<'a> {
    fn session(&self, top: &'a RawValue, keys: SessionKeys<'a>) -> Result<Session, FileError> {
        let name_given = keys.name.is_some();
        let name = match keys.name {
            Some(raw) => self.parse::<String>(raw, "name", None)?,
            None => self.path.file_stem().map_or_else(
                || "session".to_owned(),
                |s| s.to_string_lossy().into_owned(),
            ),
        };
        let robot_given = keys.robot.is_some();
        let (robot, base_given, flange_given) = match keys.robot {
            Some(raw) => self.robot(raw)?,
            // Only a pose-only session may leave it out (checked below).
            None => (Robot::new(String::new(), Vec::new()), false, false),
        };
        let sphere_diameter =
            self.sphere(self.required(keys.sphere, top, "", "sphere", None)?)?;
        let sensor_given = keys.sensor.is_some();
        let (default_side, sensor_range, mount) = match keys.sensor {
            Some(raw) => {
                let sensor: SensorKeys = self.object(raw, "sensor", None)?;
                let mount = match sensor.mount {
                    Some(raw) => self.mount(raw)?,
                    None => Mount::Flange,
                };
                let side = match sensor.side {
                    Some(side) => self.side(side, "sensor.side", None)?,
                    None => 1,
                };
                let range = match sensor.range {
                    Some(r) => Some(self.range(r)?),
                    None => None,
                };
                (side, range, mount)
            }
            None => (1, None, Mount::Flange),
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
            let m = self.measurement(index, raw, &robot, robot_given, default_side)?;
            if let Some(&first) = first_index.get(&m.id) {
                return Err(self.invalid(
                    Some(&m.id),
                    format!(
                        "{}{}",
                        rules::duplicate_id(&m.id, first, index),
                        self.at(raw)
                    ),
                ));
            }
            first_index.insert(m.id.clone(), index);
            if let Some(first) = measurements.first() {
                self.same_pose_kind(first, &m, raw)?;
            }
            measurements.push(m);
        }
        if !robot_given && measurements.is_empty() {
            self.required(keys.robot, top, "", "robot", None)?;
        }
        let mut session = Session {
            name,
            name_given,
            robot,
            robot_given,
            base_given,
            flange_given,
            sphere_diameter,
            default_side,
            sensor_given,
            sensor_range,
            mount,
            hand_eye,
            solver,
            solver_given,
            reference_distances: Vec::new(),
            measurements,
        };
        if let Some(raw) = keys.reference_distances {
            session.reference_distances = self.reference_distances(raw, &session)?;
        }
        session
            .check_rules()
            .map_err(|e| self.invalid(e.measurement.as_deref(), e.message))?;
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
            .map(|(i, item)| {
                let joint = self.object::<Joint>(item, &format!("robot.joints[{i}]"), None)?;
                rules::joint(i, &joint).map_err(|m| self.rule(None, m, item))?;
                Ok(joint)
            })
            .collect::<Result<Vec<_>, FileError>>()?;
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

    /// `sensor.mount`: `"flange"` or `"fixed"` (FORMAT.md, added 2026-11-27).
    fn mount(&self, raw: &'a RawValue) -> Result<Mount, FileError> {
        let text: String = self.parse(raw, "sensor.mount", None)?;
        Mount::parse(&text).ok_or_else(|| {
            self.invalid(
                None,
                format!(
                    "sensor.mount must be \"flange\" or \"fixed\"; found \"{text}\"{}",
                    self.at(raw)
                ),
            )
        })
    }

    /// `sensor.range`: `{"y": [min, max], "z": [min, max]}` in mm, each
    /// interval finite, `min < max`, within the plausible sensor extent.
    fn range(&self, raw: &'a RawValue) -> Result<SensorRange, FileError> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct RangeKeys {
            y: [f64; 2],
            z: [f64; 2],
        }
        let r: RangeKeys = self.object(raw, "sensor.range", None)?;
        let range = SensorRange { y: r.y, z: r.z };
        rules::range(&range).map_err(|m| self.rule(None, m, raw))?;
        Ok(range)
    }

    fn sphere(&self, raw: &'a RawValue) -> Result<f64, FileError> {
        let keys: SphereKeys = self.object(raw, "sphere", None)?;
        let d_raw = self.required(keys.diameter, raw, "sphere", "diameter", None)?;
        let diameter: f64 = self.parse(d_raw, "sphere.diameter", None)?;
        rules::sphere_diameter(diameter).map_err(|m| self.rule(None, m, d_raw))?;
        Ok(diameter)
    }

    fn solver(&self, raw: &'a RawValue) -> Result<SolverSettings, FileError> {
        let keys: SolverKeys = self.object(raw, "solver", None)?;
        let mut solver = SolverSettings::default();
        if let Some(t_raw) = keys.threshold {
            let threshold: f64 = self.parse(t_raw, "solver.threshold", None)?;
            rules::threshold(threshold).map_err(|m| self.rule(None, m, t_raw))?;
            solver.threshold = threshold;
        }
        if let Some(n_raw) = keys.max_iterations {
            let n: f64 = self.parse(n_raw, "solver.max_iterations", None)?;
            rules::max_iterations(n).map_err(|m| self.rule(None, m, n_raw))?;
            // Exact: an integer in [0, 2^53].
            solver.max_iterations = n as usize;
        }
        Ok(solver)
    }

    /// A broken rule ([`rules`]) of the value `raw`, with its position.
    fn rule(
        &self,
        m: Option<&str>,
        message: impl std::fmt::Display,
        raw: &'a RawValue,
    ) -> FileError {
        self.invalid(m, format!("{message}{}", self.at(raw)))
    }

    /// Every measurement gives `joints`, or every one gives `flange`
    /// (FORMAT.md "Additions to version 1"): mixing them is an error.
    fn same_pose_kind(
        &self,
        first: &Measurement,
        m: &Measurement,
        raw: &'a RawValue,
    ) -> Result<(), FileError> {
        match rules::mixed_pose_kind(first, m) {
            None => Ok(()),
            Some(message) => Err(self.rule(Some(&m.id), message, raw)),
        }
    }

    fn measurement(
        &self,
        index: usize,
        raw: &'a RawValue,
        robot: &Robot,
        robot_given: bool,
        default_side: i8,
    ) -> Result<Measurement, FileError> {
        let robot_joints = robot.joints.len();
        // Parsed strictly first; only when that fails is the id picked out
        // leniently, so that the error can name the measurement.
        let (keys, m, scope) = self.measurement_keys(index, raw)?;
        let m = m.as_deref();

        let id_raw = self.required(keys.id, raw, &scope, "id", m)?;
        let id: String = self.parse(id_raw, &join(&scope, "id"), m)?;
        rules::non_empty(&join(&scope, "id"), &id).map_err(|e| self.rule(m, e, id_raw))?;
        let m = Some(id.as_str());

        let station_raw = self.required(keys.station, raw, &scope, "station", m)?;
        let station: String = self.parse(station_raw, &join(&scope, "station"), m)?;
        rules::non_empty(&join(&scope, "station"), &station)
            .map_err(|e| self.rule(m, e, station_raw))?;

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

        let (joints, flange) = self.pose(&keys, raw, &scope, m, robot_given, robot_joints)?;

        let observation = self.observation(&keys, raw, &scope, m)?;

        Ok(Measurement {
            id,
            station,
            usage,
            side_given,
            side: side_given.unwrap_or(default_side),
            joints,
            flange,
            observation,
        })
    }

    /// The keys of measurement `index`, parsed strictly; when that fails
    /// the id is picked out leniently so that the error can name the
    /// measurement. Also the id so found and the scope its errors name
    /// (`measurements[i]` without an id).
    fn measurement_keys(
        &self,
        index: usize,
        raw: &'a RawValue,
    ) -> Result<(MeasurementKeys<'a>, Option<String>, String), FileError> {
        // The scope errors name: the id when there is one.
        let scope_of = |lenient: &Option<String>| {
            if lenient.is_some() {
                String::new()
            } else {
                format!("measurements[{index}]")
            }
        };
        if let Ok(keys) = self.object::<MeasurementKeys>(raw, "", None) {
            let lenient = keys
                .id
                .and_then(|r| serde_json::from_str::<String>(r.get()).ok())
                .filter(|id| !id.is_empty());
            let scope = scope_of(&lenient);
            return Ok((keys, lenient, scope));
        }
        let lenient = serde_json::from_str::<IdProbe>(raw.get())
            .ok()
            .and_then(|p| p.id)
            .filter(|id| !id.is_empty());
        let scope = scope_of(&lenient);
        let keys = self.object(raw, &scope, lenient.as_deref())?;
        Ok((keys, lenient, scope))
    }

    /// The pose of a measurement: its joint readings (one per robot
    /// joint, which needs a robot) or its flange pose, exactly one.
    fn pose(
        &self,
        keys: &MeasurementKeys<'a>,
        raw: &'a RawValue,
        scope: &str,
        m: Option<&str>,
        robot_given: bool,
        robot_joints: usize,
    ) -> Result<(Vec<f64>, Option<Isometry3<f64>>), FileError> {
        let pose = match (keys.joints, keys.flange) {
            (Some(_), Some(_)) => {
                return Err(self.invalid(
                    m,
                    format!(
                        "{}both `joints` and `flange` are given; give exactly one{}",
                        prefix(scope),
                        self.at(raw)
                    ),
                ));
            }
            (None, None) => {
                return Err(self.invalid(
                    m,
                    format!(
                        "{}missing key `joints` (or `flange`, the flange pose, in a pose-only session){}",
                        prefix(scope),
                        self.at(raw)
                    ),
                ));
            }
            (None, Some(flange_raw)) => {
                let pose = self.matrix_in(flange_raw, &join(scope, "flange"), m)?;
                (Vec::new(), Some(pose))
            }
            (Some(joints_raw), None) => {
                if !robot_given {
                    return Err(self.rule(
                        m,
                        format!("{}{}", prefix(scope), rules::JOINTS_WITHOUT_ROBOT),
                        joints_raw,
                    ));
                }
                (self.joints(joints_raw, scope, m, robot_joints)?, None)
            }
        };
        Ok(pose)
    }

    /// The observation of a measurement: its stripe points (sensor `y`,
    /// `z`, mm) or its sphere centre (sensor frame, mm), exactly one.
    fn observation(
        &self,
        keys: &MeasurementKeys<'a>,
        raw: &'a RawValue,
        scope: &str,
        m: Option<&str>,
    ) -> Result<Observation, FileError> {
        let observation = match (keys.stripe, keys.centre) {
            (Some(_), Some(_)) => {
                return Err(self.invalid(
                    m,
                    format!(
                        "{}both `stripe` and `centre` are given; give exactly one{}",
                        prefix(scope),
                        self.at(raw)
                    ),
                ));
            }
            (None, None) => {
                return Err(self.invalid(
                    m,
                    format!(
                        "{}neither `stripe` nor `centre` is given; give exactly one{}",
                        prefix(scope),
                        self.at(raw)
                    ),
                ));
            }
            (Some(stripe_raw), None) => {
                let stripe_key = join(scope, "stripe");
                let stripe: StripeKeys = self.object(stripe_raw, &stripe_key, m)?;
                let points_raw =
                    self.required(stripe.points, stripe_raw, &stripe_key, "points", m)?;
                let points_key = join(&stripe_key, "points");
                // One pass for a well-formed list; on any problem, item by
                // item for a message that names the point.
                let points =
                    if let Ok(points) = serde_json::from_str::<Vec<[f64; 2]>>(points_raw.get()) {
                        points
                    } else {
                        let items: Vec<&'a RawValue> = self.parse(points_raw, &points_key, m)?;
                        items
                            .into_iter()
                            .enumerate()
                            .map(|(i, item)| {
                                self.numbers::<2>(item, &format!("{points_key}[{i}]"), " [y, z]", m)
                            })
                            .collect::<Result<Vec<_>, _>>()?
                    };
                rules::stripe_points(&points_key, &prefix(scope), &points)
                    .map_err(|e| self.rule(m, e, points_raw))?;
                Observation::Stripe(points)
            }
            (None, Some(centre_raw)) => {
                let c = Vector3::from(self.numbers::<3>(
                    centre_raw,
                    &join(scope, "centre"),
                    " [x, y, z]",
                    m,
                )?);
                rules::centre(&join(scope, "centre"), &c)
                    .map_err(|e| self.rule(m, e, centre_raw))?;
                Observation::Centre(c)
            }
        };
        Ok(observation)
    }

    /// The joint readings of a measurement: one per robot joint.
    fn joints(
        &self,
        raw: &'a RawValue,
        scope: &str,
        m: Option<&str>,
        robot_joints: usize,
    ) -> Result<Vec<f64>, FileError> {
        let joints: Vec<f64> = self.array(raw, &join(scope, "joints"), m)?;
        rules::joints(&join(scope, "joints"), &joints, robot_joints)
            .map_err(|e| self.rule(m, e, raw))?;
        Ok(joints)
    }

    fn reference_distances(
        &self,
        raw: &'a RawValue,
        session: &Session,
    ) -> Result<Vec<ReferenceDistance>, FileError> {
        let items: Vec<&'a RawValue> = self.parse(raw, "reference_distances", None)?;
        let mut out = Vec::with_capacity(items.len());
        let mut pairs = rules::ReferencePairs::default();
        for (i, item) in items.into_iter().enumerate() {
            let key = format!("reference_distances[{i}]");
            let keys: ReferenceKeys = self.object(item, &key, None)?;
            let from_raw = self.required(keys.from, item, &key, "from", None)?;
            let from: String = self.parse(from_raw, &join(&key, "from"), None)?;
            let to_raw = self.required(keys.to, item, &key, "to", None)?;
            let to: String = self.parse(to_raw, &join(&key, "to"), None)?;
            let d_raw = self.required(keys.distance, item, &key, "distance", None)?;
            let distance: f64 = self.parse(d_raw, &join(&key, "distance"), None)?;
            let r = ReferenceDistance { from, to, distance };
            rules::reference(&key, &r, session).map_err(|(field, message)| {
                let at = match field {
                    "from" => from_raw,
                    "to" => to_raw,
                    "distance" => d_raw,
                    _ => item,
                };
                self.rule(None, message, at)
            })?;
            pairs
                .check(&key, i, &r)
                .map_err(|message| self.rule(None, message, d_raw))?;
            out.push(r);
        }
        Ok(out)
    }
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
    #[serde(skip_serializing_if = "Option::is_none")]
    robot: Option<RobotOut<'a>>,
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
    #[serde(skip_serializing_if = "Option::is_none")]
    range: Option<RangeOut>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mount: Option<&'static str>,
}

#[derive(Serialize)]
struct RangeOut {
    y: [f64; 2],
    z: [f64; 2],
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
    #[serde(skip_serializing_if = "Option::is_none")]
    joints: Option<&'a [f64]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    flange: Option<[[f64; 4]; 4]>,
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
            robot: (s.robot_given || !s.pose_only()).then(|| RobotOut {
                name: &s.robot.name,
                joints: &s.robot.joints,
                base: matrix(s.base_given, &s.robot.base),
                flange: matrix(s.flange_given, &s.robot.flange),
            }),
            sphere: SphereOut {
                diameter: s.sphere_diameter,
            },
            sensor: (s.sensor_given
                || s.default_side != 1
                || s.sensor_range.is_some()
                || s.mount != Mount::Flange)
                .then_some(SensorOut {
                    side: s.default_side,
                    range: s.sensor_range.map(|r| RangeOut { y: r.y, z: r.z }),
                    mount: (s.mount != Mount::Flange).then_some(s.mount.as_str()),
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
                    joints: m.flange.is_none().then_some(m.joints.as_slice()),
                    flange: m.flange.as_ref().map(rows_from_isometry),
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
