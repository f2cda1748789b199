//! The workbench: an egui desktop app for the whole calibration, from
//! loading a session to exporting the result. It calls the same engine
//! functions as the command line; nothing here computes a calibration.
//!
//! Layout of the code (STYLE.md habit 5), each unit using only those
//! above it:
//!
//! - [`view`]: view models built from engine outputs (a run and a reviewed
//!   result file both go through the FORMAT.md result);
//! - [`forms`]: the fields widgets edit in place, with the import wizard's
//!   and the planner's forms and the engine requests they build;
//! - [`provenance`]: the one staleness mechanism: what each derived
//!   output (plan, result, report, every file written of them) was made
//!   from, and whether it still holds (read there how to add an output);
//! - [`state`]: what the app knows ([`state::AppState`], changed only by
//!   commands and job messages);
//! - [`inputs`]: the readings of the inputs (session, left-out
//!   measurements, solver settings, Plan form, tolerance) each frame;
//! - [`commands`]: what the panels ask for, by feature;
//! - [`error`]: why a job failed ([`error::JobError`], the engine's error
//!   as its source);
//! - [`job`]: the one job slot type: named background threads, their
//!   progress, Cancel, and the rule that a late answer is dropped;
//! - [`dialog`]: the native file dialogs, one mechanism for every
//!   Browse… button;
//! - [`features`]: one module per feature (files, view, run, export,
//!   import and import_poses, history, plan, measure, compensate), each
//!   with its command handler, its message
//!   handler and the engine calls its jobs make;
//! - [`panels`]: one module per panel or view, each a `*_ui` function
//!   that reads the state, edits the forms and pushes commands;
//! - [`workbench`]: the frame loop that ties them together;
//! - [`screenshot`]: the guide's screenshots, the window driving itself
//!   through a scenario (`SPHERECAL_SCREENSHOT`, `tools/screenshots.sh`).
//!
//! **Staleness: one mechanism.** Everything derived (the plan, the
//! result with its verdict and views, the report, every file written of
//! them) is recorded in [`provenance::Provenance`] (in the state) with a
//! [`provenance::Stamp`]: the readings of the inputs it was made from
//! ([`provenance::Input`]: session, left-out measurements, solver
//! settings, Plan form, tolerance), taken by [`inputs::readings`] every
//! frame. When an input reads otherwise, the output is stale at once; the
//! step bar, the views and the export handlers all ask the provenance,
//! none keeps a flag of its own. To register a new derived output (a
//! Measure step's point clouds, a Compensate view's programs):
//!
//! 1. if it depends on an input not listed, add it to
//!    [`provenance::Input`] (and [`provenance::Input::ALL`]) and read it in
//!    [`inputs::readings`] (its fields in words, a fingerprint of all of
//!    it);
//! 2. add a variant to [`provenance::Output`] with its
//!    [`provenance::Output::inputs`] and [`provenance::Output::name`];
//! 3. when its job starts, take `state.provenance.stamp(Output::X)` and
//!    carry it with the job; when the job's output arrives,
//!    `record(Output::X, stamp)`; when it is cleared, `forget(Output::X)`;
//! 4. before writing any of its files, `check(Output::X)` and refuse with
//!    the error's text; after writing one, `wrote(what, path,
//!    Output::X, stamp)`;
//! 5. where it is on show, `stale(Output::X)` gives what changed (the
//!    views show it with `panels::stale_banner_ui`).
//!
//! Layout of the window, for an operator at 1366×768: the load and solver
//! panel on the left, the Plan, Import, Session, Stripe, Centres, Results,
//! Measure, Compensate and History views in the middle, a status bar at
//! the bottom.

pub mod commands;
pub mod dialog;
pub mod error;
pub mod features;
pub mod forms;
pub mod inputs;
pub mod job;
pub mod panels;
pub mod provenance;
pub mod screenshot;
pub mod state;
pub mod view;
pub mod workbench;

use std::path::PathBuf;

pub use workbench::WorkbenchApp;

/// The one line printed when the workbench cannot open a window.
pub const NO_DISPLAY_HINT: &str =
    "to calibrate without a display run `spherecal calibrate SESSION --out RESULT`";

/// Opens the workbench window on `session` (default: the embedded demo
/// session) and, when given, `result` for review beside it. Blocks until
/// the window closes.
///
/// # Errors
/// No display (neither `DISPLAY` nor `WAYLAND_DISPLAY` set) or a window
/// that could not be created: one line pointing to `spherecal calibrate`.
pub fn run(session: Option<PathBuf>, result: Option<PathBuf>) -> Result<(), String> {
    let shot = screenshot::Request::from_env()?;
    if shot == Some(screenshot::Request::List) {
        print!("{}", screenshot::listing());
        return Ok(());
    }
    if std::env::var_os("DISPLAY").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none() {
        return Err(format!(
            "no display (DISPLAY and WAYLAND_DISPLAY are unset); {NO_DISPLAY_HINT}"
        ));
    }
    let mut options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("spherecal workbench")
            .with_app_id("spherecal")
            .with_inner_size([1366.0, 768.0])
            .with_min_inner_size([960.0, 600.0])
            .with_drag_and_drop(true),
        ..Default::default()
    };
    // A screenshot scenario: default preferences, none stored.
    let director = match shot {
        Some(screenshot::Request::Take(spec)) => {
            let d = screenshot::Director::new(spec, &mut options);
            d.check_inputs()?;
            Some(d)
        }
        _ => None,
    };
    let outcome = director.as_ref().map(screenshot::Director::outcome);
    let opened = eframe::run_native(
        "spherecal",
        options,
        Box::new(move |cc| {
            Ok(Box::new(match director {
                Some(d) => {
                    WorkbenchApp::new(state::Prefs::default(), session, result).with_screenshot(d)
                }
                None => WorkbenchApp::from_storage(cc.storage, session, result),
            }))
        }),
    )
    .map_err(|e| format!("could not open the workbench window ({e}); {NO_DISPLAY_HINT}"));
    let Some(outcome) = outcome else {
        return opened;
    };
    screenshot::remove_storage();
    opened?;
    println!("{}", outcome.result()?);
    Ok(())
}
