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
//! - [`ledger`]: the one artefact ledger: what each artefact (plan,
//!   result, report, cloud, compensation, every file written of them)
//!   was made from, whether it still holds, and whether a file may be
//!   replaced without asking;
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
//! **Staleness: one ledger.** Every artefact is recorded in
//! [`ledger::Ledger`] (in the state) with a [`ledger::Stamp`]: the
//! readings of the inputs it was made from, taken by [`inputs::readings`]
//! every frame; an artefact made from another (a cloud, a compensation, a
//! report from the result) starts from that one's stamp. When an input
//! reads otherwise, the artefact and everything made from it are stale
//! at once; the step bar, the views and every write ask the ledger, none
//! keeps a flag of its own. To add an artefact: a variant of
//! [`ledger::Artefact`] with its inputs (new inputs read in
//! [`inputs::readings`]); its job started with `ledger.stamp(..)`, its
//! answer `record`ed with the job's stamp; its files written through
//! `Core::write`, which refuses nothing stale and asks before replacing a
//! file not written of the same inputs.
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
pub mod ledger;
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
