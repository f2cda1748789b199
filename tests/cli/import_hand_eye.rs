//! `import --joints --hand-eye`: the guess given is written to the
//! session as its initial hand-eye (as a pose file's import does), the
//! note says so, and calibrate starts from it (with --mount fixed it is the start
//! of base_from_sensor instead).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

use spherecal::engine::files::format;

use crate::support::bin::run;

fn import(csv: &Path, out: &Path, extra: &[&str]) -> (i32, String, String) {
    let joints = csv.join("joints.csv");
    let profiles = csv.join("profiles");
    let mut args = vec![
        "import",
        "--joints",
        joints.to_str().unwrap(),
        "--profiles",
        profiles.to_str().unwrap(),
        "--robot",
        "irb2400",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run(&args)
}

#[test]
fn a_joint_log_import_takes_the_hand_eye_given() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("csv");
    let (code, _, err) = run(&[
        "simulate",
        "--out",
        dir.path().join("s.json").to_str().unwrap(),
        "--csv-out",
        csv.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(code, 0, "{err}");
    // Without: no initial hand-eye in the session (calibrate's eq. 6-9).
    let plain = dir.path().join("plain.json");
    let (code, _, err) = import(&csv, &plain, &[]);
    assert_eq!(code, 0, "{err}");
    assert!(format::load_session(&plain).unwrap().hand_eye.is_none());
    // With: the result's hand-eye, written as given, said.
    let guess = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/v1/result-held-out.json");
    let expected = format::load_result(&guess).unwrap().hand_eye;
    let given = dir.path().join("given.json");
    let (code, out, err) = import(&csv, &given, &["--hand-eye", guess.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("initial hand-eye: the guess given"), "{out}");
    let he = format::load_session(&given).unwrap().hand_eye.unwrap();
    assert!((he.translation.vector - expected.translation.vector).norm() < 1e-9);
    assert!(he.rotation.angle_to(&expected.rotation) < 1e-9);
    // Calibrate starts from it: the result's initial hand-eye.
    let result = dir.path().join("given.result.json");
    let (code, _, err) = run(&[
        "calibrate",
        given.to_str().unwrap(),
        "--out",
        result.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(code, 0, "{err}");
    let initial = format::load_result(&result).unwrap().hand_eye_initial;
    assert!((initial.translation.vector - expected.translation.vector).norm() < 1e-6);
    // An unreadable guess is refused before anything is imported.
    let missing = dir.path().join("missing.json");
    let refused = dir.path().join("refused.json");
    let (code, _, err) = import(&csv, &refused, &["--hand-eye", missing.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--hand-eye"), "{err}");
    assert!(!refused.exists());
}
