//! Pose files as cells write them, plus one observation a pose (a stripe
//! profile or a sphere centre), become a session.
//!
//! # Pose files
//!
//! Read by [`crate::engine::files::program`], the layout detected from the
//! content: pose tables with or without a header (any separator), JSON
//! lists (RobCalibrator's `.rob`), FANUC `.ls`, ABB RAPID, KUKA
//! `.dat`/`.src`, URScript. Cartesian targets give a **pose-only**
//! session (FORMAT.md "Additions to version 1": `measurements[].flange`),
//! which calibrates the hand-eye and the station centres; joint targets
//! (a RAPID `jointtarget`, FANUC `J1=…` positions, URScript joint lists)
//! give a session with joints, which needs the nominal robot (`robot`).
//!
//! # Observations
//!
//! - Profiles: a folder ([`super::pairing`]: the pose file and other
//!   files in it skipped and listed, the profiles in the order of the
//!   number in their names, pose `k` paired with profile `k`; or
//!   `<id>.<ext>` when the log has ids), or one CSV with a pose column.
//! - Centres ([`Observations::Centres`]): a table of sphere centres the
//!   sensor reported, one `x y z` a pose (sensor frame, mm), giving
//!   `centre` measurements.
//!
//! # What the import decides, and says
//!
//! - **Stations**: the table's `station` column, else one station `S1`.
//! - **Uses and the initial hand-eye** ([`initial`](crate::engine::assemble::initial)): the table's
//!   `use` column, else every pose `identify` with an initial hand-eye
//!   written into the session: the one given (`hand_eye`), else the
//!   paper's eq. 6-9 when the poses hold a group of one orientation, else
//!   the general solution of [`crate::engine::calibrate::handeye::general`]; both
//!   are printed when both can be had.
//! - **Side**: the table's `side` column, or the side given; with
//!   [`SideChoice::Auto`], [`decide_side`](crate::engine::assemble::decide_side) (a step of its
//!   own, run by the caller) calibrates both and keeps the clearly better.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Vector3};

use super::pairing::{self, FolderListing};
use super::profiles::{AxisMap, PlaneProfile, ProfileFormat, ProfileSource};
use super::progress::{self, ImportProgress};
use super::{FlangeConvention, ImportError, ProfileReport, RobotSource, load_robot};
use crate::engine::base::limits;
use crate::engine::base::robot::Robot;
use crate::engine::base::session::{Observation, Use, rules};
use crate::engine::files::program::{
    self, PoseFile, PoseFormat, ProgramError, ReadSpec, TargetValue, read_number_table,
};

/// The station of a log without a `station` column.
pub const DEFAULT_STATION: &str = "S1";

/// On which side of the laser plane the sphere centres lie.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SideChoice {
    /// `x > 0` in the sensor frame (FORMAT.md `side` +1).
    Plus,
    /// `x < 0` (side −1).
    Minus,
    /// Decided from the data: both are calibrated, the clearly better
    /// one is chosen ([`decide_side`](crate::engine::assemble::decide_side)).
    Auto,
}

impl SideChoice {
    /// Parses `+1`/`1`/`plus`, `-1`/`minus` or `auto`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "+1" | "1" | "plus" => Some(Self::Plus),
            "-1" | "minus" => Some(Self::Minus),
            "auto" => Some(Self::Auto),
            _ => None,
        }
    }
}

/// What the sensor gave for each pose.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Observations {
    /// Stripe profiles.
    Profiles(ProfileSource),
    /// A table of sphere centres, one `x y z` a pose (sensor frame, mm),
    /// header optional (columns `x`, `y`, `z`, optionally `id`).
    Centres(PathBuf),
}

/// Everything the import of a pose file needs.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseImportSpec {
    /// The pose file.
    pub poses: PathBuf,
    /// Its layout; `None`: detected from the content.
    pub format: Option<PoseFormat>,
    /// How a table's or JSON list's numbers make a pose (a program's
    /// language fixes its own; given, it must agree).
    pub convention: Option<FlangeConvention>,
    /// A table's pose columns, in the convention's order; `None`: the
    /// convention's default names, or the columns in order without a
    /// header.
    pub pose_columns: Option<Vec<String>>,
    /// The sensor's observations.
    pub observations: Observations,
    /// How to read profiles.
    pub profile_format: ProfileFormat,
    /// The nominal robot: needed for joint targets; kept in a pose-only
    /// session otherwise.
    pub robot: Option<RobotSource>,
    /// Sphere diameter, mm.
    pub sphere_diameter: f64,
    /// Side of the sphere centres when the log has no `side` column.
    pub side: SideChoice,
    /// A guess of the hand-eye `eT_s` to start from instead of computing
    /// one (written into the session).
    pub hand_eye: Option<Isometry3<f64>>,
    /// Session name; `None` gives the pose file's stem.
    pub name: Option<String>,
    /// Optional reference distances between validate stations.
    pub references: Option<PathBuf>,
}

/// Where a pose was, as the pose file gave it.
#[derive(Debug, Clone, PartialEq)]
pub enum PoseValue {
    /// The flange pose `bT_e` (mm).
    Flange(Isometry3<f64>),
    /// Joint readings, deg.
    Joints(Vec<f64>),
}

/// One pose of the file, in the order the robot went to them.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseRecord {
    /// Its name in the file (`P[3]`, `p10`, `line 4`).
    pub name: String,
    /// Its id, when the table has an id column.
    pub id: Option<String>,
    /// Its station, when the table has a station column.
    pub station: Option<String>,
    /// Its use, when the table has a use column.
    pub usage: Option<Use>,
    /// Its side, when the table has a side column with a value.
    pub side: Option<i8>,
    /// The pose.
    pub value: PoseValue,
    /// 1-based line in the pose file.
    pub line: usize,
}

/// The pose file and the observations, read and paired: everything a
/// session is built from, with no decision taken yet.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseInputs {
    /// The poses, in order.
    pub records: Vec<PoseRecord>,
    /// Measurement ids, one a pose.
    pub ids: Vec<String>,
    /// One observation a pose.
    pub observations: Vec<Observation>,
    /// How the profiles were read (empty for centres).
    pub report: ProfileReport,
    /// The nominal robot, when given.
    pub robot: Option<Robot>,
    /// What was read and how, in words.
    pub notes: Vec<String>,
}

impl PoseInputs {
    /// Whether the poses are joint readings.
    #[must_use]
    pub fn joints(&self) -> bool {
        self.records
            .iter()
            .any(|r| matches!(r.value, PoseValue::Joints(_)))
    }

    /// Whether every pose has its side from the file.
    #[must_use]
    pub fn all_sides_given(&self) -> bool {
        self.records.iter().all(|r| r.side.is_some())
    }

    /// Whether the sensor gave centres (no side to decide).
    #[must_use]
    pub fn centres(&self) -> bool {
        self.observations
            .iter()
            .all(|o| matches!(o, Observation::Centre(_)))
    }
}

/// A pose file error as an import error, naming the file and the line.
pub(crate) fn program_error(e: ProgramError) -> ImportError {
    if e.line == 0 {
        ImportError::File {
            path: e.path,
            message: e.message,
        }
    } else {
        ImportError::Csv {
            path: e.path,
            line: e.line,
            message: e.message,
        }
    }
}

/// Reads a pose file: its layout detected (or forced) and printed, its
/// targets in the order the robot went to them.
///
/// # Errors
/// An unreadable file, an unknown layout, a target that is not a pose
/// (naming the line), targets that mix joints and Cartesian poses.
pub fn read_pose_log(
    path: &Path,
    format: Option<PoseFormat>,
    convention: Option<FlangeConvention>,
    columns: Option<&[String]>,
) -> Result<(Vec<PoseRecord>, Vec<String>), ImportError> {
    let file: PoseFile = program::read_pose_file(
        path,
        &ReadSpec {
            format,
            convention,
            columns: columns.map(<[String]>::to_vec),
        },
    )
    .map_err(program_error)?;
    let records = records_of(&file)?;
    let mut notes = vec![format!(
        "pose file: {} ({}); {}",
        file.format.describe(),
        if file.detected {
            "detected from its content; --pose-format forces another"
        } else {
            "as given by --pose-format"
        },
        file.order_note
    )];
    notes.extend(file.warnings.iter().map(|w| format!("warning: {w}")));
    Ok((records, notes))
}

/// The targets of a pose file as records, in the order the robot went to
/// them.
///
/// # Errors
/// A target that is not a pose (naming the line), targets that mix joints
/// and Cartesian poses.
pub fn records_of(file: &PoseFile) -> Result<Vec<PoseRecord>, ImportError> {
    let path = file.path.as_path();
    let mut records = Vec::with_capacity(file.order.len());
    let (mut poses, mut joints) = (0, 0);
    for t in file.ordered() {
        let fail = |message: String| ImportError::Csv {
            path: path.to_path_buf(),
            line: t.line,
            message: format!("{}: {message}", t.name),
        };
        let value = match &t.value {
            TargetValue::Pose { values, convention } => {
                poses += 1;
                let pose = convention
                    .pose_from_values(values)
                    .map_err(|m| fail(format!("{m} ({})", convention.describe())))?;
                for (axis, v) in ["x", "y", "z"].iter().zip(pose.translation.vector.iter()) {
                    rules::plausible(*v, limits::LENGTH_MM, &format!("flange {axis}"), "mm")
                        .map_err(|m| fail(format!("{m}; read as {}", convention.describe())))?;
                }
                PoseValue::Flange(pose)
            }
            TargetValue::Joints { deg, .. } => {
                joints += 1;
                if deg.iter().any(|v| !v.is_finite()) {
                    return Err(fail("a joint value is not a finite number".to_string()));
                }
                for (k, v) in deg.iter().enumerate() {
                    rules::plausible(*v, limits::ANGLE_DEG, &format!("joint {}", k + 1), "deg")
                        .map_err(|m| fail(m.to_string()))?;
                }
                PoseValue::Joints(deg.clone())
            }
        };
        records.push(PoseRecord {
            name: t.name.clone(),
            id: t.id.clone(),
            station: t.station.clone(),
            usage: t.usage,
            side: t.side,
            value,
            line: t.line,
        });
    }
    if poses > 0 && joints > 0 {
        return Err(ImportError::File {
            path: path.to_path_buf(),
            message: format!(
                "the file mixes {poses} Cartesian poses and {joints} joint targets: a session takes one kind"
            ),
        });
    }
    Ok(records)
}

/// A measurement id for a record without one: `pose<k>` for a table row
/// or list entry, else its name without brackets or spaces (`P[3]` → `P3`).
pub(crate) fn record_id(record: &PoseRecord, ordinal: usize) -> String {
    if record.name.starts_with("line ") || record.name.starts_with("pose ") {
        return format!("pose{ordinal}");
    }
    let id: String = record
        .name
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
        .collect();
    if id.is_empty() {
        format!("pose{ordinal}")
    } else {
        id
    }
}

/// The file name of a path, for messages.
fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// Reads the pose file and the observations and pairs them: every input
/// read once, nothing decided yet.
///
/// # Errors
/// [`ImportError`] naming the file and the line, pose or key: unreadable
/// files, poses that are not rigid transforms, missing or unusable
/// profiles, counts of poses and profiles that differ (both named).
pub fn read_pose_inputs(spec: &PoseImportSpec) -> Result<PoseInputs, ImportError> {
    read_pose_inputs_with(spec, &mut progress::quiet)
}

/// [`read_pose_inputs`], telling `progress` of each profile read; it may
/// cancel.
///
/// # Errors
/// As [`read_pose_inputs`]; [`ImportError::Cancelled`].
pub fn read_pose_inputs_with(
    spec: &PoseImportSpec,
    progress: &mut ImportProgress<'_>,
) -> Result<PoseInputs, ImportError> {
    super::check_sphere_diameter(spec.sphere_diameter)?;
    let (records, mut notes) = read_pose_log(
        &spec.poses,
        spec.format,
        spec.convention,
        spec.pose_columns.as_deref(),
    )?;
    let robot = spec.robot.as_ref().map(load_robot).transpose()?;
    if let Some(r) = records.iter().find_map(|r| match &r.value {
        PoseValue::Joints(q) => Some((r, q.len())),
        PoseValue::Flange(_) => None,
    }) {
        let Some(robot) = &robot else {
            return Err(ImportError::Spec(format!(
                "{} holds joint targets ({} at line {}): give the nominal robot (--robot) to place them",
                spec.poses.display(),
                r.0.name,
                r.0.line
            )));
        };
        if r.1 != robot.dof() {
            return Err(ImportError::Csv {
                path: spec.poses.clone(),
                line: r.0.line,
                message: format!(
                    "{}: {} joint values, the robot {} has {} joints",
                    r.0.name,
                    r.1,
                    robot.name,
                    robot.dof()
                ),
            });
        }
    }
    let (ids, observations, report) = match &spec.observations {
        Observations::Centres(path) => {
            let (ids, centres) = read_centres(path, &records, &spec.poses)?;
            notes.push(format!(
                "sphere centres from {} (sensor frame, mm): {} poses, paired in order",
                path.display(),
                centres.len()
            ));
            (
                ids,
                centres.into_iter().map(Observation::Centre).collect(),
                ProfileReport {
                    axes: AxisMap::IDENTITY,
                    axes_guessed: false,
                    poses: Vec::new(),
                    skipped: Vec::new(),
                },
            )
        }
        Observations::Profiles(source) => {
            let (ids, planes, report, pairing) = pair_profiles(spec, source, &records, progress)?;
            super::check_profile_size(&planes, &spec.profile_format, spec.sphere_diameter)?;
            notes.extend(pairing);
            notes.push(report.summary());
            (
                ids,
                planes
                    .into_iter()
                    .map(|p| Observation::Stripe(p.points))
                    .collect(),
                report,
            )
        }
    };
    Ok(PoseInputs {
        records,
        ids,
        observations,
        report,
        robot,
        notes,
    })
}

/// The rows of a centres table: `x y z` (sensor frame, mm), a header
/// and an `id` column optional.
///
/// # Errors
/// The table cannot be read (naming the line).
pub fn centre_rows(path: &Path) -> Result<Vec<program::Row>, ImportError> {
    let names: Vec<String> = ["x", "y", "z"].iter().map(|s| (*s).to_string()).collect();
    read_number_table(
        path,
        &names,
        false,
        "x, y, z (sensor frame, mm)",
        "give the table a header (`id,x,y,z` or `x,y,z,extra`)",
    )
    .map_err(program_error)
}

/// The centres of a centres table, paired with the records: by id when
/// both have ids, else in order (the counts must match).
fn read_centres(
    path: &Path,
    records: &[PoseRecord],
    poses: &Path,
) -> Result<(Vec<String>, Vec<Vector3<f64>>), ImportError> {
    let rows = centre_rows(path)?;
    for row in &rows {
        let c = Vector3::new(row.values[0], row.values[1], row.values[2]);
        rules::centre("the centre (x, y, z)", &c).map_err(|e| ImportError::Csv {
            path: path.to_path_buf(),
            line: row.line,
            message: e.to_string(),
        })?;
    }
    let record_ids: Vec<Option<&String>> = records.iter().map(|r| r.id.as_ref()).collect();
    let by_id = rows.iter().all(|r| r.id.is_some()) && record_ids.iter().all(Option::is_some);
    let mut out = Vec::with_capacity(records.len());
    let mut ids = Vec::with_capacity(records.len());
    if by_id {
        let index: HashMap<&str, &program::Row> = rows
            .iter()
            .filter_map(|r| r.id.as_deref().map(|i| (i, r)))
            .collect();
        for r in records {
            let id = r.id.clone().unwrap_or_default();
            let row = index.get(id.as_str()).ok_or_else(|| ImportError::File {
                path: path.to_path_buf(),
                message: format!("no centre for pose `{id}` of {}", poses.display()),
            })?;
            out.push(Vector3::new(row.values[0], row.values[1], row.values[2]));
            ids.push(id);
        }
    } else {
        if rows.len() != records.len() {
            return Err(ImportError::File {
                path: path.to_path_buf(),
                message: format!(
                    "{} centres for {} poses of {}: without ids on both sides, pose k takes the k-th centre, so the counts must match",
                    rows.len(),
                    records.len(),
                    poses.display()
                ),
            });
        }
        for (k, (row, r)) in rows.iter().zip(records).enumerate() {
            out.push(Vector3::new(row.values[0], row.values[1], row.values[2]));
            ids.push(
                r.id.clone()
                    .or_else(|| row.id.clone())
                    .unwrap_or_else(|| record_id(r, k + 1)),
            );
        }
    }
    Ok((ids, out))
}

/// Pose ids, their profiles in the laser plane, how they were read, and
/// the pairing in words.
type Paired = (Vec<String>, Vec<PlaneProfile>, ProfileReport, Vec<String>);

/// The pose ids, when the profiles are paired by them
/// ([`pairing::ids_naming_profiles`]); `None`: pose `k` goes with the
/// `k`-th profile.
#[must_use]
pub fn paired_by_id(source: &ProfileSource, records: &[PoseRecord]) -> Option<Vec<String>> {
    pairing::ids_naming_profiles(source, records.iter().map(|r| r.id.as_deref()))
}

/// Whether a pose's own number (`P[3]` → 3) differs from its profile's
/// (`p4.yml` → 4) anywhere in the pairing: the order may be wrong. A
/// table row or list entry (`line 4`, `pose 2`) has no number of its own.
#[must_use]
pub fn numbers_differ(records: &[PoseRecord], listing: &FolderListing) -> bool {
    records.iter().zip(&listing.numbers).any(|(r, n)| {
        let unnamed = r.name.starts_with("line ") || r.name.starts_with("pose ");
        let pose_number = (!unnamed)
            .then(|| crate::engine::files::program::number_in(&r.name))
            .flatten();
        pose_number.is_some() && n.is_some() && pose_number != *n
    })
}

/// Pose ids and their profiles, and the pairing in words: by id when the
/// log has ids that name profile files, else pose `k` with the `k`-th
/// profile in the order of their numbers.
fn pair_profiles(
    spec: &PoseImportSpec,
    source: &ProfileSource,
    records: &[PoseRecord],
    progress: &mut ImportProgress<'_>,
) -> Result<Paired, ImportError> {
    if let Some(ids) = paired_by_id(source, records) {
        let mut first: HashMap<&str, usize> = HashMap::new();
        for (r, id) in records.iter().zip(&ids) {
            if let Some(line) = first.insert(id, r.line) {
                return Err(ImportError::Csv {
                    path: spec.poses.clone(),
                    line: r.line,
                    message: format!("pose id `{id}` is used twice (first at line {line})"),
                });
            }
        }
        let (planes, report) = super::read_profiles(source, &spec.profile_format, &ids, progress)?;
        return Ok((
            ids,
            planes,
            report,
            vec!["profiles paired by pose id".to_string()],
        ));
    }
    let pairing::InOrder { ids, raws, listing } = pairing::read_in_order(
        source,
        &spec.profile_format,
        &spec.poses,
        records.len(),
        progress,
    )?;
    let mut notes = Vec::new();
    if let Some(listing) = &listing {
        notes.push(listing.summary());
        notes.push(pairing_note(records, listing));
    }
    let (planes, report) = super::planar(raws, &spec.profile_format, &ids)?;
    Ok((ids, planes, report, notes))
}

/// The warning of a pairing whose pose and profile numbers differ.
pub const NUMBERS_DIFFER_WARNING: &str =
    "; warning: some pose numbers differ from their profile's number: check the order";

/// "pairing: P[1] ↔ p1.yml, …", with a warning when numbers differ.
fn pairing_note(records: &[PoseRecord], listing: &FolderListing) -> String {
    let pairs: Vec<String> = records
        .iter()
        .zip(&listing.profiles)
        .map(|(r, p)| format!("{} ↔ {}", r.name, file_name(p)))
        .collect();
    let shown = if pairs.len() > 6 {
        format!(
            "{}, …, {}",
            pairs[..3].join(", "),
            pairs[pairs.len() - 2..].join(", ")
        )
    } else {
        pairs.join(", ")
    };
    format!(
        "pairing (pose order ↔ profile number): {shown}{}",
        if numbers_differ(records, listing) {
            NUMBERS_DIFFER_WARNING
        } else {
            ""
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sides_parse() {
        assert_eq!(SideChoice::parse("+1"), Some(SideChoice::Plus));
        assert_eq!(SideChoice::parse("-1"), Some(SideChoice::Minus));
        assert_eq!(SideChoice::parse("AUTO"), Some(SideChoice::Auto));
        assert_eq!(SideChoice::parse("2"), None);
    }

    #[test]
    fn ids_of_records_without_one() {
        let r = |name: &str| PoseRecord {
            name: name.to_string(),
            id: None,
            station: None,
            usage: None,
            side: None,
            value: PoseValue::Joints(vec![]),
            line: 1,
        };
        assert_eq!(record_id(&r("P[3]"), 3), "P3");
        assert_eq!(record_id(&r("line 4"), 2), "pose2");
        assert_eq!(record_id(&r("XP12"), 1), "XP12");
    }
}
