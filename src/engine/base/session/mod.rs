//! The validated in-memory session: what every engine function takes.
//! `session.rs` turns a FORMAT.md file into a [`Session`] (enforcing every
//! rule) and back; nothing else reads or writes session files.

use std::collections::{HashMap, HashSet};

use nalgebra::{Isometry3, Vector3};

use crate::engine::base::robot::Robot;

pub mod rules;

/// FORMAT.md default for `solver.threshold` (mm): the paper's value.
pub const DEFAULT_THRESHOLD: f64 = 0.15;
/// FORMAT.md default for `solver.max_iterations`.
pub const DEFAULT_MAX_ITERATIONS: usize = 20;
/// FORMAT.md: "A stripe needs at least 5 points": a circle has 3
/// unknowns, two more leave a residual to judge the fit. The loader checks
/// it, the circle fit needs it, the simulator never writes fewer.
pub const MIN_STRIPE_POINTS: usize = 5;

pub use super::limits;

/// What a measurement is used for (FORMAT.md `measurements[].use`).
/// Compares equal to its file spelling (`Use::Identify == "identify"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Use {
    /// Pure translation about one station: initial rotation (eq. 6-7).
    Translation,
    /// Orientation change about one station: initial translation (eq. 8-9).
    Rotation,
    /// Identification of hand-eye and kinematic errors (paper 3.2).
    Identify,
    /// Held out; scored against reference distances and within its station.
    Validate,
}

impl Use {
    /// The file spelling.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Translation => "translation",
            Self::Rotation => "rotation",
            Self::Identify => "identify",
            Self::Validate => "validate",
        }
    }

    /// Parses the file spelling.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "translation" => Some(Self::Translation),
            "rotation" => Some(Self::Rotation),
            "identify" => Some(Self::Identify),
            "validate" => Some(Self::Validate),
            _ => None,
        }
    }

    /// All uses in file order of appearance in FORMAT.md.
    pub const ALL: [Self; 4] = [
        Self::Translation,
        Self::Rotation,
        Self::Identify,
        Self::Validate,
    ];
}

impl PartialEq<&str> for Use {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

/// Where the sensor stands (FORMAT.md `sensor.mount`, added 2026-11-27).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Mount {
    /// The paper's set-up: the sensor on the flange, the sphere fixed in
    /// the cell; the hand-eye is `eT_s` and a station is a point fixed in
    /// the base frame.
    #[default]
    Flange,
    /// The sensor fixed in the cell (a laser tracker, a 3-D camera, a
    /// line scanner), the target on the flange; the hand-eye is `bT_s`
    /// (`base_from_sensor`) and a station is a point fixed in the flange
    /// frame.
    Fixed,
}

impl Mount {
    /// The file spelling.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Flange => "flange",
            Self::Fixed => "fixed",
        }
    }

    /// Parses the file spelling.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "flange" => Some(Self::Flange),
            "fixed" => Some(Self::Fixed),
            _ => None,
        }
    }

    /// The frame a station's point is fixed in: `"base"` for a sensor on
    /// the flange, `"flange"` for a fixed sensor (the result's
    /// `stations[].frame`).
    #[must_use]
    pub fn station_frame(self) -> &'static str {
        match self {
            Self::Flange => "base",
            Self::Fixed => "flange",
        }
    }

    /// What the hand-eye transform is, in words.
    #[must_use]
    pub fn hand_eye_name(self) -> &'static str {
        match self {
            Self::Flange => "hand-eye (flange from sensor)",
            Self::Fixed => "base from sensor",
        }
    }
}

/// What the sensor reported for one measurement.
#[derive(Debug, Clone, PartialEq)]
pub enum Observation {
    /// Stripe points `[y, z]` (mm) in the laser plane `x = 0`.
    Stripe(Vec<[f64; 2]>),
    /// The sphere centre already in the sensor frame (mm).
    Centre(Vector3<f64>),
}

/// One measurement of a session.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// Unique id within the session.
    pub id: String,
    /// Id of the sphere station it saw.
    pub station: String,
    /// What it is used for.
    pub usage: Use,
    /// The `side` written on the measurement itself, if any (+1 or −1).
    pub side_given: Option<i8>,
    /// Effective side: `side_given`, else the session's `sensor.side`.
    pub side: i8,
    /// Joint readings, deg, one per robot joint; empty when the
    /// measurement gives its flange pose instead.
    pub joints: Vec<f64>,
    /// The flange pose `bT_e` as the controller reported it (FORMAT.md
    /// `measurements[].flange`, mm), given instead of `joints` in a
    /// pose-only session.
    pub flange: Option<Isometry3<f64>>,
    /// Stripe or centre.
    pub observation: Observation,
}

/// A laser-tracker distance between two validate stations.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceDistance {
    /// Station id.
    pub from: String,
    /// Station id.
    pub to: String,
    /// Reference distance, mm.
    pub distance: f64,
}

/// The sensor's measuring range in the laser plane (`sensor.range`), mm,
/// sensor frame: `y` along the line, `z` in depth.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SensorRange {
    /// `[min, max]` along the laser line, mm.
    pub y: [f64; 2],
    /// `[min, max]` in depth, mm.
    pub z: [f64; 2],
}

impl SensorRange {
    /// The rectangle's area, mm².
    #[must_use]
    pub fn area(&self) -> f64 {
        (self.y[1] - self.y[0]) * (self.z[1] - self.z[0])
    }

    /// The `n × n` grid of points `[y, z]` spanning the rectangle corner
    /// to corner, `y` outer: the one grid of the range prediction, the
    /// planner's criterion and the scoring against the truth.
    #[must_use]
    pub fn grid(&self, n: usize) -> Vec<[f64; 2]> {
        let at = |lo: f64, hi: f64, k: usize| {
            if n < 2 {
                f64::midpoint(lo, hi)
            } else {
                lo + (hi - lo) * k as f64 / (n - 1) as f64
            }
        };
        (0..n)
            .flat_map(|ky| {
                (0..n).map(move |kz| [at(self.y[0], self.y[1], ky), at(self.z[0], self.z[1], kz)])
            })
            .collect()
    }

    /// Whether `(y, z)` lies in the rectangle.
    #[must_use]
    pub fn contains(&self, y: f64, z: f64) -> bool {
        (self.y[0]..=self.y[1]).contains(&y) && (self.z[0]..=self.z[1]).contains(&z)
    }
}

/// FORMAT.md `solver` block of a session.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Stop when ε (mm) falls to or below this.
    pub threshold: f64,
    /// Most updates the loop makes.
    pub max_iterations: usize,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            threshold: DEFAULT_THRESHOLD,
            max_iterations: DEFAULT_MAX_ITERATIONS,
        }
    }
}

/// A session rule that spans measurements, broken: the measurement it is
/// in (when one is to blame) and what is wrong.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}{message}", measurement.as_ref().map(|m| format!("measurement {m}: ")).unwrap_or_default())]
pub struct RuleError {
    /// The measurement to blame, if one is.
    pub measurement: Option<String>,
    /// The key at fault, when one is: relative to the measurement
    /// (`joints`, `stripe.points`) or to the file (`sphere.diameter`,
    /// `reference_distances[2]`).
    pub key: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl RuleError {
    fn at(measurement: &str, message: String) -> Self {
        Self {
            measurement: Some(measurement.to_string()),
            key: None,
            message,
        }
    }

    fn general(message: String) -> Self {
        Self {
            measurement: None,
            key: None,
            message,
        }
    }
}

/// A validated session (FORMAT.md "Session file").
#[derive(Debug, Clone, PartialEq)]
pub struct Session {
    /// Display name (the file name when the file has none).
    pub name: String,
    /// Whether `name` was written in the file (so a save keeps it absent).
    pub name_given: bool,
    /// Nominal robot model. A pose-only session without a `robot` block
    /// holds a robot with no joints (see [`Session::robot_given`]).
    pub robot: Robot,
    /// Whether the file had a `robot` block (always, unless pose-only).
    pub robot_given: bool,
    /// Whether the file gave `robot.base` / `robot.flange` explicitly.
    pub base_given: bool,
    /// See `base_given`.
    pub flange_given: bool,
    /// Sphere diameter, mm.
    pub sphere_diameter: f64,
    /// `sensor.side` (+1 default).
    pub default_side: i8,
    /// Whether the file had a `sensor` block.
    pub sensor_given: bool,
    /// `sensor.range`: where in the laser plane the calibrated sensor will
    /// measure (FORMAT.md "Additions to version 1"); `None` when not given.
    pub sensor_range: Option<SensorRange>,
    /// `sensor.mount`: on the flange (default) or fixed in the cell.
    pub mount: Mount,
    /// Initial hand-eye from the file, if given: `eT_s`, or `bT_s` for a
    /// fixed mount.
    pub hand_eye: Option<Isometry3<f64>>,
    /// Solver settings (defaults when absent).
    pub solver: SolverSettings,
    /// Whether the file had a `solver` block.
    pub solver_given: bool,
    /// Reference distances between validate stations.
    pub reference_distances: Vec<ReferenceDistance>,
    /// Measurements in file order.
    pub measurements: Vec<Measurement>,
}

impl Session {
    /// A session made in code (imported, simulated, planned) rather than
    /// read: named, its robot given (`base`/`flange` given when not the
    /// identity), a `sphere_diameter` mm sphere, side +1 and no sensor,
    /// solver or hand-eye block, no reference distances. Callers change
    /// what they know with struct update syntax.
    #[must_use]
    pub fn made(
        name: String,
        robot: Robot,
        sphere_diameter: f64,
        measurements: Vec<Measurement>,
    ) -> Self {
        Self {
            name,
            name_given: true,
            base_given: robot.base != Isometry3::identity(),
            flange_given: robot.flange != Isometry3::identity(),
            robot,
            robot_given: true,
            sphere_diameter,
            default_side: 1,
            sensor_given: false,
            sensor_range: None,
            mount: Mount::Flange,
            hand_eye: None,
            solver: SolverSettings::default(),
            solver_given: false,
            reference_distances: Vec::new(),
            measurements,
        }
    }

    /// True for a pose-only session (FORMAT.md "Additions to version 1"):
    /// every measurement gives its flange pose instead of joint readings,
    /// so only the hand-eye and the station centres are calibrated.
    #[must_use]
    pub fn pose_only(&self) -> bool {
        self.measurements
            .first()
            .is_some_and(|m| m.flange.is_some())
    }

    /// The robot whose parameters the solver estimates: the nominal robot,
    /// or for a pose-only session a robot with no joints (no kinematic
    /// unknown; the given flange poses stand in for forward kinematics).
    #[must_use]
    pub fn solver_robot(&self) -> Robot {
        if self.pose_only() {
            Robot::new(self.robot.name.clone(), Vec::new())
        } else {
            self.robot.clone()
        }
    }

    /// The flange pose `bT_e` of measurement `i` under `robot`: the given
    /// pose of a pose-only measurement, else `robot`'s forward kinematics
    /// of its joint readings.
    #[must_use]
    pub fn base_from_flange(&self, robot: &Robot, i: usize) -> Isometry3<f64> {
        let m = &self.measurements[i];
        m.flange
            .unwrap_or_else(|| robot.base_from_flange(&m.joints))
    }

    /// Sphere radius `R`, mm.
    #[must_use]
    pub fn sphere_radius(&self) -> f64 {
        self.sphere_diameter / 2.0
    }

    /// Measurements with the given use, in file order.
    pub fn with_use(&self, usage: Use) -> impl Iterator<Item = &Measurement> {
        self.measurements.iter().filter(move |m| m.usage == usage)
    }

    /// Station ids of the given use in order of first appearance, each with
    /// the indices (into `measurements`) of its measurements in file order.
    #[must_use]
    pub fn stations(&self, usage: Use) -> Vec<(String, Vec<usize>)> {
        let mut out: Vec<(String, Vec<usize>)> = Vec::new();
        // Station → its place in `out`: linear in the measurements.
        let mut index: HashMap<&str, usize> = HashMap::new();
        for (i, m) in self.measurements.iter().enumerate() {
            if m.usage != usage {
                continue;
            }
            if let Some(&k) = index.get(m.station.as_str()) {
                out[k].1.push(i);
            } else {
                index.insert(&m.station, out.len());
                out.push((m.station.clone(), vec![i]));
            }
        }
        out
    }

    /// Checks the rules of FORMAT.md `measurements[].use` and `station`
    /// that span measurements. Whether the translations are collinear and the
    /// rotations too similar is checked by the initial hand-eye itself.
    ///
    /// # Errors
    /// The first broken rule, naming the measurement where there is one.
    pub fn check_rules(&self) -> Result<(), RuleError> {
        let session = self;
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
                return Err(RuleError::at(
                    offender,
                    format!(
                        "all {} measurements must share one station: {} at station {first}, {} at station {second}",
                        usage.as_str(),
                        ids(first_ids),
                        ids(second_ids)
                    ),
                ));
            }
        }
        // A fixed sensor's initial `bT_s` follows from the identify
        // measurements (FORMAT.md 2026-11-27): no translation or rotation group.
        if session.hand_eye.is_none() && session.mount == Mount::Flange {
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
                    return Err(RuleError::general(format!(
                        "without `hand_eye`, {purpose} needs at least {needed} {} measurements; the session has {}{list}",
                        usage.as_str(),
                        found.len()
                    )));
                }
            }
        }
        for (station, indices) in session.stations(Use::Identify) {
            if indices.len() < 2 {
                let id = &session.measurements[indices[0]].id;
                return Err(RuleError::at(
                    id,
                    format!(
                        "identify station {station} has only 1 measurement ({id}); an identify station needs at least 2"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Why [`exclude_measurements`] refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExcludeError {
    /// An id names no measurement of the session.
    #[error("cannot exclude measurement {0}: the session has no measurement with that id")]
    UnknownId(String),
    /// An identify station would keep fewer than 2 measurements.
    #[error(
        "excluding {} leaves identify station {station} with {remaining} measurement(s); an identify station needs at least 2",
        excluded.join(", ")
    )]
    StationTooSmall {
        /// The station.
        station: String,
        /// Measurements it would keep.
        remaining: usize,
        /// The excluded ids of that station.
        excluded: Vec<String>,
    },
    /// A validate station named by a reference distance would be empty.
    #[error(
        "excluding {} leaves validate station {station} with no measurement, but reference distance {from} → {to} names it",
        excluded.join(", ")
    )]
    ReferencedStationEmpty {
        /// The station.
        station: String,
        /// The excluded ids of that station.
        excluded: Vec<String>,
        /// The reference distance's `from`.
        from: String,
        /// The reference distance's `to`.
        to: String,
    },
    /// The session left breaks another rule (too few translation or
    /// rotation measurements for the initial hand-eye, say).
    #[error("without the left-out measurements, {0}")]
    Rule(#[from] RuleError),
}

/// The session without the measurements `ids` (exclude-and-rerun, or a
/// session saved without them), re-checking every FORMAT.md rule the
/// removal can break: every identify station keeps at least 2
/// measurements, every validate station a reference distance names keeps
/// at least one, and without a `hand_eye` enough translation and rotation
/// measurements remain ([`Session::check_rules`]).
///
/// # Errors
/// [`ExcludeError`] naming the unknown id or the station.
pub fn exclude_measurements(session: &Session, ids: &[String]) -> Result<Session, ExcludeError> {
    let known: HashSet<&str> = session.measurements.iter().map(|m| m.id.as_str()).collect();
    if let Some(bad) = ids.iter().find(|id| !known.contains(id.as_str())) {
        return Err(ExcludeError::UnknownId(bad.clone()));
    }
    let drop: HashSet<&str> = ids.iter().map(String::as_str).collect();
    let mut out = session.clone();
    out.measurements.retain(|m| !drop.contains(m.id.as_str()));
    let excluded_of = |station: &str, usage: Use| -> Vec<String> {
        session
            .measurements
            .iter()
            .filter(|m| m.station == station && m.usage == usage && drop.contains(m.id.as_str()))
            .map(|m| m.id.clone())
            .collect()
    };
    for (station, _) in session.stations(Use::Identify) {
        let remaining = out
            .measurements
            .iter()
            .filter(|m| m.usage == Use::Identify && m.station == station)
            .count();
        if remaining < 2 {
            let excluded = excluded_of(&station, Use::Identify);
            if !excluded.is_empty() {
                return Err(ExcludeError::StationTooSmall {
                    station,
                    remaining,
                    excluded,
                });
            }
        }
    }
    for r in &session.reference_distances {
        for station in [&r.from, &r.to] {
            let left = out
                .measurements
                .iter()
                .any(|m| m.usage == Use::Validate && &m.station == station);
            if !left {
                return Err(ExcludeError::ReferencedStationEmpty {
                    station: station.clone(),
                    excluded: excluded_of(station, Use::Validate),
                    from: r.from.clone(),
                    to: r.to.clone(),
                });
            }
        }
    }
    out.check_rules()?;
    Ok(out)
}
