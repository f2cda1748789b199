//! `spherecal measure`: a session's stripes, or a raw scan (the import's
//! pose log and profiles), into a point cloud in the robot base frame (or
//! a workpiece frame) through a result's calibrated model and hand-eye,
//! each point with its σ; the sphere self-validation; PLY, E57 or CSV by
//! the output's extension. A thin caller of [`crate::engine::uses::measure`].

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;

use super::scan_flags::ScanFlags;
use super::values::{Keywords, Range, number};
use super::{CliError, QUIET_HELP};
use crate::engine::base::numeric::plural;
use crate::engine::base::robot::kinematics::Robot;
use crate::engine::base::session::Use;
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format;
use crate::engine::files::import::{self, ProfileSource};
use crate::engine::uses::measure::{
    self, CloudFormat, JointRange, LISTED_POSES, MeasureError, MeasureOptions, MeasureRequest,
    ModelChoice, Outcome, Provenance, ScanColumns, ScanFiles, ScanLog, ScanSource,
};

/// `spherecal measure`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["session", "joints", "poses"])))]
pub struct MeasureArgs {
    /// A session file: its stripes are measured as they are (every point of every stripe of the measurements chosen by --use).
    pub session: Option<PathBuf>,
    /// The result file whose calibrated model and hand-eye place the sensor (σ needs an `ml` result).
    #[arg(long)]
    pub result: PathBuf,
    /// Where to write the cloud, the extension choosing the format: `.ply` (binary: x y z double mm, sigma_mm float, pose uint), `.e57` (one scan a pose) or `.csv` (id,x,y,z,sigma_mm).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Which measurements of a session: `all`, or a comma-separated list of their uses.
    #[arg(long = "use", value_delimiter = ',', default_value = "all", value_parser = use_parser())]
    pub usage: Vec<Uses>,
    /// Write the cloud in this workpiece frame: a JSON 4x4 `base_from_workpiece` (4 rows of 4 numbers, mm; bare or under that key) [default: the robot base frame]
    #[arg(long)]
    pub frame: Option<PathBuf>,
    /// Write no σ (sigma_mm NaN in PLY and CSV, left out of E57): for a result without covariance (`--method paper`).
    #[arg(long)]
    pub no_sigma: bool,
    /// The sensor's own noise: 1σ of each in-plane coordinate of a profile point, mm, added to σ in quadrature (2·s²).
    #[arg(long, value_name = "MM", default_value_t = 0.0, value_parser = number(Range::non_negative("mm").at_most(MAX_SENSOR_NOISE_MM)))]
    pub sensor_noise: f64,
    /// Use the result's parameter covariance as written, not scaled by its variance factor (`solver.variance_factor`, ≈ 1 when ml's noise model fits the data).
    #[arg(long)]
    pub covariance_as_written: bool,
    /// Which model of the result places the sensor.
    #[arg(long, default_value = "calibrated", value_parser = model_parser())]
    pub model: ModelChoice,
    /// The session the result was calibrated from: its identify poses give the joint range the calibration saw [default: the measured session itself; a raw scan without it is not checked]
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    /// Raw scan: a joint log CSV (columns id and j1..jn, optional station and use; see --map).
    #[arg(long, conflicts_with = "poses")]
    pub joints: Option<PathBuf>,
    /// Raw scan: a pose file instead of a joint log, as the import reads it (a table with or without header, a JSON list, or a robot program: FANUC .ls, RAPID, KUKA .dat/.src, URScript; layout detected). Flange poses: only the hand-eye applies.
    #[arg(long)]
    pub poses: Option<PathBuf>,
    /// How to read the pose file and the profiles (flags shared with
    /// the other command).
    #[command(flatten)]
    pub scan: ScanFlags,
    /// Raw scan: a folder of profiles (`<id>.csv|txt|yml|yaml|json`, or in natural order for a log without ids) or one CSV with a pose column.
    #[arg(long)]
    pub profiles: Option<PathBuf>,
    /// Raw scan: the nominal robot it was taken with, checked against the result's (help text with the presets' keys).
    #[arg(long, help = format!("Raw scan: the nominal robot it was taken with (a preset key: {}; a session/result file, a URDF or a DH table), checked against the result's", super::preset_keys()))]
    pub robot: Option<String>,
    /// Raw scan: the joint log's columns, e.g. `id=Pose,j1=A1,...,station=Sphere,use=Use` [default: id, j1..jn, station, use]
    #[arg(long, value_delimiter = ',')]
    pub map: Vec<String>,
    /// Raw scan of a sphere artefact: the spheres' diameter, mm, for the self-validation of the poses' stations.
    #[arg(long, value_name = "MM", value_parser = number(Range::positive("mm").at_most(SPHERE_DIAMETER_MM)))]
    pub sphere_diameter: Option<f64>,
    /// Raw scan of a sphere artefact: reference distances between its stations (CSV from,to,distance, mm).
    #[arg(long)]
    pub references: Option<PathBuf>,
    /// `-q`: [`QUIET_HELP`](super::QUIET_HELP).
    #[arg(long, short, help = QUIET_HELP)]
    pub quiet: bool,
}

/// Largest `--sensor-noise`, mm: the simulator's limit on a sensor's
/// noise; beyond it σ says nothing about the cloud.
const MAX_SENSOR_NOISE_MM: f64 = crate::engine::tools::simulate::config::MAX_SENSOR_NOISE_MM;

/// Largest `--sphere-diameter`, mm: the session rules' limit.
const SPHERE_DIAMETER_MM: f64 = crate::engine::base::limits::SPHERE_DIAMETER_MM;

/// One value of `--use`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Uses {
    /// Every measurement.
    All,
    /// The measurements of one use.
    One(Use),
}

impl Uses {
    fn parse(s: &str) -> Option<Self> {
        if s.eq_ignore_ascii_case("all") {
            Some(Self::All)
        } else {
            Use::parse(s).map(Self::One)
        }
    }
}

/// `--use`: `all` or the session's uses.
fn use_parser() -> Keywords<Uses> {
    Keywords::plain(
        std::iter::once("all").chain(Use::ALL.map(Use::as_str)),
        Uses::parse,
    )
}

/// `--model`: the result's two models.
fn model_parser() -> Keywords<ModelChoice> {
    Keywords::new(
        vec![
            (
                ModelChoice::Calibrated.as_str(),
                Some("The calibrated model and hand-eye"),
            ),
            (
                ModelChoice::Nominal.as_str(),
                Some(
                    "The nominal model and the initial hand-eye: the cell before calibration; no σ",
                ),
            ),
        ],
        |s| match s {
            "calibrated" => Some(ModelChoice::Calibrated),
            "nominal" => Some(ModelChoice::Nominal),
            _ => None,
        },
    )
}

/// The uses `--use` names; empty for all.
fn uses(args: &MeasureArgs) -> Vec<Use> {
    args.usage
        .iter()
        .map(|u| match u {
            Uses::All => None,
            Uses::One(one) => Some(*one),
        })
        .collect::<Option<Vec<Use>>>()
        .unwrap_or_default()
}

fn from_measure(e: &MeasureError) -> CliError {
    match e {
        MeasureError::Cancelled => CliError::internal(e.to_string()),
        MeasureError::File(f) => CliError::from_file(f, true),
        MeasureError::Input(_) | MeasureError::Import(_) => CliError::input(e.to_string()),
    }
}

/// The raw scan's spec from the flags.
fn scan_files(args: &MeasureArgs, dof: usize) -> Result<ScanFiles, CliError> {
    let profiles = args.profiles.clone().ok_or_else(|| {
        CliError::input("a raw scan needs its profiles: --profiles DIR or --profiles FILE.csv")
    })?;
    let profiles = if profiles.is_dir() {
        ProfileSource::Folder(profiles)
    } else {
        ProfileSource::File {
            path: profiles,
            pose_column: args.scan.pose_column.clone(),
        }
    };
    let log = match (&args.joints, &args.poses) {
        (Some(path), _) => {
            let mut columns = ScanColumns::new(dof);
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
                    k => {
                        let slot = k
                            .strip_prefix('j')
                            .and_then(|n| n.parse::<usize>().ok())
                            .filter(|n| (1..=dof).contains(n))
                            .ok_or_else(|| {
                                CliError::input(format!(
                                    "--map key `{k}` is not id, station, use or j1..j{dof}"
                                ))
                            })?;
                        columns.joints[slot - 1] = col;
                    }
                }
            }
            ScanLog::Joints {
                path: path.clone(),
                columns,
                unit: args.scan.joint_unit,
            }
        }
        (None, Some(path)) => ScanLog::Poses {
            path: path.clone(),
            format: args.scan.pose_format,
            convention: args.scan.pose_convention,
            columns: args.scan.pose_columns(),
        },
        (None, None) => {
            return Err(CliError::input(
                "give a session, or --joints/--poses with --profiles",
            ));
        }
    };
    let robot = args
        .robot
        .as_deref()
        .map(|text| {
            let source = args.scan.robot_source(text)?;
            import::load_robot(&source).map_err(|e| CliError::input(e.to_string()))
        })
        .transpose()?;
    Ok(ScanFiles {
        log,
        profiles,
        profile_format: args.scan.profile_format()?,
        robot,
        sphere_diameter: args.sphere_diameter,
        references: args.references.clone(),
        uses: uses(args),
    })
}

/// Every input file of the command, to refuse an output that is one.
fn inputs(args: &MeasureArgs) -> Vec<PathBuf> {
    let mut inputs: Vec<PathBuf> = [
        &args.session,
        &Some(args.result.clone()),
        &args.frame,
        &args.calibration,
        &args.joints,
        &args.poses,
        &args.references,
    ]
    .into_iter()
    .flatten()
    .cloned()
    .collect();
    if let Some(r) = &args.robot {
        inputs.push(PathBuf::from(r));
    }
    if let Some(p) = &args.profiles {
        if p.is_dir() {
            inputs.extend(import::profiles::profile_files(p).unwrap_or_default());
        } else {
            inputs.push(p.clone());
        }
    }
    inputs
}

/// Seconds and points per second, for the timing line.
fn rate(points: usize, seconds: f64) -> String {
    format!(
        "{:.3} s ({:.1} M points/s)",
        seconds,
        points as f64 / seconds.max(1e-9) / 1e6
    )
}

/// The output's format from its extension, after refusing an output that
/// is one of the inputs.
fn output_format(args: &MeasureArgs) -> Result<CloudFormat, CliError> {
    let input_files = inputs(args);
    let input_refs: Vec<&Path> = input_files.iter().map(PathBuf::as_path).collect();
    CliError::guard_output(&args.out, &input_refs)?;
    let format = CloudFormat::of_path(&args.out).ok_or_else(|| {
        CliError::input(format!(
            "--out {}: the extension chooses the format: .ply, .e57 or .csv",
            args.out.display()
        ))
    })?;
    Ok(format)
}

/// The measurement's warnings on stderr, the poses outside the calibrated
/// joint range listed up to [`LISTED_POSES`].
fn print_warnings(measured: &measure::Measured) {
    for w in &measured.warnings {
        eprintln!("warning: {w}");
    }
    if !measured.out_of_range.is_empty() {
        eprintln!(
            "warning: {} pose(s) outside the joint range the calibration saw (the model was not checked there):",
            measured.out_of_range.len()
        );
        for line in measure::listed(&measured.out_of_range) {
            eprintln!("  {line}");
        }
    }
}

/// The summary on stdout: the scan's notes, the points measured and
/// dropped, the measurements left out, σ, the joint-range check, the
/// self-validation and the timing line (`loaded`: seconds to load,
/// `written`: to write).
fn print_summary(
    args: &MeasureArgs,
    result: &format::ResultFile,
    options: &MeasureOptions,
    format: CloudFormat,
    done: &Outcome,
    (started, loaded, written): (Instant, f64, f64),
) {
    let (notes, skipped) = (&done.notes, &done.skipped);
    let cloud = &done.measured.cloud;
    let n = cloud.len();
    let dropped = cloud.dropped();
    for note in notes {
        sayln!("{note}");
    }
    sayln!(
        "measured {} points of {} ({} model of {}, {}); dropped {} non-finite and {} no-return points",
        n,
        plural(cloud.poses.len(), "pose", "poses"),
        cloud.model,
        args.result.display(),
        cloud.frame,
        dropped.non_finite,
        dropped.no_return
    );
    if !skipped.is_empty() {
        let more = skipped.len().saturating_sub(LISTED_POSES);
        sayln!(
            "  {} measurement(s) give a sphere centre, no profile: not in the cloud ({}{})",
            skipped.len(),
            skipped[..skipped.len().min(LISTED_POSES)].join(", "),
            if more > 0 {
                format!(", … and {more} more")
            } else {
                String::new()
            }
        );
    }
    match cloud.sigma_stats() {
        Some(s) => sayln!(
            "σ of a point (3-D, after the cloud's best rigid alignment; {}): median {:.4} mm, rms {:.4} mm, max {:.4} mm",
            options.sigma_basis(result),
            s.median,
            s.rms,
            s.max
        ),
        None => sayln!(
            "σ: not computed (sigma_mm written as NaN{})",
            if format == CloudFormat::E57 {
                "; left out of E57"
            } else {
                ""
            }
        ),
    }
    if args.session.is_none() && args.calibration.is_none() {
        sayln!(
            "joint range: not checked (give --calibration SESSION, the session the result was calibrated from)"
        );
    }
    if let Some(c) = &done.check {
        say!("{}", c.summary());
    }
    sayln!(
        "wrote {} ({:.0} ms): load {:.3} s, transform and σ {}, write {}; self-validation {:.3} s beside them",
        args.out.display(),
        started.elapsed().as_secs_f64() * 1e3,
        loaded,
        rate(n, done.placed_secs),
        rate(n, written),
        done.checked_secs
    );
}

/// Runs `spherecal measure`: the scan measured by the one engine entry
/// ([`measure::measure_scan`], which the workbench calls too), then the
/// cloud written and the summary printed.
///
/// # Errors
/// [`CliError`] with status 2 for bad input (nothing written), 1 when the
/// cloud cannot be written.
pub fn run(args: &MeasureArgs) -> Result<(), CliError> {
    let started = Instant::now();
    let format = output_format(args)?;
    let result = format::load_result(&args.result).map_err(|e| CliError::from_file(&e, true))?;
    let joint_range = match &args.calibration {
        Some(path) => {
            let s = format::load_session(path).map_err(|e| CliError::from_file(&e, true))?;
            JointRange::of_session(&s)
        }
        None => None,
    };
    let scan = if let Some(path) = &args.session {
        ScanSource::SessionFile(path.clone(), uses(args))
    } else {
        let dof = result.robot.as_ref().map_or(0, Robot::dof);
        ScanSource::Files(Box::new(scan_files(args, dof)?))
    };
    let loaded = started.elapsed().as_secs_f64();
    let request = MeasureRequest {
        scan,
        result: result.clone(),
        joint_range,
        frame: args.frame.clone(),
        options: MeasureOptions {
            model: args.model,
            frame: None,
            sigma: !args.no_sigma && args.model == ModelChoice::Calibrated,
            sensor_noise_mm: args.sensor_noise,
            covariance_as_written: args.covariance_as_written,
        },
    };
    let options = request.options.clone();
    let done =
        measure::measure_scan(request, &mut |_| Control::Continue).map_err(|e| from_measure(&e))?;
    let provenance = Provenance {
        result: args.result.display().to_string(),
        scan: done.scan.clone(),
    };
    let t = Instant::now();
    measure::write_cloud(&done.measured.cloud, &args.out, format, &provenance)
        .map_err(|e| CliError::from_file(&e, false))?;
    let written = t.elapsed().as_secs_f64();
    if args.quiet {
        return Ok(());
    }
    print_warnings(&done.measured);
    let timing = (started, loaded + done.read_secs, written);
    print_summary(args, &result, &options, format, &done, timing);
    Ok(())
}
