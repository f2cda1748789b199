//! `spherecal import`: a pose log plus stripe profiles become a session
//! file (written atomically). A joint log (`--joints`) gives a session
//! with joint readings, with an optional check of the controller's flange
//! poses against the nominal model; a flange-pose log (`--poses`, e.g.
//! RobCalibrator's `RobPoses.rob`) gives a pose-only session; with
//! `--mount fixed` a fixed sensor's points (a laser tracker's table) or a
//! fixed line scanner's profiles beside either give a session with
//! `sensor.mount: "fixed"`. A thin caller of
//! [`crate::engine::files::import`]: the flags become its
//! [`ImportChoices`], the one import request.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;

use crate::engine::assemble;
use crate::engine::assemble::{ImportChoices, LogKind, ObservationKind, ProfilesKind};
use crate::engine::base::session::Mount;
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format;
use crate::engine::files::import::{
    self, ColumnMap, DEFAULT_POSITION_TOLERANCE_MM, DEFAULT_ROTATION_TOLERANCE_DEG,
    DEFAULT_SPHERE_DIAMETER, FlangeConvention, ImportError, ImportStage, Imported, LengthUnit,
    SideChoice,
};

use super::scan_flags::ScanFlags;
use super::values::{Keywords, Range, number};
use super::{CliError, QUIET_HELP};

/// `spherecal import`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("log").required(true).args(["joints", "poses"])))]
pub struct ImportArgs {
    /// The joint log CSV: one row a pose, with id, station, use and joint columns (see --map); needs --robot.
    #[arg(long)]
    pub joints: Option<PathBuf>,
    /// A pose file instead of a joint log: a table (header optional; commas, semicolons, tabs or spaces), a JSON list (RobCalibrator `.rob`), or a robot program (FANUC .ls, ABB RAPID, KUKA .dat/.src, URScript); the layout is detected from the content and printed. Flange poses give a pose-only session; joint targets need --robot.
    #[arg(long)]
    pub poses: Option<PathBuf>,
    /// How to read the pose file and the profiles (flags shared with
    /// the other command).
    #[command(flatten)]
    pub scan: ScanFlags,
    /// A folder of stripe profiles (`<id>.csv|txt|yml|yaml|json`; for a pose log without ids the files named alike, in the order of the number in their names: p7.yml, 7_3C_line.yml, scan_007.csv; other files, the pose file among them, are skipped and listed) or one CSV with a pose column.
    #[arg(long, required_unless_present = "centres", conflicts_with = "centres")]
    pub profiles: Option<PathBuf>,
    /// With --poses: the sphere centres the sensor reported, instead of profiles: a table with one `x y z` a pose (sensor frame, mm; any separator, header optional, an `id` column optional), paired with the poses in order. With --mount fixed (beside --joints or --poses): the fixed sensor's points (a tracker's table; see the guide's "A fixed sensor").
    #[arg(long)]
    pub centres: Option<PathBuf>,
    /// Where the sensor stands: `flange` (the sensor on the robot, the sphere in the cell) or `fixed` (a laser tracker, fixed camera or scanner in the cell measuring targets on the tool; reads --centres, or a fixed line scanner's --profiles, beside --joints or --poses).
    #[arg(long, value_enum, default_value_t = MountArg::Flange)]
    pub mount: MountArg,
    /// With --mount fixed: the unit of the points in --centres.
    #[arg(long, value_name = "UNIT", default_value = "mm", value_parser = ["mm", "m", "um"])]
    pub centre_unit: String,
    /// A hand-eye guess to start from instead of computing one: a JSON 4x4 matrix (rows, mm), or a session or result file (its `hand_eye`).
    #[arg(long)]
    pub hand_eye: Option<PathBuf>,
    /// Robot (help text with the presets' keys).
    #[arg(long, help = format!("Robot: a preset key ({}), a session/result file whose `robot` block is the nominal model, a URDF or a DH table CSV (with --dh). Needed with --joints; optional with --poses", super::preset_keys()))]
    pub robot: Option<String>,
    /// Side of the laser plane the sphere centres lie on, for a pose log without a side column.
    #[arg(long, default_value = "auto", allow_hyphen_values = true, value_parser = side_parser())]
    pub side: SideChoice,
    /// Where to write the session file (needed unless --preview).
    #[arg(long, short)]
    pub out: Option<PathBuf>,
    /// The joint log's columns, e.g. `id=Pose,station=Sphere,use=Use,side=Side,j1=A1,...`
    /// [default: id, station, use, side when the log has a `side` column, j1..jn]
    #[arg(long, value_delimiter = ',')]
    pub map: Vec<String>,
    /// Sphere diameter, mm.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_SPHERE_DIAMETER, value_parser = number(Range::positive("mm").at_most(crate::engine::base::limits::SPHERE_DIAMETER_MM)))]
    pub sphere_diameter: f64,
    /// The sensor's measuring range to write as `sensor.range`: `Y0,Y1,Z0,Z1` in mm (laser plane, sensor frame), e.g. `-40,40,-40,40`; ml then predicts the error over it.
    #[arg(long, value_name = "Y0,Y1,Z0,Z1", allow_hyphen_values = true, value_parser = super::parse_range)]
    pub range: Option<crate::engine::base::session::SensorRange>,
    /// Session name [default: the name of the joint log or pose file, without its extension]
    #[arg(long)]
    pub name: Option<String>,
    /// With --joints: check the flange poses the controller logged beside the joints against the nominal model, read in this convention.
    #[arg(long, requires = "joints", value_parser = super::scan_flags::convention_parser())]
    pub flange_poses: Option<FlangeConvention>,
    /// The flange-pose columns in the convention's order [default: x,y,z,q1..q4 | a,b,c | w,p,r | rx,ry,rz | m11..m44]
    #[arg(long, value_delimiter = ',', requires = "flange_poses")]
    pub flange_columns: Vec<String>,
    /// Flange-pose check: position tolerance, mm.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_POSITION_TOLERANCE_MM, value_parser = number(Range::positive("mm")))]
    pub position_tolerance: f64,
    /// Flange-pose check: rotation tolerance, deg.
    #[arg(long, value_name = "DEG", default_value_t = DEFAULT_ROTATION_TOLERANCE_DEG, value_parser = number(Range::positive("deg")))]
    pub rotation_tolerance: f64,
    /// Laser-tracker reference distances between validate stations: a CSV with columns from, to, distance (mm).
    #[arg(long)]
    pub references: Option<PathBuf>,
    /// With --joints: print the first N rows with the mapping applied and exit without writing.
    #[arg(long, value_name = "N", requires = "joints")]
    pub preview: Option<usize>,
    /// `-q`: [`QUIET_HELP`](super::QUIET_HELP).
    #[arg(long, short, help = QUIET_HELP)]
    pub quiet: bool,
}

/// `--mount`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MountArg {
    /// The sensor on the flange, the sphere fixed in the cell (the paper's).
    Flange,
    /// The sensor fixed in the cell, the targets on the flange.
    Fixed,
}

/// `--side`.
fn side_parser() -> Keywords<SideChoice> {
    Keywords::new(
        vec![
            ("+1", Some("Every centre at sensor x > 0")),
            ("-1", Some("Every centre at sensor x < 0")),
            (
                "auto",
                Some("Both sides calibrated, the clearly better one chosen, else refused"),
            ),
        ],
        SideChoice::parse,
    )
}

/// The import's choices from the flags (the workbench's form fills the
/// same [`ImportChoices`]). A hand-eye file is read by the caller, with
/// the command line's own words (see [`super::hand_eye_file`]).
///
/// # Errors
/// [`CliError`] (status 2) for a bad `--map` entry or an unknown robot.
pub fn choices(args: &ImportArgs) -> Result<ImportChoices, CliError> {
    let scan = &args.scan;
    let centres = args.centres.is_some();
    let mut choices = ImportChoices {
        mount: match args.mount {
            MountArg::Flange => Mount::Flange,
            MountArg::Fixed => Mount::Fixed,
        },
        log_kind: if args.poses.is_some() {
            LogKind::FlangePoses
        } else {
            LogKind::Joints
        },
        joints: args.joints.clone().unwrap_or_default(),
        poses: args.poses.clone().unwrap_or_default(),
        pose_format: scan.pose_format,
        pose_convention: scan.pose_convention,
        pose_columns: scan.pose_columns.clone(),
        observations: if centres {
            ObservationKind::Centres
        } else {
            ObservationKind::Profiles
        },
        profiles: args.profiles.clone().unwrap_or_default(),
        profiles_kind: match &args.profiles {
            Some(p) if !p.is_dir() => ProfilesKind::File,
            _ => ProfilesKind::Folder,
        },
        pose_column: scan.pose_column.clone(),
        profile_unit: scan.profile_unit,
        axes: scan.axes.clone(),
        no_return: scan.no_return.map(|v| v.to_string()).unwrap_or_default(),
        profile_key: scan.profile_key.clone(),
        centres: args.centres.clone().unwrap_or_default(),
        centre_unit: LengthUnit::parse(&args.centre_unit).ok_or_else(|| {
            CliError::input(format!("--centre-unit {}: mm, m or um", args.centre_unit))
        })?,
        side: args.side,
        robot_preset: String::new(),
        robot: args.robot.clone().unwrap_or_default(),
        urdf_tip: scan.urdf_tip.clone(),
        dh: scan.dh,
        joint_unit: scan.joint_unit,
        sphere_diameter: args.sphere_diameter,
        range: args.range.map(|r| [r.y[0], r.y[1], r.z[0], r.z[1]]),
        name: args.name.clone().unwrap_or_default(),
        flange: args.flange_poses,
        flange_columns: args.flange_columns.join(","),
        tolerance_mm: args.position_tolerance,
        tolerance_deg: args.rotation_tolerance,
        references: args.references.clone().unwrap_or_default(),
        ..ImportChoices::default()
    };
    if args.joints.is_some() {
        choices.columns = joint_log_columns(args)?;
    }
    Ok(choices)
}

fn input(e: &ImportError) -> CliError {
    CliError::input(e.to_string())
}

/// The joint log's columns: `--map` over the defaults `id`, `station`,
/// `use`, `j1..jn` (n the robot's joints).
///
/// # Errors
/// [`CliError`] (status 2): no `--robot`, a robot that does not load, a
/// bad `--map` entry.
fn joint_log_columns(args: &ImportArgs) -> Result<ColumnMap, CliError> {
    let robot = args
        .scan
        .robot_source(args.robot.as_deref().ok_or_else(|| {
        CliError::input(
            "--joints needs --robot (a preset key, a session/result file, a URDF or a DH table)",
        )
    })?)?;
    let dof = import::load_robot(&robot).map_err(|e| input(&e))?.dof();
    let mut columns = ColumnMap {
        joints: (1..=dof).map(|k| format!("j{k}")).collect(),
        ..ImportChoices::default().columns
    };
    for entry in &args.map {
        let Some((key, col)) = entry.split_once('=') else {
            return Err(CliError::input(format!(
                "--map entry `{entry}` is not KEY=Column"
            )));
        };
        let col = col.trim().to_string();
        match key.trim() {
            "id" => columns.id = col,
            "station" => columns.station = col,
            "use" => columns.usage = col,
            "side" => columns.side = Some(col),
            k => {
                let slot = k
                    .strip_prefix('j')
                    .and_then(|n| n.parse::<usize>().ok())
                    .filter(|n| (1..=dof).contains(n));
                let Some(n) = slot else {
                    return Err(CliError::input(format!(
                        "--map key `{k}` is not id, station, use, side or j1..j{dof}"
                    )));
                };
                columns.joints[n - 1] = col;
            }
        }
    }
    Ok(columns)
}

/// The `--out` path, required unless only previewing, refused when it is one of the import's inputs (the
/// pose log, a profile, the references or the robot file).
fn out_path(args: &ImportArgs) -> Result<PathBuf, CliError> {
    let out = args.out.clone().ok_or_else(|| {
        CliError::input("--out SESSION.json is needed (or --preview N to only look)")
    })?;
    let mut inputs: Vec<PathBuf> = args
        .joints
        .iter()
        .chain(&args.poses)
        .chain(&args.references)
        .cloned()
        .collect();
    if let Some(r) = &args.robot {
        inputs.push(PathBuf::from(r));
    }
    inputs.extend(args.centres.iter().chain(&args.hand_eye).cloned());
    if let Some(profiles) = &args.profiles {
        if profiles.is_dir() {
            // The files the import reads: the profiles named alike, not
            // what the folder's listing skips (an earlier output, the
            // pose file, a README).
            let exclude: Vec<&std::path::Path> = args
                .joints
                .iter()
                .chain(&args.poses)
                .map(PathBuf::as_path)
                .collect();
            if let Ok(listing) =
                crate::engine::files::import::pairing::list_profiles(profiles, &exclude, None)
            {
                inputs.extend(listing.profiles);
            }
        } else {
            inputs.push(profiles.clone());
        }
    }
    let inputs: Vec<&std::path::Path> = inputs.iter().map(PathBuf::as_path).collect();
    CliError::guard_output(&out, &inputs)?;
    Ok(out)
}

/// The progress of a long import: a line at most every
/// [`super::PROGRESS_EVERY`] (a small import prints none), and an
/// interrupt (Ctrl-C) stops it at the next profile (exit 130, nothing
/// written).
fn progress_lines(quiet: bool, started: Instant) -> impl FnMut(ImportStage) -> Control {
    let mut last = started;
    move |stage| {
        if format::interrupted() {
            return Control::Cancel;
        }
        if !quiet && let Some(line) = progress_line(stage, started, &mut last, Instant::now()) {
            sayln!("{line}");
        }
        Control::Continue
    }
}

/// The line to print for `stage` at `now`, if one is due (the last was
/// printed at `last`).
fn progress_line(
    stage: ImportStage,
    started: Instant,
    last: &mut Instant,
    now: Instant,
) -> Option<String> {
    if now.duration_since(*last) < super::PROGRESS_EVERY {
        return None;
    }
    *last = now;
    Some(format!(
        "  importing: {} ({:.0} s)",
        stage.describe(),
        now.duration_since(started).as_secs_f64()
    ))
}

/// Runs `spherecal import`: a flange-mounted sensor's profiles or
/// centres, or (`--mount fixed`) a fixed sensor's points or profiles.
///
/// # Errors
/// [`CliError`] with status 2 for bad input, 1 when the session cannot be
/// written.
pub fn run(args: &ImportArgs) -> Result<(), CliError> {
    let fixed = args.mount == MountArg::Fixed;
    if args.centres.is_some() && args.poses.is_none() && !fixed {
        return Err(CliError::input(
            "--centres reads beside a pose file (--poses), or beside a joint log with --mount fixed",
        ));
    }
    if fixed && args.centres.is_none() && args.profiles.is_none() {
        return Err(CliError::input(
            "--mount fixed needs --centres POINTS.csv (the sensor's points, one `x y z` a target and pose) or --profiles (a fixed line scanner's stripes)",
        ));
    }
    match (&args.poses, args.preview) {
        (Some(_), Some(_)) => {
            return Err(CliError::input("--preview reads a joint log (--joints)"));
        }
        (None, Some(n)) => {
            let spec = choices(args)?.joint_spec().map_err(|e| input(&e))?;
            say!("{}", import::preview(&spec, n).map_err(|e| input(&e))?);
            return Ok(());
        }
        _ => {}
    }
    // Every input refused as the output before any is read.
    let out = out_path(args)?;
    let mut request = choices(args)?.request().map_err(|e| input(&e))?;
    request.hand_eye = args
        .hand_eye
        .as_ref()
        .map(|path| super::hand_eye_file(path))
        .transpose()?;
    let mut lines = progress_lines(args.quiet, Instant::now());
    let Imported {
        session,
        checks,
        notes,
        ..
    } = assemble::import_session(&request, &mut |stage| {
        // The side decision calibrates both sides: said at once.
        if stage == ImportStage::Side && !args.quiet {
            sayln!("deciding the side of the laser plane from the data (both calibrated)…");
        }
        lines(stage)
    })
    .map_err(|e| input(&e))?;
    let out = &out;
    let text = format::session_to_json(&session);
    format::write_atomic(out, text.as_bytes()).map_err(|e| CliError::from_file(&e, false))?;
    if args.quiet {
        return Ok(());
    }
    if fixed {
        for note in &notes {
            sayln!("{note}");
        }
        let n = session.measurements.len();
        sayln!(
            "imported {n} measurements (sensor.mount fixed) into {}",
            out.display()
        );
        return Ok(());
    }
    if !session.reference_distances.is_empty() {
        sayln!(
            "{} reference distances between validate stations",
            session.reference_distances.len()
        );
    }
    sayln!(
        "imported {} measurements at {} station(s) into {}",
        session.measurements.len(),
        {
            let mut s: Vec<&str> = session
                .measurements
                .iter()
                .map(|m| m.station.as_str())
                .collect();
            s.sort_unstable();
            s.dedup();
            s.len()
        },
        out.display()
    );
    for note in &notes {
        sayln!("{note}");
    }
    if !checks.is_empty() {
        let flagged: Vec<_> = checks.iter().filter(|c| c.flagged).collect();
        let worst = checks
            .iter()
            .map(|c| c.position_error_mm)
            .fold(0.0_f64, f64::max);
        sayln!(
            "flange poses: {} checked, {} flagged (largest position mismatch {worst:.3} mm)",
            checks.len(),
            flagged.len()
        );
        for c in flagged {
            sayln!(
                "  flagged pose {}: {:.3} mm, {:.3} deg: {}",
                c.id,
                c.position_error_mm,
                c.rotation_error_deg,
                c.hint
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;

    #[test]
    fn a_long_import_prints_a_progress_line_every_two_seconds() {
        let t0 = Instant::now();
        let mut last = t0;
        let stage = ImportStage::Profiles {
            done: 120,
            total: 9600,
        };
        assert_eq!(
            progress_line(stage, t0, &mut last, t0 + Duration::from_millis(1500)),
            None
        );
        assert_eq!(
            progress_line(stage, t0, &mut last, t0 + Duration::from_secs(3)).as_deref(),
            Some("  importing: reading profiles: 120 of 9600 (3 s)")
        );
        assert_eq!(
            progress_line(
                ImportStage::Side,
                t0,
                &mut last,
                t0 + Duration::from_secs(4)
            ),
            None
        );
        assert_eq!(
            progress_line(
                ImportStage::Side,
                t0,
                &mut last,
                t0 + Duration::from_secs(5)
            )
            .as_deref(),
            Some("  importing: deciding the stripe side (calibrating both) (5 s)")
        );
    }
}
