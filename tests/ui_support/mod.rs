//! What the UI tests share: the harness at 1366×768, waiting for
//! background work, the demo app.

#![allow(dead_code)]

use std::time::Duration;

use egui_kittest::Harness;
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
        spherecal::app::commands::Command::Files(spherecal::app::commands::FilesCommand::OpenPath(
            path,
        )),
    );
    settle(h);
}

/// A small plan for UI tests (a few stations, few candidates, no
/// prediction): planned in well under a second.
pub fn small_plan(h: &mut Harness<'_, WorkbenchApp>, n_identify: usize, n_validate: usize) {
    let r = &mut h.state_mut().forms_mut().plan.request;
    r.n_identify = n_identify;
    r.identify_poses = 4;
    r.n_validate = n_validate;
    r.validate_poses = 3;
    r.candidates = 8;
    r.predict_runs = 0;
}
