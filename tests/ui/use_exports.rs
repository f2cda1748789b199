//! The calibration where it is used, from the workbench (issue 33): the
//! Results view's tool data for every controller of a joint and a
//! pose-only result, read back by the readers the command line's tests
//! use (written from the vendors' documentation); the robot's URDF back
//! and UR's calibration YAML, each what the engine gives and parsed back;
//! every one refused once the result is stale. The Compensate view's
//! current tool for a pose-only result, and its tool data's Copy disabled
//! when stale. egui_kittest, no display.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::path::{Path, PathBuf};

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use nalgebra::Isometry3;
use spherecal::app::WorkbenchApp;
use spherecal::app::command::UseExport;
use spherecal::app::command::{Command, CompensateCommand, Tab, ViewCommand};
use spherecal::app::results::export::unavailable;
use spherecal::engine::base::robot::controller::FlangeConvention;
use spherecal::engine::base::robot::{Robot, ur5e};
use spherecal::engine::calibrate::solve::Control;
use spherecal::engine::files::format::{self, ResultFile};
use spherecal::engine::files::program::ReadSpec;
use spherecal::engine::files::robot_import::robot_from_urdf;
use spherecal::engine::tools::report::tool_data::ToolTarget;
use spherecal::engine::tools::report::{ur_calibration, urdf_back};
use spherecal::engine::uses::compensate;

use crate::support::tool_readers::{
    assert_same, read_fanuc_utool, read_krl_tool, read_rapid_tooldata, read_ros, read_ur_tcp,
};
use crate::support::ui as ui_support;
use ui_support::{command, demo_app, leave_out_first, open_path};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data");

/// The file last written, by what the list of files calls it.
fn written(h: &Harness<'_, WorkbenchApp>, what: &str) -> Option<PathBuf> {
    let ledger = &h.state().state().ledger;
    ledger
        .written
        .iter()
        .rev()
        .find(|w| w.what == what)
        .map(|w| w.path.clone())
}

/// Writes `kind` of the result on show into `dir`; the file.
fn export(h: &mut Harness<'_, WorkbenchApp>, kind: UseExport, dir: &Path) -> PathBuf {
    h.state_mut().forms_mut().export_dir = dir.display().to_string();
    command(h, Command::UseExport(kind));
    let path = written(h, &kind.label()).unwrap_or_else(|| {
        panic!(
            "{} not written: {:?}",
            kind.label(),
            h.state().state().notice
        )
    });
    assert!(path.starts_with(dir), "{}", path.display());
    path
}

/// A reader of one syntax.
type Reader = fn(&str) -> Isometry3<f64>;

#[test]
fn tool_data_of_joint_and_pose_only_results_reads_back_for_every_controller() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = demo_app();
    for (k, name) in ["result.json", "result-pose-only.json"].iter().enumerate() {
        let path = PathBuf::from(format!("{DATA}/v1/{name}"));
        let result = format::load_result(&path).unwrap();
        assert_eq!(result.hand_eye_only(), k == 1, "{name}");
        open_path(&mut h, path);
        let out = dir.path().join(k.to_string());
        std::fs::create_dir(&out).unwrap();
        let readers: [(ToolTarget, Reader); 5] = [
            (ToolTarget::ALL[0], read_rapid_tooldata),
            (ToolTarget::ALL[1], read_krl_tool),
            (ToolTarget::ALL[2], read_fanuc_utool),
            (ToolTarget::ALL[3], read_ur_tcp),
            (ToolTarget::Ros, read_ros),
        ];
        for (target, read) in readers {
            let file = export(&mut h, UseExport::Tool(target), &out);
            let text = std::fs::read_to_string(&file).unwrap();
            let what = format!("{name} {}", target.key());
            assert_same(&read(&text), &result.hand_eye, 1e-6, 1e-9, &what);
        }
    }
    // Stale: a measurement left out of the session the result is shown
    // against; every export refused, nothing written.
    leave_out_first(&mut h);
    let out = dir.path().join("stale");
    std::fs::create_dir(&out).unwrap();
    h.state_mut().forms_mut().export_dir = out.display().to_string();
    command(&mut h, Command::UseExport(UseExport::Tool(ToolTarget::Ros)));
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 0);
    let notice = h.state().state().notice.clone().expect("a refusal");
    assert!(notice.body.contains("stale"), "{}", notice.body);
}

/// A copy of the v1 result with `calibrated` as its robot (errors from
/// `nominal`), written to `dir/name`.
fn result_of(nominal: &Robot, calibrated: &Robot, dir: &Path, name: &str) -> PathBuf {
    let mut r = format::load_result(Path::new(&format!("{DATA}/v1/result.json"))).unwrap();
    r.robot = Some(calibrated.clone());
    r.joint_errors = calibrated.joint_errors(nominal);
    let path = dir.join(name);
    format::save_result(&r, &path).unwrap();
    path
}

/// `nominal` with every length 0.4 mm longer and every angle 0.05° more.
fn changed(nominal: &Robot) -> Robot {
    let mut r = nominal.clone();
    for j in &mut r.joints {
        j.a += 0.4;
        j.d -= 0.4;
        j.theta += 0.05_f64.to_radians();
        j.alpha -= 0.05_f64.to_radians();
    }
    r
}

#[test]
fn the_urdf_back_and_ur_calibration_are_the_engines_and_parse_back() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = demo_app();
    // The robot's own URDF, calibrated.
    let urdf = PathBuf::from(format!("{DATA}/robots/abb_irb2400.urdf"));
    let source = std::fs::read_to_string(&urdf).unwrap();
    let nominal = robot_from_urdf(&source, &urdf).unwrap().robot;
    let path = result_of(&nominal, &changed(&nominal), dir.path(), "abb.result.json");
    open_path(&mut h, path.clone());
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Results)));
    // Without the URDF's path: disabled, saying why.
    let button = h.get_by_label("URDF back");
    assert!(button.accesskit_node().is_disabled());
    let view = h.state().state().result.clone().unwrap();
    let why = unavailable(UseExport::UrdfBack, &view, "").unwrap();
    assert!(why.contains("URDF"), "{why}");
    assert!(
        unavailable(UseExport::UrCalibration, &view, "")
            .is_some_and(|w| w.contains("not a Universal Robots arm")),
        "an IRB 2400 has no UR calibration"
    );
    h.state_mut().forms_mut().urdf_source = urdf.display().to_string();
    let file = export(&mut h, UseExport::UrdfBack, dir.path());
    let text = std::fs::read_to_string(&file).unwrap();
    let result: ResultFile = format::load_result(&path).unwrap();
    let engine = urdf_back::calibrated_urdf(&result, &source, &urdf, None).unwrap();
    assert_eq!(text, engine.text, "the engine's URDF back");
    let parsed = urdf_rs::read_from_string(&text).unwrap();
    assert!(parsed.links.iter().any(|l| l.name == "sensor"));
    // UR's calibration of a UR5e result.
    let nominal = ur5e().robot;
    let path = result_of(&nominal, &changed(&nominal), dir.path(), "ur.result.json");
    open_path(&mut h, path.clone());
    let file = export(&mut h, UseExport::UrCalibration, dir.path());
    let text = std::fs::read_to_string(&file).unwrap();
    let result = format::load_result(&path).unwrap();
    let engine = ur_calibration::ur_calibration(&result, &path.display().to_string(), false);
    assert_eq!(text, engine.unwrap(), "the engine's UR calibration");
    let yaml: serde_norway::Value = serde_norway::from_str(&text).unwrap();
    let k = &yaml["kinematics"];
    for joint in [
        "shoulder",
        "upper_arm",
        "forearm",
        "wrist_1",
        "wrist_2",
        "wrist_3",
    ] {
        for key in ["x", "y", "z", "roll", "pitch", "yaw"] {
            assert!(k[joint][key].as_f64().is_some(), "{joint}.{key}");
        }
    }
    assert!(k["hash"].as_str().unwrap().starts_with("spherecal_"));
}

#[test]
fn compensate_takes_the_current_tool_of_a_pose_only_result_and_copy_is_disabled_when_stale() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = demo_app();
    let path = PathBuf::from(format!("{DATA}/v1/result-pose-only.json"));
    let result = format::load_result(&path).unwrap();
    open_path(&mut h, path);
    let targets = dir.path().join("t.csv");
    std::fs::write(
        &targets,
        "id,x,y,z,w,p,r\nt1,800,100,400,180,0,90\nt2,850,-50,420,175,5,80\nt3,700,0,380,-170,-3,100\n",
    )
    .unwrap();
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Compensate)));
    let form = &mut h.state_mut().forms_mut().compensate;
    form.targets = targets.display().to_string();
    form.convention = Some(FlangeConvention::FanucWpr);
    // Without the current tool: what to do instead, the tool data to
    // install (Copy enabled while the result is current), no compensation.
    h.run();
    assert!(
        h.query_by_label_contains("no model to compensate targets with")
            .is_some()
    );
    let copy = h.query_all_by_label("Copy").next().expect("Copy");
    assert!(!copy.accesskit_node().is_disabled());
    command(&mut h, Command::Compensate(CompensateCommand::Run));
    assert!(h.state().state().compensate.outcome.is_none());
    // With it: the targets moved for the controller's current tool, the
    // same text as the engine's.
    let current = dir.path().join("current.txt");
    std::fs::write(&current, "! taught with UTOOL 1\n2,-1.5,250,179,0.5,-90\n").unwrap();
    h.state_mut().forms_mut().compensate.current_tool = current.display().to_string();
    command(&mut h, Command::Compensate(CompensateCommand::Run));
    let view = match &h.state().state().compensate.outcome {
        Some(Ok(v)) => v.clone(),
        other => panic!("not compensated: {other:?}"),
    };
    let read = ReadSpec {
        convention: Some(FlangeConvention::FanucWpr),
        ..ReadSpec::default()
    };
    let engine =
        compensate::compensate_file_tool_only(&result, &targets, &read, &current, &mut |_| {
            Control::Continue
        })
        .unwrap();
    assert_eq!(view.text, engine.compensation.text);
    assert!(view.tcp.contains("current tool"), "{}", view.tcp);
    let out = dir.path().join("out.csv");
    h.state_mut().forms_mut().compensate.out = out.display().to_string();
    command(&mut h, Command::Compensate(CompensateCommand::Write));
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        engine.compensation.text
    );
    // The result goes stale: the tool data's Copy is disabled, saying why.
    leave_out_first(&mut h);
    h.state_mut().forms_mut().compensate.current_tool.clear();
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Compensate)));
    h.run();
    let copies: Vec<_> = h.query_all_by_label("Copy").collect();
    assert!(!copies.is_empty());
    assert!(copies.iter().all(|c| c.accesskit_node().is_disabled()));
}
