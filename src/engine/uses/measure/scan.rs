//! What is measured: a [`Scan`], one [`ScanPose`] a robot pose (joint
//! readings or the controller's flange pose) with the profile points the
//! sensor saw there, `[y, z]` in the laser plane (mm, sensor frame).
//!
//! Two doors lead in:
//!
//! - [`Scan::from_session`]: a session's stripes as they are (every point
//!   of every stripe; the measurements chosen by their `use`). A
//!   measurement that gives a sphere centre has no profile and is skipped
//!   (listed in [`Scan::skipped`]).
//! - [`scan_from_files`]: a raw scan, the import's pose log and profile
//!   files. A part has no sphere: no segmentation, no sphere-size check,
//!   every valid point kept; NaN and no-return points are dropped and
//!   counted per pose ([`Dropped`]). This is the one function that reads
//!   raw scan files, so that a change of the pose-log readers touches it
//!   alone.

use std::path::{Path, PathBuf};

use nalgebra::Isometry3;

use crate::engine::base::limits;
use crate::engine::base::numeric::approx;
use crate::engine::base::robot::Robot;
use crate::engine::base::session::{Observation, ReferenceDistance, Session, Use};
use crate::engine::files::import::log::JointLog;
use crate::engine::files::import::pairing;
use crate::engine::files::import::poses::PoseValue;
use crate::engine::files::import::profiles::{PlaneProfile, RawProfile};
use crate::engine::files::import::progress;
use crate::engine::files::import::units::AngleUnit;
use crate::engine::files::import::units::LengthUnit;
use crate::engine::files::import::{
    AxisMap, FlangeConvention, ImportError, PoseFormat, ProfileFormat, ProfileSource,
    read_references,
};

/// Where the robot was: what the model needs to place the sensor.
#[derive(Debug, Clone, PartialEq)]
pub enum Placement {
    /// Joint readings, deg, one per robot joint: the flange pose is the
    /// model's forward kinematics.
    Joints(Vec<f64>),
    /// The flange pose `base_from_flange` the controller reported (mm): the
    /// kinematic model is not used.
    Flange(Isometry3<f64>),
}

/// Profile points dropped from one pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Dropped {
    /// Points with a NaN or infinite coordinate.
    pub non_finite: usize,
    /// Points with the sensor's no-return value.
    pub no_return: usize,
}

/// One pose of a scan.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanPose {
    /// The measurement or pose id.
    pub id: String,
    /// The sphere station it saw (sessions; a raw scan's log `station`
    /// column), if any.
    pub station: Option<String>,
    /// Its `use` (sessions; a raw scan's log `use` column), if any.
    pub usage: Option<Use>,
    /// Where the robot was.
    pub placement: Placement,
    /// Profile points `[y, z]`, mm, laser plane `x = 0` of the sensor frame.
    pub points: Vec<[f64; 2]>,
    /// Points dropped while reading.
    pub dropped: Dropped,
}

/// A scan: poses with their profiles, and what the input says about the
/// cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    /// Session name, or the pose log's file name.
    pub name: String,
    /// The nominal robot the input names (a session's `robot`, a raw
    /// scan's `--robot`), to check against the result's.
    pub robot: Option<Robot>,
    /// Diameter of the sphere the scan saw, mm (a session's sphere; for a
    /// raw scan of a sphere artefact, as given).
    pub sphere_diameter: Option<f64>,
    /// Reference distances between stations (mm).
    pub reference_distances: Vec<ReferenceDistance>,
    /// The poses, in input order.
    pub poses: Vec<ScanPose>,
    /// Ids of measurements left out because they have no profile (a
    /// session's given centres).
    pub skipped: Vec<String>,
    /// How the input was read, in words (axis map, units).
    pub notes: Vec<String>,
}

impl Scan {
    /// A session's measurements whose `use` is in `uses` (all of them when
    /// `uses` is empty), every stripe point as it is. Consumes the session
    /// (the points move, they are not copied).
    #[must_use]
    pub fn from_session(session: Session, uses: &[Use]) -> Self {
        let robot = session.robot_given.then(|| session.robot.clone());
        let mut poses = Vec::with_capacity(session.measurements.len());
        let mut skipped = Vec::new();
        for m in session.measurements {
            if !uses.is_empty() && !uses.contains(&m.usage) {
                continue;
            }
            let points = match m.observation {
                Observation::Stripe(points) => points,
                Observation::Centre(_) => {
                    skipped.push(m.id);
                    continue;
                }
            };
            let placement = match m.flange {
                Some(pose) => Placement::Flange(pose),
                None => Placement::Joints(m.joints),
            };
            poses.push(ScanPose {
                id: m.id,
                station: Some(m.station),
                usage: Some(m.usage),
                placement,
                points,
                dropped: Dropped::default(),
            });
        }
        Self {
            name: session.name,
            robot,
            sphere_diameter: Some(session.sphere_diameter),
            reference_distances: session.reference_distances,
            poses,
            skipped,
            notes: Vec::new(),
        }
    }

    /// Points in all poses.
    #[must_use]
    pub fn point_count(&self) -> usize {
        self.poses.iter().map(|p| p.points.len()).sum()
    }

    /// Points dropped in all poses.
    #[must_use]
    pub fn dropped(&self) -> Dropped {
        self.poses.iter().fold(Dropped::default(), |a, p| Dropped {
            non_finite: a.non_finite + p.dropped.non_finite,
            no_return: a.no_return + p.dropped.no_return,
        })
    }
}

/// The columns of a raw scan's joint log.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScanColumns {
    /// The pose id (required).
    pub id: String,
    /// The joint columns, joint 1 first.
    pub joints: Vec<String>,
    /// A station column, read when present (a sphere artefact's place).
    pub station: String,
    /// A `use` column, read when present.
    pub usage: String,
}

impl ScanColumns {
    /// `id`, `j1..jn`, `station`, `use`.
    #[must_use]
    pub fn new(dof: usize) -> Self {
        Self {
            id: "id".into(),
            joints: (1..=dof).map(|k| format!("j{k}")).collect(),
            station: "station".into(),
            usage: "use".into(),
        }
    }
}

/// The pose log of a raw scan.
#[derive(Debug, Clone, PartialEq)]
pub enum ScanLog {
    /// A joint log CSV: one row a pose.
    Joints {
        /// The file.
        path: PathBuf,
        /// Its columns.
        columns: ScanColumns,
        /// Unit of the joint columns.
        unit: AngleUnit,
    },
    /// A pose file (a table, a JSON list or a robot program), the
    /// import's reader ([`crate::engine::files::program`]).
    Poses {
        /// The file.
        path: PathBuf,
        /// Its layout; `None`: detected from the content.
        format: Option<PoseFormat>,
        /// How a table or JSON list writes a pose (a program fixes its own).
        convention: Option<FlangeConvention>,
        /// The pose columns of a table; `None`: the convention's.
        columns: Option<Vec<String>>,
    },
}

impl ScanLog {
    /// The log file.
    #[must_use]
    pub fn path(&self) -> &Path {
        match self {
            Self::Joints { path, .. } | Self::Poses { path, .. } => path,
        }
    }
}

/// Everything a raw scan is read from.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanFiles {
    /// The pose log.
    pub log: ScanLog,
    /// The profiles: a folder (`<id>.<ext>`, or for a log without ids every
    /// profile file in natural order) or one CSV with a pose column.
    pub profiles: ProfileSource,
    /// How to read them: unit, axis map (guessed when `None`), no-return
    /// value, key of OpenCV files.
    pub profile_format: ProfileFormat,
    /// The nominal robot the scan was taken with, to check against the
    /// result's (optional).
    pub robot: Option<Robot>,
    /// Diameter of the spheres of a sphere artefact, mm, for the
    /// self-validation (optional).
    pub sphere_diameter: Option<f64>,
    /// Reference distances between the artefact's stations (`from,to,distance`
    /// CSV, mm), optional.
    pub references: Option<PathBuf>,
    /// The poses measured: those whose `use` (the log's use column) is
    /// one of these; empty: every pose.
    pub uses: Vec<Use>,
}

/// One pose of a log before its profile: id, station, use, placement.
struct LogPose {
    id: Option<String>,
    station: Option<String>,
    usage: Option<Use>,
    placement: Placement,
}

/// A raw scan from its files (module doc): the pose log read by the
/// import's readers, each pose paired with its profile, the profiles put
/// in the laser plane by the axis map (given, or guessed from all of
/// them). No point is dropped but NaN, infinite and no-return ones.
///
/// # Errors
/// [`ImportError`] naming the file and the line or pose: an unreadable
/// log or profile, a missing column, a reading that is not a number, a
/// pose without a profile, an axis map that puts points off the plane.
pub fn scan_from_files(spec: &ScanFiles) -> Result<Scan, ImportError> {
    let mut notes = Vec::new();
    let log = match &spec.log {
        ScanLog::Joints {
            path,
            columns,
            unit,
        } => joint_log(path, columns, *unit)?,
        ScanLog::Poses {
            path,
            format,
            convention,
            columns,
        } => {
            let (records, read_notes) = crate::engine::files::import::poses::read_pose_log(
                path,
                *format,
                *convention,
                columns.as_deref(),
            )?;
            notes.extend(read_notes);
            records
                .into_iter()
                .map(|r| LogPose {
                    id: r.id,
                    station: r.station,
                    usage: r.usage,
                    placement: match r.value {
                        PoseValue::Flange(pose) => Placement::Flange(pose),
                        PoseValue::Joints(q) => Placement::Joints(q),
                    },
                })
                .collect()
        }
    };
    let (ids, raws) = pair_profiles(spec, &log, &mut notes)?;
    let (axes, guessed) = match spec.profile_format.axes {
        Some(m) => (m, false),
        None => (
            AxisMap::guess(&raws).map_err(|e| ImportError::File {
                path: raws.first().map_or_else(PathBuf::new, |r| r.source.clone()),
                message: e.to_string(),
            })?,
            true,
        ),
    };
    let mut poses = Vec::with_capacity(log.len());
    for ((pose, id), raw) in log.into_iter().zip(ids).zip(raws) {
        let plane = raw.to_plane(&axes)?;
        within_sensor_field(&plane, spec.profile_format.unit)?;
        drop(raw);
        poses.push(ScanPose {
            id,
            station: pose.station,
            usage: pose.usage,
            placement: pose.placement,
            points: plane.points,
            dropped: Dropped {
                non_finite: plane.non_finite,
                no_return: plane.no_return,
            },
        });
    }
    if !spec.uses.is_empty() {
        if let Some(p) = poses.iter().find(|p| p.usage.is_none()) {
            return Err(ImportError::File {
                path: spec.log.path().to_path_buf(),
                message: format!(
                    "pose {} has no use: choosing poses by their use needs a use column in the log (or measure every pose)",
                    p.id
                ),
            });
        }
        poses.retain(|p| p.usage.is_some_and(|u| spec.uses.contains(&u)));
        if poses.is_empty() {
            return Err(ImportError::File {
                path: spec.log.path().to_path_buf(),
                message: format!(
                    "no pose of the log is of use {}",
                    spec.uses
                        .iter()
                        .map(|u| u.as_str())
                        .collect::<Vec<_>>()
                        .join(" or ")
                ),
            });
        }
    }
    let name = spec
        .log
        .path()
        .file_name()
        .map_or_else(|| "scan".to_string(), |n| n.to_string_lossy().into_owned());
    Ok(Scan {
        name,
        robot: spec.robot.clone(),
        sphere_diameter: spec.sphere_diameter,
        reference_distances: match &spec.references {
            Some(path) => read_references(path)?,
            None => Vec::new(),
        },
        poses,
        skipped: Vec::new(),
        notes: {
            notes.push(format!(
                "profiles: axis map {axes} ({}{})",
                axes.describe(),
                if guessed {
                    ", guessed: the constant coordinate is the plane's normal"
                } else {
                    ""
                }
            ));
            notes
        },
    })
}

/// Refuses a profile with a point beyond any sensor's field
/// ([`limits::SENSOR_COORDINATE_MM`], the session's rule for stripe
/// points): a unit read wrong (millimetres as metres puts a part tens of
/// metres off), naming the file, the point and the unit it was read in.
fn within_sensor_field(plane: &PlaneProfile, unit: LengthUnit) -> Result<(), ImportError> {
    let limit = limits::SENSOR_COORDINATE_MM;
    match plane
        .points
        .iter()
        .position(|p| p[0].abs() > limit || p[1].abs() > limit)
    {
        None => Ok(()),
        Some(i) => Err(ImportError::File {
            path: plane.source.clone(),
            message: format!(
                "point {}: (y, z) = ({}, {}) mm, read in {}, lies beyond any sensor's field (at most {} mm from the sensor): check --profile-unit",
                i + 1,
                approx(plane.points[i][0]),
                approx(plane.points[i][1]),
                unit.symbol(),
                approx(limit)
            ),
        }),
    }
}

/// The poses of a raw scan's joint log, read by the import's joint-log
/// reader ([`JointLog`]): `id` and the joint columns required, `station`
/// and `use` read when the log has them.
fn joint_log(
    path: &Path,
    columns: &ScanColumns,
    unit: AngleUnit,
) -> Result<Vec<LogPose>, ImportError> {
    let log = JointLog::read_scan(
        path,
        &columns.id,
        &columns.joints,
        &columns.station,
        &columns.usage,
    )?;
    Ok(log
        .rows(unit)?
        .into_iter()
        .map(|r| LogPose {
            id: Some(r.id),
            station: r.station,
            usage: r.usage,
            placement: Placement::Joints(r.joints.iter().map(|&v| unit.to_deg(v)).collect()),
        })
        .collect())
}

/// Each pose's raw profile and id, by the import's pairing
/// ([`pairing`]): by id (`<id>.<ext>` in the folder, or the id's rows of
/// one table) when the log's ids name the profiles, else pose `k` with the
/// `k`-th profile file in the order of their numbers (ids from the file
/// names).
fn pair_profiles(
    spec: &ScanFiles,
    log: &[LogPose],
    notes: &mut Vec<String>,
) -> Result<(Vec<String>, Vec<RawProfile>), ImportError> {
    let quiet = &mut progress::quiet;
    if let Some(ids) =
        pairing::ids_naming_profiles(&spec.profiles, log.iter().map(|p| p.id.as_deref()))
    {
        let mut raws = Vec::with_capacity(ids.len());
        pairing::read_by_id(
            &spec.profiles,
            &spec.profile_format,
            &ids,
            quiet,
            |_, raw| {
                raws.push(raw);
                Ok(())
            },
        )?;
        return Ok((ids, raws));
    }
    let order = pairing::read_in_order(
        &spec.profiles,
        &spec.profile_format,
        spec.log.path(),
        log.len(),
        quiet,
    )?;
    // The folder as published: the pose file and other files skipped,
    // the profiles in the order of their number.
    notes.extend(order.listing.as_ref().map(pairing::FolderListing::summary));
    Ok((order.ids, order.raws))
}
