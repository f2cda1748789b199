//! On which side of the laser plane the sphere lies, decided from the
//! data: a step of its own, run after the inputs are read (the command
//! line and the workbench call it when the side is `auto` and the file
//! gives none). Both sides are built (each with its own initial
//! hand-eye: the centres move to the other side of the plane) and
//! calibrated with `ml`; the side whose scatter ε is at least
//! [`SIDE_EVIDENCE_RATIO`] times smaller is kept. When neither can be
//! calibrated, or the two are too close to tell, the error says why,
//! with both sides' outcome.

use super::poses::{
    PoseImportSpec, PoseInputs, SideChoice, build_pose_session, read_pose_inputs_with,
};
use super::progress::{self, ImportProgress, ImportStage};
use super::{ImportError, Imported};
use crate::engine::calibrate::solve::{self, Options};

/// How many times smaller the scatter ε of one side must be than the
/// other's for the data to decide: the wrong side moves every centre by
/// twice its distance from the plane, which on a real cell multiplies ε
/// by 10-50; below 1.5 the difference is noise.
pub const SIDE_EVIDENCE_RATIO: f64 = 1.5;

/// One side's outcome: the built session and its ε, or why not.
struct Tried {
    side: i8,
    imported: Result<Imported, ImportError>,
    epsilon: Result<f64, String>,
}

fn label(side: i8) -> &'static str {
    if side > 0 { "+1" } else { "−1" }
}

/// Builds and calibrates both sides of `inputs` and keeps the clearly
/// better one, with the evidence in its notes.
///
/// # Errors
/// Neither side can be built (the reason is the same for both: it is
/// returned as it is), or the data cannot tell (both outcomes named).
pub fn decide_side(spec: &PoseImportSpec, inputs: &PoseInputs) -> Result<Imported, ImportError> {
    let mut tried: Vec<Tried> = [1_i8, -1]
        .into_iter()
        .map(|side| {
            let imported = build_pose_session(spec, inputs, side);
            let epsilon = match &imported {
                Ok(i) => {
                    let mut options = Options::from_session(&i.session);
                    options.ml.cross_validation = false;
                    options.held_out = false;
                    solve::calibrate(&i.session, &options)
                        .map(|(_, cal)| cal.epsilon_after())
                        .map_err(|e| {
                            // A stripe that gives no centre is its profile's fault.
                            let file = match &e {
                                solve::SolveError::Stripe { id, .. } => i
                                    .profiles
                                    .poses
                                    .iter()
                                    .find(|p| p.id == *id)
                                    .map(|p| format!(" ({})", p.file.display())),
                                _ => None,
                            };
                            format!("the calibration failed: {e}{}", file.unwrap_or_default())
                        })
                }
                Err(e) => Err(e.to_string()),
            };
            Tried {
                side,
                imported,
                epsilon,
            }
        })
        .collect();
    if tried.iter().all(|t| t.imported.is_err()) {
        let plus = tried.swap_remove(0);
        let same = tried[0].epsilon.as_ref().err() == plus.epsilon.as_ref().err();
        let no_hand_eye = |i: &Result<Imported, ImportError>| {
            matches!(i, Err(ImportError::NoInitialHandEye { .. }))
        };
        let both_without_hand_eye = no_hand_eye(&plus.imported) && no_hand_eye(&tried[0].imported);
        return match plus.imported {
            Err(e) if same => Err(e),
            // Neither side has an initial hand-eye: still that error (a
            // guess is what is missing), with both sides' reasons.
            Err(ImportError::NoInitialHandEye { path, .. }) if both_without_hand_eye => {
                Err(ImportError::NoInitialHandEye {
                    path,
                    message: format!(
                        "on neither side of the laser plane: side +1: {}; side −1: {}",
                        plus.epsilon.err().unwrap_or_default(),
                        tried[0].epsilon.clone().err().unwrap_or_default()
                    ),
                })
            }
            _ => Err(ImportError::File {
                path: spec.poses.clone(),
                message: format!(
                    "neither side of the laser plane gives a session: side +1: {}; side −1: {}",
                    plus.epsilon.err().unwrap_or_default(),
                    tried[0].epsilon.clone().err().unwrap_or_default()
                ),
            }),
        };
    }
    if let (Err(a), Err(b)) = (&tried[0].epsilon, &tried[1].epsilon)
        && a == b
    {
        // The same failure whichever the side: that is the real reason.
        return Err(ImportError::File {
            path: spec.poses.clone(),
            message: format!("{a} (the same on either side of the laser plane)"),
        });
    }
    let text = |t: &Tried| match &t.epsilon {
        Ok(v) => format!("side {}: ε {v:.3} mm", label(t.side)),
        Err(e) => format!("side {}: {e}", label(t.side)),
    };
    let evidence = format!("{}; {}", text(&tried[0]), text(&tried[1]));
    let choice = match (&tried[0].epsilon, &tried[1].epsilon) {
        (Ok(p), Ok(m)) if m * SIDE_EVIDENCE_RATIO <= *p => Some(1),
        (Ok(p), Ok(m)) if p * SIDE_EVIDENCE_RATIO <= *m => Some(0),
        (Ok(_), Err(_)) => Some(0),
        (Err(_), Ok(_)) => Some(1),
        _ => None,
    };
    let Some(k) = choice else {
        let reason = if tried.iter().all(|t| t.epsilon.is_err()) {
            "neither side calibrates"
        } else {
            "the two scatters are too close to tell"
        };
        return Err(ImportError::File {
            path: spec.poses.clone(),
            message: format!(
                "cannot tell from the data on which side of the laser plane the sphere lies: {reason} ({evidence}; one must be {SIDE_EVIDENCE_RATIO}× smaller): give the side (--side +1 or --side -1)"
            ),
        });
    };
    let chosen = tried.swap_remove(k);
    let mut imported = chosen.imported?;
    imported.notes.push(format!(
        "side {} chosen from the data ({evidence})",
        label(chosen.side)
    ));
    Ok(imported)
}

/// The whole import of a pose file: [`read_pose_inputs`], then the side
/// given, or with [`SideChoice::Auto`] (and no side column, and no
/// centres) [`decide_side`], which calibrates both sides.
///
/// # Errors
/// As [`read_pose_inputs`], [`build_pose_session`] and
/// [`decide_side`].
pub fn import_poses(spec: &PoseImportSpec) -> Result<Imported, ImportError> {
    import_poses_with(spec, &mut progress::quiet)
}

/// [`import_poses`], telling `progress` of each profile read, of the side
/// decision and of the check; it may cancel.
///
/// # Errors
/// As [`import_poses`]; [`ImportError::Cancelled`].
pub fn import_poses_with(
    spec: &PoseImportSpec,
    progress: &mut ImportProgress<'_>,
) -> Result<Imported, ImportError> {
    let inputs = read_pose_inputs_with(spec, progress)?;
    match spec.side {
        SideChoice::Auto if !inputs.all_sides_given() && !inputs.centres() => {
            progress::report(progress, ImportStage::Side)?;
            decide_side(spec, &inputs)
        }
        choice => {
            progress::report(progress, ImportStage::Checking)?;
            build_pose_session(
                spec,
                &inputs,
                if choice == SideChoice::Minus { -1 } else { 1 },
            )
        }
    }
}
