//! The Compensate view (issue 21, item 5): after a calibration of the
//! demo cell, a target table written here (targets near the calibrated
//! poses, one far from them) is compensated in the window: one row per
//! target, largest correction first, the far one flagged in words; the
//! file written is byte-identical to what `spherecal compensate` and the
//! engine give for the same inputs; a new calibration marks it stale and
//! writing is refused; an unreachable target is an error naming it and
//! nothing is written; a cancelled job shows nothing. egui_kittest, no
//! display.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command as Process;

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use nalgebra::Isometry3;
use spherecal::app::WorkbenchApp;
use spherecal::app::command::Tab;
use spherecal::app::command::{Command, CompensateCommand, ViewCommand};
use spherecal::app::compensate::form::TcpChoice;
use spherecal::engine::base::robot::controller::FlangeConvention;
use spherecal::engine::base::session::Use;
use spherecal::engine::calibrate::solve::Control;
use spherecal::engine::files::format::{ResultFile, save_result};
use spherecal::engine::files::program::{self, ReadSpec};
use spherecal::engine::uses::compensate::{self, Model, Options, Tcp};

use crate::support::ui as ui_support;
use ui_support::{demo_app, labels_with, settle};

fn command(h: &mut Harness<'_, WorkbenchApp>, c: Command) {
    let ctx = h.ctx.clone();
    h.state_mut().command(&ctx, c);
}

/// The demo calibrated in the window; its result file.
fn calibrated() -> (Harness<'static, WorkbenchApp>, ResultFile) {
    let mut h = demo_app();
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    let result = h
        .state()
        .state()
        .result
        .as_ref()
        .expect("a result")
        .file
        .clone();
    assert!(
        !result.pose_joints.is_empty(),
        "a run records the joints of its poses"
    );
    (h, result)
}

/// The joint-space far target of the engine's tests: the arm turned to
/// its side, the wrist rolled.
const Q_FAR: [f64; 6] = [95.0, -20.0, 40.0, 120.0, -70.0, 60.0];

/// Targets near the validate poses (their joints moved by 1-3° per
/// joint, the sensor pose the calibrated model and hand-eye give there)
/// and one far from every pose: `(id, pose)`.
fn targets(result: &ResultFile) -> Vec<(String, Isometry3<f64>)> {
    let robot = result.robot.as_ref().expect("a robot");
    let validate: Vec<[f64; 6]> = result
        .pose_joints
        .iter()
        .filter(|(id, _)| {
            result
                .centres
                .iter()
                .any(|c| c.measurement == **id && c.usage == Use::Validate)
        })
        .map(|(_, q)| <[f64; 6]>::try_from(q.as_slice()).unwrap())
        .take(4)
        .collect();
    assert_eq!(validate.len(), 4, "the demo has validate poses");
    let mut out: Vec<(String, Isometry3<f64>)> = validate
        .iter()
        .enumerate()
        .map(|(k, q)| {
            let mut q = *q;
            for (j, v) in q.iter_mut().enumerate() {
                *v += [1.0, -2.0, 3.0][(j + k) % 3];
            }
            (
                format!("N{k}"),
                robot.base_from_flange(&q) * result.hand_eye,
            )
        })
        .collect();
    out.insert(
        2,
        (
            "FAR".to_string(),
            robot.base_from_flange(&Q_FAR) * result.hand_eye,
        ),
    );
    out
}

/// The hidden check's layout: `id,x,y,z,q1,q2,q3,q4` (mm, w first).
fn table(targets: &[(String, Isometry3<f64>)]) -> String {
    let mut s = String::from("id,x,y,z,q1,q2,q3,q4\n");
    for (id, pose) in targets {
        let v = FlangeConvention::AbbQuaternion.values_from_pose(pose);
        let cells: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
        let _ = writeln!(s, "{id},{}", cells.join(","));
    }
    s
}

/// Sets the Compensate form and presses Compensate.
fn compensate_in_view(h: &mut Harness<'_, WorkbenchApp>, targets: &Path) {
    command(h, Command::View(ViewCommand::ShowTab(Tab::Compensate)));
    h.run();
    let form = &mut h.state_mut().forms_mut().compensate;
    form.targets = targets.display().to_string();
    form.convention = Some(FlangeConvention::AbbQuaternion);
    form.tcp = TcpChoice::Sensor;
    h.run();
    h.get_by_label("Compensate targets").click();
    settle(h);
}

/// What the engine gives for the same inputs, as `spherecal compensate`
/// calls it.
fn engine_text(result: &ResultFile, targets: &Path) -> String {
    let model = Model::new(result, None, Tcp::Sensor).unwrap();
    let spec = ReadSpec {
        convention: Some(FlangeConvention::AbbQuaternion),
        ..ReadSpec::default()
    };
    let file = program::read_pose_file(targets, &spec).unwrap();
    compensate::compensate(&model, &file, &Options::default(), &mut |_| {
        Control::Continue
    })
    .unwrap()
    .text
}

#[test]
fn targets_are_compensated_largest_first_flagged_written_and_refused_when_stale() {
    let (mut h, result) = calibrated();
    let dir = tempfile::tempdir().unwrap();
    let t_csv = dir.path().join("T.csv");
    std::fs::write(&t_csv, table(&targets(&result))).unwrap();
    compensate_in_view(&mut h, &t_csv);

    // One row per target, largest correction first; the far one flagged
    // with why, the others not.
    let view = match &h.state().state().compensate.outcome {
        Some(Ok(v)) => v.clone(),
        other => panic!("{other:?}"),
    };
    assert_eq!(view.rows.len(), 5);
    for pair in view.rows.windows(2) {
        assert!(pair[0].correction_mm >= pair[1].correction_mm, "{view:?}");
    }
    for r in &view.rows {
        assert!(r.correction_mm > 0.01, "every target moves: {r:?}");
        assert_eq!(r.flags.is_empty(), r.name != "FAR", "{r:?}");
    }
    let far = view.rows.iter().find(|r| r.name == "FAR").unwrap();
    assert_eq!(far.line, 4);
    assert!(
        far.flags
            .iter()
            .any(|f| f.describe().contains("from every identify pose")),
        "{far:?}"
    );
    assert_eq!(view.summary.flagged, 1);
    assert!(
        view.summary
            .line()
            .starts_with("5 targets compensated: largest correction")
            && view
                .summary
                .line()
                .contains("; 1 flagged outside what the calibration saw"),
        "{}",
        view.summary.line()
    );
    // On screen: the summary, the far row's reason in words, the tool
    // data in RAPID (an ABB table) with its Copy button.
    // The view's line and the status bar's.
    assert_eq!(labels_with(&h, &view.summary.line()).len(), 2);
    let reasons = labels_with(&h, "outside what the calibration saw: joints");
    assert_eq!(reasons.len(), 1, "{reasons:?}");
    assert!(!labels_with(&h, "PERS tooldata tSpherecal := [TRUE,[[").is_empty());
    assert!(h.query_by_label("Copy").is_some());
    // The table's order on screen is the rows' order.
    let names: Vec<String> = view.rows.iter().map(|r| r.name.clone()).collect();
    let y = |name: &str| h.get_by_label(name).rect().min.y;
    for pair in names.windows(2) {
        assert!(y(&pair[0]) < y(&pair[1]), "{names:?}");
    }

    // Written: byte-identical to the engine's text and to what
    // `spherecal compensate` writes from the same result and targets.
    let out = dir.path().join("C.csv");
    h.state_mut().forms_mut().compensate.out = out.display().to_string();
    h.run();
    h.get_by_label("Write").click();
    settle(&mut h);
    let written = std::fs::read_to_string(&out).unwrap();
    assert_eq!(written, engine_text(&result, &t_csv));
    let r_json = dir.path().join("R.json");
    save_result(&result, &r_json).unwrap();
    let cli_out = dir.path().join("C-cli.csv");
    let status = Process::new(env!("CARGO_BIN_EXE_spherecal"))
        .args(["compensate", "--result"])
        .arg(&r_json)
        .arg("--targets")
        .arg(&t_csv)
        .args(["--pose-convention", "abb", "--tcp", "sensor", "-q", "--out"])
        .arg(&cli_out)
        .status()
        .unwrap();
    assert!(status.success());
    assert_eq!(written, std::fs::read_to_string(&cli_out).unwrap());
    assert!(
        h.state()
            .state()
            .ledger
            .written
            .iter()
            .any(|w| w.path == out && w.what == "compensated program")
    );

    // A new calibration: the compensation is stale, said so, and writing
    // is refused with the reason; the file written stays as it was.
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Compensate)));
    h.run();
    assert!(!labels_with(&h, "STALE").is_empty());
    assert!(
        !labels_with(&h, "the calibration result changed (result run #1").is_empty(),
        "what changed is said"
    );
    assert!(h.get_by_label("Write").accesskit_node().is_disabled());
    std::fs::write(&out, "old\n").unwrap();
    command(&mut h, Command::Compensate(CompensateCommand::Write));
    settle(&mut h);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old\n");
    let notice = h.state().state().notice.clone().expect("a notice");
    assert!(
        notice.body.contains("the compensation is stale")
            && notice.body.contains("the calibration result changed"),
        "{notice:?}"
    );
    // Compensated again through the new result: current, and written
    // (over a file written of other inputs: once the operator agrees).
    h.get_by_label("Compensate targets").click();
    settle(&mut h);
    assert!(labels_with(&h, "STALE").is_empty());
    h.get_by_label("Write").click();
    settle(&mut h);
    h.get_by_label("Replace").click();
    settle(&mut h);
    assert_ne!(std::fs::read_to_string(&out).unwrap(), "old\n");

    // Another pose convention marks it stale too, saying which.
    h.state_mut().forms_mut().compensate.convention = Some(FlangeConvention::KukaAbc);
    h.run();
    assert!(!labels_with(&h, "pose convention abb → kuka").is_empty());
}

#[test]
fn an_unreachable_target_is_an_error_naming_it_and_nothing_is_written() {
    let (mut h, result) = calibrated();
    let dir = tempfile::tempdir().unwrap();
    let t_csv = dir.path().join("T.csv");
    let mut text = table(&targets(&result));
    text.push_str("GONE,5000,0,500,1,0,0,0\n");
    std::fs::write(&t_csv, text).unwrap();

    // Cancel wins: the job's outcome, arriving after the Cancel, is not
    // shown.
    let form = &mut h.state_mut().forms_mut().compensate;
    form.targets = t_csv.display().to_string();
    form.convention = Some(FlangeConvention::AbbQuaternion);
    command(&mut h, Command::Compensate(CompensateCommand::Run));
    command(&mut h, Command::Compensate(CompensateCommand::Cancel));
    for _ in 0..40 {
        std::thread::sleep(std::time::Duration::from_millis(10));
        h.step();
    }
    settle(&mut h);
    assert!(h.state().state().compensate.outcome.is_none());
    assert!(ui_support::status(&h).contains("compensation cancelled"));

    compensate_in_view(&mut h, &t_csv);
    let error = match &h.state().state().compensate.outcome {
        Some(Err(e)) => e.clone(),
        other => panic!("{other:?}"),
    };
    assert!(
        error.contains("target GONE (line 7)") && error.contains("out of reach"),
        "{error}"
    );
    assert!(!labels_with(&h, "target GONE (line 7)").is_empty());
    assert!(!labels_with(&h, "nothing can be written").is_empty());
    let out: PathBuf = dir.path().join("C.csv");
    h.state_mut().forms_mut().compensate.out = out.display().to_string();
    command(&mut h, Command::Compensate(CompensateCommand::Write));
    settle(&mut h);
    assert!(!out.exists());
    let notice = h.state().state().notice.clone().expect("a notice");
    assert!(notice.body.contains("target GONE"), "{notice:?}");

    // Several: all of them listed in the view, one a line, their count in
    // the status line.
    let mut text = table(&targets(&result));
    text.push_str("GONE,5000,0,500,1,0,0,0\nGONE2,5200,0,500,1,0,0,0\nGONE3,0,5000,500,1,0,0,0\n");
    std::fs::write(&t_csv, text).unwrap();
    compensate_in_view(&mut h, &t_csv);
    for (name, line) in [("GONE", 7), ("GONE2", 8), ("GONE3", 9)] {
        // (The earlier refusal's notice still quotes the first.)
        let row: Vec<String> = labels_with(&h, &format!("target {name} (line {line}): "))
            .into_iter()
            .filter(|l| l.starts_with("target "))
            .collect();
        assert_eq!(row.len(), 1, "{name}: {row:?}");
        assert!(row[0].contains("out of reach"), "{row:?}");
    }
    assert!(
        ui_support::status(&h).contains("3 targets cannot be compensated"),
        "{}",
        ui_support::status(&h)
    );
}

/// The flag limits are the command line's options in the view: a tighter
/// σ tolerance typed in marks the table stale (saying which limit), and
/// the next compensation flags every target by it; limits wide enough
/// unflag the far one.
#[test]
fn the_flag_limits_are_set_in_the_view_and_mark_the_table_stale() {
    let (mut h, result) = calibrated();
    let dir = tempfile::tempdir().unwrap();
    let t_csv = dir.path().join("T.csv");
    std::fs::write(&t_csv, table(&targets(&result))).unwrap();
    compensate_in_view(&mut h, &t_csv);
    let flagged = |h: &Harness<'_, WorkbenchApp>| match &h.state().state().compensate.outcome {
        Some(Ok(v)) => v.summary.flagged,
        other => panic!("{other:?}"),
    };
    assert_eq!(flagged(&h), 1);

    // σ tolerance 0.25 mm (the default) → 0.001 mm, typed into its field.
    h.get_by_label("σ tolerance").focus();
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.get_by_label("σ tolerance").type_text("0.001");
    h.key_press(egui::Key::Enter);
    h.run();
    assert_eq!(
        h.state().forms().compensate.options.sigma_tolerance_mm,
        0.001
    );
    assert!(
        !labels_with(&h, "σ tolerance 0.25 mm → 0.001 mm").is_empty(),
        "the stale banner names the limit: {:?}",
        labels_with(&h, "tolerance")
    );
    h.get_by_label("Compensate targets").click();
    settle(&mut h);
    assert_eq!(flagged(&h), 5);
    let view = match &h.state().state().compensate.outcome {
        Some(Ok(v)) => v.clone(),
        other => panic!("{other:?}"),
    };
    assert!(
        view.rows
            .iter()
            .all(|r| r.flags.iter().any(|f| f.describe().contains("0.001"))),
        "{:?}",
        view.rows
    );

    // Every limit widened past the far target (its σ is about 0.57 mm).
    {
        let options = &mut h.state_mut().forms_mut().compensate.options;
        options.sigma_tolerance_mm = 1.0;
        options.far_joints_deg = 720.0;
        options.region_margin_mm = 10_000.0;
    }
    h.run();
    h.get_by_label("Compensate targets").click();
    settle(&mut h);
    let view = match &h.state().state().compensate.outcome {
        Some(Ok(v)) => v.clone(),
        other => panic!("{other:?}"),
    };
    let flags: Vec<_> = view.rows.iter().map(|r| (&r.name, &r.flags)).collect();
    assert_eq!(view.summary.flagged, 0, "{flags:?}");
}

/// The operator's defect (issue 30): after the targets changed, Write
/// wrote the new compensation under the previous program's name,
/// replacing that file without a word. The output's name now follows the
/// targets; a file this window did not write of these inputs (the
/// previous program's, or one edited since) is replaced only once the
/// operator says so, and kept when they say so.
#[test]
fn the_output_follows_the_targets_and_another_programs_file_is_replaced_only_when_asked() {
    let (mut h, result) = calibrated();
    let dir = tempfile::tempdir().unwrap();
    let all = targets(&result);
    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    let out = |h: &Harness<'_, WorkbenchApp>| PathBuf::from(&h.state().forms().compensate.out);

    let first = dir.path().join("cell-a.csv");
    std::fs::write(&first, table(&all)).unwrap();
    compensate_in_view(&mut h, &first);
    let first_out = dir.path().join("cell-a-compensated.csv");
    assert_eq!(out(&h), first_out, "named after the targets");
    h.get_by_label("Write").click();
    settle(&mut h);
    let first_text = read(&first_out);
    assert_eq!(first_text, engine_text(&result, &first));

    // Other targets: the output's name follows them; the first program
    // stays as it was.
    let second = dir.path().join("cell-b.csv");
    std::fs::write(&second, table(&all[..3])).unwrap();
    compensate_in_view(&mut h, &second);
    let second_out = dir.path().join("cell-b-compensated.csv");
    assert_eq!(out(&h), second_out, "the name follows the targets");
    h.get_by_label("Write").click();
    settle(&mut h);
    assert_eq!(read(&second_out), engine_text(&result, &second));
    assert_eq!(read(&first_out), first_text, "the first program untouched");

    // The previous program's name typed back: asked first, nothing
    // written; kept when the operator says so, replaced when they do.
    h.state_mut().forms_mut().compensate.out = first_out.display().to_string();
    h.get_by_label("Write").click();
    settle(&mut h);
    assert!(h.query_by_label("Replace").is_some(), "asked first");
    assert!(
        !labels_with(&h, "this window wrote it of the compensation").is_empty(),
        "why it asks"
    );
    assert_eq!(read(&first_out), first_text, "nothing written yet");
    h.get_by_label("Keep the file").click();
    settle(&mut h);
    assert!(h.query_by_label("Replace").is_none());
    assert_eq!(read(&first_out), first_text, "kept");
    assert!(ui_support::status(&h).contains("kept"));
    h.get_by_label("Write").click();
    settle(&mut h);
    h.get_by_label("Replace").click();
    settle(&mut h);
    assert_eq!(read(&first_out), engine_text(&result, &second), "replaced");

    // The targets edited in place (same name, other targets): stale, the
    // write refused; compensated again, the file written of the old
    // targets is replaced only once the operator agrees.
    h.state_mut().forms_mut().compensate.out = second_out.display().to_string();
    std::fs::write(&second, table(&all[..2])).unwrap();
    h.run();
    assert!(!labels_with(&h, "STALE").is_empty());
    let before = read(&second_out);
    command(&mut h, Command::Compensate(CompensateCommand::Write));
    settle(&mut h);
    assert_eq!(read(&second_out), before, "a stale compensation is refused");
    h.get_by_label("Compensate targets").click();
    settle(&mut h);
    assert_eq!(out(&h), second_out);
    h.get_by_label("Write").click();
    settle(&mut h);
    assert!(h.query_by_label("Replace").is_some(), "asked first");
    assert_eq!(read(&second_out), before);
    h.get_by_label("Replace").click();
    settle(&mut h);
    assert_eq!(read(&second_out), engine_text(&result, &second));
}
