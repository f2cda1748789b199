//! The validated in-memory session: what every engine function takes.
//! `session.rs` turns a FORMAT.md file into a [`Session`] (enforcing every
//! rule) and back; nothing else reads or writes session files.

use nalgebra::{Isometry3, Vector3};

use crate::engine::robot::Robot;

/// FORMAT.md default for `solver.threshold` (mm): the paper's value.
pub const DEFAULT_THRESHOLD: f64 = 0.15;
/// FORMAT.md default for `solver.max_iterations`.
pub const DEFAULT_MAX_ITERATIONS: usize = 20;
/// FORMAT.md: "A stripe needs at least 5 points": a circle has 3
/// unknowns, two more leave a residual to judge the fit. The loader checks
/// it, the circle fit needs it, the simulator never writes fewer.
pub const MIN_STRIPE_POINTS: usize = 5;

/// What a measurement is used for (FORMAT.md `measurements[].use`).
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
    /// Joint readings, deg, one per robot joint.
    pub joints: Vec<f64>,
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

/// A validated session (FORMAT.md "Session file").
#[derive(Debug, Clone, PartialEq)]
pub struct Session {
    /// Display name (the file name when the file has none).
    pub name: String,
    /// Whether `name` was written in the file (so a save keeps it absent).
    pub name_given: bool,
    /// Nominal robot model.
    pub robot: Robot,
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
    /// Initial hand-eye `eT_s` from the file, if given.
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
        for (i, m) in self.measurements.iter().enumerate() {
            if m.usage != usage {
                continue;
            }
            if let Some(entry) = out.iter_mut().find(|(s, _)| *s == m.station) {
                entry.1.push(i);
            } else {
                out.push((m.station.clone(), vec![i]));
            }
        }
        out
    }
}
