//! The truth file of a simulated session: the true model, hand-eye,
//! stations and sensor-frame centres (format `spherecal-truth`), written
//! beside the session so that tests and the evaluation can score against it.

use std::collections::HashSet;
use std::fmt;
use std::marker::PhantomData;
use std::path::Path;

use nalgebra::{Isometry3, Vector3};
use serde::de::{MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::config::SimConfig;
use crate::engine::base::geometry::{
    MatrixError, isometry_from_rows, rigid_from_rows, rows_from_isometry,
};
use crate::engine::base::robot::{Joint, Robot};
use crate::engine::base::session::Use;
use crate::engine::files::format::{Cap, FileError, read_text};

/// `"format"` of a truth file.
pub const TRUTH_FORMAT: &str = "spherecal-truth";
/// `"version"` of the truth files this module writes and reads.
pub const TRUTH_VERSION: u32 = 1;

/// Why a truth file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum TruthError {
    /// Not valid JSON or not the truth file's shape.
    #[error("not a valid truth file: {0}")]
    Syntax(#[from] serde_json::Error),
    /// `format` is not `spherecal-truth`.
    #[error("\"format\" is {0:?}, expected \"{TRUTH_FORMAT}\"")]
    Format(String),
    /// `version` is not one this build reads.
    #[error("truth file version {0} is not supported (this build reads version {TRUTH_VERSION})")]
    Version(u32),
    /// A 4×4 matrix is not a rigid transform.
    #[error("{what}: {source}")]
    Matrix {
        /// Which matrix.
        what: String,
        /// What is wrong with it.
        source: MatrixError,
    },
    /// Parts of the file disagree (joint counts, unknown station ids).
    #[error("{0}")]
    Inconsistent(String),
}

/// A map written as a JSON object whose keys keep their insertion order
/// (stations and measurements in file order). Duplicate keys are an error
/// on reading.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OrderedMap<V>(pub Vec<(String, V)>);

impl<V> OrderedMap<V> {
    /// The value under `key`, if any.
    #[must_use]
    pub fn get(&self, key: &str) -> Option<&V> {
        self.0.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }

    /// Entries in order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &V)> {
        self.0.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// Number of entries.
    #[must_use]
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// True when there are no entries.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl<V: Serialize> Serialize for OrderedMap<V> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

impl<'de, V: Deserialize<'de>> Deserialize<'de> for OrderedMap<V> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct MapVisitor<V>(PhantomData<V>);
        impl<'de, V: Deserialize<'de>> Visitor<'de> for MapVisitor<V> {
            type Value = OrderedMap<V>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut access: A) -> Result<Self::Value, A::Error> {
                let mut entries: Vec<(String, V)> = Vec::new();
                let mut seen = HashSet::new();
                while let Some((k, v)) = access.next_entry::<String, V>()? {
                    if !seen.insert(k.clone()) {
                        return Err(serde::de::Error::custom(format!("key {k:?} given twice")));
                    }
                    entries.push((k, v));
                }
                Ok(OrderedMap(entries))
            }
        }
        deserializer.deserialize_map(MapVisitor(PhantomData))
    }
}

/// `Use` as its FORMAT.md spelling.
mod use_serde {
    use crate::engine::base::session::Use;
    use serde::{Deserialize, Deserializer, Serializer};

    #[allow(
        clippy::trivially_copy_pass_by_ref,
        reason = "serde's `serialize_with` passes a reference"
    )]
    pub fn serialize<S: Serializer>(usage: &Use, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(usage.as_str())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Use, D::Error> {
        let s = String::deserialize(deserializer)?;
        Use::parse(&s).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "unknown use {s:?} (expected translation, rotation, identify or validate)"
            ))
        })
    }
}

/// A robot block in a truth file: FORMAT.md's session `robot` shape
/// (joints in deg and mm; `base`, `flange` 4×4 rows when not identity).
/// `name` is optional here so other simulators' truth files load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TruthRobot {
    /// Display name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// MDH joints, base to flange, file units.
    pub joints: Vec<Joint>,
    /// `B`, row-major 4×4; absent means identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<[[f64; 4]; 4]>,
    /// `F`, row-major 4×4; absent means identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flange: Option<[[f64; 4]; 4]>,
}

impl TruthRobot {
    pub(super) fn from_robot(robot: &Robot) -> Self {
        let rows =
            |iso: &Isometry3<f64>| (*iso != Isometry3::identity()).then(|| rows_from_isometry(iso));
        Self {
            name: Some(robot.name.clone()),
            joints: robot.joints.clone(),
            base: rows(&robot.base),
            flange: rows(&robot.flange),
        }
    }

    /// The robot this block describes (name "unnamed robot" when absent).
    #[must_use]
    pub fn to_robot(&self) -> Robot {
        let mut robot = Robot::new(
            self.name
                .clone()
                .unwrap_or_else(|| "unnamed robot".to_owned()),
            self.joints.clone(),
        );
        if let Some(rows) = &self.base {
            robot.base = rigid_from_rows(rows);
        }
        if let Some(rows) = &self.flange {
            robot.flange = rigid_from_rows(rows);
        }
        robot
    }
}

/// Ground truth of one measurement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeasurementTruth {
    /// Station id.
    pub station: String,
    /// FORMAT.md `use`.
    #[serde(rename = "use", with = "use_serde")]
    pub usage: Use,
    /// Joint angles the robot actually had, deg (the session's `joints` are
    /// these plus reading noise).
    pub joints_actual: Vec<f64>,
    /// The true sphere centre in the sensor frame, mm.
    pub sensor_centre: [f64; 3],
    /// Side of the laser plane, +1 or −1.
    pub side: i8,
}

/// A true distance between two validate stations (before tracker noise).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrueDistance {
    /// Station id.
    pub from: String,
    /// Station id.
    pub to: String,
    /// Distance between the station centres, mm.
    pub distance: f64,
}

/// The ground truth of a simulated session (`"format": "spherecal-truth"`,
/// version 1), the shape of shared/examples/*.truth.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Truth {
    /// Always [`TRUTH_FORMAT`].
    pub format: String,
    /// Always [`TRUTH_VERSION`].
    pub version: u32,
    /// Name of the session this is the truth of.
    pub session: String,
    /// The configuration that produced it (name and workspace resolved).
    pub config: SimConfig,
    /// The true kinematic model (nominal + `joint_errors`).
    pub robot: TruthRobot,
    /// The nominal model written into the session.
    pub nominal: TruthRobot,
    /// True minus nominal, per joint, deg and mm (paper Table 1 layout).
    pub joint_errors: Vec<Joint>,
    /// The true hand-eye `eT_s` (sensor to flange), row-major 4×4, mm.
    pub hand_eye: [[f64; 4]; 4],
    /// Sphere centre of every station, base frame, mm, in file order.
    pub stations: OrderedMap<[f64; 3]>,
    /// True distances of the session's `reference_distances`, same order.
    pub true_distances: Vec<TrueDistance>,
    /// Per measurement id, in session order.
    pub measurements: OrderedMap<MeasurementTruth>,
}

impl Truth {
    /// The true kinematic model.
    #[must_use]
    pub fn true_robot(&self) -> Robot {
        self.robot.to_robot()
    }

    /// The nominal kinematic model.
    #[must_use]
    pub fn nominal_robot(&self) -> Robot {
        self.nominal.to_robot()
    }

    /// The true hand-eye `flange_from_sensor` (mm).
    #[must_use]
    pub fn true_hand_eye(&self) -> Isometry3<f64> {
        rigid_from_rows(&self.hand_eye)
    }

    /// Sphere centre of station `id`, base frame, mm.
    #[must_use]
    pub fn station(&self, id: &str) -> Option<Vector3<f64>> {
        self.stations.get(id).map(|p| Vector3::from(*p))
    }

    /// Ground truth of measurement `id`.
    #[must_use]
    pub fn measurement(&self, id: &str) -> Option<&MeasurementTruth> {
        self.measurements.get(id)
    }
}

/// Serialises a truth file: pretty JSON (one-space indent, like the
/// shared example), keys in struct order, trailing newline.
#[must_use]
pub fn truth_to_json(truth: &Truth) -> String {
    let mut out = Vec::new();
    let formatter = serde_json::ser::PrettyFormatter::with_indent(b" ");
    let mut ser = serde_json::Serializer::with_formatter(&mut out, formatter);
    // Serialising plain structs of strings and finite numbers to memory
    // cannot fail; keep whatever was written if it somehow does.
    let _ = truth.serialize(&mut ser);
    let mut text = String::from_utf8_lossy(&out).into_owned();
    text.push('\n');
    text
}

/// Parses a truth file and checks it: format and version, rigid 4×4
/// matrices, matching joint counts, measurements naming known stations.
///
/// # Errors
/// [`TruthError`] naming what is wrong.
pub fn parse_truth(text: &str) -> Result<Truth, TruthError> {
    let truth: Truth = serde_json::from_str(text)?;
    if truth.format != TRUTH_FORMAT {
        return Err(TruthError::Format(truth.format));
    }
    if truth.version != TRUTH_VERSION {
        return Err(TruthError::Version(truth.version));
    }
    let matrix = |what: &str, rows: &[[f64; 4]; 4]| {
        isometry_from_rows(rows)
            .map(|_| ())
            .map_err(|source| TruthError::Matrix {
                what: what.to_owned(),
                source,
            })
    };
    matrix("hand_eye", &truth.hand_eye)?;
    for (label, block) in [("robot", &truth.robot), ("nominal", &truth.nominal)] {
        if let Some(rows) = &block.base {
            matrix(&format!("{label}.base"), rows)?;
        }
        if let Some(rows) = &block.flange {
            matrix(&format!("{label}.flange"), rows)?;
        }
    }
    let n = truth.robot.joints.len();
    if truth.nominal.joints.len() != n || truth.joint_errors.len() != n {
        return Err(TruthError::Inconsistent(format!(
            "robot has {n} joints, nominal {} and joint_errors {}",
            truth.nominal.joints.len(),
            truth.joint_errors.len()
        )));
    }
    for (id, m) in truth.measurements.iter() {
        if m.joints_actual.len() != n {
            return Err(TruthError::Inconsistent(format!(
                "measurement {id}: joints_actual has {} values, the robot has {n} joints",
                m.joints_actual.len()
            )));
        }
        if truth.stations.get(&m.station).is_none() {
            return Err(TruthError::Inconsistent(format!(
                "measurement {id}: station {} is not in \"stations\"",
                m.station
            )));
        }
        if m.side != 1 && m.side != -1 {
            return Err(TruthError::Inconsistent(format!(
                "measurement {id}: side must be 1 or -1, found {}",
                m.side
            )));
        }
    }
    Ok(truth)
}

/// Reads and parses a truth file.
///
/// # Errors
/// [`FileError::Io`] when it cannot be read, [`FileError::Invalid`] with
/// the [`TruthError`] message otherwise.
pub fn load_truth(path: &Path) -> Result<Truth, FileError> {
    let text = read_text(path, Cap::SESSION).map_err(|source| FileError::Io {
        action: "reading",
        path: path.to_path_buf(),
        source,
    })?;
    parse_truth(&text).map_err(|e| FileError::Invalid {
        path: path.to_path_buf(),
        measurement: None,
        message: e.to_string(),
    })
}
