//! `history` on a fixed sensor's results (issue 35): the six sensor
//! values are `base_from_sensor`, and history names them so (the
//! library's column, the series, the CSV), not the hand-eye.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use super::support::bin::run;

/// A fixed-sensor session simulated with `seed` and calibrated, its
/// result dated `date` by its name.
fn calibrated(dir: &Path, seed: &str, date: &str) {
    let session = dir.join(format!("tracker-{date}.json"));
    let s = session.to_str().unwrap();
    let (code, _, err) = run(&[
        "simulate", "--mount", "fixed", "--seed", seed, "--out", s, "-q",
    ]);
    assert_eq!(code, 0, "{err}");
    let result = dir.join(format!("tracker-{date}.result.json"));
    let (code, _, err) = run(&["calibrate", s, "--out", result.to_str().unwrap(), "-q"]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn history_names_a_fixed_sensor_s_values_base_from_sensor() {
    let dir = tempfile::tempdir().unwrap();
    calibrated(dir.path(), "4", "2026-03-02");
    calibrated(dir.path(), "5", "2026-04-06");
    let csv = dir.path().join("drift.csv");
    let (code, out, err) = run(&[
        "history",
        dir.path().to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("base_from_sensor x, y, z mm; roll, pitch, yaw deg"),
        "{out}"
    );
    assert!(
        out.contains("base_from_sensor bT_s, a fixed sensor"),
        "{out}"
    );
    assert!(!out.contains("hand-eye eT_s"), "{out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.contains("base_from_sensor.x"), "{text}");
    assert!(text.contains("base from sensor"), "{text}");
    assert!(
        !text.contains("hand_eye.x") && !text.contains(",hand-eye"),
        "{text}"
    );
}
