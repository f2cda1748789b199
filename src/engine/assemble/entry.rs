//! The import use case in one entry, [`import_session`], that `spherecal
//! import` and the workbench's import wizard both call: a joint log
//! ([`import_with`](crate::engine::files::import::import_with)) or a pose file
//! ([`import_poses_with`](super::import_poses_with): the side given, or
//! decided from the data by calibrating both), or a fixed sensor's points
//! or profiles beside either ([`import_tracker_with`](super::side::import_tracker_with),
//! FORMAT.md `sensor.mount: "fixed"`) into a session, the sensor's
//! measuring range written into it when given, with the progress of every
//! stage; and the joint log's preview, its header read and its first rows
//! mapped ([`preview_joint_log`]). The request is built from every import
//! choice by [`ImportChoices::request`](super::choices::ImportChoices::request),
//! which the command line's flags and the workbench's form both fill.

use std::path::Path;

use nalgebra::Isometry3;

use super::side::import_poses_with;
use super::side::import_tracker_with;
use crate::engine::base::session::SensorRange;
use crate::engine::files::import::tracker::TrackerSpec;
use crate::engine::files::import::{
    ImportError, ImportProgress, ImportSpec, Imported, PoseImportSpec, header, import_with, preview,
};

/// The pose log an import reads.
#[derive(Debug, Clone)]
pub enum PoseLog {
    /// A joint log CSV and its column mapping.
    Joints(ImportSpec),
    /// A pose file in any layout the program readers know.
    Poses(PoseImportSpec),
    /// A fixed sensor's points (a tracker's table) or a fixed line
    /// scanner's profiles, beside a joint log or a pose file.
    Fixed(TrackerSpec),
}

/// Everything an import needs.
#[derive(Debug, Clone)]
pub struct ImportRequest {
    /// The pose log, its profiles or centres, robot and options.
    pub log: PoseLog,
    /// The sensor's measuring range to write as `sensor.range`; `None`:
    /// the session keeps what the import found (none).
    pub range: Option<SensorRange>,
    /// A start for the hand-eye (`base_from_sensor` for a fixed sensor)
    /// written to the session instead of computing one; `None`: computed
    /// (or the pose log's spec's own).
    pub hand_eye: Option<Isometry3<f64>>,
}

/// Imports `request`'s pose log into a session, telling `progress` each
/// stage (each profile read, the side decision, the check); it may
/// cancel.
///
/// # Errors
/// [`ImportError`] naming the file, the line, the column or the pose id;
/// [`ImportError::Cancelled`].
pub fn import_session(
    request: &ImportRequest,
    progress: &mut ImportProgress<'_>,
) -> Result<Imported, ImportError> {
    let guess = request.hand_eye;
    let mut imported = match &request.log {
        PoseLog::Joints(spec) => {
            let mut imported = import_with(spec, progress)?;
            // A joint log's session starts from the guess given, as a pose
            // file's does (else calibrate computes one from the
            // translation and rotation groups, eq. 6-9).
            if let Some(he) = guess {
                let t = he.translation.vector;
                imported.notes.push(format!(
                    "initial hand-eye: the guess given (translation [{:.2}, {:.2}, {:.2}] mm), written to the session; calibrate starts from it instead of eq. 6-9",
                    t.x, t.y, t.z
                ));
                imported.session.hand_eye = Some(he);
            }
            imported
        }
        PoseLog::Poses(spec) if guess.is_some() => {
            let spec = PoseImportSpec {
                hand_eye: guess,
                ..spec.clone()
            };
            import_poses_with(&spec, progress)?
        }
        PoseLog::Poses(spec) => import_poses_with(spec, progress)?,
        PoseLog::Fixed(spec) if guess.is_some() => {
            let spec = TrackerSpec {
                hand_eye: guess,
                ..spec.clone()
            };
            import_tracker_with(&spec, progress)?
        }
        PoseLog::Fixed(spec) => import_tracker_with(spec, progress)?,
    };
    if request.range.is_some() {
        imported.session.sensor_range = request.range;
    }
    // Calibrate's verdict on the start, the import's last step: a
    // pose-only session whose centres no hand-eye brings together is a
    // misread file (another convention, unit or session), refused here
    // rather than written for `calibrate` to refuse. A session with joints
    // only warns (the nominal model's own scatter can exceed the bound and
    // still calibrate), and so does a start the user gave (a rough guess
    // is a start, not a verdict on the data).
    if let PoseLog::Poses(spec) = &request.log
        && spec.hand_eye.is_none()
        && guess.is_none()
        && imported.session.pose_only()
        && let Some(why) = super::initial::implausible_start(&imported.session)
    {
        return Err(ImportError::File {
            path: spec.poses.clone(),
            message: format!(
                "with the initial hand-eye the sphere centres scatter by {} mm (3-D rms about each station's mean), beyond what any sensor and robot give (at most {} mm); nothing is written; likely causes: {}, or poses and centres that do not belong together (another unit, another session)",
                crate::engine::base::numeric::approx(why.scatter_mm),
                crate::engine::calibrate::solve::plausible::MAX_PLAUSIBLE_SCATTER_MM,
                why.causes
            ),
        });
    }
    Ok(imported)
}

/// A joint log's header and its first `rows` rows with `spec`'s mapping
/// applied, as text; `spec` is asked for once the header is read (the
/// workbench guesses the mapping from it).
///
/// # Errors
/// The header cannot be read, `spec` refuses (its message), or a row does
/// not map.
pub fn preview_joint_log<E: From<ImportError>>(
    joint_log: &Path,
    rows: usize,
    spec: impl FnOnce(&[String]) -> Result<ImportSpec, E>,
) -> (Vec<String>, Result<String, E>) {
    let columns = match header(joint_log) {
        Ok(h) => h,
        Err(e) => return (Vec::new(), Err(e.into())),
    };
    let shown = spec(&columns).and_then(|s| Ok(preview(&s, rows)?));
    (columns, shown)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use crate::engine::files::import::{
        AngleUnit, ColumnMap, DEFAULT_SPHERE_DIAMETER, ProfileFormat, ProfileSource, RobotSource,
    };

    fn spec(log: &Path) -> ImportSpec {
        ImportSpec {
            joint_log: log.to_path_buf(),
            columns: ColumnMap {
                id: "id".into(),
                station: "station".into(),
                usage: "use".into(),
                side: None,
                joints: (1..=6).map(|k| format!("j{k}")).collect(),
            },
            joint_unit: AngleUnit::Deg,
            profiles: ProfileSource::Folder(log.with_file_name("profiles")),
            profile_format: ProfileFormat::default(),
            robot: RobotSource::Preset("irb2400".into()),
            sphere_diameter: DEFAULT_SPHERE_DIAMETER,
            name: None,
            flange: None,
            references: None,
        }
    }

    #[test]
    fn the_preview_reads_the_header_and_maps_the_rows_or_says_why_not() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("log.csv");
        std::fs::write(
            &log,
            "id,station,use,j1,j2,j3,j4,j5,j6\np1,S1,identify,1,2,3,4,5,6\n",
        )
        .unwrap();
        let (columns, shown) = preview_joint_log(&log, 8, |h| {
            assert_eq!(h.len(), 9, "the spec is asked for with the header");
            Ok::<_, ImportError>(spec(&log))
        });
        assert_eq!(columns[0], "id");
        let text = shown.unwrap();
        assert!(text.contains("p1"), "{text}");
        let (columns, shown) = preview_joint_log(&dir.path().join("none.csv"), 8, |_| {
            Ok::<_, ImportError>(spec(&log))
        });
        assert!(columns.is_empty());
        assert!(shown.unwrap_err().to_string().contains("none.csv"));
    }
}
