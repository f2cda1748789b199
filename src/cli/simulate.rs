//! `spherecal simulate`: writes a seeded simulated session (FORMAT.md) and
//! its ground truth (`spherecal-truth`), both atomically, and prints one
//! summary line. With `--plan` the poses come from a plan CSV
//! (`spherecal plan --csv`) instead of the simulator's own generation;
//! with `--csv-out DIR` it also writes the joint log, stripe profiles and
//! reference distances that `spherecal import` reads. A thin caller of
//! [`crate::engine::tools::simulate`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::ValueEnum;

use super::values::{Keywords, Range, count, number};
use super::{CliError, QUIET_HELP};
use crate::engine::base::cell::sensor;
use crate::engine::base::robot::{self, RobotChoice};
use crate::engine::base::session::{Session, Use};
use crate::engine::files::format;
use crate::engine::tools::plan;
use crate::engine::tools::simulate::config::{
    MAX_GROUP_POSES, MAX_JOINT_NOISE_DEG, MAX_SENSOR_NOISE_MM, MAX_STATIONS, MAX_TRACKER_NOISE_MM,
};
use crate::engine::tools::simulate::{
    self, ErrorModel, InitialHandEye, PartKind, PlanExecution, ScanConfig, SideChoice, SimConfig,
    SimError,
};

/// Robot preset (`--robot`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RobotArg {
    /// ABB IRB 2400/16, the paper's robot.
    Irb2400,
    /// ABB IRB 120.
    Irb120,
    /// Universal Robots UR5e.
    Ur5e,
}

impl From<RobotArg> for RobotChoice {
    fn from(r: RobotArg) -> Self {
        match r {
            RobotArg::Irb2400 => Self::Irb2400,
            RobotArg::Irb120 => Self::Irb120,
            RobotArg::Ur5e => Self::Ur5e,
        }
    }
}

/// Kinematic error model (`--errors`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ErrorsArg {
    /// The paper's Table 1.
    Table1,
    /// Gaussian: σ 0.1° for angles, 0.3 mm for lengths (times --error-scale).
    Random,
    /// The true robot is the nominal one.
    None,
}

impl From<ErrorsArg> for ErrorModel {
    fn from(e: ErrorsArg) -> Self {
        match e {
            ErrorsArg::Table1 => Self::Table1,
            ErrorsArg::Random => Self::Random,
            ErrorsArg::None => Self::None,
        }
    }
}

/// Side of the laser plane (`--side`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SideArg {
    /// Both sides, about half each.
    Mixed,
    /// Every centre at sensor x > 0.
    Plus,
    /// Every centre at sensor x < 0.
    Minus,
}

impl From<SideArg> for SideChoice {
    fn from(s: SideArg) -> Self {
        match s {
            SideArg::Mixed => Self::Mixed,
            SideArg::Plus => Self::Plus,
            SideArg::Minus => Self::Minus,
        }
    }
}

/// The fixed sensor simulated (`--fixed-sensor`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FixedSensorArg {
    /// A laser tracker 2.6 m from the base, three SMRs on the tool.
    Tracker,
    /// A fixed 3-D scanner, one sphere on the tool.
    Scanner,
    /// A fixed laser line scanner, one sphere on the tool cut by its plane: stripe profiles.
    LineScanner,
}

/// `spherecal simulate`: a simulated session with a known truth, for tests,
/// demos and what-if studies. Defaults give the paper-like demo.
#[derive(Debug, Clone, clap::Args)]
pub struct SimulateArgs {
    /// Where to write the session file (FORMAT.md `spherecal-session`); with --scan, the scan's truth.
    #[arg(long, short)]
    pub out: PathBuf,
    /// `-q`: [`QUIET_HELP`](super::QUIET_HELP).
    #[arg(long, short, help = QUIET_HELP)]
    pub quiet: bool,
    /// The sensor's measuring range to write as `sensor.range`: `Y0,Y1,Z0,Z1` in mm (laser plane, sensor frame), e.g. `-40,40,-40,40`; ml then predicts the error over it.
    #[arg(long, value_name = "Y0,Y1,Z0,Z1", allow_hyphen_values = true, value_parser = super::parse_range)]
    pub range: Option<crate::engine::base::session::SensorRange>,
    /// Spread the sphere over --range: identify and validate measurements
    /// see the sphere centre anywhere in the range (uniform along the line
    /// and in depth) instead of the paper's ±2, ±3 mm spot.
    #[arg(long, requires = "range", conflicts_with = "plan")]
    pub spread: bool,
    /// Where to write the truth file [default: the session path with
    /// `.json` replaced by `.truth.json`]
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// Seed of every random choice; the same arguments give byte-identical files.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Robot preset (nominal model, joint limits, station box).
    #[arg(long, value_enum, default_value_t = RobotArg::Irb2400)]
    pub robot: RobotArg,
    /// Kinematic errors of the true robot.
    #[arg(long, value_enum, default_value_t = ErrorsArg::Table1)]
    pub errors: ErrorsArg,
    /// Multiplies the kinematic errors (table1 and random).
    #[arg(long, default_value_t = 1.0)]
    pub error_scale: f64,
    /// Number of identify stations (P1..), --poses measurements each.
    #[arg(long, default_value_t = SimConfig::default().n_identify, value_parser = count(1, MAX_STATIONS))]
    pub identify_stations: usize,
    /// Number of validate stations (V1..); consecutive ones get a reference distance.
    #[arg(long, default_value_t = SimConfig::default().n_validate, value_parser = count(0, MAX_STATIONS))]
    pub validate_stations: usize,
    /// Measurements per identify or validate station.
    #[arg(long, default_value_t = SimConfig::default().poses_per_station, value_parser = count(2, MAX_GROUP_POSES))]
    pub poses: usize,
    /// σ of the joint reading noise, deg.
    #[arg(long, value_name = "DEG", default_value_t = SimConfig::default().joint_noise, value_parser = number(Range::non_negative("deg").at_most(MAX_JOINT_NOISE_DEG)))]
    pub joint_noise: f64,
    /// σ of the stripe point noise on each coordinate, mm.
    #[arg(long, value_name = "MM", default_value_t = SimConfig::default().stripe_noise, value_parser = number(Range::non_negative("mm").at_most(MAX_SENSOR_NOISE_MM)))]
    pub stripe_noise: f64,
    /// Fraction (0 to 1) of stripe points made outliers, displaced 0.3-3 mm.
    #[arg(long, default_value_t = SimConfig::default().outlier_fraction, value_parser = number(Range::fraction()))]
    pub outliers: f64,
    /// Side of the laser plane the sphere centres lie on.
    #[arg(long, value_enum, default_value_t = SideArg::Mixed)]
    pub side: SideArg,
    /// Write sphere centres (sensor frame) instead of stripes.
    #[arg(long)]
    pub centres: bool,
    /// σ of the centre noise on each coordinate with --centres, mm.
    #[arg(long, value_name = "MM", default_value_t = SimConfig::default().centre_noise, value_parser = number(Range::non_negative("mm").at_most(MAX_SENSOR_NOISE_MM)))]
    pub centre_noise: f64,
    /// σ of the laser-tracker reference distances, mm.
    #[arg(long, value_name = "MM", default_value_t = SimConfig::default().tracker_noise, value_parser = number(Range::non_negative("mm").at_most(MAX_TRACKER_NOISE_MM)))]
    pub tracker_noise: f64,
    /// Session name [default: `simulated <robot>, seed <seed>`]
    #[arg(long)]
    pub name: Option<String>,
    /// Write the paper's initial hand-eye into the session; without it the session has none and the engine computes it from the translation and rotation measurements.
    #[arg(long)]
    pub with_hand_eye: bool,
    /// Sphere diameter, mm.
    #[arg(long, value_name = "MM", default_value_t = SimConfig::default().diameter, value_parser = number(Range::positive("mm").at_most(crate::engine::base::limits::SPHERE_DIAMETER_MM)))]
    pub diameter: f64,
    /// Spacing of the stripe points along the arc, mm (0.5: ~57 points a stripe; 0.1: ~280, as the demo session).
    #[arg(long, value_name = "MM", default_value_t = SimConfig::default().point_spacing, value_parser = number(Range::positive("mm")))]
    pub point_spacing: f64,
    /// Simulate the poses of a plan CSV (`spherecal plan --csv`) on the --robot preset with --errors, instead of generating poses: the robot goes to the plan's joints, the sphere stands where it then sees the planned centres on average.
    #[arg(long)]
    pub plan: Option<PathBuf>,
    /// With --plan: the true hand-eye, a JSON 4x4 (rows, mm) or a session/result file's `hand_eye` [default: the paper's calibrated hand-eye, the paper's guess error applied to its initial one]
    #[arg(long, requires = "plan")]
    pub hand_eye: Option<PathBuf>,
    /// With --plan: touch every pose up as when teaching (the smallest joint change that puts the sphere at the planned sensor-frame centre on the true robot) instead of running the plan's joints as written.
    #[arg(long, requires = "plan")]
    pub touch_up: bool,
    /// Also write what `spherecal import` reads: DIR/joints.csv (joint log with the nominal ABB flange pose), DIR/profiles/<id>.csv (y,z mm) and DIR/references.csv (from,to,distance mm). With --mount fixed: DIR/joints.csv (id,use,j1..jn), DIR/poses.csv (id,use,x,y,z,q1..q4: the nominal flange poses) and DIR/points.csv (pose,target,x,y,z) or, for the line scanner, DIR/profiles/<pose>.csv.
    #[arg(long)]
    pub csv_out: Option<PathBuf>,
    /// Simulate a raw scan of this part instead of a session, with the cell of the same seed, robot and errors. Writes the joint log and profiles (`nan,nan` where a ray meets nothing) into --csv-out and the scan's truth (`spherecal-scan-truth`: the part in the base frame, the true robot, hand-eye and actual joints) to --out.
    #[arg(long, value_parser = Keywords::new(vec![("plane", Some("A plane")), ("spheres", Some("Three spheres of --diameter: a sphere artefact")), ("steps", Some("A stepped block on a table"))], PartKind::parse), requires = "csv_out", conflicts_with_all = ["plan", "centres", "spread"])]
    pub scan: Option<PartKind>,
    /// With --scan: poses along the path (per sphere for `spheres`).
    #[arg(long, requires = "scan", default_value_t = ScanConfig::default().poses, value_parser = count(1, MAX_SCAN_POSES))]
    pub scan_poses: usize,
    /// A pose-only session: every measurement reports its flange pose (the true flange position plus Gaussian error of this σ, mm, each base-frame coordinate) instead of joints, and the session has no robot (as a cell whose controller reports poses). With --mount fixed: each pose's flange pose with its error, shared by the pose's targets.
    #[arg(long, value_name = "MM", conflicts_with_all = ["plan", "scan", "csv_out"], value_parser = number(Range::non_negative("mm").at_most(MAX_SENSOR_NOISE_MM)))]
    pub pose_only: Option<f64>,
    /// Where the sensor stands: `flange` (the paper's cell) or `fixed` (a sensor fixed in the cell measuring targets on the tool; see --fixed-sensor).
    #[arg(long, value_enum, default_value_t = super::import::MountArg::Flange)]
    pub mount: super::import::MountArg,
    /// With --mount fixed: a laser tracker and three SMRs on the tool, or a fixed scanner and one sphere.
    #[arg(long, value_enum, default_value_t = FixedSensorArg::Tracker)]
    pub fixed_sensor: FixedSensorArg,
    /// With --mount fixed: the sensor's noise, mm (1σ a coordinate; the scanner's depth three times it; the line scanner's on every stripe point).
    #[arg(long, value_name = "MM", default_value_t = 0.01, value_parser = number(Range::non_negative("mm").at_most(MAX_SENSOR_NOISE_MM)))]
    pub sensor_noise: f64,
}

/// Most poses of a simulated scan (per sphere for `spheres`): a scan of
/// hundreds of thousands of profiles is no longer a test input.
pub const MAX_SCAN_POSES: usize = 100_000;

/// The engine's names of the settings in a simulation error, and the
/// flags that set them.
const FLAG_NAMES: [(&str, &str); 13] = [
    (
        "n_identify + n_validate",
        "--identify-stations + --validate-stations",
    ),
    ("error_scale", "--error-scale"),
    ("joint_noise", "--joint-noise"),
    ("stripe_noise", "--stripe-noise"),
    ("pose_only", "--pose-only"),
    ("outlier_fraction", "--outliers"),
    ("point_spacing", "--point-spacing"),
    ("centre_noise", "--centre-noise"),
    ("tracker_noise", "--tracker-noise"),
    ("poses_per_station", "--poses"),
    ("range z", "--range Z1"),
    ("view_z", "the simulated camera's distance"),
    ("arc_half_angle", "the stripe's half-angle"),
];

/// A simulation error, the settings named by their flags.
fn sim_error(e: &SimError) -> CliError {
    CliError::input(super::name_flags(&e.to_string(), &FLAG_NAMES))
}

impl SimulateArgs {
    /// The engine configuration: [`SimConfig::default`] with these options.
    #[must_use]
    pub fn to_config(&self) -> SimConfig {
        SimConfig {
            seed: self.seed,
            name: self.name.clone(),
            robot: self.robot.into(),
            errors: self.errors.into(),
            error_scale: self.error_scale,
            initial_hand_eye: if self.with_hand_eye {
                InitialHandEye::Paper
            } else {
                InitialHandEye::None
            },
            n_identify: self.identify_stations,
            n_validate: self.validate_stations,
            poses_per_station: self.poses,
            joint_noise: self.joint_noise,
            stripe_noise: self.stripe_noise,
            outlier_fraction: self.outliers,
            centres: self.centres,
            centre_noise: self.centre_noise,
            side: self.side.into(),
            tracker_noise: self.tracker_noise,
            diameter: self.diameter,
            point_spacing: self.point_spacing,
            range: self.range,
            spread: self.spread,
            pose_only: self.pose_only,
            ..SimConfig::default()
        }
    }

    /// The truth file path: `--truth`, else the session path with `.json`
    /// replaced by `.truth.json` (appended when it has no `.json`).
    #[must_use]
    pub fn truth_path(&self) -> PathBuf {
        self.truth
            .clone()
            .unwrap_or_else(|| default_truth_path(&self.out))
    }
}

/// The import inputs of `session` as files under `dir`: `joints.csv`,
/// `profiles/<id>.csv` and `references.csv` (when there are reference
/// distances).
fn import_files(session: &Session, dir: &Path) -> Result<Vec<(PathBuf, String)>, CliError> {
    let files = simulate::import_files(session).map_err(|e| CliError::input(e.to_string()))?;
    let profiles = dir.join("profiles");
    let mut out = vec![(dir.join("joints.csv"), files.joints_csv)];
    for (id, text) in files.profiles {
        out.push((profiles.join(format!("{id}.csv")), text));
    }
    if let Some(text) = files.references_csv {
        out.push((dir.join("references.csv"), text));
    }
    Ok(out)
}

/// `simulate --scan`: the raw scan's files into `dir`, its truth to `--out`.
fn run_scan(
    args: &SimulateArgs,
    part: PartKind,
    dir: &Path,
    started: Instant,
) -> Result<(), CliError> {
    let defaults = ScanConfig::default();
    let scan = ScanConfig {
        part,
        poses: args.scan_poses,
        range: args.range.unwrap_or(defaults.range),
    };
    let sim = simulate::simulate_scan(&args.to_config(), &scan).map_err(|e| sim_error(&e))?;
    let truth = serde_json::to_string_pretty(&sim.truth)
        .map_err(|e| CliError::internal(format!("the scan truth: {e}")))?;
    let truth = format!("{truth}\n");
    // Every file or none, as the session's outputs.
    let profiles = dir.join("profiles");
    let mut files: Vec<(PathBuf, &str)> = vec![(dir.join("joints.csv"), &sim.joints_csv)];
    for (id, text) in &sim.profiles {
        files.push((profiles.join(format!("{id}.csv")), text));
    }
    if let Some(text) = &sim.references_csv {
        files.push((dir.join("references.csv"), text));
    }
    files.push((args.out.clone(), &truth));
    let files: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, t)| (p.as_path(), t.as_bytes()))
        .collect();
    super::write_outputs(&files, format::Folders::Create)?;
    if args.quiet {
        return Ok(());
    }
    sayln!(
        "simulated a scan of a {part:?} part (seed {}): {} poses -> {}/joints.csv, {}/profiles/, truth {} ({:.0} ms)",
        args.seed,
        sim.profiles.len(),
        dir.display(),
        dir.display(),
        args.out.display(),
        started.elapsed().as_secs_f64() * 1e3,
    );
    Ok(())
}

fn default_truth_path(out: &Path) -> PathBuf {
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem = name.strip_suffix(".json").unwrap_or(&name);
    out.with_file_name(format!("{stem}.truth.json"))
}

/// Runs `spherecal simulate`: checks the options and every output, then
/// simulates and writes the session, the truth and the `--csv-out` files
/// as one transaction (all of them or none, each through a temporary file
/// renamed into place), and prints one summary line.
///
/// # Errors
/// A setting out of range or an unreachable station (the engine's
/// message), the two paths being the same file, or a file that cannot be
/// written (naming it).
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let started = Instant::now();
    let inputs: Vec<&Path> = args
        .plan
        .iter()
        .chain(&args.hand_eye)
        .map(PathBuf::as_path)
        .collect();
    // Folders may yet be created: only the inputs are refused here.
    let refuse = |out: &Path| {
        format::refuse_inputs(out, &inputs).map_err(|e| CliError::input(e.to_string()))
    };
    if let Some(dir) = &args.csv_out {
        refuse(&dir.join("joints.csv"))?;
        refuse(&dir.join("references.csv"))?;
    }
    if let (Some(part), Some(dir)) = (args.scan, &args.csv_out) {
        refuse(&args.out)?;
        return run_scan(args, part, dir, started);
    }
    let truth_path = args.truth_path();
    if truth_path == args.out {
        return Err(CliError::input(format!(
            "the session and the truth would both be written to {}; give --truth another path",
            args.out.display()
        )));
    }
    CliError::guard_output(&args.out, &inputs)?;
    CliError::guard_output(&truth_path, &inputs)?;
    let mut outputs: Vec<&Path> = vec![&args.out, &truth_path];
    let csv_targets: Vec<PathBuf> = args
        .csv_out
        .iter()
        .flat_map(|d| [d.join("joints.csv"), d.join("references.csv")])
        .collect();
    outputs.extend(csv_targets.iter().map(PathBuf::as_path));
    let folders = if args.csv_out.is_some() {
        format::Folders::Create
    } else {
        format::Folders::Existing
    };
    super::check_outputs(&outputs, folders)?;
    let config = args.to_config();
    config.validate().map_err(|e| sim_error(&e))?;
    let (mut session, truth) = match &args.plan {
        None => simulate::simulate(&config).map_err(|e| sim_error(&e))?,
        Some(path) => {
            let text = format::read_text(path, format::Cap::TABLE).map_err(|e| {
                CliError::input(format!("reading failed ({}): {e}", path.display()))
            })?;
            let poses = plan::read_plan_csv(&text)
                .map_err(|e| CliError::input(format!("{e} ({})", path.display())))?;
            let nominal = robot::preset(config.robot.key())
                .map(|p| p.robot)
                .ok_or_else(|| CliError::input(format!("unknown robot {}", config.robot.key())))?;
            let hand_eye = match &args.hand_eye {
                Some(he) => super::hand_eye_file(he)?,
                None => sensor::paper_hand_eye(),
            };
            let execution = if args.touch_up {
                PlanExecution::TouchUp
            } else {
                PlanExecution::AsPlanned
            };
            simulate::simulate_plan(&config, &nominal, &hand_eye, &poses, execution)
                .map_err(|e| CliError::input(format!("{e} ({})", path.display())))?
        }
    };
    if args.range.is_some() {
        // A plan's simulation echoes the configuration too; set it here
        // for every path.
        session.sensor_range = args.range;
    }
    // Whatever the options, never write a session spherecal's own loader
    // refuses.
    session.validate().map_err(|e| {
        CliError::input(format!(
            "the simulated session would not load, nothing is written: {e} ({})",
            args.out.display()
        ))
    })?;
    let mut files = vec![
        (args.out.clone(), format::session_to_json(&session)),
        (truth_path.clone(), simulate::truth_to_json(&truth)),
    ];
    if let Some(dir) = &args.csv_out {
        files.extend(import_files(&session, dir)?);
    }
    let files: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, t)| (p.as_path(), t.as_bytes()))
        .collect();
    super::write_outputs(&files, folders)?;
    if args.quiet {
        return Ok(());
    }
    let count = |usage: Use| session.with_use(usage).count();
    sayln!(
        "simulated {} (seed {}): {} measurements ({} translation, {} rotation, {} identify, {} validate), {} reference distances -> {}, truth {} ({:.0} ms)",
        session.robot.name,
        config.seed,
        session.measurements.len(),
        count(Use::Translation),
        count(Use::Rotation),
        count(Use::Identify),
        count(Use::Validate),
        session.reference_distances.len(),
        args.out.display(),
        truth_path.display(),
        started.elapsed().as_secs_f64() * 1e3,
    );
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    fn parse(extra: &[&str]) -> SimulateArgs {
        let mut argv = vec!["simulate", "--out", "dir/s.json"];
        argv.extend_from_slice(extra);
        super::super::parse_flags(&argv)
    }

    #[test]
    fn defaults_are_the_engine_defaults() {
        let args = parse(&[]);
        assert_eq!(args.to_config(), SimConfig::default());
        assert_eq!(args.truth_path(), PathBuf::from("dir/s.truth.json"));
    }

    #[test]
    fn options_reach_the_config() {
        let args = parse(&[
            "--seed",
            "7",
            "--robot",
            "ur5e",
            "--errors",
            "random",
            "--error-scale",
            "2",
            "--identify-stations",
            "4",
            "--validate-stations",
            "3",
            "--poses",
            "5",
            "--joint-noise",
            "0.01",
            "--stripe-noise",
            "0.05",
            "--outliers",
            "0.1",
            "--side",
            "plus",
            "--centres",
            "--centre-noise",
            "0.02",
            "--tracker-noise",
            "0.03",
            "--name",
            "cell 3",
            "--with-hand-eye",
            "--truth",
            "t.json",
        ]);
        let c = args.to_config();
        assert_eq!(c.seed, 7);
        assert_eq!(c.robot, RobotChoice::Ur5e);
        assert_eq!(c.errors, ErrorModel::Random);
        assert_eq!(c.error_scale, 2.0);
        assert_eq!((c.n_identify, c.n_validate, c.poses_per_station), (4, 3, 5));
        assert_eq!(
            (c.joint_noise, c.stripe_noise, c.outlier_fraction),
            (0.01, 0.05, 0.1)
        );
        assert_eq!(c.side, SideChoice::Plus);
        assert!(c.centres);
        assert_eq!((c.centre_noise, c.tracker_noise), (0.02, 0.03));
        assert_eq!(c.name.as_deref(), Some("cell 3"));
        assert_eq!(c.initial_hand_eye, InitialHandEye::Paper);
        assert_eq!(args.truth_path(), PathBuf::from("t.json"));
    }

    #[test]
    fn truth_path_without_json_extension() {
        assert_eq!(
            default_truth_path(Path::new("a/run")),
            PathBuf::from("a/run.truth.json")
        );
    }
}
