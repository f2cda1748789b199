//! Issue 34: at 1366×768 a long session name at the right of the view
//! tabs ran into the last tab, "History". The name is cut with … and
//! keeps a gap from the tabs (whole on hover).

use std::path::Path;

use egui_kittest::kittest::Queryable as _;
use spherecal::engine::files::format::{parse_session, save_session};

use crate::support::ui::{demo_app, open_path};

#[test]
fn a_long_session_name_keeps_clear_of_the_tabs() {
    let dir = tempfile::tempdir().expect("temp dir");
    let demo = Path::new(spherecal::DEMO_SESSION_NAME);
    let mut session = parse_session(spherecal::DEMO_SESSION_JSON, demo).expect("demo parses");
    let name = format!(
        "Cell 7 hand-eye check {}",
        "after the knock on line 3 ".repeat(8)
    );
    session.name.clone_from(&name);
    let path = dir.path().join("long.json");
    save_session(&session, &path).expect("save");
    let mut h = demo_app();
    open_path(&mut h, path);
    h.run();
    let history = h.get_by_label("History").rect();
    let shown: Vec<egui::Rect> = h
        .query_all_by_label_contains("Cell 7 hand-eye check")
        .map(|n| n.rect())
        .filter(|r| (r.center().y - history.center().y).abs() < history.height())
        .filter(|r| r.left() > history.left())
        .collect();
    assert_eq!(shown.len(), 1, "the name beside the tabs: {shown:?}");
    let gap = shown[0].left() - history.right();
    assert!(gap >= 20.0, "{gap} points between History and the name");
    assert!(shown[0].right() <= 1366.0, "{:?}", shown[0]);
}
