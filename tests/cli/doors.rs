//! Issue 31, the fourth round of attacks: the rows left after the high
//! and medium ones (`hostile.rs`, `pose_files.rs`, `contract.rs`), each a
//! regression test named after its row, on the real binary.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use spherecal::engine::files::format;

use crate::support::bin::{run, spherecal};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// The seed-7 cell of the guide's measuring chapter, calibrated once for
/// every test here: (session, result).
fn cell() -> &'static (PathBuf, PathBuf) {
    static CELL: OnceLock<(PathBuf, PathBuf)> = OnceLock::new();
    CELL.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap().keep();
        let (s, r) = (dir.join("cell.json"), dir.join("cell.result.json"));
        let (code, _, err) = run(&["simulate", "--seed", "7", "--out", p(&s), "-q"]);
        assert_eq!(code, 0, "{err}");
        let (code, _, err) = run(&["calibrate", p(&s), "--out", p(&r), "-q"]);
        assert_eq!(code, 0, "{err}");
        (s, r)
    })
}

fn scan(args: &[&str]) -> (i32, String, String) {
    let (_, result) = cell();
    let joints = root().join("examples/scan/joints.csv");
    let profiles = root().join("examples/scan/profiles");
    let mut all = vec![
        "measure",
        "--joints",
        p(&joints),
        "--profiles",
        p(&profiles),
        "--robot",
        "irb2400",
        "--result",
        p(result),
    ];
    all.extend_from_slice(args);
    run(&all)
}

/// `spherecal import` of the pose file `poses` beside the profiles of
/// the real set (or a copy, `profiles`), its 80 mm sphere, into `out`,
/// with `extra` flags.
fn import_real(poses: &Path, profiles: &Path, out: &Path, extra: &[&str]) -> (i32, String, String) {
    let mut args = vec![
        "import",
        "--poses",
        p(poses),
        "--profiles",
        p(profiles),
        "--sphere-diameter",
        "80",
        "--out",
        p(out),
    ];
    args.extend_from_slice(extra);
    run(&args)
}

#[test]
fn measure_profile_unit_m_putting_points_40_m_from_the_sensor_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("part.csv");
    let (code, _, err) = scan(&["--profile-unit", "m", "--out", p(&out)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("beyond any sensor's field"), "{err}");
    assert!(err.contains("check --profile-unit"), "{err}");
    assert!(err.contains("s1.csv"), "{err}");
    assert!(!out.exists());
}

#[test]
fn measure_of_a_raw_scan_takes_use_identify() {
    let dir = tempfile::tempdir().unwrap();
    // The scan's log with its first four poses `identify`.
    let text = fs::read_to_string(root().join("examples/scan/joints.csv")).unwrap();
    let mut k = 0;
    let log: String = text
        .lines()
        .map(|line| {
            if line.starts_with('#') || line.starts_with("id,") {
                return format!("{line}\n");
            }
            k += 1;
            let usage = if k <= 4 { "identify" } else { "validate" };
            format!(
                "{}\n",
                line.replacen(",validate,", &format!(",{usage},"), 1)
            )
        })
        .collect();
    let joints = dir.path().join("j.csv");
    fs::write(&joints, log).unwrap();
    let (_, result) = cell();
    let out = dir.path().join("part.csv");
    let args = |usage: &'static str| {
        vec![
            "measure".to_string(),
            "--joints".into(),
            p(&joints).into(),
            "--profiles".into(),
            p(&root().join("examples/scan/profiles")).into(),
            "--robot".into(),
            "irb2400".into(),
            "--result".into(),
            p(result).into(),
            "--out".into(),
            p(&out).into(),
            "--use".into(),
            usage.into(),
        ]
    };
    let (code, stdout, err) = run(&args("identify"));
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("of 4 poses"), "{stdout}");
    let (code, stdout, err) = run(&args("validate"));
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("of 6 poses"), "{stdout}");
    // The scan as shipped has no identify pose: said, not measured.
    let (code, _, err) = scan(&["--use", "identify", "--out", p(&out)]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("no pose of the log is of use identify"),
        "{err}"
    );
}

#[test]
fn the_frame_key_twice_is_refused_not_the_last_one_taken() {
    let dir = tempfile::tempdir().unwrap();
    let frame = dir.path().join("f.json");
    fs::write(
        &frame,
        r#"{"base_from_workpiece": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]],
            "base_from_workpiece": [[1,0,0,5],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}"#,
    )
    .unwrap();
    let out = dir.path().join("part.csv");
    let (code, _, err) = scan(&["--frame", p(&frame), "--out", p(&out)]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("duplicate key `base_from_workpiece`"), "{err}");
}

/// `RobPoses` twice in a `.rob`, `X` twice in a KRL aggregate, a header
/// column twice and a target id twice: each refused naming its line.
#[test]
fn duplicate_keys_or_columns_are_refused_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let data = root().join("data/robcalibrator-sphere");
    let out = dir.path().join("s.json");
    let import = |poses: &Path| import_real(poses, &data, &out, &["--pose-convention", "fanuc"]);
    let rob = fs::read_to_string(data.join("RobPoses.rob")).unwrap();
    let rob = format!(
        "{}, \"RobPoses\": [[1, 2, 3, 0, 0, 0]]}}",
        rob.trim_end().strip_suffix('}').unwrap()
    );
    let twice = dir.path().join("RobPoses.rob");
    fs::write(&twice, rob).unwrap();
    let (code, _, err) = import(&twice);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("the key `RobPoses` is given twice"), "{err}");

    let krl = fs::read_to_string(root().join("examples/poses/robposes.dat"))
        .unwrap()
        .replacen("{X ", "{X 5,X ", 1);
    let dat = dir.path().join("poses.dat");
    fs::write(&dat, krl).unwrap();
    let (code, _, err) = import_real(&dat, &data, &out, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("the field `X` is given twice"), "{err}");
    assert!(err.contains("line 3"), "{err}");

    let (_, result) = cell();
    let targets = fs::read_to_string(root().join("examples/targets.csv")).unwrap();
    let mut lines = targets.lines();
    let header = lines.next().unwrap();
    let first = lines.next().unwrap();
    let same_id = dir.path().join("t.csv");
    fs::write(&same_id, format!("{header}\n{first}\n{first}\n")).unwrap();
    let compensate = |targets: &Path| {
        run(&[
            "compensate",
            "--result",
            p(result),
            "--targets",
            p(targets),
            "--pose-convention",
            "abb",
            "--out",
            p(&dir.path().join("out.csv")),
        ])
    };
    let (code, _, err) = compensate(&same_id);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("the id `T1` is given twice (also at line 2)"),
        "{err}"
    );
    assert!(err.contains("line 3"), "{err}");
    let column_twice = dir.path().join("t2.csv");
    fs::write(&column_twice, format!("{header},x\n{first},5\n")).unwrap();
    let (code, _, err) = compensate(&column_twice);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("the header names `x` twice (columns 2 and 9)"),
        "{err}"
    );
}

#[test]
fn an_output_onto_an_old_output_inside_the_profiles_folder_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("set");
    fs::create_dir(&data).unwrap();
    for e in fs::read_dir(root().join("data/robcalibrator-sphere")).unwrap() {
        let e = e.unwrap();
        fs::copy(e.path(), data.join(e.file_name())).unwrap();
    }
    let out = data.join("session.json");
    let rob = data.join("RobPoses.rob");
    let import = || import_real(&rob, &data, &out, &["--pose-convention", "fanuc", "-q"]);
    let (code, _, err) = import();
    assert_eq!(code, 0, "{err}");
    // Again, onto the old output that now lies among the profiles (the
    // folder's listing skips it): written, not "the output is the input".
    let (code, _, err) = import();
    assert_eq!(code, 0, "{err}");
    // A profile itself is still refused as an output.
    let (code, _, err) = import_real(
        &rob,
        &data,
        &data.join("p3.yml"),
        &["--pose-convention", "fanuc"],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("the output is the input"), "{err}");
}

#[test]
fn plan_rapid_for_a_ur5e_or_urscript_for_an_irb_2400_is_not_written_silently() {
    let dir = tempfile::tempdir().unwrap();
    let module = dir.path().join("plan.mod");
    let (code, out, err) = run(&[
        "plan",
        "--robot",
        "ur5e",
        "--sphere",
        "500,0,200",
        "--predict",
        "0",
        "--rapid",
        p(&module),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("warning: the robot is Universal Robots UR5e, not a robot of ABB"),
        "{out}"
    );
    assert!(
        out.contains("(a URScript program is what it runs)"),
        "{out}"
    );
    let script = dir.path().join("plan.script");
    let (code, out, err) = run(&[
        "plan",
        "--sphere",
        "1050,0,475",
        "--predict",
        "0",
        "--program",
        &format!("urscript={}", p(&script)),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("not a robot of Universal Robots"), "{out}");
    // The robot's own program: no warning.
    let (code, out, err) = run(&[
        "plan",
        "--sphere",
        "1050,0,475",
        "--predict",
        "0",
        "--rapid",
        p(&module),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains("warning"), "{out}");
}

#[test]
fn calibrate_with_stdout_on_dev_full_says_its_files_are_kept() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let (session, _) = cell();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.json");
    let full = fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let o = spherecal()
        .args(["calibrate", p(session), "--out", p(&out)])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("the command's text is lost"), "{err}");
    assert!(
        err.contains("the files it wrote are whole and kept"),
        "{err}"
    );
    assert!(err.contains("r.json"), "{err}");
    format::load_result(&out).unwrap();
}

#[test]
fn a_path_with_a_line_feed_keeps_the_error_on_one_line() {
    let (code, _, err) = run(&["calibrate", "no\nsuch.json", "--out", "x.json"]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("no\\nsuch.json"), "{err}");
}

#[test]
fn a_home_jointtarget_at_zero_is_kept_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let module = fs::read_to_string(root().join("examples/path.mod"))
        .unwrap()
        .replacen(
            "  PROC main()\n",
            "  CONST jointtarget jHome := [[0,0,0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];\n  PROC main()\n    MoveAbsJ jHome, v100, fine, tool0;\n",
            1,
        );
    let path = dir.path().join("home.mod");
    fs::write(&path, &module).unwrap();
    let out = dir.path().join("home.compensated.mod");
    let (_, result) = cell();
    let (code, stdout, err) = run(&[
        "compensate",
        "--result",
        p(result),
        "--targets",
        p(&path),
        "--out",
        p(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.contains("jHome (line 14): a joint target kept as written"),
        "{stdout}"
    );
    assert!(
        stdout.contains("10 targets compensated (1 joint target kept)"),
        "{stdout}"
    );
    let written = fs::read_to_string(&out).unwrap();
    assert!(written.contains("jHome := [[0,0,0,0,0,0]"), "{written}");
}

#[test]
fn a_hand_eye_guess_rounded_to_4_decimals_is_taken_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let (c, s) = (0.3_f64.cos(), 0.3_f64.sin());
    let r = |v: f64| (v * 1e4).round() / 1e4;
    let guess = dir.path().join("he.json");
    fs::write(
        &guess,
        format!(
            "[[{}, {}, 0, 10], [{}, {}, 0, 20], [0, 0, 1, 100], [0, 0, 0, 1]]",
            r(c),
            r(-s),
            r(s),
            r(c)
        ),
    )
    .unwrap();
    let data = root().join("data/robcalibrator-sphere");
    let (code, stdout, err) = import_real(
        &data.join("RobPoses.rob"),
        &data,
        &dir.path().join("s.json"),
        &["--pose-convention", "fanuc", "--hand-eye", p(&guess)],
    );
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.contains("note: --hand-eye: the rotation is 8.2e-5 from orthonormal"),
        "{stdout}"
    );
    // Beyond 1e-3 it is no rotation: refused as before.
    fs::write(
        &guess,
        "[[0.99, 0.1, 0, 10], [-0.1, 0.99, 0, 20], [0, 0, 1, 100], [0, 0, 0, 1]]",
    )
    .unwrap();
    let (code, _, err) = run(&[
        "plan",
        "--sphere",
        "1050,0,475",
        "--hand-eye",
        p(&guess),
        "--predict",
        "0",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not orthonormal"), "{err}");
}

#[test]
fn wording_an_abb_rapid_module_and_one_pose() {
    let dir = tempfile::tempdir().unwrap();
    let data = root().join("data/robcalibrator-sphere");
    let (code, _, err) = import_real(
        &root().join("examples/poses/robposes.mod"),
        &data,
        &dir.path().join("s.json"),
        &["--pose-convention", "fanuc"],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("error: an ABB RAPID module writes"), "{err}");
    // A raw scan of one pose: "1 pose".
    let joints = fs::read_to_string(root().join("examples/scan/joints.csv")).unwrap();
    let one: String = joints.lines().take(3).map(|l| format!("{l}\n")).collect();
    let log = dir.path().join("one.csv");
    fs::write(&log, one).unwrap();
    let (_, result) = cell();
    let (code, stdout, err) = run(&[
        "measure",
        "--joints",
        p(&log),
        "--profiles",
        p(&root().join("examples/scan/profiles")),
        "--robot",
        "irb2400",
        "--result",
        p(result),
        "--out",
        p(&dir.path().join("one.ply")),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("points of 1 pose ("), "{stdout}");
}

#[test]
fn skipped_files_in_a_joint_log_profile_folder_are_listed() {
    let dir = tempfile::tempdir().unwrap();
    let profiles = dir.path().join("profiles");
    fs::create_dir(&profiles).unwrap();
    for e in fs::read_dir(root().join("examples/log/profiles")).unwrap() {
        let e = e.unwrap();
        fs::copy(e.path(), profiles.join(e.file_name())).unwrap();
    }
    fs::write(profiles.join("c999.csv"), "1,2\n").unwrap();
    fs::write(profiles.join("README.txt"), "notes\n").unwrap();
    fs::create_dir(profiles.join("old.csv")).unwrap();
    let (code, out, err) = run(&[
        "import",
        "--joints",
        p(&root().join("examples/log/log.csv")),
        "--profiles",
        p(&profiles),
        "--robot",
        "irb2400",
        "--map",
        "id=Pose,station=Sphere,use=Use,side=Side,j1=A1,j2=A2,j3=A3,j4=A4,j5=A5,j6=A6",
        "--joint-unit",
        "rad",
        "--profile-unit",
        "um",
        "--out",
        p(&dir.path().join("s.json")),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains(
            "skipped 3 entries that name no pose: README.txt, c999.csv, old.csv (a folder)"
        ),
        "{out}"
    );
}

#[test]
fn a_cr_only_ls_says_its_line_ends_not_no_pos_section() {
    let dir = tempfile::tempdir().unwrap();
    let text = fs::read_to_string(root().join("examples/poses/calib_sph.ls"))
        .unwrap()
        .replace('\n', "\r");
    let ls = dir.path().join("cr.ls");
    fs::write(&ls, text).unwrap();
    let (code, _, err) = import_real(
        &ls,
        &root().join("data/robcalibrator-sphere"),
        &dir.path().join("s.json"),
        &[],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("its lines end with CR alone"), "{err}");
    assert!(!err.contains("/POS"), "{err}");
}
