//! Import of real data: a pose log plus stripe profiles become a
//! [`Session`], validated by the same typed rules as the session loader
//! ([`Session::validate`]), a broken rule blamed on the file it came from.
//!
//! Two kinds of pose log:
//!
//! - a **joint log** ([`import`], [`log`]): one CSV row a pose with its id,
//!   station, use, side and joint readings, optionally with the flange pose
//!   the controller reports, checked against the nominal model ([`check`]);
//! - a **pose file** ([`import_poses`], [`poses`]): a pose table, a JSON
//!   list or a robot program (FANUC `.ls`, RAPID, KUKA, URScript; read by
//!   [`crate::engine::files::program`]): flange poses give a pose-only session
//!   (FORMAT.md "Additions to version 1"), which calibrates the hand-eye
//!   and the station centres only; joint targets a session with joints.
//!
//! Profiles ([`profiles`]) come as CSV/TXT or OpenCV YAML/JSON in the
//! sensor's own axes and units; an axis map puts them in FORMAT.md's laser
//! plane, and no-return points are dropped and counted.
//!
//! A long import tells its stage ([`progress`]: each profile read, the side
//! decision, the check) through [`import_with`] and [`import_poses_with`],
//! and stops when the callback cancels. [`entry`] is the one entry the
//! command line and the workbench both call.
//!
//! CSV files are read with the `csv` crate
//! ([`Table`](crate::engine::base::table::Table)): a UTF-8 byte-order
//! mark, quotes, `,` `;` or tab separators, `#` comment lines; column names
//! match case-insensitively; line numbers in messages are 1-based lines of
//! the file.

pub mod check;
pub mod choices;
pub mod entry;
mod csv_file;
pub mod initial;
pub mod log;
pub mod pairing;
pub mod poses;
pub mod preview;
pub mod profiles;
pub mod progress;
pub mod references;
pub mod robot_source;
pub mod side;
pub mod tracker;
pub mod units;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub use self::check::{
    DEFAULT_POSITION_TOLERANCE_MM, DEFAULT_ROTATION_TOLERANCE_DEG, FlangeCheck, PoseCheck,
};
pub use self::choices::{HandEyeChoice, ImportChoices, LogKind, ObservationKind, ProfilesKind};
pub use self::entry::{ImportRequest, PoseLog, import_session, preview_joint_log};
pub use self::log::{ColumnMap, DEFAULT_SIDE_COLUMN, header, preview};
pub use self::poses::{
    Observations, PoseImportSpec, PoseInputs, SideChoice, build_pose_session, read_pose_inputs,
    read_pose_inputs_with,
};
pub use self::preview::{PairingPreview, PosePreview, preview_pose_import};
pub use self::profiles::{AxisMap, PlaneProfile, ProfileFormat, ProfileSource, RawProfile};
pub use self::progress::{ImportProgress, ImportStage};
pub use self::references::{read_references, reference_rows};
pub use self::robot_source::{RobotSource, RobotSourceError, load_dh_csv, load_robot, load_urdf};
pub use self::side::{decide_side, import_poses, import_poses_with};
pub use self::units::{AngleUnit, LengthUnit};
pub use crate::engine::base::robot::controller::FlangeConvention;
pub use crate::engine::files::program::PoseFormat;

use self::log::JointLog;
use crate::engine::base::numeric::plural;
use crate::engine::base::robot::Robot;
use crate::engine::base::session::{MIN_STRIPE_POINTS, Measurement, Observation, Session};
use crate::engine::files::format::FileError;

/// Default sphere diameter, mm: the 1.5 inch sphere of the paper.
pub const DEFAULT_SPHERE_DIAMETER: f64 = 38.1;

/// Everything the import of a joint log needs.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportSpec {
    /// The joint log CSV.
    pub joint_log: PathBuf,
    /// Its column names.
    pub columns: ColumnMap,
    /// Unit of its joint columns.
    pub joint_unit: AngleUnit,
    /// The stripe profiles.
    pub profiles: ProfileSource,
    /// How to read the profiles: unit, axis map, no-return value, key.
    pub profile_format: ProfileFormat,
    /// The nominal robot model.
    pub robot: RobotSource,
    /// Sphere diameter, mm.
    pub sphere_diameter: f64,
    /// Session name; `None` gives the joint log's file stem.
    pub name: Option<String>,
    /// Optional flange-pose check.
    pub flange: Option<FlangeCheck>,
    /// Optional laser-tracker reference distances: a CSV with columns
    /// `from`, `to`, `distance` (station ids, mm).
    pub references: Option<PathBuf>,
}

/// An import failed; every message names the file and, where it applies,
/// the line, column or pose id.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// A file could not be read.
    #[error("reading failed: {source} ({path})")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A CSV problem at a line.
    #[error("line {line}: {message} ({path})")]
    Csv {
        /// The file.
        path: PathBuf,
        /// 1-based line of the file.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A problem with the file as a whole (no header, missing column).
    #[error("{message} ({path})")]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A pose of the log has no profile.
    #[error("pose {id}: no stripe profile ({path})")]
    MissingProfile {
        /// The pose id.
        id: String,
        /// The file that was expected, or the single profile file.
        path: PathBuf,
    },
    /// The specification itself is inconsistent.
    #[error("{0}")]
    Spec(String),
    /// The robot's URDF or DH table could not be read (the loader's error,
    /// naming the file and the line).
    #[error(transparent)]
    Robot(Box<crate::engine::base::robot::RobotImportError>),
    /// The built session breaks a FORMAT.md rule (the loader's message).
    #[error("{0}")]
    Session(#[from] FileError),
    /// No initial hand-eye can be had from the poses (no group of one
    /// orientation for eq. 6-9, and the general solution degenerate): a
    /// guess must be given. The message names both reasons.
    #[error("{message} ({path})")]
    NoInitialHandEye {
        /// The pose file.
        path: PathBuf,
        /// Why, both reasons named.
        message: String,
    },
    /// The caller cancelled (nothing was built).
    #[error("the import was cancelled")]
    Cancelled,
}

/// What an import built and found out.
#[derive(Debug, Clone, PartialEq)]
pub struct Imported {
    /// The session, validated by the session loader.
    pub session: Session,
    /// The flange-pose checks of a joint log (empty without a check).
    pub checks: Vec<PoseCheck>,
    /// How the profiles were read.
    pub profiles: ProfileReport,
    /// Decisions the import made, in words (axis map, uses, side, initial
    /// hand-eye), for the summary.
    pub notes: Vec<String>,
}

/// How the profiles were read: the axis map and, per pose, what was kept
/// and dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileReport {
    /// The axis map applied.
    pub axes: AxisMap,
    /// True when it was guessed from the data.
    pub axes_guessed: bool,
    /// One per pose, session order.
    pub poses: Vec<ProfileCount>,
    /// Files of a profile folder paired by pose id that name no pose (a
    /// README, an old profile), listed rather than passed over.
    pub skipped: Vec<PathBuf>,
}

/// One pose's profile as read.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileCount {
    /// Measurement id.
    pub id: String,
    /// The profile file.
    pub file: PathBuf,
    /// Points kept (finite, not the no-return value).
    pub points: usize,
    /// Points dropped for a NaN or infinite coordinate.
    pub non_finite: usize,
    /// Points dropped for the no-return value.
    pub no_return: usize,
}

impl ProfileReport {
    /// One line: the axis map and the dropped points.
    #[must_use]
    pub fn summary(&self) -> String {
        let non_finite: usize = self.poses.iter().map(|p| p.non_finite).sum();
        let no_return: usize = self.poses.iter().map(|p| p.no_return).sum();
        let points: usize = self.poses.iter().map(|p| p.points).sum();
        format!(
            "profiles: {}, {points} points; axis map {} ({}{}); dropped {non_finite} non-finite and {no_return} no-return points",
            plural(self.poses.len(), "pose", "poses"),
            self.axes,
            self.axes.describe(),
            if self.axes_guessed {
                ", guessed: the constant coordinate is the plane's normal"
            } else {
                ""
            }
        ) + &pairing::skipped_summary(&self.skipped)
    }
}

/// Reads the profiles of `ids` (in that order) and puts them in the laser
/// plane: the axis map given, or guessed from all of them together.
///
/// # Errors
/// A missing or unreadable profile, a profile with too few points, an axis
/// map that cannot be guessed or puts points off the plane.
pub fn read_profiles(
    source: &ProfileSource,
    format: &ProfileFormat,
    ids: &[String],
    progress: &mut ImportProgress<'_>,
) -> Result<(Vec<PlaneProfile>, ProfileReport), ImportError> {
    if let Some(axes) = format.axes {
        // The map is known: each profile is put in the plane as it is
        // read, one raw profile in memory at a time.
        let mut planes = Vec::with_capacity(ids.len());
        let mut poses = Vec::with_capacity(ids.len());
        pairing::read_by_id(source, format, ids, progress, |id, raw| {
            let (plane, count) = plane_of(&raw, &axes, id)?;
            planes.push(plane);
            poses.push(count);
            Ok(())
        })?;
        return Ok((
            planes,
            ProfileReport {
                axes,
                axes_guessed: false,
                poses,
                skipped: pairing::naming_no_pose(source, ids),
            },
        ));
    }
    let mut raws = Vec::with_capacity(ids.len());
    pairing::read_by_id(source, format, ids, progress, |_, raw| {
        raws.push(raw);
        Ok(())
    })?;
    let (planes, mut report) = planar(raws, format, ids)?;
    report.skipped = pairing::naming_no_pose(source, ids);
    Ok((planes, report))
}

/// Raw profiles in the laser plane, with their report. Each raw profile
/// is dropped as soon as it is converted, so the peak is the raw data
/// plus one converted profile, not both sets.
pub(crate) fn planar(
    raws: Vec<RawProfile>,
    format: &ProfileFormat,
    ids: &[String],
) -> Result<(Vec<PlaneProfile>, ProfileReport), ImportError> {
    let (axes, axes_guessed) = if let Some(m) = format.axes {
        (m, false)
    } else {
        let m = AxisMap::guess(&raws).map_err(|message| {
            // Name the profile that breaks the plane the others share.
            match AxisMap::odd_profile(&raws) {
                Some(k) => ImportError::File {
                    path: raws[k].source.clone(),
                    message: format!(
                        "this profile is not in the plane the other profiles lie in: {message}"
                    ),
                },
                None => ImportError::File {
                    path: raws.first().map_or_else(PathBuf::new, |r| r.source.clone()),
                    message: message.to_string(),
                },
            }
        })?;
        (m, true)
    };
    let mut planes = Vec::with_capacity(raws.len());
    let mut poses = Vec::with_capacity(raws.len());
    for (raw, id) in raws.into_iter().zip(ids) {
        let (plane, count) = plane_of(&raw, &axes, id)?;
        drop(raw);
        planes.push(plane);
        poses.push(count);
    }
    Ok((
        planes,
        ProfileReport {
            axes,
            axes_guessed,
            poses,
            skipped: Vec::new(),
        },
    ))
}

/// One raw profile in the laser plane, with its count; too few points is
/// an error naming the profile file.
fn plane_of(
    raw: &RawProfile,
    axes: &AxisMap,
    id: &str,
) -> Result<(PlaneProfile, ProfileCount), ImportError> {
    let plane = raw.to_plane(axes)?;
    if plane.points.len() < MIN_STRIPE_POINTS {
        return Err(ImportError::File {
            path: raw.source.clone(),
            message: format!(
                "pose {id}: the profile has {} usable points ({} non-finite and {} no-return dropped); a stripe needs at least {MIN_STRIPE_POINTS}",
                plane.points.len(),
                plane.non_finite,
                plane.no_return
            ),
        });
    }
    let count = ProfileCount {
        id: id.to_string(),
        file: raw.source.clone(),
        points: plane.points.len(),
        non_finite: plane.non_finite,
        no_return: plane.no_return,
    };
    Ok((plane, count))
}

/// Refuses a sphere diameter that is not positive or not plausible
/// (the session loader's limit), before any file is read.
///
/// # Errors
/// [`ImportError::Spec`] naming the value and the limit.
pub(crate) fn check_sphere_diameter(d: f64) -> Result<(), ImportError> {
    let limit = crate::engine::base::limits::SPHERE_DIAMETER_MM;
    if d > 0.0 && d <= limit {
        return Ok(());
    }
    Err(ImportError::Spec(format!(
        "--sphere-diameter {} mm is not plausible: a reference sphere is more than 0 and at most {limit} mm",
        crate::engine::base::numeric::show(d)
    )))
}

/// Refuses profiles whose size does not fit the sphere (a unit read
/// wrong), naming the profile unit that would fit
/// ([`units::check_profile_unit`]).
///
/// # Errors
/// [`ImportError::File`] naming the first profile's file.
pub(crate) fn check_profile_size(
    planes: &[PlaneProfile],
    format: &ProfileFormat,
    sphere_diameter: f64,
) -> Result<(), ImportError> {
    let extents: Vec<f64> = planes.iter().map(PlaneProfile::extent).collect();
    units::check_profile_unit(format.unit, sphere_diameter, &extents).map_err(|e| {
        ImportError::File {
            path: planes
                .first()
                .map_or_else(PathBuf::new, |p| p.source.clone()),
            message: e.to_string(),
        }
    })
}

/// Builds the session of a joint log and checks the flange poses, if
/// given. The session is validated by writing it as FORMAT.md JSON and
/// loading it back, so every FORMAT.md rule is enforced with the loader's
/// messages.
///
/// # Errors
/// [`ImportError`] naming the file, the line, the column or the pose id.
pub fn import(spec: &ImportSpec) -> Result<Imported, ImportError> {
    import_with(spec, &mut progress::quiet)
}

/// [`import`], telling `progress` of each profile read and of the check;
/// it may cancel.
///
/// # Errors
/// [`ImportError`] naming the file, the line, the column or the pose id;
/// [`ImportError::Cancelled`].
pub fn import_with(
    spec: &ImportSpec,
    progress: &mut ImportProgress<'_>,
) -> Result<Imported, ImportError> {
    check_sphere_diameter(spec.sphere_diameter)?;
    let robot = load_robot(&spec.robot)?;
    let log = JointLog::read(&spec.joint_log, |f| log::log_columns(spec, f, robot.dof()))?;
    let rows = log.rows(spec.joint_unit)?;
    let ids: Vec<String> = rows.iter().map(|r| r.id.clone()).collect();
    let (planes, report) = read_profiles(&spec.profiles, &spec.profile_format, &ids, progress)?;
    check_profile_size(&planes, &spec.profile_format, spec.sphere_diameter)?;
    let mut measurements = Vec::with_capacity(rows.len());
    let mut checks = Vec::new();
    for (r, plane) in rows.iter().zip(planes) {
        let csv_error = |message: String| ImportError::Csv {
            path: log.file.path.clone(),
            line: r.line,
            message: format!("pose {}: {message}", r.id),
        };
        // The import's log has a use column (log_columns requires it).
        let usage = match (r.usage, log.cols.usage) {
            (Some(u), _) => u,
            (None, c) => {
                let column = c.map_or("use", |c| log.file.header[c].as_str());
                return Err(csv_error(log::usage_message(column, "")));
            }
        };
        let joints: Vec<f64> = r
            .joints
            .iter()
            .map(|&v| spec.joint_unit.to_deg(v))
            .collect();
        if let Some(f) = &spec.flange {
            let pose = f
                .convention
                .pose_from_values(&r.flange)
                .map_err(|m| csv_error(format!("flange pose: {m}")))?;
            checks.push(check::check_pose(
                &robot,
                f,
                spec.joint_unit,
                &r.id,
                &r.joints,
                &pose,
            ));
        }
        measurements.push(Measurement {
            id: r.id.clone(),
            station: r.station.clone().unwrap_or_default(),
            usage,
            side_given: r.side,
            side: r.side.unwrap_or(1),
            joints,
            flange: None,
            observation: Observation::Stripe(plane.points),
        });
    }
    let name = spec.name.clone().unwrap_or_else(|| {
        spec.joint_log
            .file_stem()
            .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned())
    });
    progress::report(progress, ImportStage::Checking)?;
    let session = new_session(
        name,
        Some(robot),
        spec.sphere_diameter,
        None,
        spec.references.as_deref(),
        measurements,
    )?;
    let lines: HashMap<&str, usize> = rows.iter().map(|r| (r.id.as_str(), r.line)).collect();
    let session = recheck(
        session,
        &Sources {
            log: &spec.joint_log,
            lines: &lines,
            profiles: &report,
            references: spec.references.as_deref(),
        },
    )?;
    let mut notes = vec![report.summary()];
    notes.extend(units::joint_unit_warning(
        spec.joint_unit,
        session
            .measurements
            .iter()
            .flat_map(|m| m.joints.iter().copied()),
    ));
    Ok(Imported {
        session,
        checks,
        profiles: report,
        notes,
    })
}

/// Where an imported session's data came from, so that a rule the
/// session breaks is blamed on the file the user can fix.
pub(crate) struct Sources<'a> {
    /// The pose log.
    pub log: &'a Path,
    /// Line of each pose id in the log.
    pub lines: &'a HashMap<&'a str, usize>,
    /// Each pose's profile file.
    pub profiles: &'a ProfileReport,
    /// The reference distances file, if any.
    pub references: Option<&'a Path>,
}

/// The session checked by every FORMAT.md rule ([`Session::validate`],
/// the rules the file loader applies too); a broken rule is blamed on its
/// source by its measurement and key: a stripe's on the pose's profile
/// file, a pose's other data on its log line, a reference distance on its
/// row of the references file, the rest on the log.
///
/// # Errors
/// The rule's message, placed in the file it came from.
pub(crate) fn recheck(session: Session, sources: &Sources) -> Result<Session, ImportError> {
    let e = match session.validate() {
        Ok(()) => return Ok(session),
        Err(e) => e,
    };
    let key = e.key.as_deref().unwrap_or("");
    if let Some(id) = &e.measurement {
        let profile = sources.profiles.poses.iter().find(|p| p.id == *id);
        if let Some(p) = profile.filter(|_| key.starts_with("stripe")) {
            return Err(ImportError::File {
                path: p.file.clone(),
                message: format!("pose {id}: {}", e.message),
            });
        }
        if let Some(&line) = sources.lines.get(id.as_str()) {
            return Err(ImportError::Csv {
                path: sources.log.to_path_buf(),
                line,
                message: format!("pose {id}: {}", e.message),
            });
        }
    }
    if let Some(path) = sources.references
        && let Some(index) = reference_index(key)
    {
        let line = reference_rows(path)
            .ok()
            .and_then(|rows| rows.get(index).map(|(line, _)| *line));
        return Err(match line {
            Some(line) => ImportError::Csv {
                path: path.to_path_buf(),
                line,
                message: e.message,
            },
            None => ImportError::File {
                path: path.to_path_buf(),
                message: e.message,
            },
        });
    }
    Err(ImportError::File {
        path: sources.log.to_path_buf(),
        message: e.to_string(),
    })
}

/// `i` of a key `reference_distances[i]`.
fn reference_index(key: &str) -> Option<usize> {
    key.strip_prefix("reference_distances[")?
        .split(']')
        .next()?
        .parse()
        .ok()
}

/// A session built by an import: `name` given, the robot (none for a
/// pose-only log without one), the sphere, `side` as `sensor.side` when
/// the import decided it, the reference distances of `references`, and
/// default solver settings.
pub(crate) fn new_session(
    name: String,
    robot: Option<Robot>,
    sphere_diameter: f64,
    side: Option<i8>,
    references: Option<&Path>,
    measurements: Vec<Measurement>,
) -> Result<Session, ImportError> {
    let robot_given = robot.is_some();
    let robot = robot.unwrap_or_else(|| Robot::new(String::new(), Vec::new()));
    Ok(Session {
        robot_given,
        default_side: side.unwrap_or(1),
        sensor_given: side.is_some(),
        reference_distances: match references {
            Some(path) => read_references(path)?,
            None => Vec::new(),
        },
        ..Session::made(name, robot, sphere_diameter, measurements)
    })
}

/// The JSON value of a file's text (a UTF-8 byte-order mark allowed), or
/// the syntax error at its line.
pub(crate) fn json_value(text: &str, path: &Path) -> Result<serde_json::Value, ImportError> {
    serde_json::from_str(text.trim_start_matches('\u{feff}')).map_err(|e| ImportError::Csv {
        path: path.to_path_buf(),
        line: e.line(),
        message: format!("not valid JSON: {e}"),
    })
}
