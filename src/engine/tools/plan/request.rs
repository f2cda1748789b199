//! A plan as a person asks for it — the command line's flags and the
//! workbench's Plan view are two ways of filling in one [`PlanRequest`] —
//! and the files such a request may name: a hand-eye guess and a list of
//! stations.

use std::path::{Path, PathBuf};

use nalgebra::Isometry3;

use super::config::{DEFAULT_CONE_DEG, PlanConfig, PlanDesign, StationLayout};
use super::predict::PredictConfig;
use crate::engine::base::cell::workspace;
use crate::engine::base::robot::{self, JointLimit};
use crate::engine::base::session::SensorRange;
use crate::engine::files::format::{Cap, read_text};
use crate::engine::files::import::{ImportError, RobotSource, load_robot, load_urdf};
use crate::engine::files::robot_import::{self, RobotImportError};
use crate::engine::files::table::Table;

/// Why a request cannot be made into a plan configuration, or a file it
/// names cannot be read: what and where.
#[derive(Debug, thiserror::Error)]
pub enum RequestError {
    /// The robot key names no preset.
    #[error("unknown robot preset `{0}`")]
    UnknownPreset(String),
    /// The robot's URDF cannot be read or has no 6-joint chain.
    #[error(transparent)]
    Urdf(#[from] RobotImportError),
    /// The robot's session, result or DH table file cannot be read.
    #[error(transparent)]
    Robot(#[from] ImportError),
    /// A robot from a file that is not a preset needs its joint limits.
    #[error(
        "robot {robot} from {source_file} is not a preset: give its joint limits (min:max per joint, deg)"
    )]
    LimitsNeeded {
        /// The robot's name.
        robot: String,
        /// The file it came from.
        source_file: String,
    },
    /// A file the request names is wrong.
    #[error("{what}: {message} ({})", path.display())]
    File {
        /// What the file is for (`hand-eye`, `stations`).
        what: &'static str,
        /// What is wrong, with the line where there is one.
        message: String,
        /// The file.
        path: PathBuf,
    },
}

/// A plan as asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanRequest {
    /// The robot: a preset key, or a session or result file whose `robot`
    /// block is the nominal model.
    pub robot: RobotSource,
    /// Joint limits, deg; `None`: the preset's, as a cell plans within.
    pub limits: Option<Vec<JointLimit>>,
    /// The sphere, the counts of stations and poses, the cut and the
    /// candidate search.
    pub design: PlanDesign,
    /// Hand-eye guess `flange_from_sensor`; `None`: the paper's initial one.
    pub hand_eye: Option<Isometry3<f64>>,
    /// Station box `dx, dy, dz` (mm) about the sphere; `None`: the preset's.
    pub box_size: Option<[f64; 3]>,
    /// Explicit stations instead of the box.
    pub stations: Option<StationLayout>,
    /// Half-angle of the cone of approach directions, deg.
    pub cone_angle: f64,
    /// Half-range of the spin about the viewing axis in the working
    /// volume, deg.
    pub spin_deg: f64,
    /// Simulated calibrations for the predicted accuracy (0: none).
    pub predict_runs: usize,
    /// The sensor's measuring range (`sensor.range`): the plan predicts
    /// the error over it.
    pub range: Option<SensorRange>,
    /// Spread the sphere over `range` (the default with a range).
    pub spread: bool,
}

impl PlanRequest {
    /// A request with every default, for the robot `robot` and a sphere
    /// at `sphere`.
    #[must_use]
    pub fn new(robot: RobotSource, sphere: [f64; 3]) -> Self {
        Self {
            robot,
            limits: None,
            design: PlanDesign::new(sphere),
            hand_eye: None,
            box_size: None,
            stations: None,
            cone_angle: DEFAULT_CONE_DEG,
            spin_deg: super::config::DEFAULT_SPIN_DEG,
            predict_runs: PredictConfig::default().runs,
            range: None,
            spread: false,
        }
    }

    /// The planner's configuration of this request.
    ///
    /// # Errors
    /// An unknown robot or unreadable robot file, or a robot from a file
    /// that is not a preset without joint limits. (The configuration's own
    /// checks, the count of limits among them, run when it is planned.)
    pub fn config(&self) -> Result<PlanConfig, RequestError> {
        let mut config = match &self.robot {
            RobotSource::Preset(key) => {
                let preset =
                    robot::preset(key).ok_or_else(|| RequestError::UnknownPreset(key.clone()))?;
                PlanConfig::for_preset(&preset, self.design.sphere)
            }
            RobotSource::Urdf { path, tip } => {
                let options = robot_import::UrdfOptions {
                    tip: tip.clone(),
                    ..robot_import::UrdfOptions::default()
                };
                let urdf = load_urdf(path, &options)?;
                // A continuous joint has no limits: one turn each way.
                let limits = urdf
                    .limits
                    .iter()
                    .map(|l| robot::JointLimit {
                        min: l.min.max(-360.0),
                        max: l.max.min(360.0),
                    })
                    .collect();
                PlanConfig::new(urdf.robot, limits, self.design.sphere)
            }
            RobotSource::File(path) | RobotSource::DhTable { path, .. } => {
                let robot = load_robot(&self.robot)?;
                match robot::presets()
                    .into_iter()
                    .find(|p| p.robot.name == robot.name)
                {
                    Some(p) => {
                        let limits = workspace::cell_limits(p.key, &p.limits);
                        PlanConfig::new(robot, limits, self.design.sphere)
                    }
                    None if self.limits.is_some() => {
                        let limits = self.limits.clone().unwrap_or_default();
                        PlanConfig::new(robot, limits, self.design.sphere)
                    }
                    None => {
                        return Err(RequestError::LimitsNeeded {
                            robot: robot.name,
                            source_file: path.display().to_string(),
                        });
                    }
                }
            }
        };
        if let Some(limits) = &self.limits {
            config.limits.clone_from(limits);
        }
        if let Some(he) = self.hand_eye {
            config.flange_from_sensor = he;
        }
        config.design = self.design;
        if let Some(size) = self.box_size {
            config.stations = StationLayout::Box { size };
        }
        if let Some(stations) = &self.stations {
            config.stations = stations.clone();
        }
        config.cone_angle = self.cone_angle;
        config.spin_deg = self.spin_deg;
        config.range = self.range;
        config.spread = self.spread && self.range.is_some();
        Ok(config)
    }
}

/// A hand-eye `flange_from_sensor` from a JSON file: a bare 4×4 array of
/// rows, or an object with a `hand_eye` 4×4 (a session or result file);
/// with a note when its rotation, typed to a few decimals, was made
/// orthonormal ([`read_typed_transform`]).
///
/// [`read_typed_transform`]: crate::engine::files::format::read_typed_transform
///
/// # Errors
/// [`RequestError::File`] naming the file and what is wrong.
pub fn read_hand_eye(path: &Path) -> Result<(Isometry3<f64>, Option<String>), RequestError> {
    crate::engine::files::format::read_typed_transform(path, "hand_eye").map_err(|e| {
        RequestError::File {
            what: "hand-eye",
            message: e.to_string(),
            path: path.to_path_buf(),
        }
    })
}

/// Explicit stations from a CSV with columns `use` (identify or validate),
/// `x`, `y`, `z` (mm, base frame).
///
/// # Errors
/// [`RequestError::File`] naming the file, the line and what is wrong.
pub fn read_stations(path: &Path) -> Result<StationLayout, RequestError> {
    let fail = |line: usize, m: String| RequestError::File {
        what: "stations",
        message: format!("line {line}: {m}"),
        path: path.to_path_buf(),
    };
    let text = read_text(path, Cap::TABLE).map_err(|e| RequestError::File {
        what: "stations",
        message: format!("reading failed: {e}"),
        path: path.to_path_buf(),
    })?;
    let table = Table::parse(&text).map_err(|e| fail(e.line, e.message))?;
    let col = |name: &str| {
        table
            .column(name)
            .ok_or_else(|| fail(table.header_line, format!("no column `{name}`")))
    };
    let (u, x, y, z) = (col("use")?, col("x")?, col("y")?, col("z")?);
    let (mut identify, mut validate) = (Vec::new(), Vec::new());
    for (line, f) in &table.rows {
        let num = |c: usize| {
            f[c].parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    fail(
                        *line,
                        format!(
                            "`{}` is not a finite number",
                            crate::engine::files::table::excerpt(&f[c])
                        ),
                    )
                })
        };
        let p = [num(x)?, num(y)?, num(z)?];
        match f[u].as_str() {
            "identify" => identify.push(p),
            "validate" => validate.push(p),
            other => {
                return Err(fail(
                    *line,
                    format!(
                        "use `{}` is not identify or validate",
                        crate::engine::files::table::excerpt(other)
                    ),
                ));
            }
        }
    }
    Ok(StationLayout::Explicit { identify, validate })
}
