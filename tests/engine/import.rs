//! `spherecal import` against a simulated session: its joints and stripes
//! written as CSV files must import back to the same measurements and
//! calibrate; the flange-pose check must pass correct poses in all four
//! conventions and flag unit and joint-order mistakes with the right hint.

// Test helpers may panic: a panic is a test failure with its message.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fmt::Write as _;
use std::fs;
use std::path::Path;

use spherecal::engine::base::robot;
use spherecal::engine::base::session::{Observation, Session};
use spherecal::engine::calibrate::solve::{self, Options};
use spherecal::engine::files::import::{
    self, AngleUnit, ColumnMap, DEFAULT_SPHERE_DIAMETER, FlangeCheck, FlangeConvention,
    ImportError, ImportSpec, LengthUnit, ProfileSource, RobotSource,
};
use spherecal::engine::tools::simulate::{self, SimConfig};

const CONVENTIONS: [FlangeConvention; 4] = [
    FlangeConvention::AbbQuaternion,
    FlangeConvention::KukaAbc,
    FlangeConvention::FanucWpr,
    FlangeConvention::UrRotationVector,
];

/// How the test log is written.
struct LogOptions {
    /// Joints written in radians.
    radians: bool,
    /// Write joint 2's value under `j3` and joint 3's under `j2`.
    swap_23: bool,
    /// Flange poses in this convention (from the nominal FK of the true joints).
    flange: Option<FlangeConvention>,
    /// Use semicolons as separators.
    semicolon: bool,
}

const PLAIN: LogOptions = LogOptions {
    radians: false,
    swap_23: false,
    flange: None,
    semicolon: false,
};

fn simulated() -> Session {
    simulate::simulate(&SimConfig::default()).unwrap().0
}

/// Writes `log.csv` and `profiles/<id>.csv` for the session into `dir`.
fn write_files(session: &Session, dir: &Path, o: &LogOptions) {
    let sep = if o.semicolon { ";" } else { "," };
    let nominal = robot::irb2400().robot;
    let mut text = String::from("# joint log written by tests/engine/import.rs\n");
    let mut header = vec![
        "id", "station", "use", "side", "j1", "j2", "j3", "j4", "j5", "j6",
    ]
    .into_iter()
    .map(String::from)
    .collect::<Vec<_>>();
    if let Some(c) = o.flange {
        header.extend(c.default_columns());
    }
    writeln!(text, "{}", header.join(sep)).unwrap();
    let profiles = dir.join("profiles");
    fs::create_dir_all(&profiles).unwrap();
    for m in &session.measurements {
        let mut fields = vec![
            m.id.clone(),
            m.station.clone(),
            m.usage.as_str().to_string(),
            format!("{}", m.side),
        ];
        let mut q = m.joints.clone();
        if o.swap_23 {
            q.swap(1, 2);
        }
        for v in &q {
            let v = if o.radians { v.to_radians() } else { *v };
            fields.push(format!("{v:?}"));
        }
        if let Some(c) = o.flange {
            let pose = nominal.base_from_flange(&m.joints);
            fields.extend(c.values_from_pose(&pose).iter().map(|v| format!("{v:?}")));
        }
        writeln!(text, "{}", fields.join(sep)).unwrap();
        let Observation::Stripe(points) = &m.observation else {
            panic!("simulated default has stripes");
        };
        let mut p = String::from("y,z\n");
        for [y, z] in points {
            writeln!(p, "{y:?},{z:?}").unwrap();
        }
        fs::write(profiles.join(format!("{}.csv", m.id)), p).unwrap();
    }
    fs::write(dir.join("log.csv"), text).unwrap();
}

fn spec(dir: &Path, o: &LogOptions) -> ImportSpec {
    ImportSpec {
        joint_log: dir.join("log.csv"),
        columns: ColumnMap {
            id: "id".into(),
            station: "station".into(),
            usage: "use".into(),
            side: Some("side".into()),
            joints: (1..=6).map(|k| format!("J{k}")).collect(),
        },
        joint_unit: AngleUnit::Deg,
        profiles: ProfileSource::Folder(dir.join("profiles")),
        profile_format: import::ProfileFormat::default(),
        robot: RobotSource::Preset("irb2400".into()),
        sphere_diameter: DEFAULT_SPHERE_DIAMETER,
        name: Some("imported".into()),
        flange: o.flange.map(FlangeCheck::new),
        references: None,
    }
}

fn assert_same_measurements(a: &Session, b: &Session) {
    assert_eq!(a.measurements.len(), b.measurements.len());
    for (x, y) in a.measurements.iter().zip(&b.measurements) {
        assert_eq!(x.id, y.id);
        assert_eq!(x.station, y.station);
        assert_eq!(x.usage, y.usage);
        assert_eq!(x.side, y.side, "{}", x.id);
        for (p, q) in x.joints.iter().zip(&y.joints) {
            assert!((p - q).abs() < 1e-9, "{}: joint {p} vs {q}", x.id);
        }
        assert_eq!(x.observation, y.observation, "{}", x.id);
    }
}

#[test]
fn simulated_session_round_trips_and_calibrates() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let import::Imported {
        session, checks, ..
    } = import::import(&spec(dir.path(), &PLAIN)).unwrap();
    assert!(checks.is_empty());
    assert_same_measurements(&original, &session);
    assert_eq!(session.robot, robot::irb2400().robot);
    let (_, cal) = solve::calibrate(&session, &Options::from_session(&session)).unwrap();
    assert!(
        cal.epsilon_after() < cal.epsilon_before(),
        "ε {} -> {}",
        cal.epsilon_before(),
        cal.epsilon_after()
    );
}

#[test]
fn radians_semicolons_and_micrometres_convert() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    let o = LogOptions {
        radians: true,
        semicolon: true,
        ..PLAIN
    };
    write_files(&original, dir.path(), &o);
    // Rewrite the profiles in µm.
    for m in &original.measurements {
        let Observation::Stripe(points) = &m.observation else {
            unreachable!()
        };
        let mut p = String::from("\"y\",\"z\"\n");
        for [y, z] in points {
            writeln!(p, "{:?},{:?}", y * 1000.0, z * 1000.0).unwrap();
        }
        fs::write(dir.path().join("profiles").join(format!("{}.csv", m.id)), p).unwrap();
    }
    let mut s = spec(dir.path(), &o);
    s.joint_unit = AngleUnit::Rad;
    s.profile_format.unit = LengthUnit::Um;
    let import::Imported { session, .. } = import::import(&s).unwrap();
    for (x, y) in original.measurements.iter().zip(&session.measurements) {
        for (p, q) in x.joints.iter().zip(&y.joints) {
            assert!((p - q).abs() < 1e-9, "{}: joint {p} vs {q}", x.id);
        }
        let (Observation::Stripe(a), Observation::Stripe(b)) = (&x.observation, &y.observation)
        else {
            unreachable!()
        };
        for (p, q) in a.iter().zip(b) {
            assert!((p[0] - q[0]).abs() < 1e-9 && (p[1] - q[1]).abs() < 1e-9);
        }
    }
}

#[test]
fn single_profile_file_with_pose_column() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let mut all = String::from("pose,y,z\n");
    for m in &original.measurements {
        let Observation::Stripe(points) = &m.observation else {
            unreachable!()
        };
        for [y, z] in points {
            writeln!(all, "{},{y:?},{z:?}", m.id).unwrap();
        }
    }
    let file = dir.path().join("stripes.csv");
    fs::write(&file, all).unwrap();
    let mut s = spec(dir.path(), &PLAIN);
    s.profiles = ProfileSource::File {
        path: file,
        pose_column: "pose".into(),
    };
    let import::Imported { session, .. } = import::import(&s).unwrap();
    assert_same_measurements(&original, &session);
}

#[test]
fn correct_flange_poses_pass_in_every_convention() {
    let original = simulated();
    for c in CONVENTIONS {
        let dir = tempfile::tempdir().unwrap();
        let o = LogOptions {
            flange: Some(c),
            ..PLAIN
        };
        write_files(&original, dir.path(), &o);
        let import::Imported { checks, .. } = import::import(&spec(dir.path(), &o)).unwrap();
        assert_eq!(checks.len(), original.measurements.len());
        for ch in &checks {
            assert!(
                !ch.flagged && ch.position_error_mm < 1e-6 && ch.rotation_error_deg < 1e-6,
                "{c:?}: {ch:?}"
            );
        }
    }
}

#[test]
fn conventions_match_their_definitions() {
    // KUKA A=90: Rz(90); Fanuc W=90: Rx(90); UR rz=π/2: Rz(90) and metres.
    let rz = nalgebra::UnitQuaternion::from_axis_angle(
        &nalgebra::Vector3::z_axis(),
        std::f64::consts::FRAC_PI_2,
    );
    let rx = nalgebra::UnitQuaternion::from_axis_angle(
        &nalgebra::Vector3::x_axis(),
        std::f64::consts::FRAC_PI_2,
    );
    let k = FlangeConvention::KukaAbc
        .pose_from_values(&[1.0, 2.0, 3.0, 90.0, 0.0, 0.0])
        .unwrap();
    assert!(k.rotation.angle_to(&rz) < 1e-12);
    let f = FlangeConvention::FanucWpr
        .pose_from_values(&[1.0, 2.0, 3.0, 90.0, 0.0, 0.0])
        .unwrap();
    assert!(f.rotation.angle_to(&rx) < 1e-12);
    let u = FlangeConvention::UrRotationVector
        .pose_from_values(&[0.001, 0.002, 0.003, 0.0, 0.0, std::f64::consts::FRAC_PI_2])
        .unwrap();
    assert!(u.rotation.angle_to(&rz) < 1e-12);
    assert!((u.translation.vector - nalgebra::Vector3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
    let a = FlangeConvention::AbbQuaternion
        .pose_from_values(&[1.0, 2.0, 3.0, rx.w, rx.i, rx.j, rx.k])
        .unwrap();
    assert!(a.rotation.angle_to(&rx) < 1e-12);
}

#[test]
fn radians_declared_degrees_are_flagged_with_the_unit_hint() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    let o = LogOptions {
        radians: true,
        flange: Some(FlangeConvention::KukaAbc),
        ..PLAIN
    };
    write_files(&original, dir.path(), &o);
    let import::Imported { checks, .. } = import::import(&spec(dir.path(), &o)).unwrap();
    for ch in &checks {
        assert!(ch.flagged, "{ch:?}");
        assert!(
            ch.hint.contains("--joint-unit rad"),
            "{}: {}",
            ch.id,
            ch.hint
        );
    }
}

#[test]
fn swapped_joint_columns_are_flagged_with_the_swap_hint() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    let o = LogOptions {
        swap_23: true,
        flange: Some(FlangeConvention::AbbQuaternion),
        ..PLAIN
    };
    write_files(&original, dir.path(), &o);
    let import::Imported { checks, .. } = import::import(&spec(dir.path(), &o)).unwrap();
    // Where joints 2 and 3 read nearly the same, a swap is invisible.
    let visible: Vec<_> = checks
        .iter()
        .zip(&original.measurements)
        .filter(|(_, m)| (m.joints[1] - m.joints[2]).abs() > 1.0)
        .map(|(c, _)| c)
        .collect();
    assert!(visible.len() > checks.len() / 2, "{}", visible.len());
    for ch in visible {
        assert!(ch.flagged, "{ch:?}");
        assert!(
            ch.hint.contains("joint columns 2 and 3 look swapped"),
            "{}: {}",
            ch.id,
            ch.hint
        );
    }
}

#[test]
fn wrong_robot_is_flagged() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    let o = LogOptions {
        flange: Some(FlangeConvention::FanucWpr),
        ..PLAIN
    };
    write_files(&original, dir.path(), &o);
    let mut s = spec(dir.path(), &o);
    s.robot = RobotSource::Preset("irb120".into());
    let import::Imported { checks, .. } = import::import(&s).unwrap();
    assert!(checks.iter().all(|c| c.flagged));
    assert!(
        checks
            .iter()
            .any(|c| c.hint == "wrong robot model or base frame?")
    );
}

#[test]
fn missing_profile_names_the_pose() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let id = &original.measurements[7].id;
    fs::remove_file(dir.path().join("profiles").join(format!("{id}.csv"))).unwrap();
    let e = import::import(&spec(dir.path(), &PLAIN)).unwrap_err();
    assert!(matches!(e, ImportError::MissingProfile { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(msg.contains(&format!("pose {id}:")), "{msg}");
    assert!(msg.contains(&format!("{id}.csv")), "{msg}");
}

#[test]
fn malformed_number_names_file_line_and_column() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let log = dir.path().join("log.csv");
    let text = fs::read_to_string(&log).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    // Line 5 of the file: comment, header, then the third data row.
    let mut fields: Vec<String> = lines[4].split(',').map(String::from).collect();
    fields[6] = "12,5x".replace(',', ".");
    lines[4] = fields.join(",");
    fs::write(&log, lines.join("\n")).unwrap();
    let msg = import::import(&spec(dir.path(), &PLAIN))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("line 5"), "{msg}");
    assert!(msg.contains("column `j3`"), "{msg}");
    assert!(msg.contains("12.5x"), "{msg}");
    assert!(msg.contains("log.csv"), "{msg}");

    // The same in a profile file.
    let id = &original.measurements[0].id;
    let p = dir.path().join("profiles").join(format!("{id}.csv"));
    fs::write(&p, "y,z\n1.0,2.0\n1.5,abc\n").unwrap();
    write_files(&original, dir.path(), &PLAIN);
    fs::write(&p, "y,z\n1.0,2.0\n1.5,abc\n").unwrap();
    let msg = import::import(&spec(dir.path(), &PLAIN))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("line 3") && msg.contains("column `z`") && msg.contains(&format!("{id}.csv")),
        "{msg}"
    );
}

#[test]
fn session_rules_are_the_loaders() {
    // A stripe of 3 points breaks FORMAT.md's "at least 5 points".
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let id = &original.measurements[2].id;
    fs::write(
        dir.path().join("profiles").join(format!("{id}.csv")),
        "y,z\n1,2\n2,3\n3,4\n",
    )
    .unwrap();
    // The message names the pose and the profile file it came from (not a
    // line of the generated session JSON).
    let e = import::import(&spec(dir.path(), &PLAIN)).unwrap_err();
    assert!(matches!(e, ImportError::File { .. }), "{e:?}");
    let text = e.to_string();
    assert!(text.contains(&format!("pose {id}")), "{text}");
    assert!(text.contains(&format!("{id}.csv")), "{text}");
    assert!(text.contains("at least 5"), "{text}");
}

#[test]
fn preview_shows_mapped_rows_in_degrees() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    let o = LogOptions {
        radians: true,
        ..PLAIN
    };
    write_files(&original, dir.path(), &o);
    let mut s = spec(dir.path(), &o);
    s.joint_unit = AngleUnit::Rad;
    let text = import::preview(&s, 2).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 5, "{text}");
    assert!(
        lines[0].contains("rad") && lines[0].contains("deg"),
        "{text}"
    );
    assert_eq!(lines[1], "side from column `side`");
    let m = &original.measurements[1];
    assert!(lines[4].starts_with(m.id.as_str()), "{text}");
    assert!(lines[4].contains(&format!("{:.4}", m.joints[1])), "{text}");
}

#[test]
fn cli_writes_the_session_and_reports_flags() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    let o = LogOptions {
        swap_23: true,
        flange: Some(FlangeConvention::UrRotationVector),
        ..PLAIN
    };
    write_files(&original, dir.path(), &o);
    let out = dir.path().join("session.json");
    let bin = env!("CARGO_BIN_EXE_spherecal");
    let run = std::process::Command::new(bin)
        .args(["import", "--joints"])
        .arg(dir.path().join("log.csv"))
        .arg("--profiles")
        .arg(dir.path().join("profiles"))
        .args([
            "--robot",
            "irb2400",
            "--map",
            "side=side",
            "--flange-poses",
            "UR",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(run.status.success(), "{run:?}");
    let stdout = String::from_utf8_lossy(&run.stdout);
    let first = &original.measurements[0].id;
    assert!(
        stdout.contains(&format!("flagged pose {first}:")) && stdout.contains("look swapped"),
        "{stdout}"
    );
    assert!(out.is_file());

    // Bad input: one `error:` line, exit 2, nothing written.
    let out2 = dir.path().join("none.json");
    let run = std::process::Command::new(bin)
        .args(["import", "--joints"])
        .arg(dir.path().join("missing.csv"))
        .arg("--profiles")
        .arg(dir.path().join("profiles"))
        .args(["--robot", "irb2400"])
        .arg("--out")
        .arg(&out2)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2), "{run:?}");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.starts_with("error:") && stderr.contains("missing.csv"),
        "{stderr}"
    );
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(!out2.exists());
}

/// Writes the session's reference distances as `references.csv`.
fn write_references(session: &Session, dir: &Path) -> std::path::PathBuf {
    let mut text = String::from("from,to,distance\n");
    for r in &session.reference_distances {
        writeln!(text, "{},{},{}", r.from, r.to, r.distance).unwrap();
    }
    let path = dir.join("references.csv");
    fs::write(&path, text).unwrap();
    path
}

#[test]
fn reference_distances_import_and_validate() {
    let original = simulated();
    assert!(!original.reference_distances.is_empty());
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let mut s = spec(dir.path(), &PLAIN);
    s.references = Some(write_references(&original, dir.path()));
    let import::Imported { session, .. } = import::import(&s).unwrap();
    assert_eq!(session.reference_distances, original.reference_distances);
    let (_, cal) = solve::calibrate(&session, &Options::from_session(&session)).unwrap();
    let v = cal.validation.as_ref().expect("validation with references");
    assert_eq!(v.distances.len(), {
        let (_, c) = solve::calibrate(&original, &Options::from_session(&original)).unwrap();
        c.validation.unwrap().distances.len()
    });
}

#[test]
fn bad_reference_rows_name_file_and_line() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let path = dir.path().join("references.csv");
    let mut s = spec(dir.path(), &PLAIN);
    s.references = Some(path.clone());
    for (body, expect) in [
        (
            "from,to,distance\nV1,V2,-3\n",
            "line 2: distance -3 mm is not positive",
        ),
        (
            "from,to,distance\nV1,V2,abc\n",
            "line 2: column `distance`: `abc`",
        ),
        ("from,to\nV1,V2\n", "no column `distance`"),
        ("from,to,distance\n", "no reference distances"),
        ("from,to,distance\nV1,V1,10\n", "from and to are both `V1`"),
    ] {
        fs::write(&path, body).unwrap();
        let msg = import::import(&s).unwrap_err().to_string();
        assert!(msg.contains(expect), "{body:?}: {msg}");
        assert!(msg.contains("references.csv"), "{msg}");
    }
    // A station the session does not have is the loader's error.
    fs::write(&path, "from,to,distance\nV1,Q9,100\n").unwrap();
    let msg = import::import(&s).unwrap_err().to_string();
    assert!(msg.contains("Q9"), "{msg}");
}

#[test]
fn a_side_column_is_read_without_a_mapping() {
    let original = simulated();
    assert!(
        original.measurements.iter().any(|m| m.side == -1),
        "the simulated session has both sides"
    );
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let mut s = spec(dir.path(), &PLAIN);
    s.columns.side = None;
    let import::Imported { session, .. } = import::import(&s).unwrap();
    for (a, b) in session.measurements.iter().zip(&original.measurements) {
        assert_eq!(a.side, b.side, "{}", a.id);
    }
    assert!(
        import::preview(&s, 2)
            .unwrap()
            .contains("side from column `side`")
    );
}

// ---------------------------------------------------------------------------
// Issue 12: each defect of the import, reproduced
// ---------------------------------------------------------------------------

/// Excel's "CSV UTF-8" starts the file with a byte-order mark; the joint
/// log and the profiles were rejected with "no column `id` (the header
/// has: id, …)".
#[test]
fn a_byte_order_mark_in_the_log_and_the_profiles_is_read() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let mut files = vec![dir.path().join("log.csv")];
    files.extend(
        original
            .measurements
            .iter()
            .map(|m| dir.path().join("profiles").join(format!("{}.csv", m.id))),
    );
    for f in &files {
        let text = fs::read_to_string(f).unwrap();
        fs::write(f, format!("\u{feff}{text}")).unwrap();
    }
    let imported = import::import(&spec(dir.path(), &PLAIN)).unwrap();
    assert_same_measurements(&original, &imported.session);
}

/// A log in degrees read as radians gave ε 1558 → 17.9 mm and exit 0.
#[test]
fn degrees_read_as_radians_are_refused_with_the_flag_to_change() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let mut s = spec(dir.path(), &PLAIN);
    s.joint_unit = AngleUnit::Rad;
    let msg = import::import(&s).unwrap_err().to_string();
    assert!(msg.contains("--joint-unit deg"), "{msg}");
    assert!(msg.contains("beyond any robot joint's range"), "{msg}");
    assert!(msg.contains("log.csv") && msg.contains("line "), "{msg}");
    // Radians read as degrees cannot be refused (small moves are possible)
    // but are warned about.
    let o = LogOptions {
        radians: true,
        ..PLAIN
    };
    write_files(&original, dir.path(), &o);
    let imported = import::import(&spec(dir.path(), &o)).unwrap();
    assert!(
        imported
            .notes
            .iter()
            .any(|n| n.contains("--joint-unit rad")),
        "{:?}",
        imported.notes
    );
    // Read right, no warning.
    let mut s = spec(dir.path(), &o);
    s.joint_unit = AngleUnit::Rad;
    let imported = import::import(&s).unwrap();
    assert!(!imported.notes.iter().any(|n| n.contains("warning")));
}

/// Profiles in mm read as µm gave r = 0.015 mm with only warnings; in µm
/// read as mm they are a thousand times the sphere.
#[test]
fn profiles_in_the_wrong_unit_are_refused_with_the_flag_to_change() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let mut s = spec(dir.path(), &PLAIN);
    s.profile_format.unit = LengthUnit::Um;
    let msg = import::import(&s).unwrap_err().to_string();
    assert!(msg.contains("--profile-unit mm"), "{msg}");
    assert!(msg.contains("against a sphere of 38.1 mm"), "{msg}");
    // µm written, read as mm.
    for m in &original.measurements {
        let Observation::Stripe(points) = &m.observation else {
            unreachable!()
        };
        let mut p = String::from("y,z\n");
        for [y, z] in points {
            writeln!(p, "{:?},{:?}", y * 1000.0, z * 1000.0).unwrap();
        }
        fs::write(dir.path().join("profiles").join(format!("{}.csv", m.id)), p).unwrap();
    }
    let msg = import::import(&spec(dir.path(), &PLAIN))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("--profile-unit um"), "{msg}");
}

/// "stripe has 2 points … at line 988 column 19 (joints.csv)": a rule of
/// the session loader broken by a profile is blamed on the profile file,
/// without a position in the generated JSON.
#[test]
fn a_stripe_rule_broken_by_a_profile_names_the_profile_file() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let id = &original.measurements[4].id;
    let path = dir.path().join("profiles").join(format!("{id}.csv"));
    let text = fs::read_to_string(&path).unwrap();
    fs::write(&path, format!("{text}20000.0,5.0\n")).unwrap();
    let e = import::import(&spec(dir.path(), &PLAIN)).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains(&format!("pose {id}")), "{msg}");
    assert!(msg.ends_with(&format!("({})", path.display())), "{msg}");
    assert!(msg.contains("not plausible"), "{msg}");
    assert!(
        !msg.contains("column 1") && !msg.contains(" at line"),
        "{msg}"
    );
}

/// An unknown reference station was blamed on the joint log; it is the
/// references file's row.
#[test]
fn an_unknown_reference_station_names_the_references_row() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let path = dir.path().join("references.csv");
    let mut s = spec(dir.path(), &PLAIN);
    s.references = Some(path.clone());
    let validate: Vec<&str> = original
        .measurements
        .iter()
        .filter(|m| m.usage.as_str() == "validate")
        .map(|m| m.station.as_str())
        .collect();
    fs::write(
        &path,
        format!(
            "# tracker\nfrom,to,distance\n{},{},100\nV1,Q9,100\n",
            validate[0],
            validate.last().unwrap()
        ),
    )
    .unwrap();
    let msg = import::import(&s).unwrap_err().to_string();
    assert!(msg.contains("Q9"), "{msg}");
    assert!(msg.starts_with("line 4:"), "{msg}");
    assert!(msg.ends_with(&format!("({})", path.display())), "{msg}");
}

/// A pose id given twice in the joint log is named as such (it said "no
/// stripe profile").
#[test]
fn a_duplicate_pose_id_is_named_as_such() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let log = dir.path().join("log.csv");
    let text = fs::read_to_string(&log).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let second_id = original.measurements[1].id.clone();
    let first_id = original.measurements[0].id.clone();
    lines[3] = lines[3].replacen(&second_id, &first_id, 1);
    fs::write(&log, lines.join("\n")).unwrap();
    let msg = import::import(&spec(dir.path(), &PLAIN))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains(&format!(
            "pose id `{first_id}` is used twice (first at line 3)"
        )),
        "{msg}"
    );
    assert!(msg.starts_with("line 4:"), "{msg}");
}

/// A large profile is read row by row (no row of text fields kept): 200,000
/// points with a header import, and a bad cell deep in it still names
/// its line.
#[test]
fn a_large_profile_is_streamed_and_a_bad_cell_names_its_line() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let id = &original.measurements[0].id;
    let path = dir.path().join("profiles").join(format!("{id}.csv"));
    let Observation::Stripe(points) = &original.measurements[0].observation else {
        unreachable!()
    };
    let mut p = String::from("# big\ny,z\n");
    for k in 0..200_000 {
        let [y, z] = points[k % points.len()];
        writeln!(p, "{y:?},{z:?}").unwrap();
    }
    fs::write(&path, &p).unwrap();
    let imported = import::import(&spec(dir.path(), &PLAIN)).unwrap();
    let Observation::Stripe(read) = &imported.session.measurements[0].observation else {
        unreachable!()
    };
    assert_eq!(read.len(), 200_000);
    let bad = p.replacen(&format!("\n{:?},", points[3][0]), "\nx7,", 1);
    fs::write(&path, bad).unwrap();
    let msg = import::import(&spec(dir.path(), &PLAIN))
        .unwrap_err()
        .to_string();
    assert!(msg.starts_with("line 6:"), "{msg}");
    assert!(msg.contains("`x7` is not a number"), "{msg}");
}

/// An import tells its progress: every profile read, in order, then the
/// check; a cancel stops it at once with nothing built.
#[test]
fn an_import_tells_its_progress_and_can_be_cancelled() {
    use spherecal::engine::calibrate::solve::Control;
    use spherecal::engine::files::import::ImportStage;
    let original = simulated();
    let n = original.measurements.len();
    let dir = tempfile::tempdir().unwrap();
    write_files(&original, dir.path(), &PLAIN);
    let spec = spec(dir.path(), &PLAIN);
    let mut stages = Vec::new();
    let imported = import::import_with(&spec, &mut |s| {
        stages.push(s);
        Control::Continue
    })
    .unwrap();
    assert_same_measurements(&original, &imported.session);
    let mut expected: Vec<ImportStage> = (1..=n)
        .map(|done| ImportStage::Profiles { done, total: n })
        .collect();
    expected.push(ImportStage::Checking);
    assert_eq!(stages, expected);
    assert_eq!(stages[0].describe(), format!("reading profiles: 1 of {n}"));
    // Cancelled at the third profile: no more is read.
    let mut calls = 0;
    let e = import::import_with(&spec, &mut |_| {
        calls += 1;
        if calls == 3 {
            Control::Cancel
        } else {
            Control::Continue
        }
    })
    .unwrap_err();
    assert!(matches!(e, ImportError::Cancelled), "{e}");
    assert_eq!(calls, 3);
    assert_eq!(e.to_string(), "the import was cancelled");
}

/// A European cell's files: a joint log separated by semicolons with
/// decimal commas, profiles with decimal commas (a `y;z` header, or none
/// and spaces): the same measurements as with decimal points.
#[test]
fn decimal_commas_import_like_decimal_points() {
    let original = simulated();
    let dir = tempfile::tempdir().unwrap();
    let o = LogOptions {
        semicolon: true,
        ..PLAIN
    };
    write_files(&original, dir.path(), &o);
    let log = dir.path().join("log.csv");
    let text = fs::read_to_string(&log).unwrap();
    fs::write(&log, text.replace('.', ",")).unwrap();
    for (k, m) in original.measurements.iter().enumerate() {
        let Observation::Stripe(points) = &m.observation else {
            unreachable!()
        };
        let mut p = String::from(if k % 2 == 0 { "y;z\n" } else { "" });
        for [y, z] in points {
            let row = if k % 2 == 0 {
                format!("{y:?};{z:?}")
            } else {
                format!("{y:?} {z:?}")
            };
            writeln!(p, "{}", row.replace('.', ",")).unwrap();
        }
        fs::write(dir.path().join("profiles").join(format!("{}.csv", m.id)), p).unwrap();
    }
    let import::Imported { session, .. } = import::import(&spec(dir.path(), &o)).unwrap();
    assert_same_measurements(&original, &session);
}
