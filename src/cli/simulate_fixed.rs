//! `spherecal simulate --mount fixed`: a simulated cell with a fixed
//! sensor (a laser tracker and three SMRs on the tool, or a fixed scanner
//! and one sphere), its truth, and with `--csv-out` the tracker's table and
//! the joint log that `import --mount fixed` reads.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::cli::CliError;
use crate::cli::simulate::{FixedSensorArg, SimulateArgs};
use crate::engine::base::geometry::rows_from_isometry;
use crate::engine::base::session::{Observation, Session, Use};
use crate::engine::files::format;
use crate::engine::tools::simulate::{FixedCell, FixedTruth, simulate_fixed};

/// The truth of a fixed cell as JSON: the true robot's joints, `bT_s` and
/// the targets on the flange.
fn truth_json(truth: &FixedTruth) -> String {
    let value = serde_json::json!({
        "format": "spherecal-fixed-truth",
        "version": 1,
        "robot": truth.robot.joints,
        "base_from_sensor": rows_from_isometry(&truth.base_from_sensor),
        "targets": truth
            .targets
            .iter()
            .map(|(id, p)| serde_json::json!({"id": id, "point": [p.x, p.y, p.z]}))
            .collect::<Vec<_>>(),
    });
    let mut text = serde_json::to_string_pretty(&value).unwrap_or_default();
    text.push('\n');
    text
}

/// The tracker's table (`pose,target,x,y,z`, sensor frame, mm) and the
/// joint log (`id,use,j1..jn`, deg) of a fixed session.
fn tables(session: &Session) -> (String, String) {
    let mut points = String::from("pose,target,x,y,z\n");
    let mut joints = String::from("id,use");
    let dof = session.robot.dof();
    for k in 1..=dof {
        let _ = write!(joints, ",j{k}");
    }
    joints.push('\n');
    let mut last: Option<&[f64]> = None;
    let mut pose = 0;
    for m in &session.measurements {
        if last != Some(m.joints.as_slice()) {
            pose += 1;
            last = Some(m.joints.as_slice());
            let _ = write!(joints, "P{pose},{}", m.usage.as_str());
            for q in &m.joints {
                let _ = write!(joints, ",{q}");
            }
            joints.push('\n');
        }
        if let Observation::Centre(c) = &m.observation {
            let _ = writeln!(points, "P{pose},{},{},{},{}", m.station, c.x, c.y, c.z);
        }
    }
    (points, joints)
}

/// `spherecal simulate`: a fixed sensor's cell here, anything else by
/// [`crate::cli::simulate::run`].
///
/// # Errors
/// As the simulation that runs.
pub fn dispatch(args: &SimulateArgs) -> Result<(), CliError> {
    if args.mount != crate::cli::import::MountArg::Fixed {
        return crate::cli::simulate::run(args);
    }
    let truth_path = args.truth_path();
    if truth_path == args.out {
        return Err(CliError::input(format!(
            "the session and the truth would both be written to {}; give --truth another path",
            args.out.display()
        )));
    }
    run(args, &truth_path)
}

/// Simulates, writes the session, the truth and the tables, and prints.
///
/// # Errors
/// [`CliError`] for flags that do not apply to a fixed sensor, a bad
/// setting or an output that cannot be written.
fn run(args: &SimulateArgs, truth_path: &Path) -> Result<(), CliError> {
    if args.plan.is_some() || args.scan.is_some() || args.pose_only.is_some() {
        return Err(CliError::input(
            "--mount fixed simulates its own poses: --plan, --scan and --pose-only do not apply",
        ));
    }
    let noise = args.sensor_noise;
    let cell = match args.fixed_sensor {
        FixedSensorArg::Tracker => FixedCell::tracker(noise),
        FixedSensorArg::Scanner => FixedCell::scanner(noise),
    };
    let config = args.to_config();
    config
        .validate()
        .map_err(|e| CliError::input(e.to_string()))?;
    let (session, truth) =
        simulate_fixed(&config, &cell).map_err(|e| CliError::input(e.to_string()))?;
    let mut files: Vec<(PathBuf, String)> = vec![
        (args.out.clone(), format::session_to_json(&session)),
        (truth_path.to_path_buf(), truth_json(&truth)),
    ];
    let folders = if let Some(dir) = &args.csv_out {
        let (points, joints) = tables(&session);
        files.push((dir.join("points.csv"), points));
        files.push((dir.join("joints.csv"), joints));
        format::Folders::Create
    } else {
        format::Folders::Existing
    };
    let paths: Vec<&Path> = files.iter().map(|(p, _)| p.as_path()).collect();
    super::check_outputs(&paths, folders)?;
    let bytes: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, t)| (p.as_path(), t.as_bytes()))
        .collect();
    super::write_outputs(&bytes, folders)?;
    if !args.quiet {
        let count = |u: Use| session.with_use(u).count();
        sayln!(
            "simulated a fixed {} (seed {}, σ {} mm) and {} target(s) on the tool of {}: {} measurements ({} identify, {} validate) -> {}, truth {}",
            match args.fixed_sensor {
                FixedSensorArg::Tracker => "laser tracker",
                FixedSensorArg::Scanner => "scanner",
            },
            config.seed,
            noise,
            cell.targets.len(),
            session.robot.name,
            session.measurements.len(),
            count(Use::Identify),
            count(Use::Validate),
            args.out.display(),
            truth_path.display()
        );
    }
    Ok(())
}
