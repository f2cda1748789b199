//! `spherecal plan`: the poses to teach for a calibration, from a robot, a
//! rough sphere position and the sensor's hand-eye guess; optionally the
//! plan's predicted accuracy by simulation, and its exports (the joint log
//! CSV that `spherecal import` reads, controller programs). A thin caller
//! of [`crate::engine::tools::plan`]; every file is written atomically.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;

use super::values::{Range, count, number};
use super::{CliError, PROGRESS_EVERY, QUIET_HELP};
use crate::engine::base::robot::{self, JointLimit};
use crate::engine::calibrate::solve::Control;
use crate::engine::files::format;
use crate::engine::files::import::RobotSource;
use crate::engine::tools::plan::{
    self, Controller, PlanConfig, PlanDesign, PlanError, PlanProgress, PlanRequest, PlanStage,
    PredictConfig, RequestError, Selection, defaults, read_stations,
};
use crate::engine::tools::simulate;
use crate::engine::uses::check;

/// `spherecal plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Robot (help text with the presets' keys).
    #[arg(
        long,
        default_value = "irb2400",
        help = format!(
            "Robot: a preset key ({}), a session/result file whose `robot` block is the nominal model, a URDF (joint limits from its <limit> tags) or a DH table CSV (with --dh)",
            super::preset_keys()
        )
    )]
    pub robot: String,
    /// The tip link of a URDF robot, e.g. tool0 [default: the chain's only end link]
    #[arg(long)]
    pub urdf_tip: Option<String>,
    /// The convention of a DH table robot.
    #[arg(long, value_parser = super::dh_parser())]
    pub dh: Option<crate::engine::files::robot_import::DhConvention>,
    /// Joint limits, deg, `min:max` per joint, comma-separated [default: the preset's; a robot from a file needs them unless it is named like a preset]
    #[arg(
        long,
        value_name = "MIN:MAX",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub limits: Vec<String>,
    /// Rough sphere position `x,y,z` (mm, base frame): station P0 and the middle of the station box.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_triple, allow_hyphen_values = true, required_unless_present = "sensor_at")]
    pub sphere: Option<[f64; 3]>,
    /// Where the sensor stands: `flange` (the paper's cell) or `fixed` (a laser tracker, fixed camera or scanner measuring a target on the tool; needs --sensor-at; writes the joint log with --csv).
    #[arg(long, value_enum, default_value_t = super::import::MountArg::Flange)]
    pub mount: super::import::MountArg,
    /// With --mount fixed: the sensor's position `x,y,z` (mm, base frame); it looks at the middle of the workspace box.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_triple, allow_hyphen_values = true)]
    pub sensor_at: Option<[f64; 3]>,
    /// With --mount fixed: the target on the tool `x,y,z` (mm, flange frame); it faces along the flange's z.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_triple, allow_hyphen_values = true, default_value = "0,0,100")]
    pub target: [f64; 3],
    /// With --mount fixed: the sensor's reach, mm.
    #[arg(long, value_name = "MM", default_value_t = 5000.0, value_parser = number(Range::positive("mm")))]
    pub reach: f64,
    /// Hand-eye guess: a JSON file with a 4x4 matrix (rows, mm) or a session/result file with `hand_eye` [default: the paper's initial hand-eye]
    #[arg(long)]
    pub hand_eye: Option<PathBuf>,
    /// Sphere diameter, mm.
    #[arg(long, value_name = "MM", default_value_t = defaults::DIAMETER_MM, value_parser = number(Range::positive("mm").at_most(crate::engine::base::limits::SPHERE_DIAMETER_MM)))]
    pub diameter: f64,
    /// Translation poses at P0 (0, or at least 3).
    #[arg(long, default_value_t = defaults::TRANSLATIONS)]
    pub translations: usize,
    /// Rotation poses at P0 (0, or at least 2).
    #[arg(long, default_value_t = defaults::ROTATIONS)]
    pub rotations: usize,
    /// Identify stations (in the station box).
    #[arg(long, default_value_t = defaults::IDENTIFY_STATIONS)]
    pub identify_stations: usize,
    /// Poses per identify station.
    #[arg(long, default_value_t = defaults::IDENTIFY_POSES)]
    pub identify_poses: usize,
    /// Validate stations (in the station box); consecutive ones get a reference distance.
    #[arg(long, default_value_t = defaults::VALIDATE_STATIONS)]
    pub validate_stations: usize,
    /// Poses per validate station.
    #[arg(long, default_value_t = defaults::VALIDATE_POSES)]
    pub validate_poses: usize,
    /// Station box `dx,dy,dz` (mm, base axes) centred on --sphere [default: the preset's simulator box, e.g. 400,600,450 for the IRB 2400; a 300 mm cube otherwise]
    #[arg(long, value_name = "DX,DY,DZ", value_parser = parse_triple)]
    pub box_size: Option<[f64; 3]>,
    /// Explicit stations instead of the box: a CSV with columns use (identify|validate), x, y, z (mm, base frame).
    #[arg(long)]
    pub stations: Option<PathBuf>,
    /// Cut angle, deg: the laser plane cuts the sphere with its centre at sensor x = ±R·sin(angle).
    #[arg(long, value_name = "DEG", default_value_t = plan::DEFAULT_CUT_ANGLE_DEG)]
    pub angle: f64,
    /// Half-angle of the cone of approach directions, deg.
    #[arg(long, value_name = "DEG", default_value_t = plan::DEFAULT_CONE_DEG)]
    pub cone: f64,
    /// Half-range of the spin about the viewing axis in the working volume the plan is made for, deg (the flange turned about its approach from the roll with its x axis toward the station).
    #[arg(long, value_name = "DEG", default_value_t = plan::DEFAULT_SPIN_DEG)]
    pub spin: f64,
    /// Choose identify poses for the smallest predicted measuring error over the working volume (I-optimal: station box × viewing axis 10-40° from straight down over a 200° arc × spin): the default; kept for scripts.
    #[arg(long, conflicts_with_all = ["random", "d_optimal"])]
    pub volume: bool,
    /// Choose identify poses D-optimally (ln det, the parameters as a whole) instead of for the working volume.
    #[arg(long, conflicts_with = "random")]
    pub d_optimal: bool,
    /// Flange orientations drawn per station (each with every IK branch and both sides).
    #[arg(long, default_value_t = plan::DEFAULT_CANDIDATES)]
    pub candidates: usize,
    /// The sensor's measuring range `Y0,Y1,Z0,Z1` (mm, laser plane, sensor frame), e.g. `-40,40,-40,40`: the plan spreads the sphere over it (identify and validate poses see the sphere anywhere in the range, identify poses chosen for the smallest predicted error over it), compares with the plan without the spread, and --predict scores the error over it.
    #[arg(long, value_name = "Y0,Y1,Z0,Z1", allow_hyphen_values = true, value_parser = super::parse_range)]
    pub range: Option<crate::engine::base::session::SensorRange>,
    /// With --range: keep the sphere at the paper's one spot (±2, ±3 mm) and choose by ln det; the range is only predicted.
    #[arg(long, requires = "range")]
    pub no_spread: bool,
    /// Choose identify poses at random (the baseline).
    #[arg(long)]
    pub random: bool,
    /// Seed of every random choice; the same arguments give the same plan.
    #[arg(long, default_value_t = defaults::SEED)]
    pub seed: u64,
    /// Write the plan as a joint log CSV (the layout `spherecal import` reads, with the ABB flange pose).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write the plan as an ABB RAPID module (MODULE SpherecalPlan).
    #[arg(long)]
    pub rapid: Option<PathBuf>,
    /// Controller programs to write (help text with the controllers' keys).
    #[arg(
        long,
        value_name = "KEY=FILE",
        help = format!(
            "Write a controller program, KEY one of: {}; may be repeated",
            plan::PROGRAMS
                .iter()
                .map(|c| format!("{} ({})", c.key(), c.label()))
                .collect::<Vec<_>>()
                .join(", ")
        )
    )]
    pub program: Vec<String>,
    /// Predict the calibrated accuracy from N simulated calibrations (random kinematic errors, default noise, ml); 0 skips.
    #[arg(long, value_name = "N", default_value_t = PredictConfig::default().runs, value_parser = count(0, MAX_PREDICT_RUNS))]
    pub predict: usize,
    /// Plan a re-check of the cell calibrated in --result instead of a calibration: at most 30 poses at one to three sphere positions about --sphere (the layout that detects the most; --identify-poses sets the poses per position), solved on the calibrated model about the calibrated hand-eye; prints the operator's time and the smallest knock the check detects. Run them, import them, then `spherecal check`.
    #[arg(long, requires = "result")]
    pub check: bool,
    /// The result a re-check (--check) is planned for (an `ml` result).
    #[arg(long, requires = "check")]
    pub result: Option<PathBuf>,
    /// `-q`: [`QUIET_HELP`](super::QUIET_HELP).
    #[arg(long, short, help = QUIET_HELP)]
    pub quiet: bool,
}

/// Most simulated calibrations of `--predict` (the engine's bound, the
/// Plan view's too).
pub use crate::engine::tools::plan::MAX_PREDICT_RUNS;

/// The flags behind each of the plan's setting errors: a phrase of the
/// engine's message and the flags that set what it names.
const FLAGS_OF_SETTINGS: [(&str, &str); 21] = [
    (
        "stations asked for",
        "--identify-stations + --validate-stations",
    ),
    (
        "stations ×",
        "--identify-stations + --validate-stations, --candidates",
    ),
    (
        "candidate orientations per station asked for",
        "--candidates",
    ),
    ("at least one candidate orientation", "--candidates"),
    ("translation poses asked for", "--translations"),
    ("rotation poses asked for", "--rotations"),
    ("the rotation group needs", "--rotations"),
    ("identify poses per station asked for", "--identify-poses"),
    ("an identify station needs", "--identify-poses"),
    ("validate poses per station asked for", "--validate-poses"),
    ("validate stations need", "--validate-poses"),
    ("at least one identify station", "--identify-stations"),
    ("the cut angle", "--angle"),
    ("the cone angle", "--cone"),
    ("the sphere diameter", "--diameter"),
    ("the sphere position", "--sphere"),
    ("the station box", "--box-size"),
    ("station positions", "--stations"),
    ("joint limit", "--limits"),
    ("the sensor range", "--range"),
    ("joints", "--robot"),
];

/// A plan setting's error, led by the flag that set it.
fn setting_error(message: &str) -> CliError {
    match FLAGS_OF_SETTINGS
        .iter()
        .find(|(phrase, _)| message.contains(phrase))
    {
        Some((_, flags)) => CliError::input(format!("{flags}: {message}")),
        None => CliError::input(message.to_owned()),
    }
}

pub(crate) fn parse_triple(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("`{s}`: {e}; expected three numbers x,y,z"))?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|a| a.is_finite()) => Ok([*x, *y, *z]),
        _ => Err(format!("`{s}`: expected three finite numbers x,y,z")),
    }
}

fn parse_limits(items: &[String]) -> Result<Vec<JointLimit>, CliError> {
    items
        .iter()
        .map(|item| {
            let parsed = item.split_once(':').and_then(|(a, b)| {
                Some(JointLimit {
                    min: a.trim().parse().ok()?,
                    max: b.trim().parse().ok()?,
                })
            });
            parsed.ok_or_else(|| {
                CliError::input(format!("--limits entry `{item}` is not min:max (deg)"))
            })
        })
        .collect()
}

/// The engine's request of these flags (files read).
///
/// # Errors
/// [`CliError`] (status 2) for bad limits, an unreadable hand-eye or
/// stations file.
pub fn request(args: &PlanArgs) -> Result<PlanRequest, CliError> {
    let input = |e: RequestError| CliError::input(e.to_string());
    let robot = if robot::preset(&args.robot).is_some() {
        RobotSource::Preset(args.robot.clone())
    } else {
        RobotSource::from_text(&args.robot, args.urdf_tip.clone(), args.dh)
            .map_err(CliError::input)?
    };
    let sphere = args.sphere.ok_or_else(|| {
        CliError::input("--sphere X,Y,Z is needed (or --mount fixed with --sensor-at)")
    })?;
    Ok(PlanRequest {
        design: PlanDesign {
            sphere,
            diameter: args.diameter,
            n_translation: args.translations,
            n_rotation: args.rotations,
            n_identify: args.identify_stations,
            identify_poses: args.identify_poses,
            n_validate: args.validate_stations,
            validate_poses: args.validate_poses,
            cut_angle: args.angle,
            candidates: args.candidates,
            selection: if args.random {
                Selection::Random
            } else if args.d_optimal {
                Selection::DOptimal
            } else {
                Selection::Volume
            },
            seed: args.seed,
        },
        limits: if args.limits.is_empty() {
            None
        } else {
            Some(parse_limits(&args.limits)?)
        },
        hand_eye: args
            .hand_eye
            .as_deref()
            .map(super::hand_eye_file)
            .transpose()?,
        box_size: args.box_size,
        stations: args
            .stations
            .as_deref()
            .map(read_stations)
            .transpose()
            .map_err(input)?,
        cone_angle: args.cone,
        spin_deg: args.spin,
        predict_runs: args.predict,
        range: args.range,
        spread: args.range.is_some() && !args.no_spread,
        ..PlanRequest::new(robot, sphere)
    })
}

/// The engine configuration of these flags.
///
/// # Errors
/// [`CliError`] (status 2) for an unknown robot, bad limits, an unreadable
/// hand-eye or stations file.
pub fn config(args: &PlanArgs) -> Result<PlanConfig, CliError> {
    let mut config = request(args)?
        .config()
        .map_err(|e| CliError::input(e.to_string()))?;
    if let Some(result) = check_result(args)? {
        let poses =
            (args.identify_poses != defaults::IDENTIFY_POSES).then_some(args.identify_poses);
        check::choose_check_design(&mut config, &result, poses)
            .map_err(|e| CliError::input(e.to_string()))?;
    }
    config.validate().map_err(|e| plan_error(&e))?;
    Ok(config)
}

/// The result of `--check`, read.
fn check_result(args: &PlanArgs) -> Result<Option<format::ResultFile>, CliError> {
    match (&args.result, args.check) {
        (Some(path), true) => format::load_result(path)
            .map(Some)
            .map_err(|e| CliError::input(e.to_string())),
        _ => Ok(None),
    }
}

/// The smallest knocks a planned re-check detects, in words.
fn detectable_text(
    made: &plan::Plan,
    args: &PlanArgs,
    config: &PlanConfig,
) -> Result<String, CliError> {
    let Some(result) = check_result(args)? else {
        return Ok(String::new());
    };
    let d = check::plan_check(made, &result, config.stripe_sigma, check::DEFAULT_ALPHA)
        .map_err(|e| CliError::input(e.to_string()))?;
    let lines = check::detectable_lines(made, config.design.n_identify, &d);
    Ok(lines
        .iter()
        .map(|l| format!("  {l}"))
        .collect::<Vec<_>>()
        .join("\n"))
}

fn plan_error(e: &PlanError) -> CliError {
    match e {
        PlanError::Analysis(_) => CliError::internal(e.to_string()),
        PlanError::InvalidConfig(message) => setting_error(message),
        _ => CliError::input(e.to_string()),
    }
}

/// Progress lines of a long plan: at most one every [`PROGRESS_EVERY`].
struct Ticker {
    started: Instant,
    last: Instant,
}

impl Ticker {
    fn new(now: Instant) -> Self {
        Self {
            started: now,
            last: now,
        }
    }

    /// The line to print for `stage` at `now`, if one is due.
    fn tick(&mut self, stage: &PlanStage, now: Instant) -> Option<String> {
        if now.duration_since(self.last) < PROGRESS_EVERY {
            return None;
        }
        let what = match stage {
            PlanStage::Candidates { done, of } => {
                format!("candidate poses of {done} of {of} stations solved")
            }
            PlanStage::Analysis { done, of } => format!(
                "identifiability analysis of the candidate poses, {:.0} %",
                100.0 * *done as f64 / (*of).max(1) as f64
            ),
            PlanStage::Selection => "selecting the identify poses".to_owned(),
            PlanStage::Ordering => "ordering the poses".to_owned(),
            PlanStage::Comparison => "planning without the spread, for comparison".to_owned(),
        };
        self.last = now;
        Some(format!(
            "  planning: {what} ({:.0} s)",
            now.duration_since(self.started).as_secs_f64()
        ))
    }

    /// The line to print after `done` of `of` simulated calibrations.
    fn runs(&mut self, done: usize, of: usize, now: Instant) -> Option<String> {
        if now.duration_since(self.last) < PROGRESS_EVERY {
            return None;
        }
        self.last = now;
        Some(format!(
            "  predicting: {done} of {of} simulated calibrations ({:.0} s)",
            now.duration_since(self.started).as_secs_f64()
        ))
    }
}

/// The name of the timing line's part that `stage` begins, if any.
fn stage_mark(stage: PlanStage) -> Option<&'static str> {
    match stage {
        PlanStage::Candidates { .. } => None,
        PlanStage::Analysis { .. } => Some("identifiability"),
        PlanStage::Selection => Some("selection"),
        PlanStage::Ordering => Some("ordering and report"),
        PlanStage::Comparison => Some("plan without the spread"),
    }
}

/// `planned in … ms (candidates …, identifiability …, …)`: the time
/// since `started` and of each part, from when each began (`marks`)
/// to `end`.
fn timing_line(started: Instant, marks: &[(&str, Instant)], end: Instant) -> String {
    let stages: Vec<String> = marks
        .iter()
        .enumerate()
        .map(|(k, (name, at))| {
            let next = marks.get(k + 1).map_or(end, |m| m.1);
            format!("{name} {:.0}", (next - *at).as_secs_f64() * 1e3)
        })
        .collect();
    format!(
        "  planned in {:.0} ms ({} ms)",
        (end - started).as_secs_f64() * 1e3,
        stages.join(", ")
    )
}

/// Runs `spherecal plan`.
///
/// # Errors
/// [`CliError`] with status 2 for bad input or an impossible request
/// (unreachable sphere, too few reachable poses, collinear translations)
/// or an output that cannot be written (checked before planning; the
/// files are written all or none).
pub fn run(args: &PlanArgs) -> Result<(), CliError> {
    let inputs: Vec<&Path> = args
        .hand_eye
        .iter()
        .chain(&args.stations)
        .map(PathBuf::as_path)
        .chain(std::iter::once(Path::new(&args.robot)))
        .collect();
    let started = Instant::now();
    let mut programs: Vec<(Controller, PathBuf)> = Vec::new();
    if let Some(path) = &args.rapid {
        programs.push((Controller::Abb, path.clone()));
    }
    for item in &args.program {
        let parsed = item
            .split_once('=')
            .and_then(|(k, f)| Some((plan::parse_program(k.trim())?, PathBuf::from(f.trim()))));
        let Some(p) = parsed else {
            let keys: Vec<&str> = plan::PROGRAMS.iter().map(|c| c.key()).collect();
            return Err(CliError::input(format!(
                "--program `{item}` is not KEY=FILE with KEY one of: {}",
                keys.join(", ")
            )));
        };
        programs.push(p);
    }
    let outputs: Vec<&Path> = args
        .csv
        .iter()
        .map(PathBuf::as_path)
        .chain(programs.iter().map(|(_, p)| p.as_path()))
        .collect();
    for out in &outputs {
        CliError::guard_output(out, &inputs)?;
    }
    super::check_outputs(&outputs, format::Folders::Existing)?;
    let config = config(args)?;
    let quiet = args.quiet;
    // A re-check has no validate stations to score: no prediction.
    let predict = (args.predict > 0 && !args.check).then(|| PredictConfig {
        runs: args.predict,
        seed: args.seed,
        ..PredictConfig::default()
    });
    // When each stage began, for the timing line.
    let mut marks: Vec<(&str, Instant)> = vec![("candidates", Instant::now())];
    let mut ticker = Ticker::new(Instant::now());
    // When the prediction began.
    let mut predicting = Instant::now();
    let planned = plan::plan_and_predict(&config, predict.as_ref(), &mut |progress| {
        match progress {
            PlanProgress::Stage(stage) => {
                if !quiet && let Some(line) = ticker.tick(&stage, Instant::now()) {
                    eprintln!("{line}");
                }
                if let Some(name) = stage_mark(stage)
                    && marks.last().is_none_or(|(last, _)| *last != name)
                {
                    marks.push((name, Instant::now()));
                }
            }
            PlanProgress::Planned(made) => {
                if !quiet {
                    say!("{}", plan::summary(made));
                    sayln!("{}", timing_line(started, &marks, Instant::now()));
                }
                predicting = Instant::now();
                ticker = Ticker::new(predicting);
            }
            PlanProgress::Predicting { done, of } => {
                if !quiet && let Some(line) = ticker.runs(done, of, Instant::now()) {
                    eprintln!("{line}");
                }
            }
        }
        Control::Continue
    })
    .map_err(|e| plan_error(&e))?;
    let made = &planned.plan;
    if args.check && !quiet {
        sayln!("{}", detectable_text(made, args, &config)?);
    }
    if let (Some(prediction), Some(predict)) = (planned.prediction, &predict) {
        let p = prediction.map_err(|e| plan_error(&e))?;
        if !quiet {
            sayln!(
                "  predicted validation std after calibration (ml, {} simulated robots with random errors σ {}°/{} mm, joint noise {}°, stripe noise {} mm): {:.4} ± {:.4} mm",
                p.runs.len(),
                simulate::config::RANDOM_ANGLE_SIGMA_DEG,
                simulate::config::RANDOM_LENGTH_SIGMA_MM,
                predict.joint_noise,
                predict.stripe_noise,
                p.after_mean,
                p.after_spread
            );
            sayln!(
                "    before {:.3} mm; noise floor {:.4} mm; after / floor {:.2} ({:.0} ms)",
                p.before_mean,
                p.floor_mean,
                p.ratio_mean,
                predicting.elapsed().as_secs_f64() * 1e3
            );
            if let Some(r) = &p.range {
                sayln!(
                    "    error over the range (9 × 9 grid at the validate poses, against the truth): rms {:.4} mm (max {:.4} mm); floor {:.4} mm; after / floor {:.2}",
                    r.after_rms,
                    r.after_max,
                    r.floor_rms,
                    r.ratio_mean
                );
            }
            if let Some(v) = &p.volume {
                sayln!(
                    "    error over the volume (validate spheres in the base frame, aligned rigidly to the truth): rms {:.4} mm; floor {:.4} mm; after / floor {:.2} (worst run {:.2})",
                    v.after_rms,
                    v.floor_rms,
                    v.ratio_mean,
                    v.ratio_max
                );
            }
        }
        if config.design.selection != Selection::Random {
            random_baseline(&config, predict, quiet)?;
        }
    }
    // Every file or none.
    let mut files: Vec<(&Path, String, String)> = Vec::new();
    if let Some(path) = &args.csv {
        files.push((path, plan::plan_csv(made), "joint log CSV".to_owned()));
    }
    for (controller, path) in &programs {
        let what = format!("{} program", controller.key());
        if let Some(warning) = plan::other_maker_warning(*controller, made)
            && !quiet
        {
            sayln!("{warning}");
        }
        let text =
            plan::render_program(*controller, made).map_err(|e| CliError::input(e.to_string()))?;
        files.push((path, text, what));
    }
    let bytes: Vec<(&Path, &[u8])> = files.iter().map(|(p, t, _)| (*p, t.as_bytes())).collect();
    super::write_outputs(&bytes, format::Folders::Existing)?;
    if !quiet {
        for (path, _, what) in &files {
            sayln!("wrote {} ({what})", path.display());
        }
    }
    Ok(())
}

/// `--predict`'s comparison: the same stations with poses at random (the
/// paper's practice), planned and scored over the volume alike.
fn random_baseline(
    config: &PlanConfig,
    predict: &PredictConfig,
    quiet: bool,
) -> Result<(), CliError> {
    let baseline = plan::PlanConfig {
        design: PlanDesign {
            selection: Selection::Random,
            ..config.design
        },
        ..config.clone()
    };
    let other = plan::plan(&baseline, &mut |_| Control::Continue)
        .and_then(|b| plan::predict(&b, predict, &mut |_, _| Control::Continue))
        .map_err(|e| plan_error(&e))?;
    if !quiet && let Some(v) = &other.volume {
        sayln!(
            "    poses at random at the same stations (the paper's practice): error over the volume rms {:.4} mm; floor {:.4} mm; after / floor {:.2} (worst run {:.2})",
            v.after_rms,
            v.floor_rms,
            v.ratio_mean,
            v.ratio_max
        );
    }
    Ok(())
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use std::time::Duration;

    use crate::engine::tools::plan::StationLayout;

    fn parse(extra: &[&str]) -> PlanArgs {
        let mut argv = vec!["plan"];
        argv.extend_from_slice(extra);
        super::super::parse_flags(&argv)
    }

    #[test]
    fn flags_reach_the_config() {
        let args = parse(&[
            "--sphere",
            "-525,0,125.5",
            "--robot",
            "ur5e",
            "--identify-stations",
            "4",
            "--identify-poses",
            "5",
            "--validate-stations",
            "3",
            "--validate-poses",
            "2",
            "--angle",
            "35",
            "--box-size",
            "100,200,300",
            "--seed",
            "9",
            "--random",
            "--limits",
            "-360:360,-150:-10,10:160,-360:360,-360:360,-360:360",
        ]);
        let c = config(&args).unwrap();
        assert_eq!(c.design.sphere, [-525.0, 0.0, 125.5]);
        assert_eq!(c.robot.name, "Universal Robots UR5e");
        assert_eq!((c.design.n_identify, c.design.identify_poses), (4, 5));
        assert_eq!((c.design.n_validate, c.design.validate_poses), (3, 2));
        assert_eq!(c.design.cut_angle, 35.0);
        assert_eq!(c.design.seed, 9);
        assert_eq!(c.design.selection, Selection::Random);
        assert_eq!(
            c.stations,
            StationLayout::Box {
                size: [100.0, 200.0, 300.0]
            }
        );
        assert_eq!(
            c.limits[1],
            JointLimit {
                min: -150.0,
                max: -10.0
            }
        );
    }

    /// Issue 23: a long plan printed nothing for minutes.
    #[test]
    fn a_long_plan_reports_progress_every_few_seconds() {
        let t0 = Instant::now();
        let mut ticker = Ticker::new(t0);
        let stage = PlanStage::Candidates { done: 40, of: 200 };
        assert_eq!(ticker.tick(&stage, t0 + Duration::from_millis(500)), None);
        let line = ticker.tick(&stage, t0 + Duration::from_secs(3)).unwrap();
        assert!(
            line.contains("40 of 200 stations") && line.contains("(3 s)"),
            "{line}"
        );
        assert_eq!(
            ticker.tick(
                &PlanStage::Analysis { done: 0, of: 1 },
                t0 + Duration::from_secs(4)
            ),
            None
        );
        let line = ticker
            .tick(
                &PlanStage::Analysis { done: 0, of: 1 },
                t0 + Duration::from_secs(6),
            )
            .unwrap();
        assert!(line.contains("identifiability"), "{line}");
        let line = ticker.runs(3, 8, t0 + Duration::from_secs(9)).unwrap();
        assert!(line.contains("3 of 8"), "{line}");
    }

    /// Issue 23: `--identify-stations 100000` ran for minutes; it is
    /// refused at once, naming the limit.
    #[test]
    fn oversized_plans_are_refused_naming_the_limit() {
        for (flags, needle) in [
            (vec!["--identify-stations", "100000"], "at most 500"),
            (vec!["--candidates", "1000000"], "at most 1000"),
            (
                vec!["--identify-stations", "300", "--candidates", "100"],
                "at most 12000",
            ),
            (vec!["--identify-poses", "1000"], "at most 100"),
        ] {
            let mut argv = vec!["--sphere", "1050,0,475"];
            argv.extend(flags.iter().copied());
            let e = config(&parse(&argv)).unwrap_err();
            assert_eq!(e.status, 2);
            assert!(e.message.contains(needle), "{flags:?}: {}", e.message);
            // The flag that set it leads the message.
            assert!(e.message.starts_with(flags[0]), "{flags:?}: {}", e.message);
        }
    }

    #[test]
    fn bad_flags_are_input_errors() {
        assert!(parse_triple("1,2").is_err());
        assert!(parse_triple("1,x,3").is_err());
        let args = parse(&["--sphere", "1,2,3", "--limits", "0:1,2"]);
        assert_eq!(config(&args).unwrap_err().status, 2);
        let args = parse(&["--sphere", "1,2,3", "--robot", "no-such-robot.json"]);
        assert_eq!(config(&args).unwrap_err().status, 2);
    }
}
