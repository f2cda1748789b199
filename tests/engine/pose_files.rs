//! Pose files as cells write them (issue: real cells as they are
//! published): every layout from its documented syntax, written from a
//! simulated cell whose flange poses are known, imported from the
//! profile folder the pose file sits in, and compared with the truth;
//! the general initial hand-eye for sets without pure translations; the
//! plan's programs read back; bad files named with their line; mutated
//! files never panic or hang.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(
    clippy::case_sensitive_file_extension_comparisons,
    reason = "the tests name their own files, in lower case"
)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use nalgebra::{Isometry3, Point3};
use proptest::prelude::*;
use spherecal::engine::assemble;
use spherecal::engine::base::geometry::rigid_from_rows;
use spherecal::engine::base::session::{Observation, Session, Use};
use spherecal::engine::calibrate::solve::{self, Options};
use spherecal::engine::files::import::{
    self, FlangeConvention, Observations, PoseImportSpec, ProfileFormat, ProfileSource, SideChoice,
};
use spherecal::engine::files::program::{self, PoseFormat, ReadSpec};
use spherecal::engine::tools::simulate::{self, SimConfig, Truth};

use crate::support::pose as pose_support;
use pose_support::{fanuc_ls, headerless_table, station_poses};

/// True flange poses, stripes and the truth of a simulated cell.
type Cell = (Vec<Isometry3<f64>>, Vec<Vec<[f64; 2]>>, Truth);

/// One station of a simulated cell seen from `n_translation` pure
/// translations and `n_rotation` orientation changes, every centre on
/// side +1: the true flange poses (where the controller says the flange
/// is), the stripes, and the truth.
fn cell(n_translation: usize, n_rotation: usize, noisy: bool, seed: u64) -> Cell {
    let config = SimConfig {
        seed,
        n_translation,
        n_rotation,
        n_identify: 2,
        n_validate: 0,
        side: simulate::SideChoice::Plus,
        joint_noise: if noisy { 0.003 } else { 0.0 },
        stripe_noise: if noisy { 0.02 } else { 0.0 },
        // Noise-free stripes at full precision, so that "exact" is exact.
        stripe_decimals: if noisy {
            SimConfig::default().stripe_decimals
        } else {
            12
        },
        ..SimConfig::default()
    };
    let (session, truth) = simulate::simulate(&config).unwrap();
    let (poses, stripes) = station_poses(&session, &truth, "P0");
    (poses, stripes, truth)
}

/// The 8 poses of one identify station of a noisy simulated cell (the
/// simulator's noise), the sphere spread over ±20 mm of the laser plane,
/// every centre on side +1: true flange poses, stripes, truth.
fn spread_station(seed: u64) -> Cell {
    let config = SimConfig {
        seed,
        n_identify: 1,
        n_validate: 0,
        poses_per_station: 8,
        side: simulate::SideChoice::Plus,
        range: Some(spherecal::engine::base::session::SensorRange {
            y: [-20.0, 20.0],
            z: [-20.0, 20.0],
        }),
        spread: true,
        ..SimConfig::default()
    };
    let (session, truth) = simulate::simulate(&config).unwrap();
    let robot = truth.true_robot();
    let (mut poses, mut stripes) = (Vec::new(), Vec::new());
    for m in session.measurements.iter().filter(|m| m.station == "P1") {
        poses.push(robot.base_from_flange(&m.joints));
        let Observation::Stripe(p) = &m.observation else {
            panic!("stripes expected")
        };
        stripes.push(p.clone());
    }
    (poses, stripes, truth)
}

/// A folder with one `y,z` profile a pose (`p1.csv` …) and the pose file
/// `name` written by `write` inside it.
fn folder(stripes: &[Vec<[f64; 2]>], name: &str, text: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    for (k, s) in stripes.iter().enumerate() {
        let mut t = String::from("y,z\n");
        for [y, z] in s {
            writeln!(t, "{y},{z}").unwrap();
        }
        std::fs::write(dir.path().join(format!("p{}.csv", k + 1)), t).unwrap();
    }
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    (dir, path)
}

fn values(c: FlangeConvention, pose: &Isometry3<f64>) -> Vec<f64> {
    c.values_from_pose(pose)
}

fn rapid(poses: &[Isometry3<f64>]) -> String {
    let mut t = String::from("MODULE Calib\n    ! taught sphere poses\n");
    for (k, p) in poses.iter().enumerate() {
        let v = values(FlangeConvention::AbbQuaternion, p);
        writeln!(
            t,
            "    CONST robtarget p{} := [[{:.9},{:.9},{:.9}],[{:.12},{:.12},{:.12},{:.12}],[0,-1,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];",
            k + 1, v[0], v[1], v[2], v[3], v[4], v[5], v[6]
        )
        .unwrap();
    }
    t.push_str("    PROC main()\n");
    for k in 0..poses.len() {
        writeln!(
            t,
            "        MoveL p{}, v100, fine, tool0;\n        Measure;",
            k + 1
        )
        .unwrap();
    }
    t.push_str("    ENDPROC\nENDMODULE\n");
    t
}

fn kuka_dat(poses: &[Isometry3<f64>]) -> String {
    let mut t = String::from(
        "&ACCESS RVP\n&REL 1\nDEFDAT  CALIB\n;FOLD EXTERNAL DECLARATIONS;%{PE}%MKUKATPBASIS,%CEXT,%VCOMMON,%P\n;ENDFOLD (EXTERNAL DECLARATIONS)\n",
    );
    for (k, p) in poses.iter().enumerate() {
        let v = values(FlangeConvention::KukaAbc, p);
        writeln!(
            t,
            "DECL E6POS XP{}={{X {:.9},Y {:.9},Z {:.9},A {:.9},B {:.9},C {:.9},S 6,T 27,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}}\nDECL FDAT FP{}={{TOOL_NO 0,BASE_NO 0,IPO_FRAME #BASE,POINT2[] \" \",TQ_STATE FALSE}}",
            k + 1, v[0], v[1], v[2], v[3], v[4], v[5], k + 1
        )
        .unwrap();
    }
    t.push_str("ENDDAT\n");
    t
}

fn urscript(poses: &[Isometry3<f64>]) -> String {
    let mut t = String::from("def calib():\n  # sphere poses, m and rad\n");
    for p in poses {
        let v = values(FlangeConvention::UrRotationVector, p);
        writeln!(
            t,
            "  movel(p[{:.12}, {:.12}, {:.12}, {:.12}, {:.12}, {:.12}], a=0.5, v=0.05)\n  measure()",
            v[0], v[1], v[2], v[3], v[4], v[5]
        )
        .unwrap();
    }
    t.push_str("end\n");
    t
}

fn spec(poses: &Path, observations: Observations) -> PoseImportSpec {
    PoseImportSpec {
        poses: poses.to_path_buf(),
        format: None,
        convention: None,
        pose_columns: None,
        observations,
        profile_format: ProfileFormat::default(),
        robot: None,
        sphere_diameter: 38.1,
        side: SideChoice::Auto,
        hand_eye: None,
        name: None,
        references: None,
    }
}

fn assert_poses(session: &Session, truth: &[Isometry3<f64>], what: &str) {
    assert_eq!(session.measurements.len(), truth.len(), "{what}");
    for (m, t) in session.measurements.iter().zip(truth) {
        let f = m.flange.unwrap();
        let dt = (f.translation.vector - t.translation.vector).norm();
        let dr = f.rotation.angle_to(&t.rotation);
        assert!(
            dt <= 1e-6 && dr <= 1e-9,
            "{what} {}: {dt} mm, {dr} rad",
            m.id
        );
    }
}

#[test]
fn every_layout_imports_from_the_profile_folder_it_sits_in() {
    let (poses, stripes, truth) = cell(4, 8, false, 3);
    assert_eq!(poses.len(), 12, "a .ls with 12 positions");
    let layouts: [(&str, String, Option<FlangeConvention>, PoseFormat); 6] = [
        (
            "robot.txt",
            headerless_table(&poses),
            Some(FlangeConvention::FanucWpr),
            PoseFormat::Table,
        ),
        // A European spreadsheet's export: semicolons, decimal commas.
        (
            "robot_eu.csv",
            headerless_table(&poses)
                .replace('.', ",")
                .replace("   ", ";"),
            Some(FlangeConvention::FanucWpr),
            PoseFormat::Table,
        ),
        (
            "calib.ls",
            fanuc_ls(&poses, 0),
            Some(FlangeConvention::FanucWpr),
            PoseFormat::FanucLs,
        ),
        ("calib.mod", rapid(&poses), None, PoseFormat::Rapid),
        ("calib.dat", kuka_dat(&poses), None, PoseFormat::Krl),
        ("calib.script", urscript(&poses), None, PoseFormat::UrScript),
    ];
    let he_true = rigid_from_rows(&truth.hand_eye);
    for (name, text, convention, format) in layouts {
        let (dir, path) = folder(&stripes, name, &text);
        let file = program::read_pose_file(
            &path,
            &ReadSpec {
                convention,
                ..ReadSpec::default()
            },
        )
        .unwrap();
        assert_eq!(file.format, format, "{name}");
        let mut s = spec(
            &path,
            Observations::Profiles(ProfileSource::Folder(dir.path().to_path_buf())),
        );
        s.convention = convention;
        let imported = assemble::import_poses(&s).unwrap();
        assert_poses(&imported.session, &poses, name);
        let notes = imported.notes.join("\n");
        assert!(notes.contains(format.describe()), "{name}: {notes}");
        assert!(
            notes.contains(&format!("{name} (the pose file)")),
            "{name}: {notes}"
        );
        assert!(notes.contains("side +1 chosen"), "{name}: {notes}");
        // The eq. 6-9 start and the general one are both printed.
        assert!(
            notes.contains("eq. 6-9") && notes.contains("general solution"),
            "{notes}"
        );
        // Noise-free: the calibration gives the true hand-eye.
        let mut options = Options::from_session(&imported.session);
        options.threshold = 0.0;
        let (_, cal) = solve::calibrate(&imported.session, &options).unwrap();
        let dt = (cal.hand_eye.translation.vector - he_true.translation.vector).norm();
        let dr = cal
            .hand_eye
            .rotation
            .angle_to(&he_true.rotation)
            .to_degrees();
        assert!(dt < 1e-4 && dr < 1e-5, "{name}: {dt} mm, {dr}°");
    }
}

#[test]
fn a_set_without_pure_translations_starts_from_the_general_hand_eye() {
    let he_true = |t: &Truth| rigid_from_rows(&t.hand_eye);
    // Exact without noise.
    let (poses, stripes, truth) = cell(4, 8, false, 5);
    let (dir, path) = folder(&stripes[4..], "poses.txt", &headerless_table(&poses[4..]));
    let mut s = spec(
        &path,
        Observations::Profiles(ProfileSource::Folder(dir.path().to_path_buf())),
    );
    s.convention = Some(FlangeConvention::FanucWpr);
    let imported = assemble::import_poses(&s).unwrap();
    let notes = imported.notes.join("\n");
    assert!(notes.contains("no group of one orientation"), "{notes}");
    let start = imported.session.hand_eye.unwrap();
    let h = he_true(&truth);
    assert!(
        (start.translation.vector - h.translation.vector).norm() < 1e-6,
        "{} vs {} {notes}",
        start.translation.vector,
        h.translation.vector
    );
    assert!(start.rotation.angle_to(&h.rotation) < 1e-8);
    // With the simulator's noise, 8 poses spanning ≥ 30° of one identify
    // station, the sphere seen over the sensor's range (as on a real cell
    // without pure translations, the sphere is not kept at one spot of
    // the laser plane: that is what shows the rotation): within 1 mm, 0.5°.
    for seed in 1..=4 {
        let (poses, stripes, truth) = spread_station(seed);
        let span = poses
            .iter()
            .flat_map(|a| poses.iter().map(move |b| a.rotation.angle_to(&b.rotation)))
            .fold(0.0_f64, f64::max)
            .to_degrees();
        assert!(span >= 30.0, "seed {seed}: span {span}°");
        let (dir, path) = folder(&stripes, "poses.txt", &headerless_table(&poses));
        let mut s = spec(
            &path,
            Observations::Profiles(ProfileSource::Folder(dir.path().to_path_buf())),
        );
        s.convention = Some(FlangeConvention::FanucWpr);
        s.side = SideChoice::Plus;
        let imported = assemble::import_poses(&s).unwrap();
        assert!(
            imported
                .notes
                .iter()
                .any(|n| n.contains("by the general solution"))
        );
        let start = imported.session.hand_eye.unwrap();
        let h = he_true(&truth);
        let dt = (start.translation.vector - h.translation.vector).norm();
        let dr = start.rotation.angle_to(&h.rotation).to_degrees();
        assert!(dt < 1.0 && dr < 0.5, "seed {seed}: {dt} mm, {dr}°");
    }
    // Degenerate: the same orientation everywhere (6 translations).
    let (poses, stripes, _) = cell(6, 8, false, 6);
    let keep = [0, 1, 2, 3, 4, 5];
    let p: Vec<Isometry3<f64>> = keep.iter().map(|&i| poses[i]).collect();
    let st: Vec<Vec<[f64; 2]>> = keep.iter().map(|&i| stripes[i].clone()).collect();
    let (dir, path) = folder(&st, "poses.txt", &headerless_table(&p));
    let mut s = spec(
        &path,
        Observations::Profiles(ProfileSource::Folder(dir.path().to_path_buf())),
    );
    s.convention = Some(FlangeConvention::FanucWpr);
    s.side = SideChoice::Plus;
    let e = assemble::import_poses(&s).unwrap_err().to_string();
    assert!(
        e.contains("no initial hand-eye") && e.contains("--hand-eye"),
        "{e}"
    );
    assert!(e.contains("all the same"), "the reason is named: {e}");
    // With a guess it imports.
    s.hand_eye = Some(rigid_from_rows(&cell(6, 8, false, 6).2.hand_eye));
    let imported = assemble::import_poses(&s).unwrap();
    assert!(imported.notes.iter().any(|n| n.contains("the guess given")));
}

#[test]
fn centres_reported_by_the_sensor_import_as_centre_measurements() {
    let (poses, stripes, truth) = cell(4, 8, false, 7);
    let he = rigid_from_rows(&truth.hand_eye);
    let station = *truth.stations.iter().find(|(k, _)| *k == "P0").unwrap().1;
    let mut centres = String::from("x;y;z\n");
    for p in &poses {
        let c = (p * he).inverse() * Point3::from(nalgebra::Vector3::from(station));
        writeln!(centres, "{:.9};{:.9};{:.9}", c.x, c.y, c.z).unwrap();
    }
    let (dir, path) = folder(&stripes, "robot.txt", &headerless_table(&poses));
    let centres_path = dir.path().join("centres.txt");
    std::fs::write(&centres_path, centres).unwrap();
    let mut s = spec(&path, Observations::Centres(centres_path));
    s.convention = Some(FlangeConvention::FanucWpr);
    let imported = assemble::import_poses(&s).unwrap();
    assert!(
        imported
            .session
            .measurements
            .iter()
            .all(|m| matches!(m.observation, Observation::Centre(_)) && m.usage == Use::Identify)
    );
    let (_, cal) =
        solve::calibrate(&imported.session, &Options::from_session(&imported.session)).unwrap();
    assert!((cal.hand_eye.translation.vector - he.translation.vector).norm() < 1e-4);
}

#[test]
fn profile_names_with_the_number_anywhere_pair_in_numeric_order() {
    let (poses, stripes, _) = cell(4, 8, false, 3);
    let (dir, path) = folder(&[], "rob2sphere.txt", &headerless_table(&poses));
    for (k, s) in stripes.iter().enumerate() {
        let mut t = String::new();
        for [y, z] in s {
            writeln!(t, "0 {y} {z}").unwrap();
        }
        std::fs::write(dir.path().join(format!("{}_3C_line.txt", k + 1)), t).unwrap();
    }
    std::fs::write(dir.path().join("calibration.sec"), "{}").unwrap();
    let mut s = spec(
        &path,
        Observations::Profiles(ProfileSource::Folder(dir.path().to_path_buf())),
    );
    s.convention = Some(FlangeConvention::FanucWpr);
    let imported = assemble::import_poses(&s).unwrap();
    assert_poses(&imported.session, &poses, "N_3C_line");
    assert_eq!(imported.session.measurements[9].id, "10_3C_line");
    let notes = imported.notes.join("\n");
    assert!(
        notes.contains("calibration.sec (not a profile file: .sec)"),
        "{notes}"
    );
    assert!(notes.contains("line 12 ↔ 12_3C_line.txt"), "{notes}");
    // One profile too many: both counts named.
    std::fs::write(dir.path().join("13_3C_line.txt"), "0 1 2\n0 2 3\n").unwrap();
    let e = assemble::import_poses(&s).unwrap_err().to_string();
    assert!(e.contains("13 profiles for 12 poses"), "{e}");
}

/// The planner's programs import back to the planned flange poses.
#[test]
fn plan_programs_import_back_to_the_planned_poses() {
    use spherecal::engine::base::cell::workspace::Workspace;
    use spherecal::engine::base::robot;
    use spherecal::engine::base::robot::RobotChoice;
    use spherecal::engine::calibrate::solve::Control;
    use spherecal::engine::tools::plan::{self, Controller, PlanConfig};
    for (key, preset, controller) in [
        ("irb2400", robot::irb2400(), Controller::Abb),
        ("ur5e", robot::ur5e(), Controller::Ur),
    ] {
        let w = Workspace::for_robot(RobotChoice::from_key(key).unwrap());
        let sphere = [0, 1, 2].map(|i| f64::midpoint(w.min[i], w.max[i]));
        let mut config = PlanConfig::for_preset(&preset, sphere);
        config.design.n_identify = 2;
        config.design.identify_poses = 4;
        config.design.n_validate = 1;
        config.design.validate_poses = 3;
        config.design.candidates = 8;
        let plan = plan::plan(&config, &mut |_| Control::Continue).unwrap();
        let robot = key;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(format!("plan.{}", controller.extension()));
        std::fs::write(&path, plan::render_program(controller, &plan).unwrap()).unwrap();
        let file = program::read_pose_file(&path, &ReadSpec::default()).unwrap();
        let nominal = plan.robot.clone();
        let targets: Vec<_> = file.ordered().collect();
        assert_eq!(targets.len(), plan.poses.len(), "{robot}");
        for (t, p) in targets.iter().zip(&plan.poses) {
            let program::TargetValue::Joints { deg, .. } = &t.value else {
                panic!("joint targets expected")
            };
            let got = nominal.base_from_flange(deg);
            let want = nominal.base_from_flange(&p.joints);
            let dt = (got.translation.vector - want.translation.vector).norm();
            let dr = got.rotation.angle_to(&want.rotation);
            assert!(
                dt <= 1e-6 && dr <= 1e-9,
                "{robot} {}: {dt} mm, {dr} rad",
                t.name
            );
        }
    }
}

/// Each layout's bad input names the file and the line; the command exits
/// 2 and writes nothing.
#[test]
fn bad_pose_files_name_their_line_and_write_nothing() {
    let (poses, stripes, _) = cell(4, 8, false, 3);
    let cases: [(&str, String, &str); 5] = [
        (
            "robot.txt",
            headerless_table(&poses).replacen(' ', " x", 1),
            "line 1",
        ),
        (
            "calib.ls",
            fanuc_ls(&poses, 0).replacen("Y = ", "Y = ****", 1),
            "line 25",
        ),
        (
            "calib.mod",
            rapid(&poses).replacen("]];", "];", 1),
            "line 3",
        ),
        (
            "calib.dat",
            kuka_dat(&poses).replacen("B ", "B zero", 1),
            "line 6",
        ),
        (
            "calib.script",
            urscript(&poses).replacen("p[", "p[1, ", 1),
            "line 3",
        ),
    ];
    for (name, text, line) in cases {
        let (dir, path) = folder(&stripes, name, &text);
        let out = dir.path().join("session.json");
        let output = Command::new(env!("CARGO_BIN_EXE_spherecal"))
            .args([
                "import",
                "--pose-convention",
                "fanuc",
                "--sphere-diameter",
                "38.1",
                "--poses",
            ])
            .arg(&path)
            .arg("--profiles")
            .arg(dir.path())
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        if name.ends_with(".mod") || name.ends_with(".dat") || name.ends_with(".script") {
            // A program's language fixes its convention: fanuc is refused.
            assert!(stderr.contains("--pose-convention"), "{name}: {stderr}");
        } else {
            assert!(
                stderr.contains(line) && stderr.contains(name),
                "{name}: {stderr}"
            );
        }
        assert_eq!(output.status.code(), Some(2), "{name}: {stderr}");
        assert!(!out.exists(), "{name}: nothing written");
        // Without the convention, the programs' own errors name the line.
        let output = Command::new(env!("CARGO_BIN_EXE_spherecal"))
            .args(["import", "--sphere-diameter", "38.1", "--poses"])
            .arg(&path)
            .arg("--profiles")
            .arg(dir.path())
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        if !name.ends_with(".txt") {
            assert!(
                stderr.contains(line) && stderr.contains(name),
                "{name}: {stderr}"
            );
        }
        assert_eq!(output.status.code(), Some(2), "{name}: {stderr}");
        assert!(!out.exists(), "{name}: nothing written");
    }
}

/// Byte-level mutations of each layout: an error or a pose file, never a
/// panic, in time linear in the text.
fn mutate(text: &str, cut: usize, at: usize, byte: u8, repeat: usize) -> String {
    let mut b = text.as_bytes().to_vec();
    let cut = cut % (b.len() + 1);
    b.truncate(cut.max(b.len() / 2));
    if !b.is_empty() {
        let i = at % b.len();
        b[i] = byte;
        let piece: Vec<u8> = b[i..(i + 7).min(b.len())].to_vec();
        for _ in 0..repeat {
            b.splice(i..i, piece.iter().copied());
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, rng_seed: proptest::test_runner::RngSeed::Fixed(19), ..ProptestConfig::default() })]
    #[test]
    fn mutated_pose_files_never_panic(cut in 0_usize..100_000, at in 0_usize..100_000, byte in any::<u8>(), repeat in 0_usize..50) {
        let (poses, _, _) = cell(4, 8, false, 3);
        let p = &poses[..4];
        for (name, text) in [
            ("t.txt", headerless_table(p)),
            ("c.ls", fanuc_ls(p, 0)),
            ("c.mod", rapid(p)),
            ("c.dat", kuka_dat(p)),
            ("c.script", urscript(p)),
            ("c.rob", format!("{{\"RobPoses\": [[1,2,3,4,5,6],[{}]]}}", "1,".repeat(5) + "1")),
        ] {
            let m = mutate(&text, cut, at, byte, repeat);
            let started = std::time::Instant::now();
            let _ = program::parse_pose_text(m, Path::new(name), &ReadSpec { convention: Some(FlangeConvention::FanucWpr), ..ReadSpec::default() });
            prop_assert!(started.elapsed().as_secs_f64() < 2.0, "{name} took {:?}", started.elapsed());
        }
    }
}

/// A newcomer's command lines: `--axes -y,x,z` and negative numbers
/// (`--angle -40`) reach the engine instead of clap's "unexpected
/// argument"; `-q` quiets `import` and `export-model`.
#[test]
fn negative_values_and_quiet_flags_are_taken() {
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_spherecal"))
            .args(args)
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, _, err) = run(&[
        "plan",
        "--sphere",
        "1050,0,475",
        "--angle",
        "-40",
        "--csv",
        std::env::temp_dir()
            .join(format!("spherecal-angle-{}.csv", std::process::id()))
            .to_str()
            .unwrap(),
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("cut angle") && !err.contains("unexpected argument"),
        "{err}"
    );
    let (poses, stripes, _) = cell(4, 8, false, 3);
    let (dir, path) = folder(&stripes, "robot.txt", &headerless_table(&poses));
    let out = dir.path().join("s.json");
    let (code, stdout, err) = run(&[
        "import",
        "--poses",
        path.to_str().unwrap(),
        "--pose-convention",
        "fanuc",
        "--profiles",
        dir.path().to_str().unwrap(),
        "--axes",
        "-y,x,z",
        "--sphere-diameter",
        "38.1",
        "--side",
        "+1",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]);
    // The profiles are y,z in FORMAT's plane: -y,x,z puts them off it.
    assert_eq!(code, Some(2), "{stdout}{err}");
    assert!(err.contains("off the laser plane"), "{err}");
    let (code, stdout, err) = run(&[
        "import",
        "--poses",
        path.to_str().unwrap(),
        "--pose-convention",
        "fanuc",
        "--profiles",
        dir.path().to_str().unwrap(),
        "--sphere-diameter",
        "38.1",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{stdout}{err}");
    assert!(stdout.is_empty(), "quiet: {stdout}");
    let result = dir.path().join("r.json");
    let (code, _, err) = run(&[
        "calibrate",
        out.to_str().unwrap(),
        "--out",
        result.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let (code, stdout, err) = run(&[
        "export-model",
        result.to_str().unwrap(),
        "--format",
        "json",
        "-q",
        "--out",
        dir.path().join("m.json").to_str().unwrap(),
    ]);
    // A pose-only result has no model to export: the error still shows.
    assert_eq!(code, Some(2), "{err}");
    assert!(
        stdout.is_empty() && err.contains("pose-only"),
        "{stdout}{err}"
    );
}

/// A pose file's import tells its progress: every profile, then the side
/// decided by calibrating both (the file gives none); a cancel there
/// stops it with nothing built.
#[test]
fn a_pose_import_tells_its_stages_and_can_be_cancelled_at_the_side() {
    use spherecal::engine::calibrate::solve::Control;
    use spherecal::engine::files::import::{ImportError, ImportStage};
    let (poses, stripes, _) = cell(4, 8, false, 5);
    let n = poses.len();
    let (dir, path) = folder(&stripes, "poses.txt", &headerless_table(&poses));
    let mut s = spec(
        &path,
        Observations::Profiles(ProfileSource::Folder(dir.path().to_path_buf())),
    );
    s.convention = Some(FlangeConvention::FanucWpr);
    let mut stages = Vec::new();
    assemble::import_poses_with(&s, &mut |stage| {
        stages.push(stage);
        Control::Continue
    })
    .unwrap();
    let mut expected: Vec<ImportStage> = (1..=n)
        .map(|done| ImportStage::Profiles { done, total: n })
        .collect();
    expected.push(ImportStage::Side);
    assert_eq!(stages, expected);
    let e = assemble::import_poses_with(&s, &mut |stage| {
        if stage == ImportStage::Side {
            Control::Cancel
        } else {
            Control::Continue
        }
    })
    .unwrap_err();
    assert!(matches!(e, ImportError::Cancelled), "{e}");
}

/// The values of every target of a pose file, and their ids.
fn table_values(file: &program::PoseFile) -> (Vec<Vec<f64>>, Vec<Option<String>>) {
    file.ordered()
        .map(|t| match &t.value {
            program::TargetValue::Pose { values, .. } => (values.clone(), t.id.clone()),
            program::TargetValue::Joints { .. } => panic!("joints in a pose table"),
        })
        .unzip()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(31), failure_persistence: None, ..ProptestConfig::default() })]
    /// Issue 31, high: a headerless pose table with one extra numeric
    /// column (six pose values and a trailing `100`) had its first number
    /// taken as the id and every value shifted one column. In every
    /// convention, an extra column last is refused naming both readings
    /// and `--pose-columns`; ids first are read as ids only when nothing
    /// else fits, else refused the same way; `--pose-columns` reads either
    /// exactly. No value is ever shifted.
    #[test]
    fn a_headerless_pose_table_with_one_extra_column_is_never_shifted(
        convention in 0_usize..5,
        rows in proptest::collection::vec((-2000.0_f64..2000.0, -2000.0_f64..2000.0, -2000.0_f64..2000.0, -179.0_f64..179.0, -89.0_f64..89.0, -179.0_f64..179.0), 1..6),
        extra in -1e4_f64..1e4,
        start in 0_u32..100,
        step in 1_u32..10,
    ) {
        let convention = FlangeConvention::ALL[convention];
        let poses: Vec<Vec<f64>> = rows
            .iter()
            .map(|&(x, y, z, a, b, c)| {
                let pose = Isometry3::new(
                    nalgebra::Vector3::new(x, y, z),
                    nalgebra::UnitQuaternion::from_euler_angles(a.to_radians(), b.to_radians(), c.to_radians()).scaled_axis(),
                );
                convention.values_from_pose(&pose)
            })
            .collect();
        let names = convention.default_columns();
        let write = |row: &dyn Fn(usize, &[f64]) -> Vec<f64>| {
            poses
                .iter()
                .enumerate()
                .map(|(k, v)| row(k, v).iter().map(ToString::to_string).collect::<Vec<_>>().join(" ") + "\n")
                .collect::<String>()
        };
        let read = |text: &str, columns: Option<Vec<String>>| {
            program::parse_pose_text(
                text.to_string(),
                Path::new("poses.txt"),
                &ReadSpec { convention: Some(convention), columns, ..ReadSpec::default() },
            )
        };
        let with = |extra_name: &str, first: bool| {
            let mut c = names.clone();
            if first { c.insert(0, extra_name.to_string()); } else { c.push(extra_name.to_string()); }
            Some(c)
        };
        // An extra column last: refused, naming the file, both readings and the option.
        let last = write(&|_, v| [v, &[extra][..]].concat());
        let e = read(&last, None).expect_err("an extra column last must not be read as an id").to_string();
        prop_assert!(e.contains("poses.txt") && e.contains(&format!("`id,{}`", names.join(","))) && e.contains(&format!("`{},-`", names.join(","))) && e.contains("--pose-columns"), "{e}");
        let (values, ids) = table_values(&read(&last, with("-", false)).unwrap());
        prop_assert_eq!(&values, &poses);
        prop_assert!(ids.iter().all(Option::is_none));
        // Ids counting up first: read as ids with the values unshifted, or refused.
        let id = |k: usize| f64::from(start) + f64::from(step) * k as f64;
        let first = write(&|k, v| [&[id(k)][..], v].concat());
        match read(&first, None) {
            Ok(file) => {
                let (values, ids) = table_values(&file);
                prop_assert_eq!(&values, &poses);
                prop_assert_eq!(ids[0].clone(), Some(id(0).to_string()));
            }
            Err(e) => prop_assert!(e.to_string().contains("--pose-columns"), "{e}"),
        }
        let (values, ids) = table_values(&read(&first, with("id", true)).unwrap());
        prop_assert_eq!(&values, &poses);
        prop_assert_eq!(ids.last().cloned().flatten(), Some(id(poses.len() - 1).to_string()));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, rng_seed: proptest::test_runner::RngSeed::Fixed(31), failure_persistence: None, ..ProptestConfig::default() })]
    /// Issue 31, medium: pose values beyond the 100 m limit (FANUC
    /// `X = 1e308`, KUKA `X 1E308`, a table's `1e10`, URScript positions in
    /// mm) gave "no initial hand-eye … numbers not finite" with no line. In
    /// every layout the pose is refused naming the file, the line and the
    /// limit.
    #[test]
    fn a_pose_beyond_100_m_is_refused_naming_its_line(layout in 0_usize..5, k in 0_usize..4, exponent in 5.1_f64..308.0, axis in 0_usize..3) {
        let (mut poses, _, _) = cell(4, 8, false, 3);
        poses.truncate(4);
        let huge = 10_f64.powf(exponent);
        // URScript in mm: metres read a thousand times too large.
        let scale = if layout == 3 { 1000.0 } else { 1.0 };
        poses[k].translation.vector[axis] = huge.min(1e300) / scale;
        let (text, name, convention) = match layout {
            0 => (fanuc_ls(&poses, 0), "c.ls", None),
            1 => (kuka_dat(&poses), "c.dat", None),
            2 => (headerless_table(&poses), "t.txt", Some(FlangeConvention::FanucWpr)),
            3 => (urscript(&poses), "c.script", None),
            _ => (rapid(&poses), "c.mod", None),
        };
        let file = program::parse_pose_text(text, Path::new(name), &ReadSpec { convention, ..ReadSpec::default() }).unwrap();
        let line = file.ordered().nth(k).unwrap().line;
        let e = import::poses::records_of(&file).unwrap_err().to_string();
        prop_assert!(e.contains(&format!("line {line}")) && e.contains(name) && e.contains("at most 100000 mm"), "{e}");
    }
}

/// Issue 31, medium: `import` wrote sessions whose initial scatter was
/// 25 mm to 25 m, exit 0 and no warning (UR rotation vectors in degrees,
/// among others). The import applies calibrate's verdict and warns, with
/// the likely causes (calibrate then refuses the session). A pose-only import applies
/// calibrate's verdict: beyond 10 mm it is refused with the likely causes.
#[test]
fn an_import_whose_centres_scatter_beyond_any_sensor_is_warned() {
    let (poses, stripes, truth) = cell(4, 8, false, 7);
    let he = rigid_from_rows(&truth.hand_eye);
    let station = *truth.stations.iter().find(|(k, _)| *k == "P0").unwrap().1;
    let mut centres = String::from("x;y;z\n");
    for p in &poses {
        let c = (p * he).inverse() * Point3::from(nalgebra::Vector3::from(station));
        writeln!(centres, "{:.9};{:.9};{:.9}", c.x, c.y, c.z).unwrap();
    }
    // UR rotation vectors written in degrees, not radians.
    let mut degrees = String::new();
    for p in &poses {
        let mut v = FlangeConvention::UrRotationVector.values_from_pose(p);
        for a in &mut v[3..] {
            *a = a.to_degrees();
        }
        let cells: Vec<String> = v.iter().map(|x| format!("{x:.9}")).collect();
        writeln!(degrees, "{}", cells.join(" ")).unwrap();
    }
    let (dir, path) = folder(&stripes, "robot.txt", &degrees);
    let centres_path = dir.path().join("centres.txt");
    std::fs::write(&centres_path, centres).unwrap();
    let mut s = spec(&path, Observations::Centres(centres_path));
    s.convention = Some(FlangeConvention::UrRotationVector);
    let notes = assemble::import_poses(&s).unwrap().notes.join("\n");
    assert!(
        notes.contains(
            "warning: with the initial hand-eye that fits them best the sphere centres scatter by"
        ) && notes.contains("`calibrate` will refuse this session; likely causes")
            && notes.contains("robot.txt"),
        "{notes}"
    );
    // The import's one entry (the command line's and the workbench's)
    // refuses the pose-only session: its start is its verdict.
    let request = assemble::ImportRequest {
        log: assemble::PoseLog::Poses(s),
        range: None,
        hand_eye: None,
    };
    let e = assemble::import_session(&request, &mut import::progress::quiet)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("robot.txt")
            && e.contains("nothing is written")
            && e.contains("--pose-convention"),
        "{e}"
    );
}

/// Issue 31, medium: a profile folder with `p1..p15.yml` and
/// `old_p1..15.yml` paired the poses with `old_p#` silently. Two sets of
/// profiles that could both be the ones are refused, naming both.
#[test]
fn two_sets_of_profiles_named_alike_are_refused_naming_both() {
    let (poses, stripes, _) = cell(4, 8, false, 3);
    let (dir, path) = folder(&stripes, "robot.txt", &headerless_table(&poses));
    for k in 1..=poses.len() {
        std::fs::copy(
            dir.path().join(format!("p{k}.csv")),
            dir.path().join(format!("old_p{k}.csv")),
        )
        .unwrap();
    }
    let mut s = spec(
        &path,
        Observations::Profiles(ProfileSource::Folder(dir.path().to_path_buf())),
    );
    s.convention = Some(FlangeConvention::FanucWpr);
    let e = assemble::import_poses(&s).unwrap_err().to_string();
    assert!(
        e.contains("2 sets of 12 files named alike")
            && e.contains("old_p#.csv (old_p1.csv")
            && e.contains(" and p#.csv (p1.csv"),
        "{e}"
    );
}
