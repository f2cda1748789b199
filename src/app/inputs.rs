//! The readings of the workbench's inputs ([`Input`]) from the state and
//! the forms, taken every frame for the [`Provenance`] of everything
//! derived: what each is, in the fields people read, and a fingerprint
//! of all of it.
//!
//! [`Provenance`]: super::provenance::Provenance

use std::collections::BTreeSet;

use nalgebra::Isometry3;

use super::forms::{Forms, PlanForm, SolverForm};
use super::provenance::{Input, Reading};
use super::state::AppState;
use crate::engine::result_view::Tolerance;
use crate::engine::session::SensorRange;
use crate::engine::solve::Method;

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
        (Input::ResultShown, result_shown(state)),
        (Input::MeasureForm, measure_form(&forms.measure)),
    ]
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
            format!("({}, {}, {}) mm", r.sphere[0], r.sphere[1], r.sphere[2]),
        ),
        ("translations".into(), r.n_translation.to_string()),
        ("rotations".into(), r.n_rotation.to_string()),
        ("identify stations".into(), r.n_identify.to_string()),
        (
            "poses per identify station".into(),
            r.identify_poses.to_string(),
        ),
        ("validate stations".into(), r.n_validate.to_string()),
        (
            "poses per validate station".into(),
            r.validate_poses.to_string(),
        ),
        ("candidates".into(), r.candidates.to_string()),
        ("prediction runs".into(), r.predict_runs.to_string()),
        ("cut angle".into(), format!("{}°", r.cut_angle)),
        ("seed".into(), r.seed.to_string()),
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

/// The result on show: its method and ε in words, and (unseen) which
/// result it is (its origin, ε and hand-eye: a new run is another result
/// even with the same figures, its wall time differs).
#[must_use]
pub fn result_shown(state: &AppState) -> Reading {
    match &state.result {
        Some(v) => {
            let origin = match &v.origin {
                super::view::ResultOrigin::Run { seconds, .. } => {
                    format!("a run ({seconds:.2} s)")
                }
                super::view::ResultOrigin::Review(p) => p.display().to_string(),
            };
            let h = &v.file.hand_eye;
            let hidden = (
                format!("{:?}", v.origin),
                v.file.epsilon_after.to_bits(),
                h.translation
                    .vector
                    .iter()
                    .map(|x| x.to_bits())
                    .collect::<Vec<_>>(),
                h.rotation
                    .coords
                    .iter()
                    .map(|x| x.to_bits())
                    .collect::<Vec<_>>(),
            );
            Reading::new(
                vec![
                    ("result".into(), format!("{} {origin}", v.method)),
                    ("ε after".into(), format!("{:.4} mm", v.file.epsilon_after)),
                ],
                hidden,
            )
        }
        None => Reading::new(vec![("result".into(), "none".into())], 0_u64),
    }
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
