//! On which side of the laser plane the sphere lies, decided from the
//! data: a step of its own, run after the inputs are read (the command
//! line and the workbench call it when the side is `auto` and the file
//! gives none). Both sides are built (each with its own initial
//! hand-eye: the centres move to the other side of the plane) and
//! calibrated with `ml`; the side whose scatter ε is at least
//! [`SIDE_EVIDENCE_RATIO`] times smaller is kept. When neither can be
//! calibrated, or the two are too close to tell, the error says why,
//! with both sides' outcome.

use std::path::Path;

use super::pose_session::build_pose_session;
use crate::engine::calibrate::solve::{self, Options};
use crate::engine::files::import::poses::{
    PoseImportSpec, PoseInputs, SideChoice, read_pose_inputs_with,
};
use crate::engine::files::import::progress::{self, ImportProgress, ImportStage};
use crate::engine::files::import::tracker::{FixedPoints, TrackerSpec, read_tracker_with};
use crate::engine::files::import::{ImportError, Imported};

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

/// One side tried: the session built on `side` (or why not) and its ε
/// after a calibration without the cross-checks (or why it failed).
fn attempt(side: i8, imported: Result<Imported, ImportError>) -> Tried {
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
}

/// Builds and calibrates both sides of `inputs` and keeps the clearly
/// better one, with the evidence in its notes.
///
/// # Errors
/// Neither side can be built (the reason is the same for both: it is
/// returned as it is), or the data cannot tell (both outcomes named).
pub fn decide_side(spec: &PoseImportSpec, inputs: &PoseInputs) -> Result<Imported, ImportError> {
    let tried = [1_i8, -1]
        .into_iter()
        .map(|side| attempt(side, build_pose_session(spec, inputs, side)))
        .collect();
    choose(&spec.poses, tried)
}

/// The clearly better of the two sides `tried` (+1 first), with the
/// evidence in its notes; errors name `path`, the pose log.
fn choose(path: &Path, mut tried: Vec<Tried>) -> Result<Imported, ImportError> {
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
                path: path.to_path_buf(),
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
            path: path.to_path_buf(),
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
        let diameter = tried
            .iter()
            .find_map(|t| t.imported.as_ref().ok())
            .and_then(|i| diameter_misfit(&i.session));
        let advice = diameter.map_or_else(
            || "give the side (--side +1 or --side -1)".to_string(),
            |d| format!("{d}; if it is right, give the side (--side +1 or --side -1)"),
        );
        return Err(ImportError::File {
            path: path.to_path_buf(),
            message: format!(
                "cannot tell from the data on which side of the laser plane the sphere lies: {reason} ({evidence}; one must be {SIDE_EVIDENCE_RATIO}× smaller): {advice}"
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

/// Stripes whose circle is larger than the sphere, as a share of the
/// fitted ones, beyond which the diameter is in doubt: a few such stripes
/// are noise or a bad profile, a tenth is the sphere.
pub const OVERSIZED_SHARE: f64 = 0.1;

/// Largest stripe circle, as a share of the sphere radius, below which the
/// diameter is in doubt: every cut would lie more than 66° from the
/// centre, where the planner's cuts lie at about 40° (r = 0.77 R) and at
/// most 80°.
pub const LARGEST_RADIUS_SHARE: f64 = 0.4;

/// Whether the stripes' circle radii fit the session's sphere: `None`
/// when they do, else "check the sphere diameter" with the figures (many
/// circles larger than the sphere, or every one far smaller than it).
#[must_use]
pub fn diameter_misfit(session: &crate::engine::base::session::Session) -> Option<String> {
    use crate::engine::calibrate::stripe::StripeError;
    let big_r = session.sphere_diameter / 2.0;
    let analysis = solve::prepare::analyse(session);
    let mut radii = Vec::new();
    let mut oversized = Vec::new();
    for m in &analysis.measurements {
        match m {
            Ok(p) => {
                if let Some(s) = &p.stripe {
                    radii.push(s.fit.radius);
                }
            }
            Err(StripeError::RadiusTooLarge { r, .. }) => oversized.push(*r),
            Err(_) => {}
        }
    }
    let fitted = radii.len() + oversized.len();
    if fitted == 0 {
        return None;
    }
    let d = crate::engine::base::numeric::show(session.sphere_diameter);
    if oversized.len() as f64 >= OVERSIZED_SHARE * fitted as f64 {
        let largest = oversized.iter().copied().fold(0.0_f64, f64::max);
        return Some(format!(
            "{} of {fitted} stripe circles are larger than the sphere (r up to {largest:.2} mm, R = {big_r:.2} mm of the {d} mm diameter given): check the sphere diameter (--sphere-diameter)",
            oversized.len()
        ));
    }
    let largest = radii.iter().copied().fold(0.0_f64, f64::max);
    (largest < LARGEST_RADIUS_SHARE * big_r).then(|| {
        let smallest = radii.iter().copied().fold(f64::INFINITY, f64::min);
        format!(
            "the stripe circles' radii run from {smallest:.2} to {largest:.2} mm, at most {:.0} % of the sphere radius R = {big_r:.2} mm of the {d} mm diameter given (the circles need a ball of at least {:.1} mm): check the sphere diameter (--sphere-diameter)",
            100.0 * largest / big_r,
            2.0 * largest
        )
    })
}

/// The whole import of a pose file: [`read_pose_inputs`](crate::engine::files::import::read_pose_inputs), then the side
/// given, or with [`SideChoice::Auto`] (and no side column, and no
/// centres) [`decide_side`], which calibrates both sides.
///
/// # Errors
/// As [`read_pose_inputs`](crate::engine::files::import::read_pose_inputs), [`build_pose_session`] and
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

/// The import of a fixed sensor's points or profiles (FORMAT.md
/// `sensor.mount: "fixed"`): [`read_tracker_with`], and for a fixed line
/// scanner's profiles without a side (`--side auto`, and no `side` column
/// for every pose) the side decided from the data as for a flange-mounted
/// sensor: the session read on both sides, both calibrated, the clearly
/// better kept ([`SIDE_EVIDENCE_RATIO`]). On the wrong side every centre
/// moves twice its distance from the plane along the sensor's `x`, which
/// no `base_from_sensor` undoes where that distance varies.
///
/// # Errors
/// As [`read_tracker_with`]; the data cannot tell the side (both outcomes
/// named); [`ImportError::Cancelled`].
pub fn import_tracker_with(
    spec: &TrackerSpec,
    progress: &mut ImportProgress<'_>,
) -> Result<Imported, ImportError> {
    let FixedPoints::Profiles { side: None, .. } = &spec.points else {
        return read_tracker_with(spec, progress);
    };
    let on = |side: i8| {
        let mut sided = spec.clone();
        if let FixedPoints::Profiles { side: s, .. } = &mut sided.points {
            *s = Some(side);
        }
        sided
    };
    let plus = read_tracker_with(&on(1), progress)?;
    if plus
        .session
        .measurements
        .iter()
        .all(|m| m.side_given.is_some())
    {
        return Ok(plus);
    }
    progress::report(progress, ImportStage::Side)?;
    let minus = read_tracker_with(&on(-1), &mut progress::quiet);
    choose(
        spec.poses.path(),
        vec![attempt(1, Ok(plus)), attempt(-1, minus)],
    )
}
