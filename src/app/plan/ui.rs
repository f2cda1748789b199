//! The Plan view: the pose planner's settings, Make plan with progress and
//! Cancel, then the plan's quality (identifiable parameters, D-optimality
//! against a random choice, condition number, predicted accuracy), a top
//! view of the stations, the poses, and the exports (the joint-log CSV and
//! an ABB RAPID module). Nothing is computed here.

use egui::RichText;
use egui_plot::{MarkerShape, Plot, PlotPoints, Points};

use crate::app::AppState;
use crate::app::command::PlanExport;
use crate::app::command::{Command, PlanCommand};
use crate::app::dialog::Purpose;
use crate::app::job::Slot;
use crate::app::ledger::{Artefact, Stale};
use crate::app::widgets::{
    AFTER, BAD, BEFORE, DEFAULT_RANGE, MUTED, command_button, export_folder_ui, preset_ui,
    range_fields, range_of, range_values,
};
use crate::app::{Forms, plan::form::default_sphere};
use crate::engine::tools::plan::{
    Controller, MAX_PREDICT_RUNS, Plan, PlanStats, Planned, StationRole,
};

/// Width of the settings column, points.
const FORM_WIDTH: f32 = 330.0;
/// Height of the station map, points.
const MAP_HEIGHT: f32 = 260.0;

/// The whole Plan view.
pub fn plan_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    ui.horizontal_top(|ui| {
        ui.allocate_ui_with_layout(
            egui::vec2(FORM_WIDTH, ui.available_height()),
            egui::Layout::top_down(egui::Align::Min),
            |ui| {
                egui::ScrollArea::vertical()
                    .id_salt("plan_form")
                    .show(ui, |ui| form_ui(ui, state, forms, commands));
            },
        );
        ui.separator();
        ui.vertical(|ui| {
            egui::ScrollArea::vertical()
                .id_salt("plan_result")
                .auto_shrink([false, false])
                .show(ui, |ui| match &state.plan.outcome {
                    None => {
                        ui.label(
                            RichText::new(
                                "Set the robot and where the sphere roughly stands, then Make plan. \
                                 The planner places identify and validate stations around it, solves \
                                 every reachable pose with the laser plane cutting the sphere at the \
                                 cut angle on both sides, picks the poses that determine the parameters \
                                 best (D-optimal; for a measuring range, the smallest predicted error over it) and orders them for short moves.",
                            )
                            .weak(),
                        );
                    }
                    Some(Err(e)) => {
                        ui.label(RichText::new("No plan").strong().color(BAD));
                        ui.label(e);
                    }
                    Some(Ok(o)) => outcome_ui(ui, state, forms, o, commands),
                });
        });
    });
}

fn form_ui(ui: &mut egui::Ui, state: &AppState, forms: &mut Forms, commands: &mut Vec<Command>) {
    let f = &mut forms.plan;
    ui.heading("Pose plan");
    egui::Grid::new("plan_form_grid")
        .num_columns(2)
        .spacing([8.0, 6.0])
        .show(ui, |ui| {
            let l = ui.label("Robot");
            let before = f.robot.clone();
            preset_ui(ui, "plan_robot", &mut f.robot).labelled_by(l.id);
            if f.robot != before {
                f.request.design.sphere = default_sphere(&f.robot);
            }
            ui.end_row();
            for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                let l = ui.label(format!("Sphere {axis}"));
                ui.add(
                    egui::DragValue::new(&mut f.request.design.sphere[k])
                        .speed(1.0)
                        .max_decimals(1)
                        .suffix(" mm"),
                )
                .labelled_by(l.id)
                .on_hover_text("rough sphere position in the robot base frame");
                ui.end_row();
            }
            // The engine's bounds (as `spherecal plan` has them); a value
            // beyond is kept and said below, never clamped silently. A
            // typed value counts on Enter or when the field loses focus.
            let counts: [(&str, &mut usize, &str); 8] = [
                ("Translations", &mut f.request.design.n_translation, "pure translations at P0 (initial rotation, eq. 6-7)"),
                ("Rotations", &mut f.request.design.n_rotation, "orientation changes at P0 (initial translation, eq. 8-9)"),
                ("Identify stations", &mut f.request.design.n_identify, "sphere positions for the identification"),
                ("Poses per identify station", &mut f.request.design.identify_poses, "measurements at each identify station"),
                ("Validate stations", &mut f.request.design.n_validate, "sphere positions held out, with tracker distances"),
                ("Poses per validate station", &mut f.request.design.validate_poses, "measurements at each validate station"),
                ("Candidates per station", &mut f.request.design.candidates, "orientations tried per station before selection"),
                ("Predicted by (runs)", &mut f.request.predict_runs, "simulated calibrations for the predicted accuracy (0: none)"),
            ];
            for (label, value, hint) in counts {
                let l = ui.label(label);
                ui.add(
                    egui::DragValue::new(value)
                        .range(0..=COUNT_FIELD_MAX)
                        .speed(0.1)
                        .update_while_editing(false),
                )
                .labelled_by(l.id)
                .on_hover_text(hint);
                ui.end_row();
            }
            let l = ui.label("Cut angle");
            ui.add(
                egui::DragValue::new(&mut f.request.design.cut_angle)
                    .range(5.0..=80.0)
                    .speed(0.2)
                    .suffix(" deg"),
            )
            .labelled_by(l.id)
            .on_hover_text("the laser plane cuts the sphere this far from its centre (sphere centre at sensor x = ±R·sin)");
            ui.end_row();
            let l = ui.label("Seed");
            ui.add(egui::DragValue::new(&mut f.request.design.seed).speed(0.2))
                .labelled_by(l.id)
                .on_hover_text("the same settings and seed give the same plan");
            ui.end_row();
        });
    if let Some(why) = settings_error(f) {
        ui.add(
            egui::Label::new(RichText::new(format!("not plannable as set: {why}")).color(BAD))
                .wrap(),
        );
    }
    let mut known = f.request.range.is_some();
    if ui
        .checkbox(&mut known, "plan for the measuring range")
        .on_hover_text("sensor.range: predict the error over this part of the laser plane and spread the sphere over it")
        .changed()
    {
        f.request.range = if known {
            range_of(&DEFAULT_RANGE).ok()
        } else {
            None
        };
        f.request.spread = known;
    }
    if let Some(r) = f.request.range {
        let mut v = range_values(&r);
        if range_fields(ui, "plan_range", &mut v, true)
            && let Ok(r) = range_of(&v)
        {
            f.request.range = Some(r);
        }
    }
    if f.request.range.is_some() {
        ui.checkbox(&mut f.request.spread, "spread the sphere over the range")
            .on_hover_text("identify and validate poses see the sphere anywhere in the range, chosen for the smallest predicted error over it; unticked: the paper's one spot");
    }
    ui.checkbox(
        &mut f.hand_eye_from_session,
        "hand-eye guess from the open calibration",
    )
    .on_hover_text("the calibrated hand-eye of the result on show, else the open session's; unticked: the paper's initial hand-eye");
    ui.add_space(6.0);
    ui.horizontal(|ui| {
        let running = state.jobs.runs(&Slot::Plan);
        let wrong = settings_error(f);
        let make = Command::Plan(PlanCommand::Make);
        let text = RichText::new("Make plan").strong().size(16.0);
        let hover = "plan the poses on a background thread";
        command_button(ui, !running && wrong.is_none(), text, hover, make, commands)
            .on_disabled_hover_text(wrong.unwrap_or_else(|| "a plan is being made".into()));
        let cancel = Command::Plan(PlanCommand::Cancel);
        command_button(
            ui,
            running,
            "Cancel plan",
            "stop planning",
            cancel,
            commands,
        );
    });
    crate::app::widgets::slot_ui(ui, state, &Slot::Plan);
}

/// The largest count a field takes: far beyond every bound of the
/// engine (stations, poses, candidates, runs), so that a value over a
/// bound is kept and said ([`settings_error`]) rather than clamped.
const COUNT_FIELD_MAX: usize = 1_000_000;

/// What is wrong with the form's settings, in the engine's words (the
/// bounds `spherecal plan` checks), or `None`.
fn settings_error(f: &crate::app::plan::form::PlanForm) -> Option<String> {
    if f.request.predict_runs > MAX_PREDICT_RUNS {
        return Some(format!(
            "{} prediction runs asked for: at most {MAX_PREDICT_RUNS}",
            f.request.predict_runs
        ));
    }
    let checked = crate::app::plan::form::PlanForm {
        hand_eye_from_session: false,
        ..f.clone()
    };
    match checked.config(None) {
        Ok(config) => config.validate().err().map(|e| e.to_string()),
        Err(e) => Some(e),
    }
}

/// The predicted validation std after calibration (simulated
/// calibrations of the plan), or why there is none.
fn prediction_ui(ui: &mut egui::Ui, o: &Planned) {
    match &o.prediction {
        Some(Ok(p)) => {
            ui.label(
                RichText::new(format!(
                    "Predicted validation std after: {:.3} ± {:.3} mm",
                    p.after_mean, p.after_spread
                ))
                .size(24.0)
                .strong()
                .color(AFTER),
            );
            ui.label(format!(
                "{} simulated calibrations (random kinematic errors, default noise, ml): before {:.3} mm, noise floor {:.3} mm, after / floor {:.2}×",
                p.runs.len(),
                p.before_mean,
                p.floor_mean,
                p.ratio_mean
            ));
            if let Some(r) = &p.range {
                ui.label(format!(
                    "error over the range in those calibrations: rms {:.3} mm (max {:.3} mm), floor {:.3} mm, after / floor {:.2}×",
                    r.after_rms, r.after_max, r.floor_rms, r.ratio_mean
                ));
            }
        }
        Some(Err(e)) => {
            ui.label(RichText::new(format!("No prediction: {e}")).color(BAD));
        }
        None => {
            ui.label(RichText::new("No prediction asked for (runs = 0).").weak());
        }
    }
}

/// The plan's statistics: candidates, D-optimality, condition, predicted
/// errors over the range, path length, parameters identified, and what
/// the data cannot identify or separate.
fn stats_ui(ui: &mut egui::Ui, st: &PlanStats) {
    egui::Grid::new("plan_stats")
        .num_columns(2)
        .spacing([12.0, 4.0])
        .show(ui, |ui| {
            let mut row = |k: &str, v: String| {
                ui.label(k);
                ui.label(v);
                ui.end_row();
            };
            row("reachable candidates", st.candidates.to_string());
            row(
                "D-optimality, ln det",
                format!(
                    "{:.1} (a random choice of as many: {:.1}, {:+.1})",
                    st.log_det,
                    st.log_det_random,
                    st.log_det - st.log_det_random
                ),
            );
            row("condition number", format!("{:.3e}", st.condition));
            if let Some(r) = &st.range_error {
                let what = if r.region == "sensor.range" {
                    "predicted error over the range"
                } else {
                    "predicted error where the sphere is seen"
                };
                row(
                    what,
                    format!(
                        "rms {:.3} mm, max {:.3} mm (y {:.0}…{:.0}, z {:.0}…{:.0} mm)",
                        r.rms_mm, r.max_mm, r.y[0], r.y[1], r.z[0], r.z[1]
                    ),
                );
            }
            if let Some(u) = &st.range_error_unspread {
                row(
                    "the same without the spread",
                    format!("rms {:.3} mm, max {:.3} mm", u.rms_mm, u.max_mm),
                );
            }
            if let Some(s) = st.predicted_validation_std {
                row("ml's expected std after (covariance)", format!("{s:.3} mm"));
            }
            row(
                "path, weighted joint distance",
                format!(
                    "{:.0} deg in plan order ({:.0} deg as generated)",
                    st.path_deg, st.path_unordered_deg
                ),
            );
            row(
                "parameters identified",
                format!(
                    "{} of {}",
                    st.estimated.len(),
                    st.estimated.len() + st.fixed.len()
                ),
            );
        });
    if !st.fixed.is_empty() {
        ui.label(
            RichText::new(format!(
                "Not identifiable from sphere data: {}",
                st.fixed.join(", ")
            ))
            .color(MUTED),
        );
    }
    if !st.inseparable.is_empty() {
        egui::CollapsingHeader::new("combinations the data cannot separate")
            .id_salt("plan_inseparable")
            .show(ui, |ui| {
                for s in &st.inseparable {
                    ui.label(s.to_string());
                }
            });
    }
}

/// The export row: the folder, the Plan CSV and the controller's program,
/// and "Simulate and open"; refused while a file is written or the plan
/// is stale.
fn export_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    stale: Option<&Stale>,
    commands: &mut Vec<Command>,
) {
    let refused = stale.map_or_else(
        || "a file is being written".to_string(),
        |s| format!("refused: {s}; press Make plan"),
    );
    let busy = state.jobs.writing() || state.jobs.runs(&Slot::Simulate);
    ui.horizontal_wrapped(|ui| {
        export_folder_ui(ui, "Write to folder", &mut forms.export_dir, 240.0, commands);
        let robot_name = crate::engine::base::robot::presets::preset(&forms.plan.robot)
            .map(|p| p.robot.name)
            .unwrap_or_default();
        let controller = crate::engine::tools::plan::program_controller(&robot_name);
        if controller.is_none() {
            ui.label(
                RichText::new(format!(
                    "no program export for the controller of {robot_name}: use the Plan CSV"
                ))
                .color(MUTED),
            );
        }
        let exports = std::iter::once(PlanExport::Csv).chain(controller.map(PlanExport::Program));
        let mut buttons: Vec<(String, &str, Command)> = exports
            .map(|kind| {
                let hint = match kind {
                    PlanExport::Csv => "the joint-log CSV that `spherecal import` reads (id, station, use, side, joints, nominal ABB flange pose)",
                    PlanExport::Program(Controller::Abb) => "an ABB RAPID module: one jointtarget per pose, MoveAbsJ in plan order, a stop per measurement",
                    PlanExport::Program(Controller::Ur) => "a URScript program for a Universal Robots controller: one movej per pose (rad), a popup per station, a measure hook",
                    // Only the controllers of plan::PROGRAMS are offered.
                    PlanExport::Program(_) => "the controller's program",
                };
                (kind.label().to_string(), hint, Command::Plan(PlanCommand::Export(kind)))
            })
            .collect();
        buttons.push((
            "Simulate and open".to_string(),
            "a session of this plan on a simulated robot with kinematic errors, each pose touched up as when teaching: try the calibration before going to the cell",
            Command::Plan(PlanCommand::Simulate),
        ));
        for (text, hint, command) in buttons {
            command_button(ui, !busy && stale.is_none(), text, hint, command, commands)
                .on_disabled_hover_text(&refused);
        }
    });
}

fn outcome_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    o: &Planned,
    commands: &mut Vec<Command>,
) {
    let plan = &o.plan;
    let st = &plan.stats;
    let stale = state.ledger.stale(Artefact::Plan);
    if let Some(s) = &stale {
        crate::app::widgets::stale_banner_ui(
            ui,
            s,
            "Its program, CSV and simulation are refused until you press Make plan.",
        );
    }
    ui.label(RichText::new(plan.pose_counts()).strong().size(16.0));
    prediction_ui(ui, o);
    stats_ui(ui, st);
    ui.separator();
    export_ui(ui, state, forms, stale.as_ref(), commands);
    crate::app::widgets::dialog_note_ui(ui, state, &[Purpose::ExportFolder]);
    ui.separator();
    super::scene::plan_scene_ui(ui, forms, plan, stale.is_some());
    super::scene::poses_table_ui(ui, forms, plan);
    ui.separator();
    ui.label(RichText::new("Stations seen from above (base frame x, y in mm)").strong());
    map_ui(ui, plan);
}

fn map_ui(ui: &mut egui::Ui, plan: &Plan) {
    let of = |role| -> Vec<[f64; 2]> {
        plan.stations
            .iter()
            .filter(|s| s.role == role)
            .map(|s| [s.position.x, s.position.y])
            .collect()
    };
    let base = plan.robot.base.translation.vector;
    let roles = [
        (
            "◆ P0 (hand-eye groups)",
            BAD,
            StationRole::HandEye,
            MarkerShape::Diamond,
            6.0,
        ),
        (
            "● identify",
            AFTER,
            StationRole::Identify,
            MarkerShape::Circle,
            5.0,
        ),
        (
            "■ validate",
            BEFORE,
            StationRole::Validate,
            MarkerShape::Square,
            5.0,
        ),
    ];
    // The key names only what is drawn.
    let mut key: Vec<(&str, egui::Color32)> = roles
        .iter()
        .filter(|r| !of(r.2).is_empty())
        .map(|r| (r.0, r.1))
        .collect();
    key.push(("× robot base", MUTED));
    crate::app::widgets::plot_key(ui, &key);
    crate::app::widgets::plots::readable(Plot::new("plan_map"), false)
        .height(MAP_HEIGHT)
        .data_aspect(1.0)
        // The wheel scrolls the view, not the map (drag still pans).
        .allow_scroll(false)
        .x_axis_label("x (mm)")
        .y_axis_label("y (mm)")
        .show(ui, |p| {
            let base = PlotPoints::from(vec![[base.x, base.y]]);
            let base = Points::new("robot base", base).shape(MarkerShape::Cross);
            p.points(base.radius(7.0).color(MUTED));
            for (name, colour, role, shape, radius) in roles {
                let name = name.split_once(' ').map_or(name, |(_, n)| n);
                let points = Points::new(name, PlotPoints::from(of(role))).shape(shape);
                p.points(points.radius(radius).color(colour));
            }
        });
}
