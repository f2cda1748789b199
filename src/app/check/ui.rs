//! The Re-check view: plan the check poses for the result on show (the
//! sphere position, Plan the check, its CSV and program), choose the
//! check session and press Check (progress, Cancel), then the verdict:
//! HOLDS or FAILS, both tests, what moved and by how much, the fitted
//! sphere positions, and "Write the check record" (refused while stale).

use egui::RichText;

use super::job::{CheckPlanView, CheckView};
use crate::app::command::{CheckCommand, Command, PlanExport};
use crate::app::dialog::Purpose;
use crate::app::job::Slot;
use crate::app::ledger::Artefact;
use crate::app::widgets::{
    BAD, GOOD, MUTED, WARN, boxed, coloured, command_button, dialog_note_ui, export_folder_ui,
    job_ui, labelled_drag, path_row, stale_banner_ui, weak, written_ui,
};
use crate::app::{AppState, Forms};

/// The Re-check view.
pub fn check_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    egui::ScrollArea::vertical()
        .id_salt("check_scroll")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            ui.heading("Re-check the calibrated cell");
            weak(
                ui,
                "A few poses at one to three sphere positions, predicted through the calibration on show and \
                 tested against its covariance at a false-alarm rate α (the sphere may have been moved): \
                 does the cell still hold its calibration, and if not, what moved.",
            );
            if state.result.is_none() {
                coloured(ui, WARN, "No calibration on show: run the calibration (an ml result) or open a result file first.");
                return;
            }
            if let Some(s) = state.ledger.stale(Artefact::Result) {
                stale_banner_ui(ui, &s, "A check is planned and made against a current result only: run the calibration again.");
            }
            ui.add_space(4.0);
            plan_ui(ui, state, forms, commands);
            ui.separator();
            run_ui(ui, state, forms, commands);
            ui.separator();
            verdict_ui(ui, state, commands);
        });
}

/// Cancel beside the job in `slot`, when one runs; true then.
fn running_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    slot: &Slot,
    commands: &mut Vec<Command>,
) -> bool {
    let Some(job) = state.jobs.get(slot) else {
        return false;
    };
    ui.horizontal_wrapped(|ui| {
        job_ui(ui, job);
        let cancel = Command::Check(CheckCommand::Cancel);
        command_button(
            ui,
            true,
            "Cancel",
            "stop; what is on show stays",
            cancel,
            commands,
        );
    });
    true
}

/// 1: the sphere position, Plan the check, its lines and its files.
fn plan_ui(ui: &mut egui::Ui, state: &AppState, forms: &mut Forms, commands: &mut Vec<Command>) {
    ui.label(RichText::new("1. Plan the check poses").strong());
    let mut sphere = forms.check.sphere_of(forms);
    ui.horizontal_wrapped(|ui| {
        for (k, axis) in ["sphere x", "y", "z"].into_iter().enumerate() {
            let drag = egui::DragValue::new(&mut sphere[k])
                .speed(1.0)
                .suffix(" mm");
            labelled_drag(ui, axis, drag);
        }
        weak(
            ui,
            "where the sphere stands for the check, roughly (base frame)",
        );
    });
    if sphere != forms.check.sphere_of(forms) {
        forms.check.sphere = Some(sphere);
    }
    if !running_ui(ui, state, &Slot::CheckPlan, commands) {
        let hover = "plan --check: 3 translation and 2 rotation poses, then the check's own at one to three sphere positions (at most 30), the layout that detects the most";
        let plan = Command::Check(CheckCommand::Plan);
        command_button(ui, true, "Plan the check", hover, plan, commands);
    }
    match &state.check.plan {
        None => {}
        Some(Err(e)) => {
            coloured(ui, BAD, format!("not planned: {e}"));
        }
        Some(Ok(p)) => planned_ui(ui, state, forms, p, commands),
    }
}

fn planned_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    p: &CheckPlanView,
    commands: &mut Vec<Command>,
) {
    let stale = state.ledger.stale(Artefact::CheckPlan);
    if let Some(s) = &stale {
        stale_banner_ui(
            ui,
            s,
            "Its files are refused until you press Plan the check.",
        );
    }
    for line in &p.lines {
        ui.label(line);
    }
    let refused = stale.map(|s| format!("refused: {s}; press Plan the check"));
    ui.horizontal_wrapped(|ui| {
        export_folder_ui(ui, "Write to folder", &mut forms.export_dir, 240.0, commands);
        let busy = state.jobs.writing();
        for kind in std::iter::once(PlanExport::Csv).chain(p.controller.map(PlanExport::Program)) {
            let hover = refused.as_deref().unwrap_or(
                "as the Plan view writes a plan: run it at the robot, import the scan like any session",
            );
            let export = Command::Check(CheckCommand::Export(kind));
            command_button(ui, refused.is_none() && !busy, kind.label(), hover, export, commands);
        }
    });
    dialog_note_ui(ui, state, &[Purpose::ExportFolder]);
    written_ui(ui, state, &[Artefact::CheckPlan]);
}

/// 2: the check session, α, and Check.
fn run_ui(ui: &mut egui::Ui, state: &AppState, forms: &mut Forms, commands: &mut Vec<Command>) {
    ui.label(RichText::new("2. Check the scan of those poses").strong());
    let busy = state.jobs.runs(&Slot::Dialog);
    let form = &mut forms.check;
    ui.horizontal(|ui| {
        let (hint, purpose) = (
            "the check's scan imported as a session (.json)",
            Purpose::CheckSession,
        );
        path_row(
            ui,
            "Check session",
            &mut form.session,
            hint,
            busy,
            purpose,
            commands,
        );
    });
    ui.horizontal(|ui| {
        let drag = egui::DragValue::new(&mut form.alpha)
            .range(1e-5..=0.2)
            .speed(0.0001)
            .max_decimals(5);
        labelled_drag(ui, "False-alarm rate α", drag).on_hover_text(
            "the share of checks of an unchanged cell that fail (0.001: one in a thousand)",
        );
    });
    dialog_note_ui(ui, state, &[Purpose::CheckSession]);
    if !running_ui(ui, state, &Slot::Check, commands) {
        let why = forms
            .check
            .session
            .trim()
            .is_empty()
            .then_some("choose the check session first");
        let hover = why.unwrap_or("test the session against the result on show (spherecal check)");
        let run = Command::Check(CheckCommand::Run);
        command_button(ui, why.is_none(), "Check", hover, run, commands);
    }
}

/// 3: the verdict and its record.
fn verdict_ui(ui: &mut egui::Ui, state: &AppState, commands: &mut Vec<Command>) {
    match &state.check.outcome {
        None => {
            weak(
                ui,
                "No check yet: plan it, run it at the robot, import the scan, then press Check.",
            );
        }
        Some(Err(e)) => {
            boxed(ui, BAD, "Not checked", |ui| {
                ui.label(e);
            });
        }
        Some(Ok(v)) => checked_ui(ui, state, v, commands),
    }
}

fn checked_ui(ui: &mut egui::Ui, state: &AppState, v: &CheckView, commands: &mut Vec<Command>) {
    let stale = state.ledger.stale(Artefact::Check);
    if let Some(s) = &stale {
        stale_banner_ui(
            ui,
            s,
            "This verdict does not hold for what is on show now; its record is refused: press Check again.",
        );
    }
    let t = &v.checked.test;
    let (word, colour) = match (t.holds, stale.is_some()) {
        (_, true) => (
            if t.holds {
                "HOLDS (stale)"
            } else {
                "FAILS (stale)"
            },
            MUTED,
        ),
        (true, false) => ("HOLDS", GOOD),
        (false, false) => ("FAILS", BAD),
    };
    ui.label(RichText::new(word).size(28.0).strong().color(colour));
    ui.label(RichText::new(v.headline()).strong());
    for note in &v.checked.notes {
        coloured(ui, MUTED, format!("note: {note}"));
    }
    for s in &v.checked.skipped {
        coloured(ui, WARN, format!("left out: {s}"));
    }
    for line in &v.lines {
        ui.label(line);
    }
    for line in &v.moved {
        coloured(ui, BAD, line);
    }
    ui.add_space(4.0);
    let why = stale.map(|s| format!("refused: {s}; press Check again"));
    ui.horizontal_wrapped(|ui| {
        let path = crate::engine::files::format::check_record_path(&v.session_path);
        let hover = why.clone().unwrap_or_else(|| {
            format!(
                "{} (history lists it beside the calibrations)",
                path.display()
            )
        });
        let enabled = why.is_none() && !state.jobs.writing();
        let record = Command::Check(CheckCommand::Record);
        command_button(
            ui,
            enabled,
            "Write the check record",
            &hover,
            record,
            commands,
        );
        if let Some(w) = &why {
            coloured(ui, WARN, w);
        }
    });
    written_ui(ui, state, &[Artefact::Check]);
}
