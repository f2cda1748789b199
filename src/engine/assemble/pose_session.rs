//! The session of a pose file: its measurements on the side decided or
//! given, their uses and the initial hand-eye settled ([`settle`]), the
//! session checked against FORMAT.md's rules and blamed on the file.

use std::collections::HashMap;

use super::initial::settle;
use crate::engine::base::session::{Measurement, Use};
use crate::engine::files::import::poses::{DEFAULT_STATION, PoseImportSpec, PoseInputs, PoseValue};
use crate::engine::files::import::{ImportError, Imported, Sources, new_session, recheck};

/// The session of `inputs` with every measurement on side `side` (unless
/// the file gave one), its uses and initial hand-eye settled
/// ([`settle`]). Runs no calibration.
///
/// # Errors
/// The initial hand-eye cannot be had (naming why), or the session breaks
/// a FORMAT.md rule (naming the file and line it came from).
pub fn build_pose_session(
    spec: &PoseImportSpec,
    inputs: &PoseInputs,
    side: i8,
) -> Result<Imported, ImportError> {
    let given_uses = inputs.records.iter().filter(|r| r.usage.is_some()).count();
    if given_uses != 0 && given_uses != inputs.records.len() {
        return Err(ImportError::File {
            path: spec.poses.clone(),
            message: "some poses have a use and some not: give every pose a use, or none".into(),
        });
    }
    let auto_uses = given_uses == 0;
    let measurements: Vec<Measurement> = inputs
        .records
        .iter()
        .zip(&inputs.ids)
        .zip(&inputs.observations)
        .map(|((r, id), observation)| {
            let (joints, flange) = match &r.value {
                PoseValue::Flange(pose) => (Vec::new(), Some(*pose)),
                PoseValue::Joints(q) => (q.clone(), None),
            };
            Measurement {
                id: id.clone(),
                station: r
                    .station
                    .clone()
                    .unwrap_or_else(|| DEFAULT_STATION.to_string()),
                usage: r.usage.unwrap_or(Use::Identify),
                side_given: r.side,
                side: r.side.unwrap_or(side),
                joints,
                flange,
                observation: observation.clone(),
            }
        })
        .collect();
    let name = spec.name.clone().unwrap_or_else(|| {
        spec.poses
            .file_stem()
            .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned())
    });
    let session = new_session(
        name,
        inputs.robot.clone(),
        spec.sphere_diameter,
        (!inputs.centres()).then_some(side),
        spec.references.as_deref(),
        measurements,
    )?;
    let (session, hand_eye_notes) = settle(
        session,
        auto_uses,
        spec.hand_eye,
        &spec.poses,
        &inputs.report,
    )?;
    let mut notes = inputs.notes.clone();
    notes.push(if inputs.joints() {
        format!(
            "{} joint targets: the robot's kinematic errors are identified with the hand-eye",
            inputs.records.len()
        )
    } else {
        format!(
            "{} flange poses, pose-only: only the hand-eye and the station centres are calibrated, no kinematic parameter",
            inputs.records.len()
        )
    });
    notes.extend(hand_eye_notes);
    let lines: HashMap<&str, usize> = inputs
        .ids
        .iter()
        .zip(&inputs.records)
        .map(|(id, r)| (id.as_str(), r.line))
        .collect();
    let session = recheck(
        session,
        &Sources {
            log: &spec.poses,
            lines: &lines,
            profiles: &inputs.report,
            references: spec.references.as_deref(),
        },
    )?;
    Ok(Imported {
        session,
        checks: Vec::new(),
        profiles: inputs.report.clone(),
        notes,
    })
}
