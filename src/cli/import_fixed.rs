//! `spherecal import --mount fixed`: a fixed sensor's points (a laser
//! tracker's table, a fixed camera's or scanner's) beside a joint log
//! become a session with `sensor.mount: "fixed"`
//! ([`import_tracker`](crate::engine::files::import::tracker::import_tracker)).

use crate::cli::CliError;
use crate::cli::import::{ImportArgs, MountArg, joint_log_columns};
use crate::engine::files::format;
use crate::engine::files::import::tracker::{TrackerSpec, import_tracker};
use crate::engine::files::import::{self, LengthUnit};

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

/// Imports, writes the session and prints what was read.
///
/// # Errors
/// [`CliError`] (status 2) for a missing flag or a bad input, naming the
/// file, line and column.
fn run(args: &ImportArgs) -> Result<(), CliError> {
    if args.poses.is_some() {
        return Err(CliError::input(
            "--mount fixed reads a joint log (--joints) beside --centres; a pose file is not read for a fixed sensor yet",
        ));
    }
    if args.hand_eye.is_some() {
        return Err(CliError::input(
            "--hand-eye is the guess of a sensor on the flange; a fixed sensor's pose in the base is found from its points (leave --hand-eye out)",
        ));
    }
    let Some(points) = &args.centres else {
        return Err(CliError::input(
            "--mount fixed needs --centres POINTS.csv: the fixed sensor's points, one `x y z` a target and pose",
        ));
    };
    let Some(out) = &args.out else {
        return Err(CliError::input("--out SESSION.json is needed"));
    };
    let (joint_log, robot, columns) = joint_log_columns(args)?;
    CliError::guard_output(out, &[points.as_path(), joint_log.as_path()])?;
    let robot = import::load_robot(&robot).map_err(|e| CliError::input(e.to_string()))?;
    let length_unit = LengthUnit::parse(&args.centre_unit).ok_or_else(|| {
        CliError::input(format!("--centre-unit {}: mm, m or um", args.centre_unit))
    })?;
    let name = args.name.clone().unwrap_or_else(|| {
        joint_log
            .file_stem()
            .map_or_else(|| "imported".into(), |s| s.to_string_lossy().into_owned())
    });
    let spec = TrackerSpec {
        points: points.clone(),
        joint_log,
        id_column: columns.id,
        joint_columns: columns.joints,
        angle_unit: args.scan.joint_unit,
        length_unit,
        robot,
        diameter: args.sphere_diameter,
        name,
    };
    let (mut session, notes) = import_tracker(&spec).map_err(|e| CliError::input(e.to_string()))?;
    if args.range.is_some() {
        session.sensor_range = args.range;
    }
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
