//! The Import view: a wizard that turns a pose log and stripe profile
//! files into a session (the engine's [`crate::engine::files::import`], as
//! `spherecal import`). A joint log CSV, or a pose file in any layout the
//! engine reads (tables with or without a header, `.rob`, FANUC `.ls`,
//! RAPID, KUKA, URScript; [`super::poses_ui`]: layout detected,
//! pairing shown before the import, a hand-eye guess, centres); profiles
//! as CSV/TXT or OpenCV YAML/JSON in the sensor's axes. Steps on one page:
//! files, robot, units and axes, column mapping with a preview of the
//! first rows (joint logs); then Import opens the session and says what it
//! decided (axis map, side, initial hand-eye) and the flange-pose checks.

use std::path::PathBuf;

use egui::RichText;

use crate::app::AppState;
use crate::app::Forms;
use crate::app::command::{Command, ImportCommand};
use crate::app::dialog::Purpose;
use crate::app::import::form::{
    CONVENTIONS, ImportChoices, LogKind, ObservationKind, ProfilesKind,
};
use crate::app::job::Slot;
use crate::app::widgets::{
    BAD, DEFAULT_RANGE, GOOD, PATH_WIDTH, WARN, boxed, choice, coloured, command_button, form_grid,
    labelled_drag, labelled_field, path_row, preset_ui, range_fields, range_of, scrolled_text,
    table, weak,
};
use crate::engine::base::session::Mount;
use crate::engine::files::import::{AngleUnit, LengthUnit, SideChoice};
use crate::engine::files::robot_import::DhConvention;

/// Largest height of the import's error above the form, points: a long
/// message scrolls rather than push the form off a 768-pixel screen.
const ERROR_HEIGHT: f32 = 90.0;
/// Width of a column-name field, points.
const COLUMN_WIDTH: f32 = 90.0;

/// The whole Import view. An edit makes the preview, the last outcome
/// and the checks stale (the ledger clears them); a pose file that reads
/// otherwise than at the last scan is read and paired again (the ledger
/// asks for it).
pub fn import_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    ui.heading("Import a pose log and stripe profiles");
    crate::app::widgets::dialog_note_ui(
        ui,
        state,
        &[
            Purpose::ImportJoints,
            Purpose::ImportPoses,
            Purpose::ImportProfiles,
            Purpose::ImportReferences,
            Purpose::ImportCentres,
            Purpose::ImportHandEye,
        ],
    );
    ui.label(
        RichText::new(
            "A joint log (id, station, use, joints a row) or a pose file as the cell wrote it (program or table; \
             flange poses give a pose-only session); one profile file a pose (CSV/TXT, OpenCV YAML/JSON), one file \
             with a pose column, or the sensor's sphere centres. Checked by the session file's rules.",
        )
        .weak(),
    );
    let jobs = &state.jobs;
    let busy = [Slot::Import, Slot::ImportPreview, Slot::Dialog]
        .iter()
        .any(|s| jobs.runs(s));
    let cx = &mut Ctx {
        state,
        busy,
        commands,
    };
    let f = &mut forms.import;
    let joints = f.log_kind == LogKind::Joints;
    let poses = !joints && f.mount == Mount::Flange;
    // The actions stay in view above the form (it is taller than the
    // window at 1366×768); the full outcome is at the form's end.
    actions_ui(ui, cx, joints);
    ui.separator();
    egui::ScrollArea::vertical()
        .auto_shrink([false, false])
        .show(ui, |ui| {
            files_ui(ui, cx, f);
            ui.separator();
            if poses {
                super::poses_ui::detected_ui(ui, cx);
                ui.separator();
                super::poses_ui::hand_eye_ui(ui, cx, f);
                ui.separator();
            }
            robot_ui(ui, f);
            ui.separator();
            if joints {
                mapping_ui(ui, state, f);
                ui.separator();
            }
            if joints && f.mount == Mount::Flange {
                flange_ui(ui, f);
                ui.separator();
            }
            if !poses {
                // A start for a joint log's or a fixed sensor's session
                // (`--hand-eye`), below what the import needs.
                super::poses_ui::hand_eye_ui(ui, cx, f);
                ui.separator();
            }
            outcome_ui(ui, state);
            preview_ui(ui, state);
        });
}

/// Preview and Guess mapping (joint logs), Import and open, and the last
/// outcome in one line.
fn actions_ui(ui: &mut egui::Ui, cx: &mut Ctx<'_>, joints: bool) {
    let state = cx.state;
    ui.horizontal_wrapped(|ui| {
        let text = RichText::new("Import and open").strong().size(16.0);
        let hover = "build the session and open it (save it with Save as… afterwards)";
        cx.button(ui, text, hover, ImportCommand::Run);
        if joints {
            let hover = "read the header and show the first rows with this mapping";
            let preview = ImportCommand::Preview { guess: false };
            cx.button(ui, "Preview", hover, preview);
            let hover = "fill the column names from the header where they are obvious";
            let guess = ImportCommand::Preview { guess: true };
            cx.button(ui, "Guess mapping", hover, guess);
        }
        if let Some(job) = state.jobs.get(&Slot::Import) {
            crate::app::widgets::job_ui(ui, job);
            let hover = "stop the import: nothing is opened, what is open stays";
            let cancel = Command::Import(ImportCommand::Cancel);
            command_button(ui, true, "Cancel import", hover, cancel, cx.commands);
        } else if state.jobs.runs(&Slot::ImportPreview) {
            ui.spinner();
        }
        if let Some(Ok(text)) = &state.import.outcome {
            coloured(ui, GOOD, text.lines().next().unwrap_or_default());
        }
    });
    if let Some(Err(e)) = &state.import.outcome {
        boxed(ui, BAD, "The import failed", |ui| {
            if state.import.guess_needed.is_some() {
                let what = "A hand-eye guess is needed: give one under \"Initial hand-eye\" below (numbers or a file).";
                ui.label(RichText::new(what).strong());
            }
            scrolled_text(ui, "import_error", ERROR_HEIGHT, e);
        });
    }
}

/// A row of radio buttons, one a choice.
pub(super) fn radios<T: PartialEq + Copy>(ui: &mut egui::Ui, value: &mut T, choices: &[(T, &str)]) {
    for (v, text) in choices {
        ui.radio_value(value, *v, *text);
    }
}

/// A grid row: `label`, then `add`'s widgets side by side.
fn row(ui: &mut egui::Ui, label: &str, add: impl FnOnce(&mut egui::Ui)) {
    ui.label(label);
    ui.horizontal(add);
    ui.end_row();
}

/// A line of its own: `label`, then a radio button a choice.
fn radio_line<T: PartialEq + Copy>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    choices: &[(T, &str)],
) {
    ui.horizontal(|ui| {
        ui.label(label);
        radios(ui, value, choices);
    });
}

/// What the Import view's parts share: the state shown, whether a job
/// runs (the buttons wait for it), the commands asked for.
pub(super) struct Ctx<'a> {
    pub state: &'a AppState,
    pub busy: bool,
    pub commands: &'a mut Vec<Command>,
}

impl Ctx<'_> {
    /// A path field with its Browse… button (a row of a three-column
    /// grid).
    pub(super) fn path(
        &mut self,
        ui: &mut egui::Ui,
        (label, hint): (&str, &str),
        path: &mut PathBuf,
        purpose: Purpose,
    ) {
        let shown = path.to_string_lossy().into_owned();
        let mut text = shown.clone();
        path_row(
            ui,
            label,
            &mut text,
            hint,
            self.busy,
            purpose,
            self.commands,
        );
        if text != shown {
            *path = PathBuf::from(text);
        }
    }

    /// A button asking for `command` (greyed out while a job runs).
    pub(super) fn button(
        &mut self,
        ui: &mut egui::Ui,
        text: impl Into<egui::WidgetText>,
        hover: &str,
        command: ImportCommand,
    ) -> egui::Response {
        let command = Command::Import(command);
        command_button(ui, !self.busy, text, hover, command, self.commands)
    }
}

fn files_ui(ui: &mut egui::Ui, cx: &mut Ctx<'_>, f: &mut ImportChoices) {
    ui.label(RichText::new("1 · Files").strong());
    let mounts = [
        (Mount::Flange, "on the flange, the sphere in the cell"),
        (
            Mount::Fixed,
            "fixed in the cell, targets on the tool (a tracker, camera or line scanner)",
        ),
    ];
    radio_line(ui, "Sensor", &mut f.mount, &mounts);
    let logs = [
        (LogKind::Joints, "joint log (CSV)"),
        (
            LogKind::FlangePoses,
            "a pose file (robot program or pose table)",
        ),
    ];
    radio_line(ui, "Pose log", &mut f.log_kind, &logs);
    let fixed = f.mount == Mount::Fixed;
    form_grid(ui, "import_files", 3, |ui| {
        if f.log_kind == LogKind::Joints {
            let what = ("Joint log CSV", "/path/to/joints.csv");
            cx.path(ui, what, &mut f.joints, Purpose::ImportJoints);
        } else {
            super::poses_ui::pose_file_rows(ui, cx, f);
        }
        if fixed || f.log_kind == LogKind::FlangePoses {
            observations_row(ui, f);
        }
        if f.observations == ObservationKind::Centres
            && (fixed || f.log_kind == LogKind::FlangePoses)
        {
            let what = if fixed {
                (
                    "Points table",
                    "x y z a target and pose (sensor frame), a tracker's export",
                )
            } else {
                (
                    "Centres file",
                    "x y z a pose (sensor frame, mm), paired with the poses in order",
                )
            };
            cx.path(ui, what, &mut f.centres, Purpose::ImportCentres);
            if fixed {
                row(ui, "Points unit", |ui| {
                    radios(ui, &mut f.centre_unit, &lengths());
                });
            }
        } else {
            profiles_rows(ui, cx, f);
        }
        if !fixed {
            let what = (
                "Reference distances CSV",
                "optional: from,to,distance (mm), from the laser tracker",
            );
            cx.path(ui, what, &mut f.references, Purpose::ImportReferences);
        }
    });
}

/// The stripe profiles' rows (and a pose file's or a fixed scanner's
/// side).
fn profiles_rows(ui: &mut egui::Ui, cx: &mut Ctx<'_>, f: &mut ImportChoices) {
    let fixed = f.mount == Mount::Fixed;
    if fixed || f.log_kind == LogKind::FlangePoses {
        // A fixed scanner's side is given: nothing decides it.
        let sides = [
            (SideChoice::Auto, "decide from the data"),
            (SideChoice::Plus, "+1 (sensor x > 0)"),
            (SideChoice::Minus, "−1"),
        ];
        let sides = &sides[usize::from(fixed)..];
        row(ui, "Sphere side", |ui| radios(ui, &mut f.side, sides));
    }
    let hint = match f.profiles_kind {
        ProfilesKind::Folder => "/path/to/profiles/ (one file per pose: <id>.csv, .yml …)",
        ProfilesKind::File => "/path/to/profiles.csv (with a pose column)",
    };
    let what = ("Stripe profiles", hint);
    cx.path(ui, what, &mut f.profiles, Purpose::ImportProfiles);
    row(ui, "", |ui| {
        let folder = "a folder, one file per pose";
        radios(
            ui,
            &mut f.profiles_kind,
            &[
                (ProfilesKind::Folder, folder),
                (ProfilesKind::File, "one file"),
            ],
        );
        let l = ui.label("pose column");
        // Sized, not squeezed by the grid's column.
        ui.add_enabled_ui(f.profiles_kind == ProfilesKind::File, |ui| {
            ui.add_sized(
                [COLUMN_WIDTH, ui.spacing().interact_size.y],
                egui::TextEdit::singleline(&mut f.pose_column),
            )
            .labelled_by(l.id);
        });
    });
}

/// The length units a file may be written in.
fn lengths() -> [(LengthUnit, &'static str); 3] {
    [LengthUnit::Mm, LengthUnit::Um, LengthUnit::M].map(|u| (u, u.symbol()))
}

/// What the sensor gave: profiles, or the points it measured itself
/// (a pose file's sphere centres, a fixed sensor's target points).
fn observations_row(ui: &mut egui::Ui, f: &mut ImportChoices) {
    row(ui, "The sensor gives", |ui| {
        let (profiles, points, hover) = if f.mount == Mount::Fixed {
            (
                "stripe profiles (a fixed line scanner)",
                "target points (a tracker's or camera's table)",
                "one x y z a target and pose (any separator, header optional, targets as named columns or rows): --mount fixed --centres",
            )
        } else {
            (
                "stripe profiles",
                "sphere centres (its own sphere fit)",
                "a table with one x y z a pose, sensor frame, mm (any separator, header optional): --centres",
            )
        };
        ui.radio_value(&mut f.observations, ObservationKind::Profiles, profiles);
        ui.radio_value(&mut f.observations, ObservationKind::Centres, points)
            .on_hover_text(hover);
    });
}

fn robot_ui(ui: &mut egui::Ui, f: &mut ImportChoices) {
    ui.label(RichText::new("2 · Robot, units, sphere").strong());
    form_grid(ui, "import_robot", 2, |ui| {
        let l = ui.label("Nominal robot");
        ui.horizontal(|ui| {
            let from_file = !f.robot.trim().is_empty();
            ui.add_enabled_ui(!from_file, |ui| {
                preset_ui(ui, "import_robot_preset", &mut f.robot_preset).labelled_by(l.id);
            });
            labelled_field(
                ui,
                "or robot file",
                &mut f.robot,
                "session/result file, URDF or DH table CSV",
                260.0,
            );
            if f.robot.trim().to_ascii_lowercase().ends_with(".csv") {
                let dh = [
                    (Some(DhConvention::Standard), "standard DH"),
                    (Some(DhConvention::Modified), "modified DH"),
                ];
                radios(ui, &mut f.dh, &dh);
            }
        });
        ui.end_row();
        if f.log_kind == LogKind::FlangePoses {
            row(ui, "", |ui| {
                weak(
                    ui,
                    "pose-only: no robot model is needed (no kinematic parameter is identified); a robot given here is kept in the session",
                );
            });
        }
        let angles = [(AngleUnit::Deg, "deg"), (AngleUnit::Rad, "rad")];
        row(ui, "Joint unit", |ui| {
            radios(ui, &mut f.joint_unit, &angles);
        });
        row(ui, "Profile unit", |ui| {
            radios(ui, &mut f.profile_unit, &lengths());
        });
        let l = ui.label("Profile axes");
        ui.horizontal(|ui| {
                ui.add(
                    egui::TextEdit::singleline(&mut f.axes)
                        .hint_text("auto")
                        .desired_width(COLUMN_WIDTH),
                )
                .labelled_by(l.id)
                .on_hover_text(
                    "auto: the coordinate that is constant is the laser plane's normal; or a map such as -y,x,z (spherecal x = −y, y = x, z = z); a mirroring map is refused",
                );
                labelled_field(
                    ui,
                    "no-return value",
                    &mut f.no_return,
                    "none",
                    COLUMN_WIDTH,
                );
            });
        ui.end_row();
        let l = ui.label("Sphere diameter");
        ui.horizontal(|ui| {
                let drag = egui::DragValue::new(&mut f.sphere_diameter).range(1.0..=500.0);
                ui.add(drag.speed(0.01).max_decimals(4).suffix(" mm"))
                    .labelled_by(l.id);
                let mut known = f.range.is_some();
                if ui
                    .checkbox(&mut known, "measuring range known (sensor.range)")
                    .on_hover_text("the part of the laser plane the sensor measures in: ml predicts the error over it, the planner spreads the sphere over it")
                    .changed()
                {
                    f.range = known.then_some(DEFAULT_RANGE);
                }
            });
        ui.end_row();
        if let Some(v) = &mut f.range {
            ui.label("Measuring range");
            ui.vertical(|ui| {
                range_fields(ui, "import_range", v, true);
                if let Err(why) = range_of(v) {
                    coloured(ui, BAD, why);
                }
            });
            ui.end_row();
        }
        let hint = "default: the pose log's file name";
        labelled_field(ui, "Session name", &mut f.name, hint, PATH_WIDTH);
        ui.end_row();
    });
}

fn mapping_ui(ui: &mut egui::Ui, state: &AppState, f: &mut ImportChoices) {
    ui.label(RichText::new("3 · Columns of the joint log").strong());
    if state.import.header.is_empty() {
        weak(
            ui,
            "Preview reads the header; Guess mapping fills the fields from it.",
        );
    } else {
        ui.label(format!("Header: {}", state.import.header.join(", ")));
    }
    let header = &state.import.header;
    let c = &mut f.columns;
    ui.horizontal_wrapped(|ui| {
        column_field(ui, "id", &mut c.id, header);
        column_field(ui, "station", &mut c.station, header);
        column_field(ui, "use", &mut c.usage, header);
        // No side column: every side +1.
        let mut side = c.side.clone().unwrap_or_default();
        column_field(ui, "side", &mut side, header);
        c.side = (!side.is_empty()).then_some(side);
    });
    ui.horizontal_wrapped(|ui| {
        for (k, j) in c.joints.iter_mut().enumerate() {
            column_field(ui, &format!("joint {}", k + 1), j, header);
        }
    });
    let missing: Vec<&str> = [&c.id, &c.station, &c.usage]
        .into_iter()
        .chain(&c.joints)
        .chain(c.side.iter().filter(|s| !s.trim().is_empty()))
        .map(|s| s.trim())
        .filter(|c| !header.is_empty() && !header.iter().any(|h| h.eq_ignore_ascii_case(c)))
        .collect();
    if !missing.is_empty() {
        coloured(
            ui,
            WARN,
            format!("not in the header: {}", missing.join(", ")),
        );
    }
}

/// A column-name field with a menu of the header's names.
fn column_field(ui: &mut egui::Ui, label: &str, value: &mut String, header: &[String]) {
    let l = ui.label(label);
    ui.add(egui::TextEdit::singleline(value).desired_width(COLUMN_WIDTH))
        .labelled_by(l.id);
    if !header.is_empty() {
        egui::ComboBox::from_id_salt(("import_column", label))
            .selected_text("")
            .width(18.0)
            .show_ui(ui, |ui| {
                if label == "side" {
                    ui.selectable_value(value, String::new(), "(none: every side +1)");
                }
                for h in header {
                    ui.selectable_value(value, h.clone(), h);
                }
            })
            .response
            .on_hover_text(format!("choose the {label} column from the header"));
    }
    ui.add_space(8.0);
}

fn flange_ui(ui: &mut egui::Ui, f: &mut ImportChoices) {
    ui.label(RichText::new("4 · Flange poses from the controller (optional)").strong());
    ui.horizontal(|ui| {
        let conventions = CONVENTIONS.map(|(c, l)| (Some(c), l.to_string()));
        let options = std::iter::once((None, "no check".to_string())).chain(conventions);
        choice(ui, "", "import_flange", &mut f.flange, options).on_hover_text(
            "compare the controller's flange poses with the nominal model's forward kinematics",
        );
        if let Some(c) = f.flange {
            labelled_field(
                ui,
                "columns",
                &mut f.flange_columns,
                &c.default_columns().join(","),
                180.0,
            );
            let mm = egui::DragValue::new(&mut f.tolerance_mm).range(0.01..=100.0);
            labelled_drag(ui, "tolerance", mm.speed(0.05).suffix(" mm"));
            let deg = egui::DragValue::new(&mut f.tolerance_deg).range(0.01..=45.0);
            ui.add(deg.speed(0.01).suffix(" deg"));
        }
    });
}

/// The preview of the mapped rows, below the buttons.
fn preview_ui(ui: &mut egui::Ui, state: &AppState) {
    if let Some(preview) = &state.import.preview {
        match preview {
            Ok(text) => {
                egui::ScrollArea::horizontal()
                    .id_salt("import_preview")
                    .show(ui, |ui| {
                        ui.label(RichText::new(text).monospace());
                    });
            }
            Err(e) => {
                coloured(ui, BAD, format!("Preview failed: {e}"));
            }
        }
    }
}

fn outcome_ui(ui: &mut egui::Ui, state: &AppState) {
    let view = &state.import;
    // The first line says what was imported; then what the import
    // decided, the side and the initial hand-eye marked, warnings in
    // orange. A failure is shown above the form, beside Import.
    if let Some(Ok(text)) = &view.outcome {
        for (k, line) in text.lines().enumerate() {
            let decided = line.starts_with("initial hand-eye")
                || line.starts_with("side ")
                || line.starts_with("pose file:");
            let text = RichText::new(line);
            ui.label(if k == 0 || decided {
                text.strong()
            } else if line.contains("warning") {
                text.color(WARN)
            } else {
                text
            });
        }
    }
    let flagged: Vec<_> = view.checks.iter().filter(|c| c.flagged).collect();
    if view.checks.is_empty() {
        return;
    }
    let worst = view
        .checks
        .iter()
        .map(|c| c.position_error_mm)
        .fold(0.0_f64, f64::max);
    ui.label(format!(
        "Flange poses: {} checked, {} flagged, largest position mismatch {worst:.3} mm",
        view.checks.len(),
        flagged.len()
    ));
    if flagged.is_empty() {
        return;
    }
    let headers = ["pose", "position (mm)", "rotation (deg)", "likely cause"];
    table(ui, "import_flagged", &headers, |ui| {
        for c in flagged {
            coloured(ui, WARN, &c.id);
            ui.label(format!("{:.3}", c.position_error_mm));
            ui.label(format!("{:.3}", c.rotation_error_deg));
            ui.label(&c.hint);
            ui.end_row();
        }
    });
}
