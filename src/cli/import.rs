//! `spherecal import`: a joint log CSV plus stripe profiles become a session
//! file (written atomically), with an optional check of the controller's
//! flange poses against the nominal model. A thin caller of
//! [`crate::engine::import`].

use std::path::PathBuf;

use clap::Args;

use crate::engine::format;
use crate::engine::import::{
    self, AngleUnit, ColumnMap, DEFAULT_POSITION_TOLERANCE_MM, DEFAULT_ROTATION_TOLERANCE_DEG,
    DEFAULT_SPHERE_DIAMETER, FlangeCheck, FlangeConvention, ImportError, ImportSpec, LengthUnit,
    ProfileSource, RobotSource,
};

use super::CliError;

/// `spherecal import`.
#[derive(Debug, Args)]
pub struct ImportArgs {
    /// The joint log CSV: one row a pose, with id, station, use and joint columns.
    #[arg(long)]
    pub joints: PathBuf,
    /// A folder of `<id>.csv` stripe files (columns y, z) or one CSV with a pose column.
    #[arg(long)]
    pub profiles: PathBuf,
    /// Column of the pose id in a single profile file.
    #[arg(long, default_value = "pose")]
    pub pose_column: String,
    /// Robot preset key (irb2400, irb120, ur5e) or a session/result file whose `robot` block is the nominal model.
    #[arg(long)]
    pub robot: String,
    /// Where to write the session file (required unless --preview).
    #[arg(long, short)]
    pub out: Option<PathBuf>,
    /// Unit of the joint columns: deg or rad.
    #[arg(long, default_value = "deg", value_parser = parse_angle_unit)]
    pub joint_unit: AngleUnit,
    /// Unit of the profile coordinates: mm, um or m.
    #[arg(long, default_value = "mm", value_parser = parse_length_unit)]
    pub profile_unit: LengthUnit,
    /// Column mapping, e.g. `id=Pose,station=Sphere,use=Use,side=Side,j1=A1,...`
    /// (defaults: id, station, use, side when the log has a `side` column, j1..jn).
    #[arg(long, value_delimiter = ',')]
    pub map: Vec<String>,
    /// Sphere diameter, mm.
    #[arg(long, default_value_t = DEFAULT_SPHERE_DIAMETER)]
    pub sphere_diameter: f64,
    /// Session name (default: the joint log's file name).
    #[arg(long)]
    pub name: Option<String>,
    /// Check the controller's flange poses: ABB (quaternion), KUKA (ABC), FANUC (WPR) or UR (rotation vector).
    #[arg(long, value_parser = parse_convention)]
    pub flange_poses: Option<FlangeConvention>,
    /// The flange-pose columns in the convention's order (default: x,y,z,q1..q4 | a,b,c | w,p,r | rx,ry,rz).
    #[arg(long, value_delimiter = ',')]
    pub flange_columns: Vec<String>,
    /// Flange-pose position tolerance, mm.
    #[arg(long, default_value_t = DEFAULT_POSITION_TOLERANCE_MM)]
    pub position_tolerance: f64,
    /// Flange-pose rotation tolerance, deg.
    #[arg(long, default_value_t = DEFAULT_ROTATION_TOLERANCE_DEG)]
    pub rotation_tolerance: f64,
    /// Laser-tracker reference distances between validate stations: a CSV with columns from, to, distance (mm).
    #[arg(long)]
    pub references: Option<PathBuf>,
    /// Print the first N rows with the mapping applied and exit without writing.
    #[arg(long)]
    pub preview: Option<usize>,
}

fn parse_angle_unit(s: &str) -> Result<AngleUnit, String> {
    AngleUnit::parse(s).ok_or_else(|| format!("unknown joint unit `{s}`, expected `deg` or `rad`"))
}

fn parse_length_unit(s: &str) -> Result<LengthUnit, String> {
    LengthUnit::parse(s)
        .ok_or_else(|| format!("unknown profile unit `{s}`, expected `mm`, `um` or `m`"))
}

fn parse_convention(s: &str) -> Result<FlangeConvention, String> {
    FlangeConvention::parse(s)
        .ok_or_else(|| format!("unknown flange convention `{s}`, expected ABB, KUKA, FANUC or UR"))
}

fn input(e: &ImportError) -> CliError {
    CliError::input(e.to_string())
}

/// The engine's spec from the flags.
///
/// # Errors
/// [`CliError`] (status 2) for a bad `--map` entry or an unknown robot.
pub fn spec(args: &ImportArgs) -> Result<ImportSpec, CliError> {
    let robot = if args.robot.ends_with(".json") {
        RobotSource::File(PathBuf::from(&args.robot))
    } else {
        RobotSource::Preset(args.robot.clone())
    };
    let dof = import::load_robot(&robot).map_err(|e| input(&e))?.dof();
    let mut columns = ColumnMap {
        id: "id".into(),
        station: "station".into(),
        usage: "use".into(),
        side: None,
        joints: (1..=dof).map(|k| format!("j{k}")).collect(),
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
    let profiles = if args.profiles.is_dir() {
        ProfileSource::Folder(args.profiles.clone())
    } else {
        ProfileSource::File {
            path: args.profiles.clone(),
            pose_column: args.pose_column.clone(),
        }
    };
    let flange = args.flange_poses.map(|convention| {
        let mut check = FlangeCheck::new(convention);
        if !args.flange_columns.is_empty() {
            check.columns.clone_from(&args.flange_columns);
        }
        check.tolerance_mm = args.position_tolerance;
        check.tolerance_deg = args.rotation_tolerance;
        check
    });
    Ok(ImportSpec {
        joint_log: args.joints.clone(),
        columns,
        joint_unit: args.joint_unit,
        profiles,
        profile_unit: args.profile_unit,
        robot,
        sphere_diameter: args.sphere_diameter,
        name: args.name.clone(),
        flange,
        references: args.references.clone(),
    })
}

/// Runs `spherecal import`.
///
/// # Errors
/// [`CliError`] with status 2 for bad input, 1 when the session cannot be
/// written.
pub fn run(args: &ImportArgs) -> Result<(), CliError> {
    let spec = spec(args)?;
    if let Some(n) = args.preview {
        print!("{}", import::preview(&spec, n).map_err(|e| input(&e))?);
        return Ok(());
    }
    let Some(out) = &args.out else {
        return Err(CliError::input(
            "--out SESSION.json is needed (or --preview N to only look)",
        ));
    };
    let (session, checks) = import::import(&spec).map_err(|e| input(&e))?;
    let text = format::session_to_json(&session);
    format::write_atomic(out, text.as_bytes()).map_err(|e| CliError::from_file(&e, false))?;
    if !session.reference_distances.is_empty() {
        println!(
            "{} reference distances between validate stations",
            session.reference_distances.len()
        );
    }
    println!(
        "imported {} measurements at {} stations into {}",
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
    if !checks.is_empty() {
        let flagged: Vec<_> = checks.iter().filter(|c| c.flagged).collect();
        let worst = checks
            .iter()
            .map(|c| c.position_error_mm)
            .fold(0.0_f64, f64::max);
        println!(
            "flange poses: {} checked, {} flagged (largest position mismatch {worst:.3} mm)",
            checks.len(),
            flagged.len()
        );
        for c in flagged {
            println!(
                "  flagged pose {}: {:.3} mm, {:.3} deg: {}",
                c.id, c.position_error_mm, c.rotation_error_deg, c.hint
            );
        }
    }
    Ok(())
}
