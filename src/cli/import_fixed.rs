//! `spherecal import --mount fixed`: a fixed sensor's points (a laser
//! tracker's table, a fixed camera's) or a fixed line scanner's stripe
//! profiles, beside a joint log or a pose file, become a session with
//! `sensor.mount: "fixed"`, through the one import entry
//! ([`import_session`](crate::engine::assemble::import_session) with
//! [`PoseLog::Fixed`]).

use crate::cli::CliError;
use crate::cli::import::{ImportArgs, MountArg, joint_log_columns};
use crate::engine::assemble;
use crate::engine::assemble::{ImportRequest, PoseLog};
use crate::engine::files::format;
use crate::engine::files::import::tracker::{FixedPoints, FixedPoses, TrackerSpec};
use crate::engine::files::import::{self, Imported, LengthUnit, ProfileSource, SideChoice};

/// `spherecal import`: a fixed sensor's points here, anything else by
/// [`crate::cli::import::run`].
///
/// # Errors
/// As the import that runs.
pub fn dispatch(args: &ImportArgs) -> Result<(), CliError> {
    if args.mount == MountArg::Fixed {
        run(args)
    } else {
        crate::cli::import::run(args)
    }
}

/// The engine's spec of a fixed sensor's import from the flags.
///
/// # Errors
/// [`CliError`] (status 2) for a missing or contradicting flag, a robot
/// that does not load, an unreadable hand-eye.
fn fixed_spec(args: &ImportArgs) -> Result<TrackerSpec, CliError> {
    let length_unit = LengthUnit::parse(&args.centre_unit).ok_or_else(|| {
        CliError::input(format!("--centre-unit {}: mm, m or um", args.centre_unit))
    })?;
    let (poses, robot) = match (&args.joints, &args.poses) {
        (Some(_), Some(_)) => {
            return Err(CliError::input(
                "--joints and --poses both given: a fixed sensor's poses come from one of them",
            ));
        }
        (None, None) => {
            return Err(CliError::input(
                "--mount fixed needs the poses: a joint log (--joints) or a pose file (--poses)",
            ));
        }
        (Some(_), None) => {
            let (path, robot, columns) = joint_log_columns(args)?;
            (
                FixedPoses::Joints {
                    path,
                    id_column: columns.id,
                    joint_columns: columns.joints,
                    angle_unit: args.scan.joint_unit,
                },
                Some(robot),
            )
        }
        (None, Some(path)) => (
            FixedPoses::File {
                path: path.clone(),
                format: args.scan.pose_format,
                convention: args.scan.pose_convention,
                pose_columns: args.scan.pose_columns(),
            },
            args.robot
                .as_deref()
                .map(|r| args.scan.robot_source(r))
                .transpose()?,
        ),
    };
    let robot = robot
        .map(|r| import::load_robot(&r))
        .transpose()
        .map_err(|e| CliError::input(e.to_string()))?;
    let points = match (&args.centres, &args.profiles) {
        (Some(path), _) => FixedPoints::Table {
            path: path.clone(),
            unit: length_unit,
        },
        (None, Some(profiles)) => FixedPoints::Profiles {
            source: if profiles.is_dir() {
                ProfileSource::Folder(profiles.clone())
            } else {
                ProfileSource::File {
                    path: profiles.clone(),
                    pose_column: args.scan.pose_column.clone(),
                }
            },
            format: args.scan.profile_format()?,
            side: match args.side {
                SideChoice::Minus => Some(-1),
                SideChoice::Plus => Some(1),
                // Decided from the data unless the log says.
                SideChoice::Auto => None,
            },
        },
        (None, None) => {
            return Err(CliError::input(
                "--mount fixed needs --centres POINTS.csv (the sensor's points, one `x y z` a target and pose) or --profiles (a fixed line scanner's stripes)",
            ));
        }
    };
    let hand_eye = args
        .hand_eye
        .as_ref()
        .map(|p| super::hand_eye_file(p))
        .transpose()?;
    let name = args.name.clone().unwrap_or_else(|| {
        poses
            .path()
            .file_stem()
            .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned())
    });
    Ok(TrackerSpec {
        poses,
        points,
        robot,
        diameter: args.sphere_diameter,
        hand_eye,
        name,
    })
}

/// Imports, writes the session and prints what was read.
///
/// # Errors
/// [`CliError`] (status 2) for a missing flag or a bad input, naming the
/// file, line and column.
fn run(args: &ImportArgs) -> Result<(), CliError> {
    let Some(out) = &args.out else {
        return Err(CliError::input("--out SESSION.json is needed"));
    };
    let spec = fixed_spec(args)?;
    let mut inputs = vec![spec.poses.path().to_path_buf()];
    inputs.extend(args.centres.iter().chain(&args.hand_eye).cloned());
    if let Some(p) = args.profiles.as_ref().filter(|p| !p.is_dir()) {
        inputs.push(p.clone());
    }
    let inputs: Vec<&std::path::Path> = inputs.iter().map(std::path::PathBuf::as_path).collect();
    CliError::guard_output(out, &inputs)?;
    let request = ImportRequest {
        log: PoseLog::Fixed(spec),
        range: args.range,
    };
    let Imported { session, notes, .. } = assemble::import_session(&request, &mut |_| {
        if format::interrupted() {
            crate::engine::calibrate::solve::Control::Cancel
        } else {
            crate::engine::calibrate::solve::Control::Continue
        }
    })
    .map_err(|e| CliError::input(e.to_string()))?;
    let text = format::session_to_json(&session);
    format::write_atomic(out, text.as_bytes()).map_err(|e| CliError::from_file(&e, false))?;
    if args.quiet {
        return Ok(());
    }
    for note in &notes {
        sayln!("{note}");
    }
    sayln!(
        "imported {} measurements (sensor.mount fixed) into {}",
        session.measurements.len(),
        out.display()
    );
    Ok(())
}
