//! The file formats of FORMAT.md against fixtures: every published format
//! version keeps a fixture that must load forever (`tests/data/v1/`), an
//! independent implementation's session must load, every session rule has
//! one failing fixture whose message must name the measurement and the
//! problem (`tests/data/invalid/`), and saves round-trip exactly and
//! atomically.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    reason = "tests fail by panicking"
)]

use std::fs;
use std::path::{Path, PathBuf};

use spherecal::engine::base::session::MIN_STRIPE_POINTS;
use spherecal::engine::base::session::{Observation, Session, Use};
use spherecal::engine::files::format::FileError;
use spherecal::engine::files::format::{
    load_result, load_session, parse_result, parse_session, result_to_json, save_result,
    save_session, session_to_json, write_atomic,
};

fn data(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(path)
}

fn load(path: &str) -> Session {
    let path = data(path);
    load_session(&path).unwrap_or_else(|e| panic!("{} must load: {e}", path.display()))
}

fn count(session: &Session, usage: Use) -> usize {
    session.with_use(usage).count()
}

// ---------------------------------------------------------------------------
// Files that must load forever
// ---------------------------------------------------------------------------

#[test]
fn v1_session_with_every_key_loads() {
    let s = load("v1/session-all-keys.json");
    assert_eq!(s.name, "fixture: every key of session format version 1");
    assert!(s.name_given);
    assert_eq!(s.robot.name, "ABB IRB 2400/16");
    assert_eq!(s.robot.joints.len(), 6);
    assert_eq!(s.robot.joints[0].d, 615.0);
    assert_eq!(s.robot.joints[1].theta, -90.0);
    assert_eq!(s.robot.joints[2].beta, 0.05);
    assert!(s.base_given && s.flange_given);
    assert!((s.robot.base.translation.vector.x - 120.5).abs() < 1e-12);
    assert!((s.robot.base.rotation.angle() - 30_f64.to_radians()).abs() < 1e-12);
    assert!((s.robot.flange.rotation.angle() - std::f64::consts::PI).abs() < 1e-12);
    assert_eq!(s.sphere_diameter, 38.1);
    assert!((s.sphere_radius() - 19.05).abs() < 1e-15);
    assert!(s.sensor_given);
    assert_eq!(s.default_side, 1);
    let hand_eye = s.hand_eye.expect("the fixture has a hand_eye");
    assert!((hand_eye.translation.vector.z - 287.804).abs() < 1e-12);
    assert!(s.solver_given);
    assert_eq!(s.solver.threshold, 0.15);
    assert_eq!(s.solver.max_iterations, 20, "20.0 is an integer");
    assert_eq!(s.reference_distances.len(), 1);
    assert_eq!(s.reference_distances[0].from, "V1");
    assert_eq!(s.reference_distances[0].to, "V2");
    assert_eq!(s.reference_distances[0].distance, 512.3456);

    assert_eq!(s.measurements.len(), 14);
    assert_eq!(count(&s, Use::Translation), 3);
    assert_eq!(count(&s, Use::Rotation), 2);
    assert_eq!(count(&s, Use::Identify), 5);
    assert_eq!(count(&s, Use::Validate), 4);
    let by_id = |id: &str| s.measurements.iter().find(|m| m.id == id).unwrap();
    let t1 = by_id("t1");
    assert_eq!(
        t1.joints,
        vec![0.0, 10.0, 5.0, 0.0, 60.0, 0.0],
        "1e1 and -0.0 are numbers"
    );
    assert_eq!(t1.side_given, None);
    assert_eq!(t1.side, 1);
    let t2 = by_id("t2");
    assert_eq!((t2.side_given, t2.side), (Some(-1), -1), "-1.0 is a side");
    match &t1.observation {
        Observation::Centre(c) => assert_eq!(c.z, -4.547_473_508_864_641e-13),
        Observation::Stripe(_) => panic!("t1 gives a centre"),
    }
    match &by_id("r1").observation {
        Observation::Stripe(points) => {
            assert_eq!(points.len(), MIN_STRIPE_POINTS);
            assert_eq!(points[0], [-15.82, 4.11]);
        }
        Observation::Centre(_) => panic!("r1 gives a stripe"),
    }
    assert_eq!(by_id("i1").side, -1);
    assert_eq!(by_id("i5").side_given, Some(1));
    assert_eq!(s.stations(Use::Identify).len(), 2);
    assert_eq!(s.stations(Use::Validate).len(), 2);
}

#[test]
fn v1_result_loads() {
    let r = load_result(&data("v1/result.json")).unwrap();
    assert_eq!(r.session, "fixture: every key of session format version 1");
    assert_eq!(r.robot.as_ref().unwrap().joints.len(), 6);
    assert_eq!(r.joint_errors.len(), 6);
    assert_eq!(r.solver.method(), "paper");
    assert_eq!(r.solver.paper().and_then(|p| p.kept_directions), Some(27));
    assert_eq!(r.iterations.len(), 3);
    assert_eq!(r.epsilon_before, r.iterations[0].epsilon);
    assert_eq!(r.epsilon_after, 0.149);
    assert_eq!(r.centres.len(), 14);
    assert_eq!(r.centres[0].measurement, "t1");
    assert_eq!(r.centres[0].usage, "translation");
    let v = r.validation.as_ref().expect("the fixture has validation");
    assert_eq!(v.distances.len(), 2);
    assert_eq!(v.distances[1].pose, 1);
    assert_eq!(v.within_station.after.max, 0.31);
    // The robot block is a usable model (its base and flange were checked on load).
    assert!(
        r.robot
            .as_ref()
            .unwrap()
            .base_from_flange(&[0.0; 6])
            .translation
            .vector
            .iter()
            .all(|v| v.is_finite())
    );
}

#[test]
fn independent_example_session_loads() {
    let s = load("v1/example-irb2400.json");
    assert_eq!(s.name, "example IRB 2400 session (simulated)");
    assert_eq!(s.measurements.len(), 52);
    assert_eq!(s.robot.joints.len(), 6);
    assert_eq!(s.robot.joints[3].d, 755.0);
    assert!(!s.base_given && !s.flange_given && s.hand_eye.is_none());
    assert_eq!(s.sphere_diameter, 38.1);
    assert_eq!(s.default_side, 1);
    assert_eq!(s.solver.max_iterations, 20);
    assert_eq!(count(&s, Use::Translation), 4);
    assert_eq!(count(&s, Use::Rotation), 6);
    assert_eq!(count(&s, Use::Identify), 24);
    assert_eq!(count(&s, Use::Validate), 18);
    assert_eq!(s.stations(Use::Identify).len(), 4);
    assert_eq!(s.stations(Use::Validate).len(), 3);
    assert_eq!(s.reference_distances.len(), 2);
    // Mixed sides: some measurements override sensor.side with -1.
    let minus = s.measurements.iter().filter(|m| m.side == -1).count();
    assert_eq!(minus, 29);
    assert!(
        s.measurements
            .iter()
            .all(|m| m.side_given.is_none() || m.side_given == Some(-1))
    );
    for m in &s.measurements {
        assert_eq!(m.joints.len(), 6);
        match &m.observation {
            Observation::Stripe(points) => {
                assert!(points.len() >= 40, "{}: {}", m.id, points.len());
            }
            Observation::Centre(_) => {
                panic!("{} gives a centre; the example has stripes only", m.id)
            }
        }
    }
}

#[test]
fn independent_example_truth_matches_its_session() {
    // The truth is the simulator's own format; here only its link to the
    // session is checked (ids and name), so the pair stays together.
    let text = fs::read_to_string(data("v1/example-irb2400.truth.json")).unwrap();
    let truth: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(truth["format"], "spherecal-truth");
    let s = load("v1/example-irb2400.json");
    assert_eq!(truth["session"], s.name.as_str());
    let ids = truth["measurements"].as_object().unwrap();
    assert_eq!(ids.len(), s.measurements.len());
    assert!(s.measurements.iter().all(|m| ids.contains_key(&m.id)));
}

// ---------------------------------------------------------------------------
// One failing fixture per rule
// ---------------------------------------------------------------------------

/// File in `tests/data/invalid/` (without `.json`), the measurement the
/// error must name (or none), and phrases the message must contain.
const INVALID: &[(&str, Option<&str>, &[&str])] = &[
    (
        "syntax-error",
        None,
        &["not valid JSON", "expected `,` or `}` at line 4 column 3"],
    ),
    (
        "nan-literal",
        None,
        &["not valid JSON", "NaN and Infinity are not JSON numbers"],
    ),
    (
        "infinity-literal",
        None,
        &["not valid JSON", "NaN and Infinity are not JSON numbers"],
    ),
    (
        "number-out-of-range",
        None,
        &["reference_distances[0].distance: number out of range at line 32"],
    ),
    (
        "trailing-characters",
        None,
        &["not valid JSON", "trailing characters"],
    ),
    (
        "not-an-object",
        None,
        &["expected an object, found an array at line 1 column 1"],
    ),
    (
        "missing-format",
        None,
        &["missing key `format`", "not a spherecal session file"],
    ),
    (
        "wrong-format",
        None,
        &["format is \"spherecal-result\"", "this is a result file"],
    ),
    ("missing-version", None, &["missing key `version`"]),
    (
        "newer-version",
        None,
        &["version 2 is newer than this build", "reads version 1"],
    ),
    (
        "version-not-integer",
        None,
        &[
            "version 1.5 is not a session format version",
            "reads version 1",
        ],
    ),
    ("missing-key-top", None, &["missing key `sphere`"]),
    ("unknown-key-top", None, &["unknown key `comment`"]),
    ("duplicate-key-top", None, &["duplicate key `name`"]),
    (
        "name-not-string",
        None,
        &["name: invalid type: integer `5`, expected a string"],
    ),
    ("robot-missing-name", None, &["robot: missing key `name`"]),
    ("unknown-key-in-robot", None, &["robot: unknown key `dof`"]),
    (
        "unknown-key-in-joint",
        None,
        &["robot.joints[0]: unknown key `offset`"],
    ),
    (
        "duplicate-key-in-joint",
        None,
        &["robot.joints[3]: duplicate key `d`"],
    ),
    (
        "missing-joint-key",
        None,
        &["robot.joints[3]: missing key `d`"],
    ),
    (
        "joint-not-object",
        None,
        &["robot.joints[0]: expected an object, found an array"],
    ),
    (
        "no-joints",
        None,
        &["robot.joints is empty: at least one joint is needed"],
    ),
    (
        "base-not-a-rotation",
        None,
        &["robot.base: 3x3 block is not orthonormal"],
    ),
    (
        "base-row-too-short",
        None,
        &["robot.base[2] must hold 4 numbers, found 3"],
    ),
    (
        "flange-last-row",
        None,
        &["robot.flange: last row must be [0, 0, 0, 1]"],
    ),
    (
        "not-a-rotation",
        None,
        &["hand_eye: 3x3 block is not orthonormal"],
    ),
    (
        "hand-eye-reflection",
        None,
        &["hand_eye: 3x3 block has determinant -1", "reflection"],
    ),
    (
        "matrix-wrong-shape",
        None,
        &["hand_eye must be 4 rows of 4 numbers, found 3 rows"],
    ),
    (
        "null-optional-key",
        None,
        &["sensor: expected an object, found null"],
    ),
    (
        "diameter-zero",
        None,
        &["sphere.diameter must be positive (mm), found 0"],
    ),
    (
        "diameter-string",
        None,
        &["sphere.diameter: invalid type: string \"38.1\", expected a number"],
    ),
    (
        "unknown-key-in-sphere",
        None,
        &["sphere: unknown key `radius`"],
    ),
    (
        "sensor-side-zero",
        None,
        &["sensor.side must be 1 or -1, found 0"],
    ),
    ("side-zero", Some("i5"), &["side must be 1 or -1, found 0"]),
    (
        "side-half",
        Some("v2"),
        &["side must be 1 or -1, found -0.5"],
    ),
    (
        "threshold-negative",
        None,
        &["solver.threshold must be zero or positive"],
    ),
    (
        "max-iterations-fraction",
        None,
        &["solver.max_iterations must be a non-negative integer, found 20.5"],
    ),
    (
        "max-iterations-negative",
        None,
        &["solver.max_iterations must be a non-negative integer, found -1"],
    ),
    (
        "unknown-key-in-solver",
        None,
        &["solver: unknown key `tolerance`"],
    ),
    (
        "duplicate-id",
        Some("i1"),
        &["id `i1` is used by measurements[5] and measurements[7]"],
    ),
    ("empty-id", None, &["measurements[13].id must not be empty"]),
    ("missing-id", None, &["measurements[13]: missing key `id`"]),
    ("empty-station", Some("v4"), &["station must not be empty"]),
    ("missing-use", Some("v4"), &["missing key `use`"]),
    (
        "unknown-use",
        Some("i4"),
        &["use must be one of translation, rotation, identify, validate; found \"identity\""],
    ),
    (
        "unknown-key-in-measurement",
        Some("i2"),
        &["unknown key `sied`"],
    ),
    (
        "duplicate-key-in-measurement",
        Some("i2"),
        &["duplicate key `station`"],
    ),
    (
        "unknown-key-in-stripe",
        Some("i1"),
        &["stripe: unknown key `fit`"],
    ),
    (
        "duplicate-key-in-stripe",
        Some("r1"),
        &["stripe: duplicate key `points`"],
    ),
    (
        "wrong-joint-count",
        Some("v1"),
        &["joints has 5 readings, the robot has 6 joints"],
    ),
    (
        "joint-reading-not-number",
        Some("v1"),
        &["joints[1]: invalid type: string \"15.0\", expected a number"],
    ),
    (
        "both-stripe-and-centre",
        Some("i2"),
        &["both `stripe` and `centre` are given"],
    ),
    (
        "neither-stripe-nor-centre",
        Some("i3"),
        &["neither `stripe` nor `centre` is given"],
    ),
    (
        "stripe-too-short",
        Some("r1"),
        &["stripe has 4 points, at least 5 are needed"],
    ),
    (
        "stripe-point-three-numbers",
        Some("i1"),
        &["stripe.points[1] must hold 2 numbers [y, z], found 3"],
    ),
    (
        "stripe-point-null",
        Some("i1"),
        &["stripe.points[2]: invalid type: null, expected a number"],
    ),
    (
        "centre-two-numbers",
        Some("i4"),
        &["centre must hold 3 numbers [x, y, z], found 2"],
    ),
    (
        "translations-two-stations",
        Some("t3"),
        &[
            "all translation measurements must share one station",
            "t1, t2 at station P0, t3 at station P9",
        ],
    ),
    (
        "rotations-two-stations",
        Some("r2"),
        &[
            "all rotation measurements must share one station",
            "r1 at station P0, r2 at station P1",
        ],
    ),
    (
        "too-few-translations",
        None,
        &[
            "without `hand_eye`",
            "at least 3 translation measurements; the session has 2 (t1, t2)",
        ],
    ),
    (
        "too-few-rotations",
        None,
        &[
            "without `hand_eye`",
            "at least 2 rotation measurements; the session has 1 (r1)",
        ],
    ),
    (
        "identify-station-single",
        Some("i3"),
        &["identify station P3 has only 1 measurement (i3)"],
    ),
    (
        "reference-unknown-station",
        None,
        &[
            "reference_distances[0].to: station `V9` has no validate measurements",
            "no measurement has this station",
        ],
    ),
    (
        "reference-identify-station",
        None,
        &[
            "reference_distances[0].from: station `P1` has no validate measurements",
            "it has identify measurements",
        ],
    ),
    (
        "reference-same-station",
        None,
        &["reference_distances[0]: from and to are the same station `V1`"],
    ),
    (
        "reference-distance-zero",
        None,
        &["reference_distances[0].distance must be positive (mm), found 0"],
    ),
    (
        "reference-missing-distance",
        None,
        &["reference_distances[0]: missing key `distance`"],
    ),
];

#[test]
fn the_base_of_the_invalid_fixtures_is_valid() {
    // Every file in invalid/ is this one with a single change, so each
    // fails for its own reason only.
    let s = load("base.json");
    assert!(s.hand_eye.is_none());
    assert_eq!(s.measurements.len(), 14);
}

#[test]
fn every_invalid_fixture_fails_with_its_message() {
    let mut failures = Vec::new();
    for &(name, measurement, phrases) in INVALID {
        let path = data(&format!("invalid/{name}.json"));
        match load_session(&path) {
            Ok(_) => failures.push(format!("{name}: loaded")),
            Err(err) => {
                let text = err.to_string();
                if !matches!(err, FileError::Invalid { .. }) {
                    failures.push(format!("{name}: not an Invalid error: {text}"));
                }
                if err.measurement() != measurement {
                    failures.push(format!(
                        "{name}: names measurement {:?}, expected {measurement:?}: {text}",
                        err.measurement()
                    ));
                }
                for phrase in phrases {
                    if !text.contains(phrase) {
                        failures.push(format!("{name}: message lacks {phrase:?}: {text}"));
                    }
                }
                // FileError's Display: "measurement ID: MESSAGE (PATH)".
                if !text.ends_with(&format!("({})", path.display())) {
                    failures.push(format!(
                        "{name}: message does not end with the path: {text}"
                    ));
                }
                if let Some(id) = measurement
                    && !text.starts_with(&format!("measurement {id}: "))
                {
                    failures.push(format!(
                        "{name}: message does not start with the measurement: {text}"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_invalid_fixture_is_in_the_table() {
    let mut names: Vec<String> = fs::read_dir(data("invalid"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut listed: Vec<String> = INVALID
        .iter()
        .map(|(n, _, _)| format!("{n}.json"))
        .collect();
    listed.sort();
    assert_eq!(names, listed);
}

#[test]
fn errors_give_line_and_column() {
    let err = load_session(&data("invalid/side-zero.json")).unwrap_err();
    let base = fs::read_to_string(data("invalid/side-zero.json")).unwrap();
    let line = base
        .lines()
        .position(|l| l.contains("\"side\": 0"))
        .unwrap()
        + 1;
    assert!(
        err.to_string().contains(&format!("at line {line} column ")),
        "{err}"
    );
    let err = load_session(&data("invalid/missing-joint-key.json")).unwrap_err();
    let text = fs::read_to_string(data("invalid/missing-joint-key.json")).unwrap();
    let line = text.lines().position(|l| l.contains("\"a\": 135")).unwrap() + 1;
    assert!(
        err.to_string()
            .contains(&format!(" at line {line} column ")),
        "{err}"
    );
}

// ---------------------------------------------------------------------------
// Other loading behaviour
// ---------------------------------------------------------------------------

#[test]
fn name_defaults_to_the_file_stem_and_stays_absent() {
    let text = fs::read_to_string(data("base.json")).unwrap();
    let text = text.replace("  \"name\": \"base of the invalid fixtures\",\n", "");
    let s = parse_session(&text, Path::new("/cells/cell-3 2026-11-20.json")).unwrap();
    assert_eq!(s.name, "cell-3 2026-11-20");
    assert!(!s.name_given);
    let saved = session_to_json(&s);
    let top: serde_json::Value = serde_json::from_str(&saved).unwrap();
    assert!(top.get("name").is_none(), "{saved}");
}

#[test]
fn optional_blocks_take_their_defaults() {
    let text = r#"{"format": "spherecal-session", "version": 1,
      "robot": {"name": "one axis", "joints": [{"alpha": 0, "a": 0, "beta": 0, "theta": 0, "d": 100}]},
      "sphere": {"diameter": 25},
      "hand_eye": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
      "measurements": [
        {"id": "a", "station": "S", "use": "identify", "joints": [10], "centre": [1, 2, 3]},
        {"id": "b", "station": "S", "use": "identify", "joints": [20], "centre": [1, 2, 3]}
      ]}"#;
    let s = parse_session(text, Path::new("x.json")).unwrap();
    assert_eq!(s.default_side, 1);
    assert!(!s.sensor_given && !s.solver_given && !s.base_given && !s.flange_given);
    assert_eq!(s.solver.threshold, 0.15);
    assert_eq!(s.solver.max_iterations, 20);
    assert!(s.reference_distances.is_empty());
    assert!(
        s.measurements
            .iter()
            .all(|m| m.side == 1 && m.side_given.is_none())
    );
    // Without any translation or rotation measurement: hand_eye is given.
    assert_eq!(
        parse_session(&session_to_json(&s), Path::new("x.json")).unwrap(),
        s
    );
}

#[test]
fn a_result_file_is_not_a_session_and_vice_versa() {
    let err = load_session(&data("v1/result.json")).unwrap_err();
    assert!(err.to_string().contains("this is a result file"), "{err}");
    let err = load_result(&data("v1/session-all-keys.json")).unwrap_err();
    assert!(err.to_string().contains("this is a session file"), "{err}");
}

#[test]
fn unreadable_file_is_an_io_error_naming_the_file() {
    let path = data("no-such-file.json");
    let err = load_session(&path).unwrap_err();
    assert!(matches!(
        err,
        FileError::Io {
            action: "reading",
            ..
        }
    ));
    assert!(err.to_string().contains("no-such-file.json"), "{err}");
}

#[test]
fn result_rules_are_checked() {
    let text = fs::read_to_string(data("v1/result.json")).unwrap();
    let path = Path::new("r.json");
    // FORMAT.md "Additions to version 1": a result may carry further
    // top-level keys of the engine's own; a reader ignores those it does
    // not know (records inside stay strict, see `k` below).
    let extra_top = text.replacen(
        "\"session\":",
        "\"predicted_range_error\": {\"mean\": 0.1},\n \"session\":",
        1,
    );
    assert_eq!(
        parse_result(&extra_top, path).unwrap(),
        parse_result(&text, path).unwrap()
    );
    let cases: &[(&str, &str, &str)] = &[
        (
            "\"session\":",
            "\"session\": \"x\",\n \"session\":",
            "duplicate key `session`",
        ),
        (
            "\"method\": \"paper\",",
            "\"method\": \"paper\",\n  \"method\": \"ml\",",
            "duplicate key `method`",
        ),
        ("\"method\": \"paper\",", "", "solver: missing key `method`"),
        (
            "\"epsilon_after\": 0.149",
            "\"epsilon_after\": 0.15",
            "epsilon_after (0.15) differs from the last iterations entry (0.149)",
        ),
        (
            "\"use\": \"translation\"",
            "\"use\": \"translate\"",
            "centres[0].use must be one of",
        ),
        ("\"pose\": 0,", "\"pose\": 0, \"k\": 0,", "unknown key `k`"),
    ];
    for (old, new, phrase) in cases {
        assert!(text.contains(old), "{old}");
        let broken = text.replacen(old, new, 1);
        let err = parse_result(&broken, path).unwrap_err();
        assert!(err.to_string().contains(phrase), "{phrase}: {err}");
    }
    // serde would take a record written as an array of its values.
    let as_array = text.replacen("{\"epsilon\": 0.466}", "[0.466]", 1);
    assert_ne!(as_array, text);
    let err = parse_result(&as_array, path).unwrap_err();
    assert!(
        err.to_string()
            .contains("iterations[0]: expected an object, found an array"),
        "{err}"
    );
    // Unknown keys inside `solver` are the method's own.
    let extra = text.replacen(
        "\"method\": \"paper\",",
        "\"method\": \"paper\",\n  \"anything\": {\"goes\": [1, 2]},",
        1,
    );
    assert_eq!(
        parse_result(&extra, path)
            .unwrap()
            .solver
            .paper()
            .unwrap()
            .extra["anything"]["goes"][1],
        2
    );
}

// ---------------------------------------------------------------------------
// Round trips
// ---------------------------------------------------------------------------

#[test]
fn sessions_round_trip_exactly() {
    for file in [
        "v1/session-all-keys.json",
        "v1/example-irb2400.json",
        "base.json",
    ] {
        let s = load(file);
        let text = session_to_json(&s);
        let back =
            parse_session(&text, &data(file)).unwrap_or_else(|e| panic!("{file}: {e}\n{text}"));
        assert_eq!(back, s, "{file}");
        assert_eq!(session_to_json(&back), text, "{file}: writing is stable");
    }
}

#[test]
fn a_round_trip_adds_no_keys() {
    let s = load("v1/example-irb2400.json");
    let before: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(data("v1/example-irb2400.json")).unwrap())
            .unwrap();
    let after: serde_json::Value = serde_json::from_str(&session_to_json(&s)).unwrap();
    fn keys(v: &serde_json::Value, path: &str, out: &mut Vec<String>) {
        match v {
            serde_json::Value::Object(m) => {
                for (k, v) in m {
                    let p = format!("{path}.{k}");
                    out.push(p.clone());
                    keys(v, &p, out);
                }
            }
            serde_json::Value::Array(a) => {
                for (i, v) in a.iter().enumerate() {
                    keys(v, &format!("{path}[{i}]"), out);
                }
            }
            _ => {}
        }
    }
    let (mut a, mut b) = (Vec::new(), Vec::new());
    keys(&before, "", &mut a);
    keys(&after, "", &mut b);
    assert_eq!(a, b);
    // And the numbers are the same numbers.
    assert_eq!(
        before["measurements"][7]["stripe"],
        after["measurements"][7]["stripe"]
    );
}

#[test]
fn results_round_trip_exactly() {
    let r = load_result(&data("v1/result.json")).unwrap();
    let text = result_to_json(&r);
    let back = parse_result(&text, Path::new("r.json")).unwrap();
    assert_eq!(back, r);
    assert_eq!(result_to_json(&back), text);
    let mut without = r.clone();
    without.validation = None;
    let text = result_to_json(&without);
    assert!(!text.contains("\"validation\""));
    assert_eq!(parse_result(&text, Path::new("r.json")).unwrap(), without);
}

#[test]
fn saves_reload_and_leave_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let s = load("v1/session-all-keys.json");
    let path = dir.path().join("cell.json");
    save_session(&s, &path).unwrap();
    save_session(&s, &path).unwrap(); // over an existing file
    assert_eq!(load_session(&path).unwrap(), s);
    let r = load_result(&data("v1/result.json")).unwrap();
    let rpath = dir.path().join("cell.result.json");
    save_result(&r, &rpath).unwrap();
    assert_eq!(load_result(&rpath).unwrap(), r);
    let mut names: Vec<String> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["cell.json", "cell.result.json"]);
}

/// Issue 12: a reference distance of 1e308 gave `"std": null` in a result
/// that `report` and `export-model` then rejected. A result with a
/// non-finite number is not written at all, and the error names the key.
#[test]
fn a_result_with_a_non_finite_number_is_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let good = load_result(&data("v1/result.json")).unwrap();
    let path = dir.path().join("r.json");
    type Spoil = Box<dyn Fn(&mut spherecal::engine::files::format::ResultFile)>;
    let cases: Vec<(Spoil, &str)> = vec![
        (Box::new(|r| r.epsilon_after = f64::NAN), "epsilon_after"),
        (
            Box::new(|r| r.centres[1].sensor[2] = f64::INFINITY),
            "centres[1].sensor[2]",
        ),
        (
            Box::new(|r| {
                if let Some(v) = r.validation.as_mut() {
                    v.after.std = f64::NAN;
                }
            }),
            "validation.after.std",
        ),
    ];
    for (spoil, key) in cases {
        let mut r = good.clone();
        spoil(&mut r);
        let e = save_result(&r, &path).unwrap_err().to_string();
        assert!(
            e.contains(&format!("`{key}` is not a finite number")),
            "{e}"
        );
        assert!(e.contains("not written"), "{e}");
        assert!(!path.exists(), "{key}: a file was written");
        assert!(
            entries(dir.path()).is_empty(),
            "{key}: {:?}",
            entries(dir.path())
        );
    }
    save_result(&good, &path).unwrap();
    assert_eq!(load_result(&path).unwrap(), good);
}

// ---------------------------------------------------------------------------
// Atomic writes
// ---------------------------------------------------------------------------

fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn write_atomic_replaces_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.json");
    write_atomic(&path, b"first").unwrap();
    write_atomic(&path, b"second").unwrap();
    assert_eq!(fs::read(&path).unwrap(), b"second");
    assert_eq!(entries(dir.path()), ["out.json"]);
}

#[test]
fn write_atomic_onto_a_directory_fails_and_cleans_up() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("taken");
    fs::create_dir(&target).unwrap();
    fs::write(target.join("inside"), b"keep").unwrap();
    let err = write_atomic(&target, b"data").unwrap_err();
    assert!(
        matches!(
            err,
            FileError::Io {
                action: "writing",
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("taken"), "{err}");
    assert!(target.is_dir());
    assert_eq!(fs::read(target.join("inside")).unwrap(), b"keep");
    assert_eq!(entries(dir.path()), ["taken"], "no temporary file is left");
}

#[test]
fn write_atomic_into_a_missing_directory_fails() {
    let dir = tempfile::tempdir().unwrap();
    let err = write_atomic(&dir.path().join("missing/out.json"), b"data").unwrap_err();
    assert!(matches!(err, FileError::Io { .. }), "{err}");
    assert!(entries(dir.path()).is_empty());
}

#[cfg(unix)]
#[test]
fn write_atomic_in_a_read_only_directory_keeps_the_old_file() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.json");
    fs::write(&path, b"old").unwrap();
    fs::set_permissions(dir.path(), fs::Permissions::from_mode(0o555)).unwrap();
    // Root ignores directory permissions; then there is nothing to test.
    let probe = dir.path().join("probe");
    let enforced = fs::write(&probe, b"").is_err();
    let _ = fs::remove_file(&probe);
    let result = write_atomic(&path, b"new");
    fs::set_permissions(dir.path(), fs::Permissions::from_mode(0o755)).unwrap();
    if enforced {
        let err = result.unwrap_err();
        assert!(
            matches!(
                err,
                FileError::Io {
                    action: "writing",
                    ..
                }
            ),
            "{err}"
        );
        assert_eq!(fs::read(&path).unwrap(), b"old");
    }
    assert_eq!(entries(dir.path()), ["out.json"]);
}

#[test]
fn write_atomic_without_a_file_name_fails() {
    assert!(write_atomic(Path::new("/"), b"x").is_err());
}
