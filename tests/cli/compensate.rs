//! `spherecal compensate` against simulated truth: targets near the
//! validate poses of seeded sessions, written as the table the hidden
//! check uses, compensated on the command line, driven by a controller
//! that knows only the nominal model (with the calibrated hand-eye as its
//! tool data), and scored on the TRUE robot after the best rigid
//! alignment (sphere data do not see the base frame).

// Test helpers may panic: a panic is a test failure with its message.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::support::bin::run;
use nalgebra::{Isometry3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use spherecal::engine::base::geometry::kabsch;
use spherecal::engine::base::robot::Robot;
use spherecal::engine::base::robot::controller::FlangeConvention;
use spherecal::engine::base::session::Use;
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::tools::simulate::{self, Truth};

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A simulated session, its truth and its calibration, through the CLI.
struct Cell {
    dir: PathBuf,
    result: ResultFile,
    result_path: PathBuf,
    truth: Truth,
}

fn cell(dir: &Path, seed: u64) -> Cell {
    let session = dir.join(format!("s{seed}.json"));
    let truth_path = dir.join(format!("s{seed}.truth.json"));
    let result_path = dir.join(format!("s{seed}.result.json"));
    let seed_text = seed.to_string();
    let (status, _, err) = run(&[
        "simulate",
        "--out",
        path(&session),
        "--truth",
        path(&truth_path),
        "--seed",
        &seed_text,
    ]);
    assert_eq!(status, 0, "{err}");
    let (status, _, err) = run(&[
        "calibrate",
        path(&session),
        "--out",
        path(&result_path),
        "--no-cross-validation",
        "-q",
    ]);
    assert_eq!(status, 0, "{err}");
    Cell {
        dir: dir.to_path_buf(),
        result: format::load_result(&result_path).unwrap(),
        result_path,
        truth: simulate::load_truth(&truth_path).unwrap(),
    }
}

/// A target: its id, the joints it was made from (the controller's start
/// for the branch) and the sensor pose wanted (base frame).
struct Target {
    id: String,
    joints: [f64; 6],
    pose: Isometry3<f64>,
}

/// Targets near the validate poses: each validate pose's true joints
/// moved by up to `spread` degrees per joint, the pose the TRUE robot
/// and hand-eye reach there.
fn targets_near_validate(cell: &Cell, spread: f64, seed: u64) -> Vec<Target> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let robot = cell.truth.true_robot();
    let hand_eye = cell.truth.true_hand_eye();
    let limits = spherecal::engine::base::robot::irb2400().limits;
    cell.truth
        .measurements
        .iter()
        .filter(|(_, m)| m.usage == Use::Validate)
        .map(|(id, m)| {
            let mut q: [f64; 6] = m.joints_actual.clone().try_into().unwrap();
            for (v, l) in q.iter_mut().zip(&limits) {
                *v = (*v + rng.random_range(-spread..=spread)).clamp(l.min + 1.0, l.max - 1.0);
            }
            Target {
                id: format!("T{id}"),
                joints: q,
                pose: robot.base_from_flange(&q) * hand_eye,
            }
        })
        .collect()
}

/// The hidden check's table: `id,x,y,z,q1,q2,q3,q4` (mm, w first).
fn table(targets: &[Target]) -> String {
    let mut s = String::from("id,x,y,z,q1,q2,q3,q4\n");
    for t in targets {
        let v = FlangeConvention::AbbQuaternion.values_from_pose(&t.pose);
        let cells: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
        let _ = writeln!(s, "{},{}", t.id, cells.join(","));
    }
    s
}

/// Reads a table of the same layout back: (id, pose).
fn read_table(text: &str) -> Vec<(String, Isometry3<f64>)> {
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("id,x,y,z,q1,q2,q3,q4"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let v: Vec<f64> = f[1..].iter().map(|x| x.parse().unwrap()).collect();
            let pose = FlangeConvention::AbbQuaternion
                .pose_from_values(&v)
                .unwrap();
            (f[0].to_string(), pose)
        })
        .collect()
}

/// Where a controller running `nominal` with `tool` as its tool data
/// puts the TRUE sensor when commanded `pose`: nominal IK from `start`
/// (the branch), then the true robot and hand-eye at those joints.
fn reached(
    cell: &Cell,
    nominal: &Robot,
    tool: &Isometry3<f64>,
    pose: &Isometry3<f64>,
    start: &[f64; 6],
) -> Isometry3<f64> {
    let q = nominal
        .inverse_kinematics(&(pose * tool.inverse()), start, None)
        .expect("the nominal controller reaches the commanded pose");
    cell.truth.true_robot().base_from_flange(&q) * cell.truth.true_hand_eye()
}

/// RMS position error (mm) of `reached` against `wanted` after the best
/// rigid alignment of the one onto the other.
fn aligned_rms(reached: &[Isometry3<f64>], wanted: &[Isometry3<f64>]) -> f64 {
    let from: Vec<Vector3<f64>> = reached.iter().map(|p| p.translation.vector).collect();
    let to: Vec<Vector3<f64>> = wanted.iter().map(|p| p.translation.vector).collect();
    let fit = kabsch(&from, &to).unwrap();
    let sq: f64 = from
        .iter()
        .zip(&to)
        .map(|(a, b)| {
            (fit * nalgebra::Point3::from(*a) - nalgebra::Point3::from(*b)).norm_squared()
        })
        .sum();
    (sq / from.len() as f64).sqrt()
}

/// Before and after (rms mm, aligned) of the table path on one cell.
fn table_check(cell: &Cell, targets: &[Target]) -> (f64, f64) {
    let t_csv = cell.dir.join("T.csv");
    let c_csv = cell.dir.join("C.csv");
    std::fs::write(&t_csv, table(targets)).unwrap();
    let (status, out, err) = run(&[
        "compensate",
        "--result",
        path(&cell.result_path),
        "--targets",
        path(&t_csv),
        "--pose-convention",
        "abb",
        "--tcp",
        "sensor",
        "--out",
        path(&c_csv),
    ]);
    assert_eq!(status, 0, "{out}{err}");
    let back = read_table(&std::fs::read_to_string(&c_csv).unwrap());
    assert_eq!(back.len(), targets.len());
    let nominal = cell.result.nominal().unwrap();
    let tool = cell.result.hand_eye;
    let wanted: Vec<Isometry3<f64>> = targets.iter().map(|t| t.pose).collect();
    let before: Vec<Isometry3<f64>> = targets
        .iter()
        .map(|t| reached(cell, &nominal, &tool, &t.pose, &t.joints))
        .collect();
    let after: Vec<Isometry3<f64>> = targets
        .iter()
        .zip(&back)
        .map(|(t, (id, pose))| {
            assert_eq!(*id, t.id, "ids and row order kept");
            reached(cell, &nominal, &tool, pose, &t.joints)
        })
        .collect();
    (aligned_rms(&before, &wanted), aligned_rms(&after, &wanted))
}

#[test]
fn a_nominal_controller_reaches_compensated_table_targets() {
    let dir = tempfile::tempdir().unwrap();
    for seed in [11, 23] {
        let cell = cell(dir.path(), seed);
        let targets = targets_near_validate(&cell, 3.0, seed);
        let (before, after) = table_check(&cell, &targets);
        println!(
            "seed {seed}: before {before:.4} mm, after {after:.4} mm ({:.2} %)",
            100.0 * after / before
        );
        assert!(before > 1.0, "{before}");
        assert!(after <= 0.03 * before, "seed {seed}: {after} of {before}");
    }
}

/// The same model, TRUE: a result whose calibrated model and hand-eye are
/// the truth compensates exactly (no alignment needed, its base frame is
/// the true one), through the engine as the workbench calls it.
#[test]
fn with_the_true_model_compensation_is_exact() {
    use spherecal::engine::calibrate::solve::Control;
    use spherecal::engine::files::program::{ReadSpec, parse_pose_text};
    use spherecal::engine::uses::compensate::{self, Model, Options, Tcp};
    let dir = tempfile::tempdir().unwrap();
    let c = cell(dir.path(), 5);
    let mut result = c.result.clone();
    let true_robot = c.truth.true_robot();
    result.joint_errors = true_robot.joint_errors(&c.truth.nominal_robot());
    result.robot = Some(true_robot.clone());
    result.hand_eye = c.truth.true_hand_eye();
    let model = Model::new(&result, None, Tcp::Sensor).unwrap();
    let targets = targets_near_validate(&c, 3.0, 5);
    let spec = ReadSpec {
        convention: Some(FlangeConvention::AbbQuaternion),
        ..ReadSpec::default()
    };
    let file = parse_pose_text(table(&targets), Path::new("T.csv"), &spec).unwrap();
    let mut seen = 0;
    let done = compensate::compensate(&model, &file, &Options::default(), &mut |p| {
        seen = p.done;
        Control::Continue
    })
    .unwrap();
    assert_eq!(seen, targets.len());
    let nominal = c.truth.nominal_robot();
    for (t, r) in targets.iter().zip(&done.targets) {
        let q = nominal
            .inverse_kinematics(&(r.commanded * result.hand_eye.inverse()), &t.joints, None)
            .unwrap();
        let reached = true_robot.base_from_flange(&q) * result.hand_eye;
        let miss = (reached.translation.vector - t.pose.translation.vector).norm();
        assert!(miss < 1e-6, "{}: {miss} mm", t.id);
        assert!(reached.rotation.angle_to(&t.pose.rotation) < 1e-9);
        // The controller drives exactly the calibrated solution.
        let same =
            |a: &f64, b: &f64| spherecal::engine::base::geometry::wrap_deg(a - b).abs() < 1e-6;
        assert!(
            q.iter().zip(&r.joints).all(|(a, b)| same(a, b)),
            "{q:?} {:?}",
            r.joints
        );
    }
    // A cancelled run returns no file.
    let cancelled =
        compensate::compensate(&model, &file, &Options::default(), &mut |_| Control::Cancel);
    assert_eq!(cancelled, Err(compensate::CompensateError::Cancelled));
}

/// A program in one robot language, built from the targets with the
/// language's usual precision, and the same numbers as a table in that
/// language's convention.
struct Program {
    name: &'static str,
    file: &'static str,
    convention: FlangeConvention,
    text: String,
    table: String,
}

/// `v` with `d` decimals.
fn fixed(v: f64, d: usize) -> String {
    format!("{v:.d$}")
}

fn programs(
    targets: &[Target],
    model: &spherecal::engine::uses::compensate::Model,
) -> Vec<Program> {
    use spherecal::engine::uses::compensate::config::{Vendor, posture};
    let branch = |t: &Target| {
        let flange = t.pose * model.tool.inverse();
        let (q, _) = model.arms.nominal_branch(&flange, None).unwrap();
        q
    };
    let values = |c: FlangeConvention, t: &Target, d: &[usize]| -> Vec<String> {
        c.values_from_pose(&t.pose)
            .iter()
            .zip(d)
            .map(|(v, d)| fixed(*v, *d))
            .collect()
    };
    let table_of = |c: FlangeConvention, rows: &[Vec<String>]| {
        let mut s = format!("id,{}\n", c.default_columns().join(","));
        for (t, r) in targets.iter().zip(rows) {
            let _ = writeln!(s, "{},{}", t.id, r.join(","));
        }
        s
    };
    let mut out = Vec::new();
    // ABB RAPID.
    let c = FlangeConvention::AbbQuaternion;
    let rows: Vec<Vec<String>> = targets
        .iter()
        .map(|t| values(c, t, &[3, 3, 3, 6, 6, 6, 6]))
        .collect();
    let mut text = String::from(
        "MODULE Compensated\n  ! targets of a sensor path\n  PERS tooldata tSensor := [TRUE,[[0,0,100],[1,0,0,0]],[1,[0,0,1],[1,0,0,0],0,0,0]];\n",
    );
    for (t, r) in targets.iter().zip(&rows) {
        let q = branch(t);
        let cf = Vendor::Abb.config(&q, posture(&model.arms.nominal, &q));
        let _ = writeln!(
            text,
            "  CONST robtarget p{} := [[{},{},{}],[{},{},{},{}],{cf},[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];",
            t.id, r[0], r[1], r[2], r[3], r[4], r[5], r[6]
        );
    }
    text.push_str("  PROC main()\n");
    for t in targets {
        let _ = writeln!(text, "    MoveL p{}, v100, fine, tSensor;", t.id);
    }
    text.push_str("  ENDPROC\nENDMODULE\n");
    out.push(Program {
        name: "RAPID",
        file: "path.mod",
        convention: c,
        table: table_of(c, &rows),
        text,
    });
    // KUKA .dat.
    let c = FlangeConvention::KukaAbc;
    let rows: Vec<Vec<String>> = targets
        .iter()
        .map(|t| values(c, t, &[3, 3, 3, 4, 4, 4]))
        .collect();
    let mut text = String::from("&ACCESS RVP\nDEFDAT  PATH\n;FOLD EXTERNAL DECLARATIONS\n");
    for (t, r) in targets.iter().zip(&rows) {
        let q = branch(t);
        let spherecal::engine::uses::compensate::config::Config::Kuka { s: st, t: tt } =
            Vendor::Kuka.config(&q, posture(&model.arms.nominal, &q))
        else {
            unreachable!()
        };
        let _ = writeln!(
            text,
            "DECL E6POS X{}={{X {},Y {},Z {},A {},B {},C {},S {st},T {tt},E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}}\nDECL FDAT F{}={{TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE}}",
            t.id, r[0], r[1], r[2], r[3], r[4], r[5], t.id
        );
    }
    text.push_str("ENDDAT\n");
    out.push(Program {
        name: "KRL",
        file: "path.dat",
        convention: c,
        table: table_of(c, &rows),
        text,
    });
    // FANUC .ls.
    let c = FlangeConvention::FanucWpr;
    let rows: Vec<Vec<String>> = targets.iter().map(|t| values(c, t, &[3; 6])).collect();
    let mut text = String::from("/PROG  PATH\n/ATTR\nOWNER\t\t= MNEDITOR;\n/MN\n");
    for (k, _) in targets.iter().enumerate() {
        let _ = writeln!(text, "{:>4}:L P[{}] 100mm/sec FINE    ;", k + 1, k + 1);
    }
    text.push_str("/POS\n");
    for (k, (t, r)) in targets.iter().zip(&rows).enumerate() {
        let q = branch(t);
        let cfg = Vendor::Fanuc
            .config(&q, posture(&model.arms.nominal, &q))
            .to_string();
        let _ = write!(
            text,
            "P[{}]{{\n   GP1:\n\tUF : 0, UT : 1,\t\tCONFIG : {cfg},\n\tX = {:>10} mm,\tY = {:>10} mm,\tZ = {:>10} mm,\n\tW = {:>10} deg,\tP = {:>10} deg,\tR = {:>10} deg\n}};\n",
            k + 1,
            r[0],
            r[1],
            r[2],
            r[3],
            r[4],
            r[5]
        );
    }
    text.push_str("/END\n");
    out.push(Program {
        name: "FANUC",
        file: "path.ls",
        convention: c,
        table: table_of(c, &rows),
        text,
    });
    // URScript.
    let c = FlangeConvention::UrRotationVector;
    let rows: Vec<Vec<String>> = targets.iter().map(|t| values(c, t, &[6; 6])).collect();
    let mut text = String::from("def path():\n  set_tcp(p[0, 0, 0.1, 0, 0, 0])  # the sensor\n");
    for r in &rows {
        let _ = writeln!(
            text,
            "  movel(p[{}, {}, {}, {}, {}, {}], a=1.2, v=0.25)",
            r[0], r[1], r[2], r[3], r[4], r[5]
        );
    }
    text.push_str("end\n");
    out.push(Program {
        name: "URScript",
        file: "path.script",
        convention: c,
        table: table_of(c, &rows),
        text,
    });
    out
}

/// `text` with the numbers of every target and every configuration read
/// from it replaced by `#`: what must not change.
fn skeleton(text: &str, file_name: &str) -> String {
    let file = spherecal::engine::files::program::parse_pose_text(
        text.to_string(),
        Path::new(file_name),
        &spherecal::engine::files::program::ReadSpec::default(),
    )
    .unwrap();
    let mut ranges: Vec<std::ops::Range<usize>> = file
        .targets
        .iter()
        .flat_map(|t| {
            t.spans
                .iter()
                .cloned()
                .chain(t.config.iter().map(|(_, r)| r.clone()))
        })
        .collect();
    ranges.sort_by_key(|r| r.start);
    let mut out = String::new();
    let mut at = 0;
    for r in ranges {
        out.push_str(&text[at..r.start]);
        out.push('#');
        at = r.end;
    }
    out.push_str(&text[at..]);
    out
}

/// Poses of a file's targets in their order.
fn poses_of(
    text: &str,
    file_name: &str,
    convention: Option<FlangeConvention>,
) -> Vec<Isometry3<f64>> {
    use spherecal::engine::files::program::{ReadSpec, TargetValue, parse_pose_text};
    let spec = ReadSpec {
        convention,
        ..ReadSpec::default()
    };
    let file = parse_pose_text(text.to_string(), Path::new(file_name), &spec).unwrap();
    file.ordered()
        .map(|t| match &t.value {
            TargetValue::Pose { values, convention } => {
                convention.pose_from_values(values).unwrap()
            }
            TargetValue::Joints { .. } => panic!("a pose expected"),
        })
        .collect()
}

#[test]
fn programs_in_four_languages_keep_every_other_byte_and_match_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let c = cell(dir.path(), 7);
    let targets: Vec<Target> = targets_near_validate(&c, 3.0, 7)
        .into_iter()
        .take(12)
        .collect();
    let model = spherecal::engine::uses::compensate::Model::new(
        &c.result,
        None,
        spherecal::engine::uses::compensate::Tcp::Sensor,
    )
    .unwrap();
    for p in programs(&targets, &model) {
        let input = dir.path().join(p.file);
        let output = dir.path().join(format!("out-{}", p.file));
        std::fs::write(&input, &p.text).unwrap();
        let (status, out, err) = run(&[
            "compensate",
            "--result",
            path(&c.result_path),
            "--targets",
            path(&input),
            "--out",
            path(&output),
        ]);
        assert_eq!(status, 0, "{}: {out}{err}", p.name);
        let written = std::fs::read_to_string(&output).unwrap();
        assert_ne!(written, p.text, "{}: the positions change", p.name);
        assert_eq!(
            skeleton(&written, p.file),
            skeleton(&p.text, p.file),
            "{}: every other byte kept",
            p.name
        );
        // The table path with the same numbers.
        let t_in = dir.path().join(format!("{}.csv", p.name));
        let t_out = dir.path().join(format!("{}-out.csv", p.name));
        std::fs::write(&t_in, &p.table).unwrap();
        let (status, out, err) = run(&[
            "compensate",
            "--result",
            path(&c.result_path),
            "--targets",
            path(&t_in),
            "--pose-convention",
            p.convention.key(),
            "--out",
            path(&t_out),
        ]);
        assert_eq!(status, 0, "{}: {out}{err}", p.name);
        let from_table = poses_of(
            &std::fs::read_to_string(&t_out).unwrap(),
            "t.csv",
            Some(p.convention),
        );
        let from_program = poses_of(&written, p.file, None);
        assert_eq!(from_table.len(), targets.len());
        for (k, (a, b)) in from_program.iter().zip(&from_table).enumerate() {
            let dp = (a.translation.vector - b.translation.vector).norm();
            let dr = a.rotation.angle_to(&b.rotation);
            // Programs write 3 decimals of mm, FANUC 3 of its degrees.
            assert!(
                dp < 2e-3 && dr < 3e-5,
                "{} target {k}: {dp} mm, {dr} rad",
                p.name
            );
        }
        if p.name == "RAPID" {
            assert!(out.contains("PERS tooldata tSpherecal"), "{out}");
        }
    }
    // The first table as a European spreadsheet writes it (semicolons,
    // decimal commas): the same poses, written back with decimal commas.
    let p = &programs(&targets, &model)[0];
    let e_in = dir.path().join("eu.csv");
    let e_out = dir.path().join("eu-out.csv");
    std::fs::write(&e_in, p.table.replace(',', ";").replace('.', ",")).unwrap();
    let (status, out, err) = run(&[
        "compensate",
        "--result",
        path(&c.result_path),
        "--targets",
        path(&e_in),
        "--pose-convention",
        p.convention.key(),
        "--out",
        path(&e_out),
    ]);
    assert_eq!(status, 0, "{out}{err}");
    let written = std::fs::read_to_string(&e_out).unwrap();
    assert!(!written.contains('.') && written.contains(';'), "{written}");
    let from_eu = poses_of(&written.replace(',', "."), "t.csv", Some(p.convention));
    let dotted = dir.path().join(format!("{}-out.csv", p.name));
    let from_table = poses_of(
        &std::fs::read_to_string(&dotted).unwrap(),
        "t.csv",
        Some(p.convention),
    );
    assert_eq!(from_eu.len(), targets.len());
    for (a, b) in from_eu.iter().zip(&from_table) {
        assert!((a.translation.vector - b.translation.vector).norm() < 1e-9);
        assert!(a.rotation.angle_to(&b.rotation) < 1e-12);
    }
}

#[test]
fn far_targets_are_flagged_and_unreachable_ones_are_errors_with_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let c = cell(dir.path(), 7);
    let mut targets: Vec<Target> = targets_near_validate(&c, 3.0, 7)
        .into_iter()
        .take(3)
        .collect();
    // The arm turned to its side, the wrist rolled: far from every pose
    // the calibration saw.
    let q_far = [95.0, -20.0, 40.0, 120.0, -70.0, 60.0];
    targets.push(Target {
        id: "Tfar".into(),
        joints: q_far,
        pose: c.truth.true_robot().base_from_flange(&q_far) * c.truth.true_hand_eye(),
    });
    let t_csv = dir.path().join("T.csv");
    let c_csv = dir.path().join("C.csv");
    std::fs::write(&t_csv, table(&targets)).unwrap();
    let args = |extra: &[&str]| {
        let mut a = vec![
            "compensate",
            "--result",
            path(&c.result_path),
            "--targets",
            path(&t_csv),
            "--pose-convention",
            "abb",
            "--out",
            path(&c_csv),
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    // Flagged: compensated, written and listed, with why.
    let (status, out, err) = args(&[]);
    assert_eq!(status, 0, "{out}{err}");
    let flagged_line = out
        .lines()
        .find(|l| l.contains("Tfar (line 5):"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(flagged_line.contains("outside the box"), "{flagged_line}");
    assert!(
        out.contains("1 flagged outside what the calibration saw"),
        "{out}"
    );
    let back = read_table(&std::fs::read_to_string(&c_csv).unwrap());
    let moved = (back[3].1.translation.vector - targets[3].pose.translation.vector).norm();
    assert!(moved > 1.0, "the far target is compensated too: {moved}");
    // --strict refuses it and leaves the old output as it was.
    std::fs::write(&c_csv, "old\n").unwrap();
    let (status, _, err) = args(&["--strict"]);
    assert_eq!(status, 2, "{err}");
    assert!(
        err.starts_with("error: ") && err.contains("Tfar") && err.contains("T.csv"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&c_csv).unwrap(), "old\n");
    // An unreachable target is an error naming it (and its line); nothing
    // is written.
    let mut text = table(&targets);
    text.push_str("Tgone,5000,0,500,1,0,0,0\n");
    std::fs::write(&t_csv, text).unwrap();
    std::fs::remove_file(&c_csv).unwrap();
    let (status, _, err) = args(&[]);
    assert_eq!(status, 2, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("target Tgone (line 6)")
            && err.contains("out of reach")
            && err.contains("T.csv"),
        "{err}"
    );
    assert!(!c_csv.exists());
    // Every target that cannot be compensated is named at once, in the
    // robot's order (the first 8, the rest counted); nothing is written.
    let mut text = table(&targets);
    for k in 0..10 {
        let _ = writeln!(text, "Tgone{k},{},0,500,1,0,0,0", 5000 + 100 * k);
    }
    std::fs::write(&t_csv, text).unwrap();
    let (status, _, err) = args(&[]);
    assert_eq!(status, 2, "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("10 targets cannot be compensated"), "{err}");
    for k in 0..8 {
        assert!(
            err.contains(&format!("target Tgone{k} (line {})", 6 + k)),
            "{err}"
        );
    }
    assert!(
        err.contains("and 2 more") && !err.contains("Tgone8"),
        "{err}"
    );
    assert!(!c_csv.exists());
}

#[test]
fn joint_targets_are_compensated_or_kept() {
    let dir = tempfile::tempdir().unwrap();
    let c = cell(dir.path(), 7);
    let q = [5.0, 25.0, 15.0, -20.0, 50.0, 10.0];
    let text = format!(
        "MODULE J\n  CONST jointtarget j1 := [[{}],[9E9,9E9,9E9,9E9,9E9,9E9]];\n  PROC main()\n    MoveAbsJ j1, v100, fine, tool0;\n  ENDPROC\nENDMODULE\n",
        q.map(|v| format!("{v:.3}")).join(",")
    );
    let input = dir.path().join("j.mod");
    let output = dir.path().join("j-out.mod");
    std::fs::write(&input, &text).unwrap();
    let (status, out, err) = run(&[
        "compensate",
        "--result",
        path(&c.result_path),
        "--targets",
        path(&input),
        "--out",
        path(&output),
    ]);
    assert_eq!(status, 0, "{out}{err}");
    let written = std::fs::read_to_string(&output).unwrap();
    let file = spherecal::engine::files::program::parse_pose_text(
        written,
        Path::new("j.mod"),
        &spherecal::engine::files::program::ReadSpec::default(),
    )
    .unwrap();
    let spherecal::engine::files::program::TargetValue::Joints { deg, .. } = &file.targets[0].value
    else {
        panic!("a joint target")
    };
    // The calibrated model at the joints written reaches the pose the
    // nominal model gives the joints taught (to the 4 decimals written).
    let calibrated = c.result.robot.clone().unwrap();
    let wanted = c.result.nominal().unwrap().base_from_flange(&q) * c.result.hand_eye;
    let got = calibrated.base_from_flange(deg) * c.result.hand_eye;
    let miss = (got.translation.vector - wanted.translation.vector).norm();
    assert!(miss < 5e-3, "{miss} mm");
    assert!(
        deg.iter().zip(&q).any(|(a, b)| (a - b).abs() > 0.05),
        "{deg:?}"
    );
    // Kept as taught.
    let (status, out, err) = run(&[
        "compensate",
        "--result",
        path(&c.result_path),
        "--targets",
        path(&input),
        "--out",
        path(&output),
        "--joint-targets",
        "keep",
    ]);
    assert_eq!(status, 0, "{out}{err}");
    assert_eq!(std::fs::read_to_string(&output).unwrap(), text);
    assert!(out.contains("kept"), "{out}");
}

#[test]
fn results_record_the_joints_of_their_poses() {
    let dir = tempfile::tempdir().unwrap();
    let c = cell(dir.path(), 7);
    let session = format::load_session(&dir.path().join("s7.json")).unwrap();
    let expected: Vec<(String, Vec<f64>)> = session
        .measurements
        .iter()
        .filter(|m| matches!(m.usage, Use::Identify | Use::Validate))
        .map(|m| (m.id.clone(), m.joints.clone()))
        .collect();
    assert_eq!(c.result.pose_joints, expected);
}

/// An older result, without `pose_joints`: `--session` gives the poses
/// and the same compensation; without it the branch is the one a cell
/// teaches, and the output says what is not checked.
#[test]
fn older_results_take_the_poses_from_the_session() {
    let dir = tempfile::tempdir().unwrap();
    let c = cell(dir.path(), 11);
    let targets = targets_near_validate(&c, 3.0, 11);
    let t_csv = dir.path().join("T.csv");
    std::fs::write(&t_csv, table(&targets)).unwrap();
    let mut value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&c.result_path).unwrap()).unwrap();
    assert!(
        value
            .as_object_mut()
            .unwrap()
            .remove("pose_joints")
            .is_some()
    );
    let old = dir.path().join("old.result.json");
    std::fs::write(&old, serde_json::to_string_pretty(&value).unwrap()).unwrap();
    let compensated = |result: &Path, session: Option<&Path>| {
        let out = dir.path().join("C.csv");
        let mut a = vec![
            "compensate",
            "--result",
            path(result),
            "--targets",
            path(&t_csv),
            "--pose-convention",
            "abb",
            "--out",
            path(&out),
        ];
        if let Some(s) = session {
            a.extend(["--session", path(s)]);
        }
        let (status, stdout, err) = run(&a);
        assert_eq!(status, 0, "{stdout}{err}");
        (std::fs::read_to_string(&out).unwrap(), stdout)
    };
    let (recorded, _) = compensated(&c.result_path, None);
    let (from_session, _) = compensated(&old, Some(&dir.path().join("s11.json")));
    assert_eq!(from_session, recorded);
    let (_, stdout) = compensated(&old, None);
    assert!(stdout.contains("records no joints"), "{stdout}");
    // A session that is not the result's is refused.
    let other = dir.path().join("other.json");
    let (status, _, err) = run(&[
        "simulate",
        "--out",
        path(&other),
        "--seed",
        "3",
        "--robot",
        "ur5e",
    ]);
    assert_eq!(status, 0, "{err}");
    let (status, _, err) = run(&[
        "compensate",
        "--result",
        path(&old),
        "--targets",
        path(&t_csv),
        "--pose-convention",
        "abb",
        "--out",
        path(&dir.path().join("D.csv")),
        "--session",
        path(&other),
    ]);
    assert_eq!(status, 2, "{err}");
    assert!(
        err.contains("not the session the result was calibrated from"),
        "{err}"
    );
}
