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
use crate::app::compensate::job::{CompensationView, TargetRow};
use crate::app::dialog::Purpose;
use crate::app::job::Slot;
use crate::app::ledger::Artefact;
use crate::app::widgets::{BAD, MUTED, WARN, dialog_note_ui, labelled_field, stale_banner_ui};
use crate::engine::base::robot::controller::FlangeConvention;
use crate::engine::uses::compensate::{JointTargets, Options};

/// Most target rows drawn (largest corrections first); every target is
/// compensated and written. A robot program has tens to a few hundred
/// targets; a table of thousands would make each frame slow.
const ROWS_SHOWN: usize = 1000;

/// Width of the path fields, points: a whole path at 1366×768 beside the
/// side panel.
const PATH_WIDTH: f32 = 420.0;

/// The Compensate view.
pub fn compensate_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    super::scene::scene_panel_ui(ui, state, forms);
    // Both ways: the rows wider than the view beside the scene scroll
    // instead of running under it.
    egui::ScrollArea::both()
        .id_salt("compensate_scroll")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            ui.heading("Compensate targets through the calibration");
            ui.label(
                RichText::new(
                    "The controller runs its nominal kinematics: each target (the TCP pose wanted, base frame) \
                     is replaced by the pose to command so that the nominal controller drives the joints the \
                     calibrated model needs for it. Positions are rewritten in place, every other byte kept.",
                )
                .small()
                .color(MUTED),
            );
            ui.add_space(4.0);
            if state.result.is_none() {
                ui.label(
                    RichText::new(
                        "No calibration on show: run the calibration (step 4) or open a result file first.",
                    )
                    .color(WARN),
                );
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

/// The targets file, the pose convention, the TCP, and Compensate.
fn inputs_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    form: &mut CompensateForm,
    commands: &mut Vec<Command>,
) {
    let dialog_busy = state.jobs.runs(&Slot::Dialog);
    egui::Grid::new("compensate_inputs")
        .num_columns(2)
        .spacing([8.0, 6.0])
        .show(ui, |ui| {
            ui.label("Targets");
            ui.horizontal(|ui| {
                labelled_field(
                    ui,
                    "file",
                    &mut form.targets,
                    "a pose table (.csv) or a robot program (.mod, .src/.dat, .ls, .script)",
                    PATH_WIDTH,
                );
                if ui
                    .add_enabled(!dialog_busy, egui::Button::new("Open targets…"))
                    .clicked()
                {
                    commands.push(Command::Browse(Purpose::CompensateTargets));
                }
                dialog_note_ui(ui, state, &[Purpose::CompensateTargets]);
            });
            ui.end_row();
            let on_demo = state
                .loaded
                .as_ref()
                .is_some_and(|l| l.source == crate::app::session::Source::Demo);
            if on_demo && state.result.is_some() {
                ui.label("");
                if ui
                    .button("Use the guide's example targets")
                    .on_hover_text(format!(
                        "the demo's cell: ten sensor poses along a scan path (examples/targets.csv of the guide), written to the export folder as {} and compensated",
                        super::EXAMPLE_TARGETS_NAME
                    ))
                    .clicked()
                {
                    commands.push(Command::Compensate(CompensateCommand::ExampleTargets));
                }
                ui.end_row();
            }

            let l = ui.label("Pose convention");
            ui.horizontal(|ui| {
                egui::ComboBox::from_id_salt("compensate_convention")
                    .selected_text(CompensateForm::convention_label(form.convention))
                    .width(260.0)
                    .show_ui(ui, |ui| {
                        ui.selectable_value(
                            &mut form.convention,
                            None,
                            CompensateForm::convention_label(None),
                        );
                        for c in FlangeConvention::ALL {
                            ui.selectable_value(&mut form.convention, Some(c), c.key())
                                .on_hover_text(c.describe());
                        }
                    })
                    .response
                    .labelled_by(l.id);
                ui.label(
                    RichText::new(form.convention.map_or(
                        "a table or JSON list needs one; a program's language fixes its own",
                        FlangeConvention::describe,
                    ))
                    .small()
                    .color(MUTED),
                );
            });
            ui.end_row();

            ui.label("TCP");
            ui.horizontal(|ui| {
                for choice in TcpChoice::ALL {
                    ui.radio_value(&mut form.tcp, choice, choice.label());
                }
            });
            ui.end_row();
            if form.tcp == TcpChoice::ToolFile {
                ui.label("");
                ui.horizontal(|ui| {
                    labelled_field(
                        ui,
                        "tool",
                        &mut form.tool,
                        "JSON: flange_from_tcp, a 4×4 matrix (rows, mm)",
                        PATH_WIDTH - 30.0,
                    );
                    if ui
                        .add_enabled(!dialog_busy, egui::Button::new("Open tool…"))
                        .clicked()
                    {
                        commands.push(Command::Browse(Purpose::CompensateTool));
                    }
                    dialog_note_ui(ui, state, &[Purpose::CompensateTool]);
                });
                ui.end_row();
            }
            options_rows_ui(ui, &mut form.options);
        });
    ui.add_space(4.0);
    ui.horizontal(|ui| {
        if let Some(job) = state.jobs.get(&Slot::Compensate) {
            crate::app::widgets::job_ui(ui, job);
            if ui.button("Cancel").clicked() {
                commands.push(Command::Compensate(CompensateCommand::Cancel));
            }
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
        let button = egui::Button::new(RichText::new("Compensate targets").strong());
        let response = ui
            .add_enabled(why_not.is_none(), button)
            .on_hover_text("compensate every target through the result on show")
            .on_disabled_hover_text(why_not.unwrap_or_default());
        if response.clicked() {
            commands.push(Command::Compensate(CompensateCommand::Run));
        }
        if let Some(w) = why_not {
            ui.label(RichText::new(w).small().color(MUTED));
        }
    });
}

/// What joint targets mean, and the three limits beyond which a target is
/// flagged (`--joint-targets`, `--sigma-tolerance`, `--far-joints`,
/// `--region-margin`); rows of the inputs grid.
fn options_rows_ui(ui: &mut egui::Ui, options: &mut Options) {
    ui.label("Joint targets");
    ui.horizontal(|ui| {
        ui.radio_value(
            &mut options.joint_targets,
            JointTargets::Compensate,
            "compensated (offline-programmed: the nominal pose of the joints is wanted)",
        );
        ui.radio_value(
            &mut options.joint_targets,
            JointTargets::Keep,
            "kept as written (taught on the robot)",
        );
    });
    ui.end_row();

    ui.label("Flag a target");
    ui.horizontal_wrapped(|ui| {
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
            let l = ui.label(label);
            ui.add(
                egui::DragValue::new(value)
                    .range(0.0..=max)
                    .speed(0.05)
                    .max_decimals(3)
                    .suffix(unit),
            )
            .labelled_by(l.id)
            .on_hover_text(hint);
        }
    });
    ui.end_row();
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
            ui.label(RichText::new(&view.summary).strong());
            ui.add(egui::Label::new(RichText::new(&view.file_line).small()).wrap());
            ui.label(RichText::new(format!("TCP: {}", view.tcp)).small());
            for w in &view.warnings {
                ui.label(RichText::new(format!("warning: {w}")).small().color(WARN));
            }
            for n in &view.notes {
                ui.add(
                    egui::Label::new(RichText::new(format!("note: {n}")).small().color(MUTED))
                        .wrap(),
                );
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
        labelled_field(
            ui,
            "Write to",
            &mut form.out,
            "where the compensated file goes",
            PATH_WIDTH - 60.0,
        );
        let write = ui
            .add_enabled(why_not.is_none() && !busy, egui::Button::new("Write"))
            .on_hover_text("write the compensated file to this path (atomic: all or nothing)");
        if let Some(w) = why_not {
            write.clone().on_disabled_hover_text(w);
        }
        if write.clicked() {
            commands.push(Command::Compensate(CompensateCommand::Write));
        }
        let dialog = ui
            .add_enabled(
                why_not.is_none() && !busy,
                egui::Button::new("Write compensated program…"),
            )
            .on_hover_text("choose where to write the compensated file");
        if let Some(w) = why_not {
            dialog.clone().on_disabled_hover_text(w);
        }
        if dialog.clicked() {
            commands.push(Command::Browse(Purpose::CompensateOut));
        }
        if let Some(w) = why_not {
            ui.label(RichText::new(w).small().color(WARN));
        }
    });
    dialog_note_ui(ui, state, &[Purpose::CompensateOut]);
    crate::app::widgets::written_ui(ui, state, &[Artefact::Compensation]);
}

/// One row per target, largest correction first.
fn table_ui(ui: &mut egui::Ui, rows: &[TargetRow]) {
    let shown = rows.len().min(ROWS_SHOWN);
    if shown < rows.len() {
        ui.label(
            RichText::new(format!(
                "the {shown} largest corrections of {} targets (all are compensated and written)",
                rows.len()
            ))
            .small()
            .color(MUTED),
        );
    }
    egui::Grid::new("compensate_targets")
        .striped(true)
        .num_columns(8)
        .spacing([14.0, 3.0])
        .show(ui, |ui| {
            for (h, hover) in [
                ("target", "its name in the file"),
                ("line", "its line in the file"),
                ("correction mm", "how far the pose to command is from the target (TCP position)"),
                ("correction °", "the rotation between the pose to command and the target"),
                ("Δq max °", "the largest joint change between the nominal and the calibrated solution"),
                ("σ mm (1σ)", "the predicted 1σ residual of the TCP position after compensation (ml's covariance)"),
                ("nearest pose °", "joint-space distance to the nearest identify pose"),
                ("flag", "why a target lies outside what the calibration saw (compensated and written all the same)"),
            ] {
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
                ui.label(r.sigma_mm.map_or_else(|| "–".to_string(), |s| format!("{s:.3}")));
                ui.label(
                    r.nearest_identify_deg
                        .map_or_else(|| "–".to_string(), |d| format!("{d:.1}")),
                );
                let flag = if flagged {
                    RichText::new(format!("outside what the calibration saw: {}", r.flags.join("; ")))
                        .color(WARN)
                } else if r.kept {
                    RichText::new("joint target kept").color(MUTED)
                } else {
                    RichText::new("")
                };
                let response = ui.add(egui::Label::new(flag).wrap());
                if !r.notes.is_empty() {
                    response.on_hover_text(r.notes.join("\n"));
                }
                ui.end_row();
            }
        });
}
