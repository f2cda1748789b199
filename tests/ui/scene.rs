//! The 3-D scene of the cell (issue 34): the Session view shows it beside
//! the table; dragging orbits, the standard views move the eye, a click
//! on a pose's mark selects it in the table, and selecting a row shows
//! that pose. The Measure view shows the cloud in it with its budget.

use egui_kittest::kittest::Queryable as _;

use super::support::ui::{demo_app, labels_with, settle};
use spherecal::app::command::{Command, ViewCommand};

fn scene_rect(h: &egui_kittest::Harness<'_, spherecal::app::WorkbenchApp>) -> egui::Rect {
    h.get_by_label("3-D scene session").rect()
}

#[test]
fn dragging_orbits_the_session_scene_and_the_views_move_the_eye() {
    let mut h = demo_app();
    h.run();
    let rect = scene_rect(&h);
    assert!(rect.width() > 250.0 && rect.height() > 250.0, "{rect:?}");
    let before = h.state().forms().scene.session.clone();
    assert!(!before.drawn_marks.is_empty(), "the poses are drawn");
    // A drag from the middle to the right and down.
    let from = rect.center() + egui::vec2(-40.0, -60.0);
    h.hover_at(from);
    h.drag_at(from);
    h.run();
    for k in 1..=8 {
        h.hover_at(from + egui::vec2(10.0 * k as f32, 4.0 * k as f32));
        h.run();
    }
    h.drop_at(from + egui::vec2(80.0, 32.0));
    h.run();
    let after = h.state().forms().scene.session.clone();
    assert!(
        after.yaw < before.yaw - 0.3,
        "{} → {}",
        before.yaw,
        after.yaw
    );
    assert!(
        after.pitch > before.pitch + 0.1,
        "{} → {}",
        before.pitch,
        after.pitch
    );
    // The poses are drawn elsewhere.
    let moved = before
        .drawn_marks
        .iter()
        .zip(&after.drawn_marks)
        .filter(|(a, b)| a.1.distance(b.1) > 5.0)
        .count();
    assert!(moved > before.drawn_marks.len() / 2, "{moved} marks moved");
    // The Top button looks from above.
    h.get_by_label("Top").click();
    h.run();
    let top = h.state().forms().scene.session.clone();
    assert_eq!(top.pitch, std::f64::consts::FRAC_PI_2);
    assert_eq!(top.zoom, 1.0);
    // Zoom in with the wheel over the scene.
    h.hover_at(rect.center());
    h.event(egui::Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, 120.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Unknown,
        modifiers: egui::Modifiers::NONE,
    });
    for _ in 0..20 {
        h.step();
    }
    h.run();
    assert!(h.state().forms().scene.session.zoom > 1.05);
}

#[test]
fn picking_a_pose_selects_it_in_the_session_and_back() {
    let mut h = demo_app();
    h.run();
    let selected = h.state().state().selected;
    let marks = h.state().forms().scene.session.drawn_marks.clone();
    let n = h
        .state()
        .state()
        .loaded
        .as_ref()
        .expect("demo")
        .session
        .measurements
        .len();
    assert_eq!(marks.len(), n, "every pose drawn in the scene");
    // A mark with no other within the pick radius, not the first.
    let (k, at) = marks
        .iter()
        .copied()
        .filter(|(k, _)| Some(*k) != selected && *k > 0)
        .find(|(k, p)| marks.iter().all(|(j, q)| j == k || p.distance(*q) > 12.0))
        .expect("a mark on its own");
    h.hover_at(at);
    h.run();
    h.drag_at(at);
    h.run();
    h.drop_at(at);
    h.run();
    assert_eq!(h.state().state().selected, Some(k), "picked {k}");
    let id = h
        .state()
        .state()
        .loaded
        .as_ref()
        .expect("demo")
        .session
        .measurements[k]
        .id
        .clone();
    // The table shows the row selected; the scene names the pose.
    assert!(
        labels_with(&h, &format!("{id} (station")).len() == 1,
        "the caption names {id}"
    );
    // And back: a row selected in the table is the pose the scene shows.
    let ctx = h.ctx.clone();
    h.state_mut()
        .command(&ctx, Command::View(ViewCommand::Select(0)));
    settle(&mut h);
    let first = h
        .state()
        .state()
        .loaded
        .as_ref()
        .expect("demo")
        .session
        .measurements[0]
        .id
        .clone();
    assert_eq!(labels_with(&h, &format!("{first} (station")).len(), 1);
    assert!(labels_with(&h, &format!("{id} (station")).is_empty());
    // The selected mark is drawn on top of the others near it: the
    // nearest to its place is it.
    let marks = h.state().forms().scene.session.drawn_marks.clone();
    let at0 = marks.iter().find(|m| m.0 == 0).expect("mark 0").1;
    assert!(marks.iter().filter(|m| m.1 == at0).any(|m| m.0 == 0));
    // The row is selected in the table too.
    assert!(h.query_by_label(&first).is_some());
}
