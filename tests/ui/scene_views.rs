//! The 3-D scene in Plan, Compensate and for a fixed sensor (issue 34
//! item 1, issue 35): dragging orbits the Plan view's scene, picking a
//! planned pose selects it in the plan's table and a row clicked there is
//! the pose the scene shows; the Compensate view's scene draws every
//! target as written and as compensated with the move between them; a
//! fixed-sensor session made by `spherecal simulate --mount fixed` shows
//! its cell (the sensor in the base frame, the targets on the flange),
//! calibrates in the window, and its Results show `base_from_sensor`,
//! the targets and the calibrated cell.

#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use egui::accesskit::Toggled;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use spherecal::app::WorkbenchApp;
use spherecal::app::command::{Command, CompensateCommand, PlanCommand, Tab, ViewCommand};
use spherecal::app::compensate::form::TcpChoice;
use spherecal::engine::base::robot::controller::FlangeConvention;

use super::support::bin::run;
use super::support::ui::{demo_app, labels_with, open_path, settle, small_plan};

fn command(h: &mut Harness<'_, WorkbenchApp>, c: Command) {
    let ctx = h.ctx.clone();
    h.state_mut().command(&ctx, c);
}

/// Wheels the view under `at` down until the canvas `label` is wholly on
/// screen; its rectangle.
fn scene_on_screen(h: &mut Harness<'_, WorkbenchApp>, label: &str, at: egui::Pos2) -> egui::Rect {
    for _ in 0..40 {
        if let Some(n) = h.query_by_label(label) {
            let r = n.rect();
            if r.min.y >= 60.0 && r.max.y <= 700.0 {
                return r;
            }
        }
        h.hover_at(at);
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::vec2(0.0, -120.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Unknown,
            modifiers: egui::Modifiers::NONE,
        });
        for _ in 0..10 {
            h.step();
        }
        h.run();
    }
    panic!(
        "{label} never came wholly on screen: {:?}",
        h.query_by_label(label).map(|n| n.rect())
    );
}

/// A click at `at` (press and release in place).
fn click_at(h: &mut Harness<'_, WorkbenchApp>, at: egui::Pos2) {
    h.hover_at(at);
    h.run();
    h.drag_at(at);
    h.run();
    h.drop_at(at);
    h.run();
}

/// A drag from `from` by `by`, in eight steps.
fn drag(h: &mut Harness<'_, WorkbenchApp>, from: egui::Pos2, by: egui::Vec2) {
    h.hover_at(from);
    h.drag_at(from);
    h.run();
    for k in 1..=8 {
        h.hover_at(from + by * (k as f32 / 8.0));
        h.run();
    }
    h.drop_at(from + by);
    h.run();
}

/// A mark drawn with no other within the pick radius, not `but`.
fn lone_mark(marks: &[(usize, egui::Pos2)], but: usize) -> (usize, egui::Pos2) {
    marks
        .iter()
        .copied()
        .filter(|(k, _)| *k != but)
        .find(|(k, p)| marks.iter().all(|(j, q)| j == k || p.distance(*q) > 14.0))
        .expect("a mark on its own")
}

/// The demo's Plan view with a small plan made.
fn planned() -> Harness<'static, WorkbenchApp> {
    let mut h = demo_app();
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Plan)));
    small_plan(&mut h, 3, 2);
    command(&mut h, Command::Plan(PlanCommand::Make));
    settle(&mut h);
    assert!(matches!(h.state().state().plan.outcome, Some(Ok(_))));
    h
}

/// Where to wheel the Plan view's result column: above its scene.
const PLAN_COLUMN: egui::Pos2 = egui::pos2(1000.0, 250.0);

#[test]
fn dragging_orbits_the_plan_scene() {
    let mut h = planned();
    let rect = scene_on_screen(&mut h, "3-D scene plan", PLAN_COLUMN);
    assert!(rect.width() > 300.0 && rect.height() > 300.0, "{rect:?}");
    let before = h.state().forms().scene.plan.clone();
    let n = match &h.state().state().plan.outcome {
        Some(Ok(o)) => o.plan.poses.len(),
        _ => unreachable!(),
    };
    assert_eq!(before.drawn_marks.len(), n, "every planned pose is drawn");
    drag(
        &mut h,
        rect.center() + egui::vec2(-60.0, -40.0),
        egui::vec2(90.0, 40.0),
    );
    let after = h.state().forms().scene.plan.clone();
    assert!(
        after.yaw < before.yaw - 0.3,
        "{} → {}",
        before.yaw,
        after.yaw
    );
    assert!(after.pitch > before.pitch + 0.1);
    let moved = before
        .drawn_marks
        .iter()
        .zip(&after.drawn_marks)
        .filter(|(a, b)| a.1.distance(b.1) > 5.0)
        .count();
    assert!(moved > n / 2, "{moved} of {n} marks moved");
    // The session's camera is another: it did not turn.
    assert_eq!(h.state().forms().scene.session.yaw, before.yaw);
    // Every pose runs as planned: said under the scene.
    assert_eq!(
        labels_with(&h, &format!("All {n} poses run as planned")).len(),
        1
    );
}

#[test]
fn picking_a_planned_pose_selects_it_in_the_table_and_back() {
    let mut h = planned();
    scene_on_screen(&mut h, "3-D scene plan", PLAN_COLUMN);
    let poses: Vec<String> = match &h.state().state().plan.outcome {
        Some(Ok(o)) => o.plan.poses.iter().map(|p| p.id.clone()).collect(),
        _ => unreachable!(),
    };
    assert_eq!(h.state().forms().scene.plan_pose, None);
    let marks = h.state().forms().scene.plan.drawn_marks.clone();
    let (k, at) = lone_mark(&marks, 0);
    click_at(&mut h, at);
    settle(&mut h);
    assert_eq!(h.state().forms().scene.plan_pose, Some(k), "picked {k}");
    // The table opened on it: its row is there and selected; the caption
    // names it.
    let row = h.get_by_label(&poses[k]);
    assert_eq!(row.accesskit_node().toggled(), Some(Toggled::True));
    assert_eq!(labels_with(&h, &format!("{} (station", poses[k])).len(), 1);
    // And back: another row clicked is the pose the scene shows.
    // The row above the picked one is in sight beside it.
    let other = k - 1;
    h.get_by_label(&poses[other]).click();
    h.run();
    h.run();
    assert_eq!(h.state().forms().scene.plan_pose, Some(other));
    assert_eq!(
        labels_with(&h, &format!("{} (station", poses[other])).len(),
        1
    );
    assert!(labels_with(&h, &format!("{} (station", poses[k])).is_empty());
    assert_eq!(
        h.get_by_label(&poses[k]).accesskit_node().toggled(),
        Some(Toggled::False)
    );
}

#[test]
fn the_compensate_scene_shows_the_targets_moved() {
    let mut h = demo_app();
    h.get_by_label("▶ Run").click();
    settle(&mut h);
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Compensate)));
    h.run();
    // No compensation yet: no scene.
    assert!(h.query_by_label("3-D scene compensate").is_none());
    let targets = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/targets.csv");
    let form = &mut h.state_mut().forms_mut().compensate;
    form.targets = targets.display().to_string();
    form.convention = Some(FlangeConvention::AbbQuaternion);
    form.tcp = TcpChoice::Sensor;
    command(&mut h, Command::Compensate(CompensateCommand::Run));
    settle(&mut h);
    let rows = match &h.state().state().compensate.outcome {
        Some(Ok(v)) => v.rows.clone(),
        other => panic!("not compensated: {other:?}"),
    };
    assert!(rows.len() >= 3);
    let rect = h.get_by_label("3-D scene compensate").rect();
    assert!(rect.width() > 250.0 && rect.height() > 250.0, "{rect:?}");
    let marks = h.state().forms().scene.compensate.drawn_marks.clone();
    assert_eq!(marks.len(), rows.len(), "a mark a target");
    // What is drawn: each target's move from as written to as
    // compensated, the scale said.
    let (scene, scale) = spherecal::app::compensate::scene::compensation_scene(&rows, None);
    let arrows: Vec<_> = scene
        .lines
        .iter()
        .filter(|l| l.stroke.color == spherecal::app::widgets::AFTER)
        .collect();
    assert_eq!(arrows.len(), rows.len());
    for (a, r) in arrows.iter().zip(&rows) {
        let d: f64 = (0..3)
            .map(|k| (a.points[1][k] - a.points[0][k]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(
            (d - scale * r.correction_mm).abs() < 1e-6,
            "{d} vs {scale} × {}",
            r.correction_mm
        );
        assert!(r.correction_mm > 0.0);
    }
    let said = if scale > 1.0 {
        format!("the moves drawn ×{scale:.0}")
    } else {
        "the moves drawn to scale".to_string()
    };
    assert_eq!(labels_with(&h, &said).len(), 1, "{said}");
    // The largest correction is selected first; a pick selects another.
    assert_eq!(
        labels_with(&h, &format!("Selected {} (line", rows[0].name)).len(),
        1
    );
    if let Some((k, at)) = marks
        .iter()
        .copied()
        .filter(|(k, _)| *k != 0)
        .find(|(k, p)| marks.iter().all(|(j, q)| j == k || p.distance(*q) > 14.0))
    {
        click_at(&mut h, at);
        assert_eq!(h.state().forms().scene.compensate_target, Some(k));
        assert_eq!(
            labels_with(&h, &format!("Selected {} (line", rows[k].name)).len(),
            1
        );
    }
}

#[test]
fn a_fixed_sensor_session_shows_its_cell_calibrates_and_shows_base_from_sensor() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tracker.json");
    let (code, _, err) = run(&[
        "simulate",
        "--mount",
        "fixed",
        "--seed",
        "4",
        "--out",
        path.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(code, 0, "{err}");
    let mut h = demo_app();
    open_path(&mut h, path);
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Session)));
    h.run();
    let n = h
        .state()
        .state()
        .loaded
        .as_ref()
        .unwrap()
        .session
        .measurements
        .len();
    // The Session's scene is the fixed cell: a mark at every target, the
    // caption says what is drawn.
    assert!(h.query_by_label("3-D scene session").is_some());
    assert_eq!(h.state().forms().scene.session.drawn_marks.len(), n);
    assert_eq!(
        labels_with(
            &h,
            "Fixed sensor (yellow ball) at the initial base_from_sensor"
        )
        .len(),
        1
    );
    // Calibrate in the window.
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
    assert_eq!(
        result.mount(),
        spherecal::engine::base::session::Mount::Fixed
    );
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Results)));
    h.run();
    let results_column = egui::pos2(700.0, 200.0);
    let found = super::support::ui::scroll_to(&mut h, results_column, "Base from sensor bT_s");
    assert!(found, "the hand-eye table is titled base from sensor");
    // The calibrated base_from_sensor as the table shows it.
    let x = format!("{:.4}", result.hand_eye.translation.vector.x);
    assert!(!labels_with(&h, &x).is_empty(), "base_from_sensor x {x}");
    assert!(super::support::ui::scroll_to(
        &mut h,
        results_column,
        "Targets on the flange"
    ));
    for st in &result.stations {
        assert_eq!(st.frame, "flange");
        assert!(
            !labels_with(&h, &format!("{:.3}", st.point[2])).is_empty(),
            "{}",
            st.id
        );
    }
    // The calibrated cell under it: a mark at every pose the result
    // records the joints of.
    assert!(super::support::ui::scroll_to(
        &mut h,
        results_column,
        "3-D scene results"
    ));
    assert_eq!(
        labels_with(
            &h,
            "Fixed sensor (yellow ball) at the calibrated base_from_sensor"
        )
        .len(),
        1
    );
    // The Centres view says what its points are.
    command(&mut h, Command::View(ViewCommand::ShowTab(Tab::Centres)));
    h.run();
    assert_eq!(
        labels_with(&h, "3D, targets in the flange frame (a fixed sensor)").len(),
        1
    );
}
