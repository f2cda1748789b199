//! What the UI tests share: the harness at 1366×768, waiting for
//! background work, the demo app.

#![allow(dead_code)]

use std::time::Duration;

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT as _, Queryable as _};
use spherecal::app::WorkbenchApp;
use spherecal::app::state::Prefs;

/// Frames to wait for background work (with a short sleep each): generous
/// for a loaded CI machine; a run of the demo takes well under a second.
const MAX_FRAMES: usize = 6000;

pub fn harness(app: WorkbenchApp) -> Harness<'static, WorkbenchApp> {
    Harness::builder()
        .with_size(egui::vec2(1366.0, 768.0))
        .build_ui_state(|ui, app: &mut WorkbenchApp| app.show(ui), app)
}

/// Steps frames until no background work is in flight, then settles.
pub fn settle(h: &mut Harness<'_, WorkbenchApp>) {
    for _ in 0..MAX_FRAMES {
        h.step();
        if !h.state().is_busy() {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(!h.state().is_busy(), "background work did not finish");
    h.run();
}

pub fn demo_app() -> Harness<'static, WorkbenchApp> {
    let mut h = harness(WorkbenchApp::new(Prefs::default(), None, None));
    settle(&mut h);
    assert!(
        h.state().state().loaded.is_some(),
        "the demo session did not load"
    );
    h
}

/// Opens a session or result file as the panels would, and waits.
pub fn open_path(h: &mut Harness<'_, WorkbenchApp>, path: std::path::PathBuf) {
    let ctx = h.ctx.clone();
    h.state_mut().command(
        &ctx,
        spherecal::app::command::Command::Files(spherecal::app::command::FilesCommand::OpenPath(
            path,
        )),
    );
    settle(h);
}

/// A small plan for UI tests (a few stations, few candidates, no
/// prediction): planned in well under a second.
pub fn small_plan(h: &mut Harness<'_, WorkbenchApp>, n_identify: usize, n_validate: usize) {
    let r = &mut h.state_mut().forms_mut().plan.request;
    r.design.n_identify = n_identify;
    r.design.identify_poses = 4;
    r.design.n_validate = n_validate;
    r.design.validate_poses = 3;
    r.design.candidates = 8;
    r.predict_runs = 0;
}

/// The label of the step bar's step `name` (e.g. "4. Calibrated"), with
/// its mark first (● done, ! attention or stale, – skipped, … under way,
/// ○ to do).
pub fn step_label(h: &Harness<'_, WorkbenchApp>, name: &str) -> String {
    let labels: Vec<String> = h
        .query_all_by_label_contains(name)
        .filter_map(|n| {
            let a = n.accesskit_node();
            a.label().or_else(|| a.value())
        })
        .filter(|l| l.ends_with(name) && l.len() < name.len() + 8)
        .collect();
    assert_eq!(labels.len(), 1, "one step {name}: {labels:?}");
    labels[0].clone()
}

/// The text of every widget whose label contains `part` (its label, or
/// its value where it has no label).
pub fn labels_with(h: &Harness<'_, WorkbenchApp>, part: &str) -> Vec<String> {
    h.query_all_by_label_contains(part)
        .filter_map(|n| {
            let a = n.accesskit_node();
            a.label().or_else(|| a.value())
        })
        .collect()
}

/// The status line's text.
/// A command applied as the window would, then settled.
pub fn command(h: &mut Harness<'_, WorkbenchApp>, c: spherecal::app::command::Command) {
    let ctx = h.ctx.clone();
    h.state_mut().command(&ctx, c);
    settle(h);
}

/// The open session's first measurement left out (what makes the result
/// on show stale).
pub fn leave_out_first(h: &mut Harness<'_, WorkbenchApp>) {
    let Some(loaded) = h.state().state().loaded.as_ref() else {
        panic!("no session open");
    };
    let id = loaded.session.measurements[0].id.clone();
    command(
        h,
        spherecal::app::command::Command::View(spherecal::app::command::ViewCommand::SetIncluded {
            id,
            included: false,
        }),
    );
}

pub fn status(h: &Harness<'_, WorkbenchApp>) -> String {
    h.state()
        .state()
        .status
        .as_ref()
        .map(|s| s.text.clone())
        .unwrap_or_default()
}

/// A simulated session written to `dir/name` (as `spherecal simulate`
/// does), for tests that need a session of a given size.
pub fn simulated(
    dir: &std::path::Path,
    name: &str,
    config: &spherecal::engine::tools::simulate::SimConfig,
) -> std::path::PathBuf {
    let (session, _) = spherecal::engine::tools::simulate::simulate(config).expect("simulate");
    let path = dir.join(name);
    spherecal::engine::files::format::save_session(&session, &path).expect("save");
    path
}

/// Scrolls the view under `at` down (the wheel, 200 points a turn) until
/// a widget whose label contains `text` is laid out on screen; false
/// when none comes within 40 turns.
pub fn scroll_to(h: &mut Harness<'_, WorkbenchApp>, at: egui::Pos2, text: &str) -> bool {
    for _ in 0..40 {
        if h.query_all_by_label_contains(text).next().is_some() {
            return true;
        }
        h.hover_at(at);
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: egui::vec2(0.0, -200.0),
            phase: egui::TouchPhase::Move,
            source: egui::MouseWheelSource::Unknown,
            modifiers: egui::Modifiers::NONE,
        });
        h.run();
    }
    h.query_all_by_label_contains(text).next().is_some()
}
