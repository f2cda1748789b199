//! Issue 23, the third round of attacks: nothing hostile is accepted
//! silently. Each test is a regression test of one finding — a URDF with
//! duplicate names or absurd origins, a joint log with more joints than
//! the robot, DH tables sorted otherwise or in radians, contradicting
//! reference distances, the OpenCV profile corner cases, implausible
//! result files, a calibration that "converges" to a scatter no sensor
//! gives, a threshold that calibrates nothing, a plan of 100,000 stations.
//! (Parsers' fuzz cases are in `tests/engine/fuzz.rs`; the outputs' all-or-none
//! in `tests/cli/contract.rs`.)

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

use spherecal::engine::files::format;
use spherecal::engine::files::import::{
    self, AngleUnit, ColumnMap, DEFAULT_SPHERE_DIAMETER, ImportSpec, ProfileFormat, ProfileSource,
    RobotSource,
};
use spherecal::engine::files::robot_import::{DhConvention, robot_from_dh_csv, robot_from_urdf};

fn data(name: &str) -> String {
    fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/robots")
            .join(name),
    )
    .unwrap()
}

fn urdf_error(text: &str) -> String {
    robot_from_urdf(text, Path::new("cell.urdf"))
        .unwrap_err()
        .to_string()
}

/// Duplicate link or joint names were ignored; an origin of 1e300 or NaN
/// became another robot (or an error blamed on joints.csv).
#[test]
fn a_urdf_with_duplicate_names_or_absurd_origins_is_refused() {
    let irb = data("abb_irb2400.urdf");
    assert!(robot_from_urdf(&irb, Path::new("cell.urdf")).is_ok());
    let twice = irb.replacen(
        "<link name=\"link_1\">",
        "<link name=\"link_1\"/><link name=\"link_1\">",
        1,
    );
    let e = urdf_error(&twice);
    assert!(e.contains("two links are named `link_1`"), "{e}");
    let twice = irb.replacen("name=\"joint_2\"", "name=\"joint_1\"", 1);
    let e = urdf_error(&twice);
    assert!(e.contains("joint `joint_1`: two joints"), "{e}");
    // The first joint origin of the file, made absurd.
    let start = irb.find("<joint ").unwrap();
    let at = start + irb[start..].find("<origin xyz=\"").unwrap() + "<origin xyz=\"".len();
    let end = at + irb[at..].find('"').unwrap();
    for (xyz, needle) in [
        ("1e300 0 0", "origin xyz=\"1e300 0 0\" is not plausible"),
        ("nan 0 0", "origin xyz=\"NaN 0 0\""),
    ] {
        let mut bad = irb.clone();
        bad.replace_range(at..end, xyz);
        let e = urdf_error(&bad);
        assert!(
            e.contains("cell.urdf: joint `joint_1`") && e.contains(needle),
            "{e}"
        );
    }
    // An angle of 1e300 rad is no joint's zero offset either.
    let bad = irb.replacen(
        "<joint name=\"joint_1\" type=\"revolute\">\n    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>",
        "<joint name=\"joint_1\" type=\"revolute\">\n    <origin xyz=\"0 0 0\" rpy=\"0 0 1e300\"/>",
        1,
    );
    assert_ne!(bad, irb);
    let e = urdf_error(&bad);
    assert!(
        e.contains("joint `joint_1`") && e.contains("origin rpy=\"0 0 1e300\""),
        "{e}"
    );
}

/// The import spec of `dir/log.csv` with `robot`.
fn spec(dir: &Path, robot: RobotSource, joints: usize) -> ImportSpec {
    ImportSpec {
        joint_log: dir.join("log.csv"),
        columns: ColumnMap {
            id: "id".into(),
            station: "station".into(),
            usage: "use".into(),
            side: None,
            joints: (1..=joints).map(|k| format!("j{k}")).collect(),
        },
        joint_unit: AngleUnit::Deg,
        profiles: ProfileSource::Folder(dir.join("profiles")),
        profile_format: ProfileFormat::default(),
        robot,
        sphere_diameter: DEFAULT_SPHERE_DIAMETER,
        name: None,
        flange: None,
        references: None,
    }
}

/// A 1-joint URDF with a 6-joint log imported and dropped j2-j6.
#[test]
fn a_log_with_more_joints_than_the_robot_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = dir.path().join("one.urdf");
    fs::write(
        &urdf,
        r#"<robot name="one">
  <link name="base"/><link name="tip"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#,
    )
    .unwrap();
    fs::write(
        dir.path().join("log.csv"),
        "id,station,use,j1,j2,j3,j4,j5,j6\nt1,P0,translation,1,2,3,4,5,6\n",
    )
    .unwrap();
    let robot = RobotSource::Urdf {
        path: urdf,
        tip: None,
    };
    let e = import::import(&spec(dir.path(), robot, 1))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`j2`") && e.contains("`j6`") && e.contains("1 joint"),
        "{e}"
    );
    assert!(
        e.ends_with(&format!("({})", dir.path().join("log.csv").display())),
        "{e}"
    );
}

fn dh_error(text: &str, convention: DhConvention) -> String {
    robot_from_dh_csv(text, Path::new("robot.csv"), convention)
        .unwrap_err()
        .to_string()
}

/// A DH table's joint labels were ignored (rows taken in file order),
/// angles in radians read as degrees, a length of 1e300 blamed later on
/// joints.csv.
#[test]
fn dh_tables_sorted_otherwise_in_radians_or_absurd_are_refused() {
    let irb = data("abb_irb2400_mdh.csv");
    assert!(robot_from_dh_csv(&irb, Path::new("robot.csv"), DhConvention::Modified).is_ok());
    let swapped = irb.replace(
        "2,-90,100,0,-90,0\n3,0,705,0,0,0",
        "3,0,705,0,0,0\n2,-90,100,0,-90,0",
    );
    let e = dh_error(&swapped, DhConvention::Modified);
    assert!(
        e.contains("robot.csv, line 6") && e.contains("labels this row `3` after `1`"),
        "{e}"
    );
    let labelled = irb.replace("\n1,", "\nJ1,").replace("\n2,", "\nJ2,");
    assert!(robot_from_dh_csv(&labelled, Path::new("r.csv"), DhConvention::Modified).is_ok());
    let radians = "joint,a,alpha,d,theta\n1,0,1.5708,162.5,0\n2,-425,0,0,0\n3,-392.2,0,0,0\n4,0,1.5708,133.3,0\n5,0,-1.5708,99.7,0\n6,0,0,99.6,0\n";
    let e = dh_error(radians, DhConvention::Standard);
    assert!(
        e.contains("line 2") && e.contains("looks like radians") && e.contains("alpha_rad"),
        "{e}"
    );
    // Said in the header, radians are read as such.
    let said = radians.replace("alpha,", "alpha_rad,");
    let ur = robot_from_dh_csv(&said, Path::new("r.csv"), DhConvention::Standard).unwrap();
    assert!(
        (ur.joints[1].alpha - 90.0).abs() < 1e-3,
        "{:?}",
        ur.joints[1]
    );
    let absurd = irb.replace("3,0,705,0,0,0", "3,0,1e300,0,0,0");
    let e = dh_error(&absurd, DhConvention::Modified);
    assert!(
        e.contains("robot.csv, line 7: column `a`: 1e300 mm is not plausible"),
        "{e}"
    );
}

/// Two contradicting distances for one pair were accepted (the
/// validation std became 78 mm).
#[test]
fn contradicting_reference_distances_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let refs = dir.path().join("references.csv");
    fs::write(&refs, "from,to,distance\nV1,V2,500\nV3,V4,400\nV2,V1,590\n").unwrap();
    let e = import::read_references(&refs).unwrap_err().to_string();
    assert!(
        e.contains("line 4") && e.contains("first on line 2") && e.contains("contradict"),
        "{e}"
    );
    fs::write(&refs, "from,to,distance\nV1,V2,500\nV1,V2,500\n").unwrap();
    let e = import::read_references(&refs).unwrap_err().to_string();
    assert!(e.contains("count its pairs twice"), "{e}");
    // In a session file too.
    let mut v: serde_json::Value = serde_json::from_str(spherecal::DEMO_SESSION_JSON).unwrap();
    let list = v["reference_distances"].as_array_mut().unwrap();
    let mut copy = list[0].clone();
    copy["distance"] = serde_json::json!(copy["distance"].as_f64().unwrap() + 78.0);
    list.push(copy);
    let e = format::parse_session(&v.to_string(), Path::new("s.json"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("contradict each other") && e.contains("reference_distances[0]"),
        "{e}"
    );
}

fn read(path: &Path, format: &ProfileFormat) -> Result<import::RawProfile, String> {
    import::profiles::read_profile(path, format).map_err(|e| e.to_string())
}

/// OpenCV YAML with `.nan` in the plane's normal coordinate was read as
/// pairs; `--no-return 0` dropped every point of a planar profile; a
/// 1e300 was reported as `points[3]`; the axis guess blamed the first
/// profile instead of the odd one.
#[test]
fn profile_corner_cases_are_read_right_and_blamed_right() {
    let dir = tempfile::tempdir().unwrap();
    let yml = dir.path().join("c1.yml");
    fs::write(
        &yml,
        "%YAML:1.0\n---\nscan_line: [ 1.5, 0., -2., 1.6, .nan, 2.1,\n  1.7, 0., 2.2, 1.8, 0., 2.3 ]\n",
    )
    .unwrap();
    let p = read(&yml, &ProfileFormat::default()).unwrap();
    assert_eq!(
        p.points,
        [[1.5, 0.0, -2.0], [1.7, 0.0, 2.2], [1.8, 0.0, 2.3]]
    );
    assert_eq!(p.non_finite, 1);
    // The no-return value 0 is a reading on x and z, not on the plane's y.
    let csv = dir.path().join("c2.csv");
    fs::write(&csv, "x,y,z\n1,0,2\n2,0,0\n3,0,4\n4,0,5\n").unwrap();
    let zero = ProfileFormat {
        no_return: Some(0.0),
        ..ProfileFormat::default()
    };
    let p = read(&csv, &zero).unwrap();
    assert_eq!(
        p.points,
        [[1.0, 0.0, 2.0], [3.0, 0.0, 4.0], [4.0, 0.0, 5.0]]
    );
    assert_eq!(p.no_return, 1);
    let pairs = dir.path().join("c3.txt");
    fs::write(&pairs, "1 2\n3 0\n5 6\n").unwrap();
    let p = read(&pairs, &zero).unwrap();
    assert_eq!((p.points.len(), p.no_return), (2, 1));
    // A value beyond any sensor: its line.
    fs::write(&csv, "y,z\n1,2\n3,4\n1e300,5\n").unwrap();
    let e = read(&csv, &ProfileFormat::default()).unwrap_err();
    assert!(e.contains("line 4: y = 1e300 mm is not plausible"), "{e}");
    // The odd profile out is named, not the first one.
    let folder = dir.path().join("profiles");
    fs::create_dir(&folder).unwrap();
    let ids: Vec<String> = (1..=3).map(|k| format!("p{k}")).collect();
    for id in &ids {
        // p1 and p2 lie in the plane x = 0; p3 tilts out of it.
        let x = |k: i32| {
            if id == "p3" {
                1.0 + 0.1 * f64::from(k)
            } else {
                0.0
            }
        };
        let text: String = (0..6)
            .map(|k| format!("{},{k},{}\n", x(k), k * k))
            .collect();
        fs::write(folder.join(format!("{id}.csv")), format!("x,y,z\n{text}")).unwrap();
    }
    let e = import::read_profiles(
        &ProfileSource::Folder(folder.clone()),
        &ProfileFormat::default(),
        &ids,
        &mut import::progress::quiet,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.ends_with(&format!("({})", folder.join("p3.csv").display())),
        "{e}"
    );
    assert!(
        e.contains("not in the plane the other profiles lie in"),
        "{e}"
    );
}

/// A result with a hand-eye of 1e308 mm or a length of 1e300 mm flowed
/// into history, report and every export; refused on reading, and never
/// written.
#[test]
fn implausible_result_files_are_refused() {
    let session =
        format::parse_session(spherecal::DEMO_SESSION_JSON, Path::new("demo.json")).unwrap();
    let mut options = spherecal::engine::calibrate::solve::Options::from_session(&session);
    options.max_iterations = 2;
    options.ml.cross_validation = false;
    let (_, cal) = spherecal::engine::calibrate::solve::calibrate(&session, &options).unwrap();
    let result = format::ResultFile::from_calibration(&session, &cal);
    let text = format::result_to_json(&result);
    assert!(format::parse_result(&text, Path::new("r.json")).is_ok());
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["hand_eye"][0][3] = serde_json::json!(1e308);
    let e = format::parse_result(&v.to_string(), Path::new("r.json"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`hand_eye[0][3]` = 1e308 mm is not plausible"),
        "{e}"
    );
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["robot"]["joints"][2]["a"] = serde_json::json!(1e300);
    let e = format::parse_result(&v.to_string(), Path::new("r.json"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("`robot.joints[2].a` = 1e300 mm"), "{e}");
    let mut bad = result.clone();
    bad.hand_eye.translation.vector.x = 1e308;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.json");
    let e = format::save_result(&bad, &out).unwrap_err().to_string();
    assert!(e.contains("the result is not written"), "{e}");
    assert!(!out.exists());
}

fn spherecal_cli(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_spherecal"))
        .args(args)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// A simulated session (`dir/s.json`).
fn simulated(dir: &Path) -> PathBuf {
    let s = dir.join("s.json");
    let (code, _, err) = spherecal_cli(&["simulate", "--out", s.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    s
}

/// A log in radians read as degrees calibrated to ε 19 mm, exit 0 (and a
/// FANUC pose log read as KUKA to a 75 mm scatter): a scatter beyond any
/// sensor is a failed calibration, written only on request.
#[test]
fn a_calibration_that_scatters_beyond_any_sensor_fails() {
    let dir = tempfile::tempdir().unwrap();
    let s = simulated(dir.path());
    let mut v: serde_json::Value = serde_json::from_str(&fs::read_to_string(&s).unwrap()).unwrap();
    for m in v["measurements"].as_array_mut().unwrap() {
        for q in m["joints"].as_array_mut().unwrap() {
            *q = serde_json::json!(q.as_f64().unwrap().to_radians());
        }
    }
    let rad = dir.path().join("rad.json");
    fs::write(&rad, v.to_string()).unwrap();
    let out = dir.path().join("r.json");
    let (r, o) = (rad.to_str().unwrap(), out.to_str().unwrap());
    let (code, _, err) = spherecal_cli(&["calibrate", r, "--out", o, "-q"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("the calibration failed") && err.contains("--joint-unit"),
        "{err}"
    );
    assert!(!out.exists());
    let (code, _, err) = spherecal_cli(&["calibrate", r, "--out", o, "--accept-implausible"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning: the calibration failed"), "{err}");
    assert!(out.exists());
    // The report, which calibrates first, as well.
    let html = dir.path().join("r.html");
    let (code, _, err) = spherecal_cli(&["report", r, "--out", html.to_str().unwrap(), "-q"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("the calibration failed") && !html.exists(),
        "{err}"
    );
}

/// `--threshold 1e308`: 0 updates, "converged", the uncalibrated result
/// written. Refused; a threshold above the starting ε is said plainly.
#[test]
fn a_threshold_that_calibrates_nothing_is_refused_or_said() {
    let dir = tempfile::tempdir().unwrap();
    let s = simulated(dir.path());
    let out = dir.path().join("r.json");
    let (s, o) = (s.to_str().unwrap(), out.to_str().unwrap());
    let (code, _, err) = spherecal_cli(&["calibrate", s, "--out", o, "--threshold", "1e308"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("'1e308' for '--threshold <MM>': expected a number of mm from 0 to 1000"),
        "{err}"
    );
    assert!(!out.exists());
    let (code, _, err) = spherecal_cli(&["calibrate", s, "--out", o, "--threshold", "500"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("nothing was identified"), "{err}");
}

/// `plan --identify-stations 100000` printed nothing for two minutes.
#[test]
fn an_oversized_plan_is_refused_at_once() {
    let started = std::time::Instant::now();
    let (code, _, err) = spherecal_cli(&[
        "plan",
        "--sphere",
        "1050,0,475",
        "--identify-stations",
        "100000",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("100010 stations asked for") && err.contains("at most 500"),
        "{err}"
    );
    assert!(started.elapsed().as_secs_f64() < 10.0);
}

/// 1e308 in options, history or YAML was printed as 309 digits.
#[test]
fn huge_numbers_are_shown_short() {
    let dir = tempfile::tempdir().unwrap();
    let s = simulated(dir.path());
    let o = dir.path().join("r.json");
    let yml = dir.path().join("p.yml");
    fs::write(&yml, "scan_line: [ 1e308, 1, 2, 1e308, 3, 4 ]\n").unwrap();
    let library = Path::new(env!("CARGO_MANIFEST_DIR")).join("sessions/history");
    let runs = [
        vec![
            "calibrate",
            s.to_str().unwrap(),
            "--out",
            o.to_str().unwrap(),
            "--threshold",
            "1e308",
        ],
        vec!["plan", "--sphere", "1e308,0,0"],
        vec!["plan", "--sphere", "1050,0,475", "--diameter", "1e308"],
        vec![
            "simulate",
            "--out",
            o.to_str().unwrap(),
            "--diameter",
            "1e308",
        ],
        vec!["history", library.to_str().unwrap(), "--k", "1e308"],
    ];
    for args in runs {
        let (code, out, err) = spherecal_cli(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains("1e308"), "{args:?}: {err}");
        assert!(
            !format!("{out}{err}").contains("0000000000"),
            "{args:?}: {out}{err}"
        );
    }
    let e = import::profiles::read_profile(&yml, &ProfileFormat::default()).unwrap_err();
    assert!(e.to_string().contains("1e308"), "{e}");
}

/// A simulated session and its calibration (`dir/s.json`, `dir/r.json`).
fn calibrated(dir: &Path) -> (PathBuf, PathBuf) {
    let s = simulated(dir);
    let r = dir.join("r.json");
    let (code, _, err) = spherecal_cli(&[
        "calibrate",
        s.to_str().unwrap(),
        "--out",
        r.to_str().unwrap(),
        "--no-cross-validation",
        "-q",
    ]);
    assert_eq!(code, 0, "{err}");
    (s, r)
}

/// `calibrate /dev/zero` read until 4 GB were in memory (the size caps
/// asked the file system, which says 0 bytes for a device or a FIFO):
/// every file is read through one reader bounded by the bytes it reads,
/// so an endless device as a session, a result, targets or poses is
/// refused at its cap, naming the file and the cap.
#[cfg(unix)]
#[test]
fn an_endless_device_is_refused_at_the_cap_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (s, r) = calibrated(dir.path());
    let (x, i) = (dir.path().join("x.json"), dir.path().join("i.json"));
    let out = dir.path().join("out.csv");
    let out = out.to_str().unwrap();
    let zero = "/dev/zero";
    let runs: [(Vec<&str>, &str); 4] = [
        (
            vec!["calibrate", zero, "--out", x.to_str().unwrap()],
            "the 256 MiB a session or result file may have",
        ),
        (
            vec![
                "compensate",
                "--result",
                zero,
                "--targets",
                s.to_str().unwrap(),
                "--out",
                out,
            ],
            "the 256 MiB a session or result file may have",
        ),
        (
            vec![
                "compensate",
                "--result",
                r.to_str().unwrap(),
                "--targets",
                zero,
                "--pose-convention",
                "abb",
                "--out",
                out,
            ],
            "the 256 MiB a pose file or robot program may have",
        ),
        (
            vec![
                "import",
                "--poses",
                zero,
                "--pose-convention",
                "abb",
                "--profiles",
                dir.path().to_str().unwrap(),
                "--out",
                i.to_str().unwrap(),
            ],
            "the 256 MiB a pose file or robot program may have",
        ),
    ];
    for (args, cap) in runs {
        let started = std::time::Instant::now();
        let (code, _, err) = spherecal_cli(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(cap) && err.contains(zero), "{args:?}: {err}");
        assert!(
            started.elapsed().as_secs_f64() < 20.0,
            "{args:?}: {:?}",
            started.elapsed()
        );
    }
}

/// `compensate --tcp tool.json` with a translation of 1e200 mm ran (IK
/// on a tool beyond any cell) without end: the three 4×4 readers were
/// one for `--hand-eye` with a size cap and two without the plausibility
/// caps. One reader now refuses it at once, naming the key.
#[test]
fn an_absurd_tool_is_refused_at_once_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let (_, r) = calibrated(dir.path());
    let tool = dir.path().join("tool.json");
    fs::write(
        &tool,
        r#"{"flange_from_tcp": [[1,0,0,1e200],[0,1,0,0],[0,0,1,150],[0,0,0,1]]}"#,
    )
    .unwrap();
    let targets = dir.path().join("t.csv");
    fs::write(&targets, "id,x,y,z,q1,q2,q3,q4\nT1,1000,0,800,0,0,1,0\n").unwrap();
    let out = dir.path().join("c.csv");
    let started = std::time::Instant::now();
    let (code, _, err) = spherecal_cli(&[
        "compensate",
        "--result",
        r.to_str().unwrap(),
        "--targets",
        targets.to_str().unwrap(),
        "--pose-convention",
        "abb",
        "--tcp",
        tool.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("flange_from_tcp: a translation of 1e200 mm is not plausible")
            && err.contains("tool.json"),
        "{err}"
    );
    assert!(!out.exists());
    assert!(started.elapsed().as_secs_f64() < 10.0);
}

/// Issue 31, high: `compensate --tcp tcp0.json --out tcp0.json` exited 0
/// having overwritten the tool file with the compensated table. Every
/// input of every command, side files too (`--tcp`, `--frame`,
/// `--hand-eye`, `--centres`, `--references`, `--plan`, `--stations`), is
/// refused as an output, before any work, and is left as it was.
#[test]
fn every_input_of_every_command_is_refused_as_an_output() {
    let dir = tempfile::tempdir().unwrap();
    let (s, r) = calibrated(dir.path());
    let at = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let tool = at("tcp0.json");
    let eye = r#"{"flange_from_tcp": [[1,0,0,0],[0,1,0,0],[0,0,1,150],[0,0,0,1]]}"#;
    fs::write(&tool, eye).unwrap();
    let frame = at("frame.json");
    fs::write(
        &frame,
        r#"{"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}"#,
    )
    .unwrap();
    let targets = at("t.csv");
    fs::write(&targets, "id,x,y,z,q1,q2,q3,q4\nT1,1000,0,800,0,0,1,0\n").unwrap();
    let poses = at("poses.csv");
    fs::write(&poses, "id,x,y,z,q1,q2,q3,q4\np1,1000,0,800,0,0,1,0\n").unwrap();
    let centres = at("centres.csv");
    fs::write(&centres, "id,x,y,z\np1,30,0,100\n").unwrap();
    let references = at("references.csv");
    fs::write(&references, "a,b,distance\nV1,V2,100\n").unwrap();
    let csv_dir = at("csv");
    fs::create_dir(&csv_dir).unwrap();
    let plan_in_csv = format!("{csv_dir}/joints.csv");
    fs::write(&plan_in_csv, "id,station,use,j1\n").unwrap();
    let (s, r) = (s.to_str().unwrap(), r.to_str().unwrap());
    let import = |extra: &[&str], out: &str| -> Vec<String> {
        let mut a: Vec<&str> = vec!["import", "--poses", &poses, "--pose-convention", "abb"];
        a.extend(extra);
        a.extend(["--out", out]);
        a.iter().map(ToString::to_string).collect()
    };
    let runs: Vec<(Vec<String>, &str)> = vec![
        (
            [
                "compensate",
                "--result",
                r,
                "--targets",
                &targets,
                "--pose-convention",
                "abb",
                "--tcp",
                &tool,
                "--out",
                &tool,
            ]
            .iter()
            .map(ToString::to_string)
            .collect(),
            &tool,
        ),
        (
            [
                "measure", s, "--result", r, "--frame", &frame, "--out", &frame,
            ]
            .iter()
            .map(ToString::to_string)
            .collect(),
            &frame,
        ),
        (import(&["--centres", &centres], &centres), &centres),
        (
            import(&["--centres", &centres, "--hand-eye", &tool], &tool),
            &tool,
        ),
        (
            import(
                &["--centres", &centres, "--references", &references],
                &references,
            ),
            &references,
        ),
        (
            [
                "simulate",
                "--plan",
                &plan_in_csv,
                "--csv-out",
                &csv_dir,
                "--out",
                &at("sim.json"),
            ]
            .iter()
            .map(ToString::to_string)
            .collect(),
            &plan_in_csv,
        ),
        (
            [
                "plan",
                "--sphere",
                "1050,0,475",
                "--hand-eye",
                &tool,
                "--csv",
                &tool,
            ]
            .iter()
            .map(ToString::to_string)
            .collect(),
            &tool,
        ),
        (
            ["report", s, "--result", r, "-o", r]
                .iter()
                .map(ToString::to_string)
                .collect(),
            r,
        ),
    ];
    for (args, input) in runs {
        let before = fs::read(input).unwrap();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = spherecal_cli(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains("the output is the input") && err.contains(input),
            "{args:?}: {err}"
        );
        assert_eq!(fs::read(input).unwrap(), before, "{args:?} changed {input}");
    }
}

/// Issue 31, high: `import --poses P --pose-convention matrix --centres
/// c.csv` with one centre `1e308,1,2` ran without end. A centres table
/// goes through the session's plausibility rules (10 m from the sensor),
/// refused at once naming the file and the line.
#[test]
fn a_centre_of_1e308_is_refused_at_once_naming_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let poses = dir.path().join("poses.csv");
    let mut text = String::new();
    for k in 0..6 {
        let (c, s) = (
            f64::from(k).to_radians().cos(),
            f64::from(k).to_radians().sin(),
        );
        text += &format!(
            "{c} {} 0 {} {s} {c} 0 {} 0 0 1 800 0 0 0 1\n",
            -s,
            1000 + 10 * k,
            20 * k
        );
    }
    fs::write(&poses, text).unwrap();
    for (centre, shown) in [
        ("1e308,1,2", "1e308"),
        ("20000,1,2", "20000"),
        ("1,nan,2", "NaN"),
    ] {
        let centres = dir.path().join("c.csv");
        let mut rows: Vec<String> = (0..6).map(|k| format!("{},0,100", 30 + k)).collect();
        rows[3] = centre.to_string();
        fs::write(&centres, rows.join("\n") + "\n").unwrap();
        let out = dir.path().join("s.json");
        let started = std::time::Instant::now();
        let (code, _, err) = spherecal_cli(&[
            "import",
            "--poses",
            poses.to_str().unwrap(),
            "--pose-convention",
            "matrix",
            "--centres",
            centres.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{centre}: {err}");
        assert!(
            err.contains("line 4") && err.contains("c.csv") && err.contains(shown),
            "{centre}: {err}"
        );
        assert!(!out.exists());
        assert!(started.elapsed().as_secs_f64() < 10.0, "{centre}");
    }
}

/// A program of `plain` motions to its first target, then `modified` (the
/// motion under test), in `language`: its text, file name, and the line of
/// the modified motion.
fn program_with(language: usize, plain: usize, modified: &str) -> (String, &'static str, usize) {
    match language {
        0 => {
            let mut t = String::from("/PROG  CALIB\n/MN\n");
            for k in 0..plain {
                t += &format!("{:>4}:J P[1] 100% FINE    ;\n", k + 1);
            }
            t += &format!("{:>4}:{modified}    ;\n/POS\n", plain + 1);
            for k in 1..=2 {
                t += &format!(
                    "P[{k}]{{\n   GP1:\n\tUF : 0, UT : 0,\n\tX = {k}00.0  mm,\tY = 2.0  mm,\tZ = 3.0  mm,\n\tW = 0.0 deg,\tP = 0.0 deg,\tR = 0.0 deg\n}};\n"
                );
            }
            (t + "/END\n", "c.ls", plain + 3)
        }
        1 => {
            let mut t = String::from("MODULE M\n");
            for k in 1..=2 {
                t += &format!(
                    "  CONST robtarget p{k} := [[{k}00,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                );
            }
            t += "  PROC main()\n";
            t += &"    MoveL p1, v100, fine, tool0;\n".repeat(plain);
            (
                t + &format!("    {modified};\n  ENDPROC\nENDMODULE\n"),
                "c.mod",
                plain + 5,
            )
        }
        2 => {
            let mut t = String::from(
                "def calib():\n  p1 = p[0.4, 0, 0.3, 0, 0, 0]\n  p2 = p[0.5, 0, 0.3, 0, 0, 0]\n",
            );
            t += &"  movel(p1, a=0.5, v=0.05)\n".repeat(plain);
            (t + &format!("  {modified}\nend\n"), "c.script", plain + 4)
        }
        _ => {
            let mut t = String::from("DEF calib( )\n");
            t += &"  PTP {X 400,Y 2,Z 3,A 0,B 0,C 0}\n".repeat(plain);
            (t + &format!("  {modified}\nEND\n"), "c.src", plain + 2)
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 64, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(31), ..proptest::prelude::ProptestConfig::default() })]
    /// Issue 31, medium: program motion modifiers (RAPID `Offs`/`RelTool`,
    /// URScript `pose_trans`, FANUC `INC`, `Offset,PR[1]`, `Tool_Offset`,
    /// KRL `LIN_REL`) were dropped as "never moved to" or read as the plain
    /// target. In every language, each is refused naming its line.
    #[test]
    fn motion_modifiers_are_refused_naming_their_line(case in 0_usize..9, plain in 0_usize..5) {
        let (language, modified, named) = [
            (0, "L P[2] 100mm/sec FINE Offset,PR[1]", "Offset"),
            (0, "J P[2] 100% FINE INC", "INC"),
            (0, "L P[2] 100mm/sec FINE Tool_Offset,PR[2]", "Tool_Offset"),
            (0, "L P[2] 100mm/sec FINE VOFFSET,VR[1]", "VOFFSET"),
            (1, "MoveL Offs(p2,0,0,10), v100, fine, tool0", "Offs"),
            (1, "MoveJ RelTool(p2,0,0,10), v100, fine, tool0", "RelTool"),
            (2, "movel(pose_trans(p2, p[0, 0, 0.01, 0, 0, 0]), a=0.5, v=0.05)", "pose_trans"),
            (2, "movej(pose_add(p2, p[0, 0, 0.01, 0, 0, 0]), a=0.5, v=0.05)", "pose_add"),
            (3, "LIN_REL {X 10}", "LIN_REL"),
        ][case];
        let (text, name, line) = program_with(language, plain, modified);
        let e = spherecal::engine::files::program::parse_pose_text(text, Path::new(name), &spherecal::engine::files::program::ReadSpec::default()).unwrap_err();
        proptest::prop_assert_eq!(e.line, line, "{}", e);
        proptest::prop_assert!(e.to_string().contains(named) && e.to_string().contains(name), "{}", e);
    }
}

/// Issue 31, medium: malformed position blocks were skipped (FANUC
/// `P[3] junk {`, a KUKA E6POS without A, B, C), a motion to a position
/// the file does not hold (`P[99]`) went unreported, and a RAPID target
/// declared twice was read from its later declaration; a RAPID `\WObj`
/// or a second tool was not warned. Each is refused or warned naming the line.
#[test]
fn malformed_positions_and_doubtful_motions_are_named_with_their_line() {
    let read = |text: String, name: &str| {
        spherecal::engine::files::program::parse_pose_text(
            text,
            Path::new(name),
            &spherecal::engine::files::program::ReadSpec::default(),
        )
    };
    let (fanuc, _, _) = program_with(0, 1, "J P[2] 100% FINE");
    let junk = fanuc.replace("/END\n", "P[3] junk {\n   GP1:\n\tX = 1.0 mm\n};\n/END\n");
    let e = read(junk, "c.ls").unwrap_err();
    assert!(
        e.line == 18 && e.message.contains("P[3]") && e.message.contains("junk"),
        "{e}"
    );
    let (missing, _, _) = program_with(0, 1, "J P[99] 100% FINE");
    let e = read(missing, "c.ls").unwrap_err();
    assert!(e.line == 4 && e.message.contains("P[99]"), "{e}");
    let dat = "DEFDAT CALIB\nDECL E6POS XP1={X 1,Y 2,Z 3,A 0,B 0,C 0}\nDECL E6POS XP2={X 1,Y 2,Z 3,S 6,T 27}\nENDDAT\n";
    let e = read(dat.to_string(), "c.dat").unwrap_err();
    assert!(
        e.line == 3 && e.message.contains("XP2") && e.message.contains("no A, B, C"),
        "{e}"
    );
    let (twice, _, _) = program_with(1, 0, "MoveL p2, v100, fine, tool0");
    let twice = twice.replace(
        "  PROC",
        "  CONST robtarget P1 := [[9,9,9],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n  PROC",
    );
    let e = read(twice, "c.mod").unwrap_err();
    assert!(
        e.line == 4 && e.message.contains("declared twice (also at line 2)"),
        "{e}"
    );
    let (wobj, _, _) = program_with(1, 1, "MoveL p2, v100, fine, tSensor\\WObj:=wobj1");
    let file = read(wobj, "c.mod").unwrap();
    let warned = file.warnings.join("\n");
    assert!(
        warned.contains("line 6: moves in work object `wobj1`")
            && warned.contains("2 tools, `tool0` (line 5), `tsensor` (line 6)"),
        "{warned}"
    );
}

/// Issue 31, medium: `measure` took a result whose `variance_factor` was
/// −4 (as 1) and a covariance with 1e300, one beyond its variances (not
/// positive semi-definite) or a label twice. The result reader refuses
/// each, naming the key.
#[test]
fn a_result_with_an_implausible_covariance_or_variance_factor_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (_, r) = calibrated(dir.path());
    let text = fs::read_to_string(&r).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert!(format::parse_result(&text, Path::new("r.json")).is_ok());
    type Edit = fn(&mut serde_json::Value);
    let edits: [(&str, Edit); 4] = [
        ("variance_factor` = -4", |v| {
            v["solver"]["variance_factor"] = serde_json::json!(-4.0);
        }),
        ("= 1e300 is not plausible", |v| {
            v["solver"]["covariance"]["matrix"][0][0] = serde_json::json!(1e300);
        }),
        ("not positive semi-definite", |v| {
            let d = v["solver"]["covariance"]["matrix"][0][0].as_f64().unwrap();
            let e = v["solver"]["covariance"]["matrix"][1][1].as_f64().unwrap();
            let big = serde_json::json!(2.0 * (d * e).sqrt() + 1.0);
            v["solver"]["covariance"]["matrix"][0][1] = big.clone();
            v["solver"]["covariance"]["matrix"][1][0] = big;
        }),
        ("twice", |v| {
            let first = v["solver"]["covariance"]["labels"][0].clone();
            v["solver"]["covariance"]["labels"][1] = first;
        }),
    ];
    for (want, edit) in edits {
        let mut bad = v.clone();
        edit(&mut bad);
        let e = format::parse_result(&bad.to_string(), Path::new("r.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(want) && e.contains("r.json"), "{want}: {e}");
    }
}
