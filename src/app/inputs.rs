//! The readings of the workbench's inputs ([`Input`]) from the state and
//! the forms, taken every frame for the [`Ledger`] of every artefact
//! derived: what each is, in the fields people read, and a fingerprint
//! of all of it.
//!
//! [`Ledger`]: super::ledger::Ledger

use std::collections::BTreeSet;

use nalgebra::Isometry3;

use super::forms::compensate::{CompensateForm, TcpChoice};
use super::forms::{Forms, PlanForm, SolverForm};
use super::ledger::{Input, Reading};
use super::state::AppState;
use crate::engine::base::session::SensorRange;
use crate::engine::calibrate::solve::Method;
use crate::engine::tools::result_view::Tolerance;
use crate::engine::uses::compensate::JointTargets;

/// Left-out ids named in a reading; more are counted.
const IDS_SHOWN: usize = 3;

/// Every input as it reads now.
#[must_use]
pub fn readings(state: &AppState, forms: &Forms) -> Vec<(Input, Reading)> {
    vec![
        (Input::Session, session(state)),
        (Input::LeftOut, left_out(&state.excluded)),
        (Input::Solver, solver(&forms.solver)),
        (
            Input::PlanForm,
            plan_form(&forms.plan, plan_hand_eye(state)),
        ),
        (Input::Tolerance, tolerance(&forms.tolerance)),
        (Input::Calibration, calibration(state)),
        (Input::Targets, targets(&forms.compensate)),
        (Input::MeasureForm, measure_form(&forms.measure)),
        (
            Input::ImportForm,
            Reading::new(Vec::new(), format!("{:?}", forms.import)),
        ),
        (
            Input::PoseFile,
            Reading::new(Vec::new(), format!("{:?}", forms.import.pose_scan_key())),
        ),
        (
            Input::Library,
            Reading::new(
                vec![(
                    "library".into(),
                    format!("{} (scan {})", forms.history.folder, state.history.scans),
                )],
                state.history.scans,
            ),
        ),
        (Input::HistoryChoice, history_choice(&forms.history)),
    ]
}

/// The History view's choice: the robot, the results left out, `k`.
fn history_choice(f: &super::forms::HistoryForm) -> Reading {
    Reading::new(
        vec![
            ("robot".into(), f.robot.clone().unwrap_or_default()),
            ("unticked".into(), f.unselected.len().to_string()),
            ("k".into(), f.k.to_string()),
        ],
        (&f.unselected, f.k.to_bits()),
    )
}

/// The hand-eye guess "from the open calibration": the result's on show,
/// else the open session's.
#[must_use]
pub fn plan_hand_eye(state: &AppState) -> Option<Isometry3<f64>> {
    state
        .result
        .as_ref()
        .map(|v| v.file.hand_eye)
        .or_else(|| state.loaded.as_ref().and_then(|l| l.session.hand_eye))
}

fn range_text(r: Option<&SensorRange>) -> String {
    r.map_or_else(
        || "none".to_string(),
        |r| format!("y {}…{}, z {}…{} mm", r.y[0], r.y[1], r.z[0], r.z[1]),
    )
}

/// The open session: its name, its measuring range, and (unseen) which
/// load of a session it is.
fn session(state: &AppState) -> Reading {
    match &state.loaded {
        Some(l) => Reading::new(
            vec![
                ("session".into(), format!("\"{}\"", l.session.name)),
                (
                    "measuring range".into(),
                    range_text(l.session.sensor_range.as_ref()),
                ),
            ],
            state.session_loads,
        ),
        None => Reading::new(vec![("session".into(), "none".into())], 0_u64),
    }
}

/// The measurements left out: how many, the first few ids.
#[must_use]
pub fn left_out(excluded: &BTreeSet<String>) -> Reading {
    let mut ids: Vec<&str> = excluded
        .iter()
        .take(IDS_SHOWN)
        .map(String::as_str)
        .collect();
    if excluded.len() > IDS_SHOWN {
        ids.push("…");
    }
    let text = if excluded.is_empty() {
        "none".to_string()
    } else {
        format!("{} ({})", excluded.len(), ids.join(", "))
    };
    Reading::new(vec![("left out".into(), text)], excluded)
}

/// The solver settings (pairing and SVD tolerance only for the paper's
/// method, which alone uses them).
#[must_use]
pub fn solver(s: &SolverForm) -> Reading {
    let mut fields = vec![
        ("method".into(), s.method.as_str().to_string()),
        ("threshold".into(), format!("{} mm", s.threshold)),
        ("max iterations".into(), s.max_iterations.to_string()),
    ];
    if s.method == Method::Paper {
        fields.push(("pairs".into(), s.pairing.as_str().to_string()));
        fields.push(("SVD tolerance".into(), format!("{:e}", s.svd_tolerance)));
    }
    Reading::new(fields, ())
}

/// The Plan form: every field it shows, the hand-eye guess, and (unseen)
/// the whole request.
#[must_use]
pub fn plan_form(f: &PlanForm, session_hand_eye: Option<Isometry3<f64>>) -> Reading {
    let r = &f.request;
    let hand_eye = match (f.hand_eye_from_session, session_hand_eye) {
        (false, _) => "the paper's initial one".to_string(),
        (true, None) => "from the open calibration (none open)".to_string(),
        (true, Some(h)) => {
            let t = h.translation.vector;
            format!(
                "from the open calibration ({:.3}, {:.3}, {:.3} mm)",
                t.x, t.y, t.z
            )
        }
    };
    let fields = vec![
        ("robot".into(), f.robot.clone()),
        (
            "sphere".into(),
            format!(
                "({}, {}, {}) mm",
                r.design.sphere[0], r.design.sphere[1], r.design.sphere[2]
            ),
        ),
        ("translations".into(), r.design.n_translation.to_string()),
        ("rotations".into(), r.design.n_rotation.to_string()),
        ("identify stations".into(), r.design.n_identify.to_string()),
        (
            "poses per identify station".into(),
            r.design.identify_poses.to_string(),
        ),
        ("validate stations".into(), r.design.n_validate.to_string()),
        (
            "poses per validate station".into(),
            r.design.validate_poses.to_string(),
        ),
        ("candidates".into(), r.design.candidates.to_string()),
        ("prediction runs".into(), r.predict_runs.to_string()),
        ("cut angle".into(), format!("{}°", r.design.cut_angle)),
        ("seed".into(), r.design.seed.to_string()),
        ("range".into(), range_text(r.range.as_ref())),
        ("spread".into(), r.spread.to_string()),
        ("hand-eye guess".into(), hand_eye),
    ];
    // Fields the view does not show (cone, box, …) still count.
    let unseen = format!("{r:?}");
    Reading::new(fields, unseen)
}

/// The acceptance tolerance.
#[must_use]
pub fn tolerance(t: &Tolerance) -> Reading {
    Reading::new(
        vec![
            ("std ≤".into(), format!("{:.3} mm", t.std_mm)),
            ("max ≤".into(), format!("{:.3} mm", t.max_mm)),
        ],
        (t.std_mm.to_bits(), t.max_mm.to_bits()),
    )
}

/// The calibration result on show: which one (the how-many-th shown in
/// this window, where it came from, its method); a new run or a result
/// opened reads otherwise even with the same numbers.
#[must_use]
pub fn calibration(state: &AppState) -> Reading {
    let text = match &state.result {
        None => "none".to_string(),
        Some(r) => match &r.origin {
            super::view::ResultOrigin::Run { .. } => {
                format!("run #{} ({})", state.results_shown, r.method)
            }
            super::view::ResultOrigin::Review(p) => format!(
                "{} (#{}, {})",
                p.file_name().map_or_else(
                    || p.display().to_string(),
                    |n| n.to_string_lossy().into_owned()
                ),
                state.results_shown,
                r.method
            ),
        },
    };
    Reading::new(
        vec![("result".into(), text)],
        (state.result.is_some(), state.results_shown),
    )
}

/// Size and modification time of a file, when it can be read: a file
/// rewritten in place reads otherwise.
fn file_stamp(path: &str) -> Option<(u64, std::time::SystemTime)> {
    let path = path.trim();
    if path.is_empty() {
        return None;
    }
    let m = std::fs::metadata(path).ok()?;
    Some((m.len(), m.modified().ok()?))
}

/// The Compensate view's targets file and options: the fields it shows,
/// and (unseen) the size and time of the targets and tool files.
#[must_use]
pub fn targets(f: &CompensateForm) -> Reading {
    let tcp = match f.tcp {
        TcpChoice::ToolFile if f.tool.trim().is_empty() => "tool file (none chosen)".to_string(),
        TcpChoice::ToolFile => format!("tool {}", f.tool.trim()),
        other => other.key().to_string(),
    };
    let fields = vec![
        (
            "file".into(),
            if f.targets.trim().is_empty() {
                "none".to_string()
            } else {
                f.targets.trim().to_string()
            },
        ),
        (
            "pose convention".into(),
            CompensateForm::convention_label(f.convention),
        ),
        ("TCP".into(), tcp),
        (
            "joint targets".into(),
            match f.options.joint_targets {
                JointTargets::Compensate => "compensated",
                JointTargets::Keep => "kept",
            }
            .to_string(),
        ),
        (
            "σ tolerance".into(),
            format!("{} mm", f.options.sigma_tolerance_mm),
        ),
        (
            "far in joints".into(),
            format!("{}°", f.options.far_joints_deg),
        ),
        (
            "region margin".into(),
            format!("{} mm", f.options.region_margin_mm),
        ),
    ];
    let tool = (f.tcp == TcpChoice::ToolFile).then(|| file_stamp(&f.tool));
    Reading::new(fields, (file_stamp(&f.targets), tool))
}

/// The Measure form: what is measured and how (not where it is
/// exported).
#[must_use]
pub fn measure_form(f: &super::forms::measure::MeasureForm) -> Reading {
    use super::forms::measure::ScanChoice;
    let scan = match f.choice {
        ScanChoice::OpenSession => "the open session".to_string(),
        ScanChoice::SessionFile => f.session_file.trim().to_string(),
        ScanChoice::RawScan => format!("{} + {}", f.log.trim(), f.profiles.trim()),
    };
    let fields = vec![
        ("scan".into(), scan),
        (
            "use".into(),
            f.usage.map_or("all", |u| u.as_str()).to_string(),
        ),
        (
            "frame".into(),
            f.frame_path()
                .map_or_else(|| "base".to_string(), |p| p.display().to_string()),
        ),
        ("sensor noise".into(), format!("{} mm", f.sensor_noise_mm)),
        (
            "σ".into(),
            if f.no_sigma { "no" } else { "yes" }.to_string(),
        ),
    ];
    let mut unseen = f.clone();
    unseen.out.clear();
    Reading::new(fields, format!("{unseen:?}"))
}
