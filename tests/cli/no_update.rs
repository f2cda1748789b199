//! Issue 34: a run whose ε starts within the threshold makes no update
//! (FORMAT.md "The iteration": one `iterations` entry) and `calibrate`
//! says so with the figures and the way to refine anyway; the way it
//! names (`--threshold 0`) refines the start toward the truth.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use spherecal::engine::files::format;

use crate::support::bin::run;

/// Distance (mm) between the translations of a result's hand-eye and the
/// truth's.
fn off_truth(hand_eye: &nalgebra::Isometry3<f64>, truth: &Path) -> f64 {
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(truth).unwrap()).unwrap();
    let t = &truth["hand_eye"];
    let at = |i: usize| t[i][3].as_f64().unwrap();
    let true_t = nalgebra::Vector3::new(at(0), at(1), at(2));
    (hand_eye.translation.vector - true_t).norm()
}

#[test]
fn a_start_within_the_threshold_is_said_and_threshold_zero_refines_it() {
    let dir = tempfile::tempdir().unwrap();
    let session = dir.path().join("pose-only.json");
    let s = session.to_str().unwrap();
    // A pose-only cell whose start is already good (the case:
    // ε 0.107 mm against the session's 0.15 mm).
    let (code, _, err) = run(&["simulate", "--pose-only", "0.02", "--out", s, "-q"]);
    assert_eq!(code, 0, "{err}");
    let start = dir.path().join("start.result.json");
    let (code, out, err) = run(&[
        "calibrate",
        s,
        "--method",
        "ml",
        "--out",
        start.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    // The stop line does not call an unrefined start "converged".
    let console = format!("{out}{err}");
    assert!(
        console
            .contains("no update: ε = 0.1068 mm was within the threshold 0.1500 mm at the start"),
        "{console}"
    );
    assert!(!console.contains("converged"), "{console}");
    assert!(
        err.contains(
            "warning: no update: ε = 0.1068 mm started within the threshold 0.15 mm, so nothing was identified"
        ),
        "{err}"
    );
    assert!(
        err.contains("run again with threshold 0 (`--threshold 0`"),
        "{err}"
    );
    let start = format::load_result(&start).unwrap();
    assert_eq!(start.iterations.len(), 1, "no update: one entry");
    assert_eq!(start.hand_eye, start.hand_eye_initial);
    assert!(start.no_update_warning().is_some());

    // The way it names refines the start: closer to the truth, no warning.
    let refined = dir.path().join("refined.result.json");
    let (code, _, err) = run(&[
        "calibrate",
        s,
        "--method",
        "ml",
        "--threshold",
        "0",
        "--out",
        refined.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("no update"), "{err}");
    let refined = format::load_result(&refined).unwrap();
    assert!(refined.no_update_warning().is_none());
    assert!(refined.epsilon_after < refined.epsilon_before);
    let truth = dir.path().join("pose-only.truth.json");
    let (before, after) = (
        off_truth(&start.hand_eye, &truth),
        off_truth(&refined.hand_eye, &truth),
    );
    // 0.049 mm at the start, 0.0067 mm refined (seed 1).
    assert!(
        after < before / 3.0,
        "start {before} mm, refined {after} mm"
    );
    assert!(after < 0.02, "refined {after} mm off the truth");
}
