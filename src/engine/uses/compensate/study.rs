//! The validation of compensation in simulation (README "Compensating
//! robot targets"). Per seed, a paper-like session (`SimConfig` default:
//! the IRB 2400 with Table 1 errors) is simulated with its truth and
//! calibrated with `ml`; then
//!
//! - **near targets**: each validate pose's true joints moved by up to
//!   ±3° per joint (within the limits), the sensor pose the TRUE robot
//!   and hand-eye reach there;
//! - **far targets**: random joints over the arm's range (`|q5| ≥ 15°`),
//!   the same way;
//! - **ISO 9283 poses**: P1…P5 of ISO 9283's test cube (P1 the centre,
//!   P2…P5 on a diagonal plane at 10 % of its diagonal from the corners),
//!   one orientation, in a cube of 300 mm inside the identify region and
//!   in one 500 mm beside it.
//!
//! Every target goes through [`compensate`](super::compensate) as a pose
//! table (`id,x,y,z,q1..q4`); a controller that knows only the nominal
//! model, with the calibrated hand-eye as its tool data, is commanded the
//! target as written (before) and as compensated (after): nominal inverse
//! kinematics from the target's own joints (its branch), then the TRUE
//! robot and hand-eye at the joints it drives. Errors are TCP position
//! errors after the best rigid alignment, fitted on the near targets and
//! applied to every target (sphere data do not see the base frame; a
//! work frame taught in the region takes that motion out). ISO 9283's
//! positioning accuracy `AP_P` is the distance from the commanded
//! position to the barycentre of the attained ones over 30 cycles, each
//! with the robot's joint repeatability (the session's joint noise).

use std::fmt::Write as _;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::arms::joint_distance;
use super::{Model, Options, Tcp, compensate};
use crate::engine::base::geometry::kabsch;
use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::base::robot::ik::DOF;
use crate::engine::base::robot::{JointLimit, Robot, irb2400};
use crate::engine::base::session::Use;
use crate::engine::calibrate::solve::{self, Control};
use crate::engine::files::format::ResultFile;
use crate::engine::files::program::{ReadSpec, parse_pose_text};
use crate::engine::tools::simulate::{self, SimConfig, Truth};

/// Joint spread of a near target about its validate pose, ± deg.
pub const NEAR_SPREAD_DEG: f64 = 3.0;
/// Far targets per seed.
pub const FAR_TARGETS: usize = 60;
/// Smallest `|q5|` of a far target, deg: away from the wrist singularity.
const FAR_MIN_WRIST_DEG: f64 = 15.0;
/// Random joints drawn for the far targets, at most.
const FAR_DRAWS: usize = 2000;
/// Margin of a far target's joints from the limits, deg: the calibrated
/// solution moves a few degrees from the nominal one.
const FAR_LIMIT_MARGIN_DEG: f64 = 5.0;
/// A target's chosen nominal solution and its own joints differ by the
/// nominal-versus-true model (a few degrees) on the same branch; another
/// branch is tens of degrees away.
const SAME_BRANCH_DEG: f64 = 10.0;
/// Side of the ISO 9283 cube inside the identify region, mm.
pub const ISO_CUBE_MM: f64 = 300.0;
/// How far beside the identify region the far ISO cube's centre is, mm
/// (along the base y axis).
pub const ISO_FAR_OFFSET_MM: f64 = 500.0;
/// Cycles per ISO 9283 pose.
pub const ISO_CYCLES: usize = 30;

/// Why the study could not run.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A step failed, for the seed.
    #[error("seed {seed}: {stage}: {message}")]
    Step {
        /// The seed.
        seed: u64,
        /// What was being done.
        stage: &'static str,
        /// What failed.
        message: String,
    },
}

/// One target of the study.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyTarget {
    /// Near a validate pose (else far or ISO).
    pub near: bool,
    /// Joint distance to the nearest identify pose, deg.
    pub nearest_deg: f64,
    /// Predicted σ, mm.
    pub sigma_mm: f64,
    /// Working point outside the identify box, mm.
    pub outside_mm: f64,
    /// Flagged by the defaults.
    pub flagged: bool,
    /// Error commanded as written, mm (aligned).
    pub before_mm: f64,
    /// Error commanded as compensated, mm (aligned).
    pub after_mm: f64,
}

/// ISO 9283 positioning accuracy of one cube.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Accuracy {
    /// ISO poses reached (of 5).
    pub poses: usize,
    /// Largest `AP_P` commanded as written, mm.
    pub before_mm: f64,
    /// Largest `AP_P` commanded as compensated, mm.
    pub after_mm: f64,
}

/// One seed.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedStudy {
    /// The seed.
    pub seed: u64,
    /// Near and far targets.
    pub targets: Vec<StudyTarget>,
    /// ISO 9283 inside the identify region.
    pub iso_near: Accuracy,
    /// ISO 9283 beside it.
    pub iso_far: Accuracy,
}

/// A target to compensate: the joints it was made from and its pose.
struct Made {
    joints: [f64; DOF],
    pose: Isometry3<f64>,
}

/// The study of one seed (module doc).
///
/// # Errors
/// A simulation, calibration or compensation that fails.
pub fn run_seed(seed: u64) -> Result<SeedStudy, StudyError> {
    let fail = |stage: &'static str| {
        move |e: String| StudyError::Step {
            seed,
            stage,
            message: e,
        }
    };
    let config = SimConfig {
        seed,
        ..SimConfig::default()
    };
    let (session, truth) =
        simulate::simulate(&config).map_err(|e| fail("simulate")(e.to_string()))?;
    let prepared = solve::prepare(&session).map_err(|e| fail("prepare")(e.to_string()))?;
    let mut options = solve::Options::from_session(&session);
    options.ml.cross_validation = false;
    let cal = solve::run(&session, &prepared, &options, &mut |_| Control::Continue)
        .map_err(|e| fail("calibrate")(e.to_string()))?;
    let result = ResultFile::from_calibration(&session, &cal);
    let model = Model::new(&result, None, Tcp::Sensor).map_err(|e| fail("model")(e.to_string()))?;
    let limits = irb2400().limits;
    let true_robot = truth.true_robot();
    let true_hand_eye = truth.true_hand_eye();
    let made = |q: [f64; DOF]| Made {
        joints: q,
        pose: true_robot.base_from_flange(&q) * true_hand_eye,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let near: Vec<Made> = truth
        .measurements
        .iter()
        .filter(|(_, m)| m.usage == Use::Validate)
        .filter_map(|(_, m)| <[f64; DOF]>::try_from(m.joints_actual.as_slice()).ok())
        .map(|mut q| {
            for (v, l) in q.iter_mut().zip(&limits) {
                *v = (*v + rng.random_range(-NEAR_SPREAD_DEG..=NEAR_SPREAD_DEG))
                    .clamp(l.min + 1.0, l.max - 1.0);
            }
            made(q)
        })
        .collect();
    // Far targets on the branch compensation takes for them (a table
    // names none): the controller is started from their own joints.
    let mut far: Vec<Made> = Vec::with_capacity(FAR_TARGETS);
    for _ in 0..FAR_DRAWS {
        if far.len() == FAR_TARGETS {
            break;
        }
        let m = made(random_joints(&mut rng, &limits));
        let flange = m.pose * model.tool.inverse();
        if model
            .arms
            .nominal_branch(&flange, None)
            .is_some_and(|(q, _)| joint_distance(&q, &m.joints) < SAME_BRANCH_DEG)
        {
            far.push(m);
        }
    }
    let all: Vec<&Made> = near.iter().chain(&far).collect();
    let (before, after, reports) = drive(&model, &truth, &all).map_err(fail("compensate"))?;
    // The rigid alignment, fitted on the near targets.
    let wanted: Vec<Vector3<f64>> = all.iter().map(|m| m.pose.translation.vector).collect();
    let n = near.len();
    let fit = |reached: &[Vector3<f64>]| kabsch(&reached[..n], &wanted[..n]);
    let (Some(fit_before), Some(fit_after)) = (fit(&before), fit(&after)) else {
        return Err(fail("align")("too few near targets".into()));
    };
    let error = |g: &Isometry3<f64>, r: &Vector3<f64>, w: &Vector3<f64>| {
        (g * Point3::from(*r) - Point3::from(*w)).norm()
    };
    let targets = (0..all.len())
        .map(|i| StudyTarget {
            near: i < n,
            nearest_deg: reports[i].nearest_identify_deg.unwrap_or(f64::NAN),
            sigma_mm: reports[i].sigma_mm.unwrap_or(f64::NAN),
            outside_mm: reports[i].outside_mm,
            flagged: !reports[i].flags.is_empty(),
            before_mm: error(&fit_before, &before[i], &wanted[i]),
            after_mm: error(&fit_after, &after[i], &wanted[i]),
        })
        .collect();
    let mut iso = |offset: Vector3<f64>| {
        iso_accuracy(
            &model,
            &truth,
            &result,
            &near,
            offset,
            (&fit_before, &fit_after),
            &mut rng,
            config.joint_noise,
        )
    };
    let iso_near = iso(Vector3::zeros()).map_err(fail("iso near"))?;
    let iso_far = iso(Vector3::new(0.0, ISO_FAR_OFFSET_MM, 0.0)).map_err(fail("iso far"))?;
    Ok(SeedStudy {
        seed,
        targets,
        iso_near,
        iso_far,
    })
}

/// Random joints over the arm's range, `|q5| ≥` [`FAR_MIN_WRIST_DEG`].
fn random_joints(rng: &mut ChaCha8Rng, limits: &[JointLimit]) -> [f64; DOF] {
    let mut q = [0.0; DOF];
    for (k, (v, l)) in q.iter_mut().zip(limits).enumerate() {
        let (lo, hi) = (
            l.min.max(-180.0) + FAR_LIMIT_MARGIN_DEG,
            l.max.min(180.0) - FAR_LIMIT_MARGIN_DEG,
        );
        loop {
            *v = rng.random_range(lo..=hi);
            if k != 4 || v.abs() >= FAR_MIN_WRIST_DEG {
                break;
            }
        }
    }
    q
}

/// The TRUE TCP positions commanded as written and as compensated, and
/// the compensation's reports.
type Driven = (
    Vec<Vector3<f64>>,
    Vec<Vector3<f64>>,
    Vec<super::TargetReport>,
);

/// Compensates `targets` as an ABB pose table and drives the nominal
/// controller to each as written and as compensated: the TRUE TCP
/// positions (before, after) and the reports.
fn drive(model: &Model, truth: &Truth, targets: &[&Made]) -> Result<Driven, String> {
    let mut text = String::from("id,x,y,z,q1,q2,q3,q4\n");
    for (i, t) in targets.iter().enumerate() {
        let v = FlangeConvention::AbbQuaternion.values_from_pose(&t.pose);
        let cells: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
        let _ = writeln!(text, "t{},{}", i + 1, cells.join(","));
    }
    let spec = ReadSpec {
        convention: Some(FlangeConvention::AbbQuaternion),
        ..ReadSpec::default()
    };
    let file = parse_pose_text(text, std::path::Path::new("study.csv"), &spec)
        .map_err(|e| e.to_string())?;
    let done = compensate(model, &file, &Options::default(), &mut |_| {
        Control::Continue
    })
    .map_err(|e| e.to_string())?;
    let true_robot = truth.true_robot();
    let true_hand_eye = truth.true_hand_eye();
    let nominal = &model.arms.nominal;
    let reach = |pose: &Isometry3<f64>, start: &[f64; DOF]| -> Result<Vector3<f64>, String> {
        let q = controller(nominal, &model.tool, pose, start)?;
        Ok((true_robot.base_from_flange(&q) * true_hand_eye)
            .translation
            .vector)
    };
    let mut before = Vec::with_capacity(targets.len());
    let mut after = Vec::with_capacity(targets.len());
    for (t, r) in targets.iter().zip(&done.targets) {
        before.push(reach(&t.pose, &t.joints)?);
        after.push(reach(&r.commanded, &t.joints)?);
    }
    Ok((before, after, done.targets))
}

/// The joints a controller running `nominal` with `tool` as its tool data
/// drives to for the TCP pose `pose`: inverse kinematics from `start`.
fn controller(
    nominal: &Robot,
    tool: &Isometry3<f64>,
    pose: &Isometry3<f64>,
    start: &[f64; DOF],
) -> Result<[f64; DOF], String> {
    nominal
        .inverse_kinematics(&(pose * tool.inverse()), start, None)
        .and_then(|q| q.try_into().ok())
        .ok_or_else(|| "the nominal controller does not reach a commanded pose".to_string())
}

/// ISO 9283's P1…P5 in a cube of [`ISO_CUBE_MM`] at the centre of the
/// identify sphere positions moved by `offset`, oriented as the near
/// target nearest that centre.
#[allow(clippy::too_many_arguments, reason = "one study step with its inputs")]
fn iso_accuracy(
    model: &Model,
    truth: &Truth,
    result: &ResultFile,
    near: &[Made],
    offset: Vector3<f64>,
    fits: (&Isometry3<f64>, &Isometry3<f64>),
    rng: &mut ChaCha8Rng,
    joint_noise_deg: f64,
) -> Result<Accuracy, String> {
    let identify: Vec<Vector3<f64>> = result
        .centres
        .iter()
        .filter(|c| c.usage == Use::Identify)
        .map(|c| Vector3::from(c.after))
        .collect();
    let centre = identify.iter().sum::<Vector3<f64>>() / identify.len().max(1) as f64 + offset;
    let reference = near
        .iter()
        .min_by(|a, b| {
            let d = |m: &Made| (m.pose.translation.vector - centre + offset).norm();
            d(a).total_cmp(&d(b))
        })
        .ok_or("no near target")?;
    let rotation: UnitQuaternion<f64> = reference.pose.rotation;
    // P1 the centre; P2…P5 on the diagonal plane x = y (cube axes along
    // the base axes), 10 % of the plane's diagonal in from its corners.
    let h = ISO_CUBE_MM / 2.0;
    let corners = [
        Vector3::new(-h, -h, -h),
        Vector3::new(h, h, -h),
        Vector3::new(h, h, h),
        Vector3::new(-h, -h, h),
    ];
    let mut points = vec![centre];
    points.extend(corners.iter().map(|c| centre + c * 0.8));
    let true_robot = truth.true_robot();
    let true_hand_eye = truth.true_hand_eye();
    let noise = Normal::new(0.0, joint_noise_deg.max(0.0)).map_err(|e| e.to_string())?;
    let mut acc = Accuracy::default();
    for p in points {
        let pose = Isometry3::from_parts(Translation3::from(p), rotation);
        let flange = pose * model.tool.inverse();
        let Some((start, _)) = model.arms.nominal_branch(&flange, None) else {
            continue;
        };
        let table = format!(
            "id,x,y,z,q1,q2,q3,q4\nP,{}\n",
            FlangeConvention::AbbQuaternion
                .values_from_pose(&pose)
                .iter()
                .map(|x| format!("{x}"))
                .collect::<Vec<_>>()
                .join(",")
        );
        let spec = ReadSpec {
            convention: Some(FlangeConvention::AbbQuaternion),
            ..ReadSpec::default()
        };
        let file = parse_pose_text(table, std::path::Path::new("iso.csv"), &spec)
            .map_err(|e| e.to_string())?;
        let Ok(done) = compensate(model, &file, &Options::default(), &mut |_| {
            Control::Continue
        }) else {
            continue;
        };
        let mut ap = [0.0; 2];
        for (k, (commanded, fit)) in [(pose, fits.0), (done.targets[0].commanded, fits.1)]
            .iter()
            .enumerate()
        {
            let q = controller(&model.arms.nominal, &model.tool, commanded, &start)?;
            let mut sum = Vector3::zeros();
            for _ in 0..ISO_CYCLES {
                let mut noisy = q;
                for v in &mut noisy {
                    *v += noise.sample(rng);
                }
                let attained = (true_robot.base_from_flange(&noisy) * true_hand_eye)
                    .translation
                    .vector;
                sum += (*fit * Point3::from(attained)).coords;
            }
            ap[k] = (sum / ISO_CYCLES as f64 - p).norm();
        }
        acc.poses += 1;
        acc.before_mm = acc.before_mm.max(ap[0]);
        acc.after_mm = acc.after_mm.max(ap[1]);
    }
    Ok(acc)
}

/// RMS of `f` over the targets that pass `keep`.
fn rms(targets: &[StudyTarget], keep: fn(&StudyTarget) -> bool, f: fn(&StudyTarget) -> f64) -> f64 {
    let v: Vec<f64> = targets.iter().filter(|t| keep(t)).map(f).collect();
    (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// Largest `f` over the targets that pass `keep`.
fn largest(
    targets: &[StudyTarget],
    keep: fn(&StudyTarget) -> bool,
    f: fn(&StudyTarget) -> f64,
) -> f64 {
    targets
        .iter()
        .filter(|t| keep(t))
        .map(f)
        .fold(0.0, f64::max)
}

/// The README table: per seed, near targets (rms before → after, the
/// ratio, the largest σ, flagged), far targets (rms before → after,
/// flagged) and ISO 9283's largest `AP_P` in and beside the region.
#[must_use]
pub fn markdown(studies: &[SeedStudy]) -> String {
    let near = |t: &StudyTarget| t.near;
    let far = |t: &StudyTarget| !t.near;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| seed | near: rms before → after (mm) | after / before | near: largest σ, flagged | far: rms before → after (mm) | far: flagged | ISO 9283 AP_P in the region (mm) | AP_P 500 mm beside it (mm) |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for st in studies {
        let t = &st.targets;
        let count = |keep: fn(&StudyTarget) -> bool| t.iter().filter(|x| keep(x)).count();
        let flagged =
            |keep: fn(&StudyTarget) -> bool| t.iter().filter(|x| keep(x) && x.flagged).count();
        let (nb, na) = (rms(t, near, |x| x.before_mm), rms(t, near, |x| x.after_mm));
        let _ = writeln!(
            s,
            "| {} | {nb:.2} → {na:.3} | {:.1} % | {:.3} mm, {} of {} | {:.1} → {:.2} | {} of {} | {:.2} → {:.3} | {:.2} → {:.3} |",
            st.seed,
            100.0 * na / nb,
            largest(t, near, |x| x.sigma_mm),
            flagged(near),
            count(near),
            rms(t, far, |x| x.before_mm),
            rms(t, far, |x| x.after_mm),
            flagged(far),
            count(far),
            st.iso_near.before_mm,
            st.iso_near.after_mm,
            st.iso_far.before_mm,
            st.iso_far.after_mm,
        );
    }
    s
}
