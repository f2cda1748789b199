//! The Compensate view: a pose table or a robot program compensated
//! through the result on show (`spherecal compensate` in the window).
//! The inputs (targets file, pose convention, TCP, joint targets and the
//! flag limits), the Compensate
//! button with its progress and Cancel, then the summary line, the tool
//! data to set on the controller (TCP = sensor, with Copy), one row per
//! target (largest correction first, flagged ones in orange with why)
//! and "Write compensated program…", refused with the reason when the
//! compensation is stale or the targets had errors.

use egui::RichText;

use crate::app::AppState;
use crate::app::Forms;
use crate::app::command::{Command, CompensateCommand};
use crate::app::compensate::form::{CompensateForm, TcpChoice};
use crate::app::compensate::job::{CompensationView, flags_text};
use crate::app::dialog::Purpose;
use crate::app::job::Slot;
use crate::app::ledger::Artefact;
use crate::app::session::Source;
use crate::app::widgets::{
    BAD, MUTED, WARN, choice, coloured, command_button, dialog_note_ui, labelled_drag,
    labelled_field, stale_banner_ui,
};
use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::uses::compensate::{JointTargets, Options, TargetReport, report};

/// Most target rows drawn (largest corrections first); every target is
/// compensated and written. A robot program has tens to a few hundred
/// targets; a table of thousands would make each frame slow.
const ROWS_SHOWN: usize = 1000;

/// Width of the path fields, points: a whole path at 1366×768 beside the
/// side panel and the scene.
const PATH_WIDTH: f32 = 340.0;

/// Narrowest the column of the form and the table gets beside the scene,
/// points: every row of the form (wrapped) fits it, and the scene takes
/// what is left (issue 34: at 1366×768 the scene clipped the column).
const COLUMN_MIN: f32 = 600.0;

/// The Compensate view.
pub fn compensate_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    let scene_max = (ui.available_width() - COLUMN_MIN).max(260.0);
    super::scene::scene_panel_ui(ui, state, forms, scene_max);
    // Vertical only: the rows wrap to the column's width; the table alone
    // scrolls sideways ([`table_ui`]).
    egui::ScrollArea::vertical()
        .id_salt("compensate_scroll")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            ui.heading("Compensate targets through the calibration");
            let about = "The controller runs its nominal kinematics: each target (the TCP pose wanted, base frame) is replaced by the pose to command so that the nominal controller drives the joints the calibrated model needs for it. Positions are rewritten in place, every other byte kept.";
            ui.label(RichText::new(about).small().color(MUTED));
            ui.add_space(4.0);
            if state.result.is_none() {
                let text = "No calibration on show: run the calibration (step 4) or open a result file first.";
                coloured(ui, WARN, text);
            }
            pose_only_ui(ui, state, &mut forms.compensate, commands);
            inputs_ui(ui, state, &mut forms.compensate, commands);
            ui.separator();
            outcome_ui(ui, state, &mut forms.compensate, commands);
        });
}

/// A pose-only result: the current tool's path (`--current-tool`), and
/// without it what to do instead, with the tool data to install.
fn pose_only_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    form: &mut CompensateForm,
    commands: &mut Vec<Command>,
) {
    let Some(view) = state.result.as_ref().filter(|r| r.file.hand_eye_only()) else {
        return;
    };
    crate::app::widgets::boxed(ui, WARN, "A pose-only result", |ui| {
        crate::app::widgets::form_grid(ui, "compensate_current_tool", 3, |ui| {
            let hint = "the tool the controller holds now, with which the program was taught (JSON flange_from_tcp, or one line of the tool's values)";
            let busy = state.jobs.runs(&Slot::Dialog);
            crate::app::widgets::path_row(
                ui,
                "Current tool",
                &mut form.current_tool,
                hint,
                busy,
                Purpose::CompensateCurrentTool,
                commands,
            );
        });
        dialog_note_ui(ui, state, &[Purpose::CompensateCurrentTool]);
        if !form.current_tool.trim().is_empty() {
            ui.label(
                RichText::new(crate::engine::uses::compensate::tool_only::TOOL_ONLY_NOTE)
                    .small()
                    .color(MUTED),
            );
            return;
        }
        ui.add(egui::Label::new(RichText::new(super::POSE_ONLY_WHAT_TO_DO).color(WARN)).wrap());
        let tool = &view.file.hand_eye;
        let data: Vec<(String, String)> = crate::engine::base::robot::controller::Controller::ALL
            .iter()
            .map(|c| {
                (
                    c.tool_data_kind().to_string(),
                    c.tool_data(tool, crate::engine::uses::compensate::report::TOOL_NAME),
                )
            })
            .collect();
        let stale = state.ledger.stale(Artefact::Result).map(|s| s.to_string());
        tool_data_list_ui(ui, &data, stale.as_deref());
    });
}

/// The targets file, the pose convention, the TCP, and Compensate; each
/// row wraps to the column.
fn inputs_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    form: &mut CompensateForm,
    commands: &mut Vec<Command>,
) {
    let idle = !state.jobs.runs(&Slot::Dialog);
    ui.horizontal_wrapped(|ui| {
        let hint = "a pose table (.csv) or a robot program (.mod, .src/.dat, .ls, .script)";
        labelled_field(ui, "Targets file", &mut form.targets, hint, PATH_WIDTH);
        let open = Command::Browse(Purpose::CompensateTargets);
        let hover = "choose the targets file with the desktop's dialog";
        command_button(ui, idle, "Open targets…", hover, open, commands);
        dialog_note_ui(ui, state, &[Purpose::CompensateTargets]);
    });
    let on_demo = state
        .loaded
        .as_ref()
        .is_some_and(|l| l.source == Source::Demo);
    if on_demo && state.result.is_some() {
        let hover = format!(
            "the demo's cell: ten sensor poses along a scan path (examples/targets.csv of the guide), written to the export folder as {} and compensated",
            super::EXAMPLE_TARGETS_NAME
        );
        let example = Command::Compensate(CompensateCommand::ExampleTargets);
        command_button(
            ui,
            true,
            "Use the guide's example targets",
            &hover,
            example,
            commands,
        );
    }
    ui.horizontal_wrapped(|ui| {
        let conventions = FlangeConvention::ALL.map(|c| (Some(c), c.key().to_string()));
        let none = (None, CompensateForm::convention_label(None));
        let options = std::iter::once(none).chain(conventions);
        let id = "compensate_convention";
        choice(ui, "Pose convention", id, &mut form.convention, options);
        let what = "a table or JSON list needs one; a program's language fixes its own";
        let what = form.convention.map_or(what, FlangeConvention::describe);
        ui.label(RichText::new(what).small().color(MUTED));
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("TCP");
        for choice in TcpChoice::ALL {
            ui.radio_value(&mut form.tcp, choice, choice.label());
        }
    });
    if form.tcp == TcpChoice::ToolFile {
        ui.horizontal_wrapped(|ui| {
            let hint = "JSON: flange_from_tcp, a 4×4 matrix (rows, mm)";
            labelled_field(ui, "Tool file", &mut form.tool, hint, PATH_WIDTH);
            let open = Command::Browse(Purpose::CompensateTool);
            let hover = "choose the tool file with the desktop's dialog";
            command_button(ui, idle, "Open tool…", hover, open, commands);
            dialog_note_ui(ui, state, &[Purpose::CompensateTool]);
        });
    }
    options_ui(ui, &mut form.options);
    ui.add_space(4.0);
    ui.horizontal_wrapped(|ui| {
        if let Some(job) = state.jobs.get(&Slot::Compensate) {
            crate::app::widgets::job_ui(ui, job);
            let cancel = Command::Compensate(CompensateCommand::Cancel);
            command_button(ui, true, "Cancel", "stop compensating", cancel, commands);
            return;
        }
        let pose_only = state
            .result
            .as_ref()
            .is_some_and(|r| r.file.hand_eye_only());
        let why_not = if state.result.is_none() {
            Some("calibrate first: there is no result on show")
        } else if pose_only && form.current_tool.trim().is_empty() {
            Some("a pose-only result: give the current tool, or install the tool data above")
        } else if form.targets.trim().is_empty() {
            Some("choose a targets file first")
        } else {
            None
        };
        let text = RichText::new("Compensate targets").strong();
        let hover = "compensate every target through the result on show";
        let run = Command::Compensate(CompensateCommand::Run);
        command_button(ui, why_not.is_none(), text, hover, run, commands)
            .on_disabled_hover_text(why_not.unwrap_or_default());
        if let Some(w) = why_not {
            ui.label(RichText::new(w).small().color(MUTED));
        }
    });
}

/// What joint targets mean, and the three limits beyond which a target is
/// flagged (`--joint-targets`, `--sigma-tolerance`, `--far-joints`,
/// `--region-margin`).
fn options_ui(ui: &mut egui::Ui, options: &mut Options) {
    ui.horizontal_wrapped(|ui| {
        ui.label("Joint targets");
        let value = &mut options.joint_targets;
        let compensated =
            "compensated (offline-programmed: the nominal pose of the joints is wanted)";
        ui.radio_value(value, JointTargets::Compensate, compensated);
        ui.radio_value(
            value,
            JointTargets::Keep,
            "kept as written (taught on the robot)",
        );
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("Flag a target:");
        let limits: [(&str, &mut f64, f64, &str, &str); 3] = [
            (
                "σ tolerance",
                &mut options.sigma_tolerance_mm,
                100.0,
                " mm",
                "flagged when its predicted 1σ residual (ml covariance) exceeds this",
            ),
            (
                "far in joints",
                &mut options.far_joints_deg,
                720.0,
                "°",
                "flagged when farther than this from every identify pose (joint-space norm)",
            ),
            (
                "region margin",
                &mut options.region_margin_mm,
                10_000.0,
                " mm",
                "flagged when its working point lies farther than this outside the box of the identify working points",
            ),
        ];
        for (label, value, max, unit, hint) in limits {
            let drag = egui::DragValue::new(value).range(0.0..=max).speed(0.05);
            labelled_drag(ui, label, drag.max_decimals(3).suffix(unit)).on_hover_text(hint);
        }
    });
}

/// What the last compensation gave: its stale mark, the error naming the
/// target, or the summary, tool data, write row and table.
fn outcome_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    form: &mut CompensateForm,
    commands: &mut Vec<Command>,
) {
    let stale = state.ledger.stale(Artefact::Compensation);
    match &state.compensate.outcome {
        None => {
            ui.label(
                RichText::new(
                    "No compensation yet: choose a targets file and press Compensate targets.",
                )
                .color(MUTED),
            );
        }
        Some(Err(e)) => {
            ui.label(
                RichText::new("Not compensated (nothing can be written)")
                    .strong()
                    .color(BAD),
            );
            // One line a failed target (several are listed).
            egui::ScrollArea::vertical()
                .id_salt("compensate_failures")
                .max_height(300.0)
                .show(ui, |ui| {
                    for line in e.lines() {
                        ui.add(egui::Label::new(RichText::new(line).color(BAD)).wrap());
                    }
                });
        }
        Some(Ok(view)) => {
            if let Some(s) = &stale {
                stale_banner_ui(
                    ui,
                    s,
                    "The table below is not what the targets give now; writing is refused: press Compensate targets again.",
                );
            }
            ui.label(RichText::new(view.summary.line()).strong());
            ui.label(RichText::new(report::file_line(&view.file)).small());
            ui.label(RichText::new(format!("TCP: {}", view.tcp)).small());
            for w in &view.file.warnings {
                ui.label(RichText::new(format!("warning: {w}")).small().color(WARN));
            }
            for n in &view.notes {
                ui.label(RichText::new(format!("note: {n}")).small().color(MUTED));
            }
            let stale_why = stale.as_ref().map(ToString::to_string);
            tool_data_ui(ui, view, stale_why.as_deref());
            ui.add_space(4.0);
            write_ui(ui, state, form, stale.is_some(), commands);
            ui.add_space(6.0);
            table_ui(ui, &view.rows);
        }
    }
}

/// The tool data to set on the controller, each with a Copy button
/// (disabled with `stale`'s reason while the compensation is stale).
fn tool_data_ui(ui: &mut egui::Ui, view: &CompensationView, stale: Option<&str>) {
    if view.tool_data.is_empty() {
        return;
    }
    ui.add_space(4.0);
    ui.label(
        RichText::new("Tool data to set on the controller (the calibrated hand-eye): the compensated targets assume it")
            .strong(),
    );
    tool_data_list_ui(ui, &view.tool_data, stale);
}

/// Each controller's tool data with a Copy button, disabled with why
/// while `stale` (the result it was made of is out of date).
fn tool_data_list_ui(ui: &mut egui::Ui, data: &[(String, String)], stale: Option<&str>) {
    for (k, (controller, text)) in data.iter().enumerate() {
        ui.horizontal(|ui| {
            ui.label(RichText::new(controller).small());
            let copy = ui
                .push_id(("copy_tool", k), |ui| {
                    ui.add_enabled(stale.is_none(), egui::Button::new("Copy").small())
                })
                .inner
                .on_hover_text(format!("copy the {controller} to the clipboard"))
                .on_disabled_hover_text(format!("not copied: {}", stale.unwrap_or_default()));
            if copy.clicked() {
                ui.ctx().copy_text(text.clone());
            }
        });
        egui::Frame::group(ui.style()).show(ui, |ui| {
            ui.add(egui::Label::new(RichText::new(text.trim_end()).monospace().size(12.0)).wrap());
        });
    }
}

/// The output path, Write, and Write compensated program… (save
/// dialog); disabled with the reason when stale.
fn write_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    form: &mut CompensateForm,
    stale: bool,
    commands: &mut Vec<Command>,
) {
    let busy = state.jobs.writing() || state.jobs.runs(&Slot::Dialog);
    let why_not = stale.then_some("the compensation is stale: press Compensate targets again");
    ui.horizontal_wrapped(|ui| {
        let hint = "where the compensated file goes";
        labelled_field(ui, "Write to", &mut form.out, hint, PATH_WIDTH);
        let idle = why_not.is_none() && !busy;
        let buttons = [
            (
                "Write",
                "write the compensated file to this path (atomic: all or nothing)",
                Command::Compensate(CompensateCommand::Write),
            ),
            (
                "Write compensated program…",
                "choose where to write the compensated file",
                Command::Browse(Purpose::CompensateOut),
            ),
        ];
        for (text, hover, command) in buttons {
            command_button(ui, idle, text, hover, command, commands)
                .on_disabled_hover_text(why_not.unwrap_or("a file is being written"));
        }
        if let Some(w) = why_not {
            ui.label(RichText::new(w).small().color(WARN));
        }
    });
    dialog_note_ui(ui, state, &[Purpose::CompensateOut]);
    crate::app::widgets::written_ui(ui, state, &[Artefact::Compensation]);
}

/// One row per target, largest correction first; the table alone scrolls
/// sideways when it is wider than the column.
fn table_ui(ui: &mut egui::Ui, rows: &[TargetReport]) {
    let shown = rows.len().min(ROWS_SHOWN);
    if shown < rows.len() {
        let text = format!(
            "the {shown} largest corrections of {} targets (all are compensated and written)",
            rows.len()
        );
        ui.label(RichText::new(text).small().color(MUTED));
    }
    let headers = [
        ("target", "its name in the file"),
        ("line", "its line in the file"),
        (
            "correction mm",
            "how far the pose to command is from the target (TCP position)",
        ),
        (
            "correction °",
            "the rotation between the pose to command and the target",
        ),
        (
            "Δq max °",
            "the largest joint change between the nominal and the calibrated solution",
        ),
        (
            "σ mm (1σ)",
            "the predicted 1σ residual of the TCP position after compensation (ml's covariance)",
        ),
        (
            "nearest pose °",
            "joint-space distance to the nearest identify pose",
        ),
        (
            "flag",
            "why a target lies outside what the calibration saw (compensated and written all the same)",
        ),
    ];
    let or_dash = |v: Option<f64>, decimals: usize| {
        v.map_or_else(|| "–".to_string(), |v| format!("{v:.decimals$}"))
    };
    egui::ScrollArea::horizontal()
        .id_salt("compensate_table")
        .show(ui, |ui| {
            let grid = egui::Grid::new("compensate_targets").striped(true);
            grid.spacing([14.0, 3.0]).show(ui, |ui| {
                for (h, hover) in headers {
                    ui.label(RichText::new(h).strong()).on_hover_text(hover);
                }
                ui.end_row();
                for r in &rows[..shown] {
                    let flagged = !r.flags.is_empty();
                    let name = RichText::new(&r.name);
                    ui.label(if flagged { name.color(WARN) } else { name });
                    ui.label(r.line.to_string());
                    ui.label(format!("{:.3}", r.correction_mm));
                    ui.label(format!("{:.4}", r.correction_deg));
                    ui.label(format!("{:.3}", r.joint_change_deg));
                    ui.label(or_dash(r.sigma_mm, 3));
                    ui.label(or_dash(r.nearest_identify_deg, 1));
                    let flag = if flagged {
                        let why = flags_text(r);
                        RichText::new(format!("outside what the calibration saw: {why}"))
                            .color(WARN)
                    } else if !r.written {
                        RichText::new("joint target kept").color(MUTED)
                    } else {
                        RichText::new("")
                    };
                    let response = ui.label(flag);
                    if !r.notes.is_empty() {
                        response.on_hover_text(r.notes.join("\n"));
                    }
                    ui.end_row();
                }
            });
        });
}
