//! `spherecal simulate --mount fixed`: a simulated cell with a fixed
//! sensor (a laser tracker and three SMRs on the tool, or a fixed scanner
//! and one sphere, or a fixed line scanner's stripes of one sphere), its
//! truth, and with `--csv-out` the joint log and the tracker's table (or
//! the line scanner's profiles, `profiles/<pose>.csv`, the flange
//! sessions' `y,z` format) that `import --mount fixed` reads.

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

/// The files of a fixed session as a cell would leave them.
struct Tables {
    /// The tracker's table, `pose,target,x,y,z` (sensor frame, mm).
    points: String,
    /// The joint log, `id,use,j1..jn` (deg).
    joints: String,
    /// The pose file, `id,use,x,y,z,q1,q2,q3,q4` (mm, ABB's unit
    /// quaternion w, x, y, z): the flange poses as the controller reports
    /// them, by the nominal kinematics.
    poses: String,
    /// The line scanner's stripe profiles, `(P<k>, "y,z" mm)`.
    profiles: Vec<(String, String)>,
}

/// The [`Tables`] of a fixed session.
fn tables(session: &Session) -> Tables {
    let mut profiles = Vec::new();
    let mut poses = String::from("id,use,x,y,z,q1,q2,q3,q4\n");
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
            let flange = session.robot.base_from_flange(&m.joints);
            let (t, r) = (flange.translation.vector, flange.rotation);
            let _ = writeln!(
                poses,
                "P{pose},{},{},{},{},{},{},{},{}",
                m.usage.as_str(),
                t.x,
                t.y,
                t.z,
                r.w,
                r.i,
                r.j,
                r.k
            );
        }
        match &m.observation {
            Observation::Centre(c) => {
                let _ = writeln!(points, "P{pose},{},{},{},{}", m.station, c.x, c.y, c.z);
            }
            Observation::Stripe(stripe) => {
                let mut text = String::from("y,z\n");
                for [y, z] in stripe {
                    let _ = writeln!(text, "{y},{z}");
                }
                profiles.push((format!("P{pose}"), text));
            }
        }
    }
    Tables {
        points,
        joints,
        poses,
        profiles,
    }
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
    if args.plan.is_some() || args.scan.is_some() {
        return Err(CliError::input(
            "--mount fixed simulates its own poses: --plan and --scan do not apply",
        ));
    }
    let noise = args.sensor_noise;
    let cell = match args.fixed_sensor {
        FixedSensorArg::Tracker => FixedCell::tracker(noise),
        FixedSensorArg::Scanner => FixedCell::scanner(noise),
        FixedSensorArg::LineScanner => FixedCell::line_scanner(noise),
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
        let t = tables(&session);
        if t.profiles.is_empty() {
            files.push((dir.join("points.csv"), t.points));
        }
        files.push((dir.join("joints.csv"), t.joints));
        files.push((dir.join("poses.csv"), t.poses));
        for (pose, text) in t.profiles {
            files.push((dir.join("profiles").join(format!("{pose}.csv")), text));
        }
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
            "simulated a fixed {} (seed {}, σ {} mm) and {} target(s) on the tool of {}{}: {} measurements ({} identify, {} validate) -> {}, truth {}",
            match args.fixed_sensor {
                FixedSensorArg::Tracker => "laser tracker",
                FixedSensorArg::Scanner => "scanner",
                FixedSensorArg::LineScanner => "line scanner",
            },
            config.seed,
            noise,
            cell.targets.len(),
            truth.robot.name,
            config.pose_only.map_or_else(String::new, |sigma| format!(
                " (pose-only: its flange poses off by {sigma} mm)"
            )),
            session.measurements.len(),
            count(Use::Identify),
            count(Use::Validate),
            args.out.display(),
            truth_path.display()
        );
    }
    Ok(())
}
