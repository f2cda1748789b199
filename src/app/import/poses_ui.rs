//! The Import view's pose-file parts (`spherecal import --poses`): the
//! pose file with its layout (detected, or forced as `--pose-format`) and
//! convention, profiles or the sensor's own sphere centres (`--centres`),
//! what the engine detected in the file (its warnings in orange), the
//! pairing of every pose with its profile file before the import (poses
//! without a profile, profiles without a pose, the folder's other files
//! skipped), and the initial hand-eye: computed (eq. 6-9, else the
//! general solution) or a guess (`--hand-eye`), required with the
//! engine's reason when the poses give none.

use egui::RichText;

use super::ui::{Ctx, radios};
use crate::app::command::{Command, ImportCommand};
use crate::app::dialog::Purpose;
use crate::app::import::form::{HandEyeChoice, ImportChoices};
use crate::app::job::Slot;
use crate::app::widgets::{
    BAD, GOOD, MUTED, WARN, boxed, coloured, command_button, form_grid, scrolled_text, weak,
};
use crate::engine::assemble::{PairingPreview, PosePreview};
use crate::engine::base::session::Mount;
use crate::engine::files::import::{FlangeConvention, PoseFormat};
use crate::engine::files::program::name_list;

/// Height of the pairing list, points: a dozen rows, the rest scrolled
/// (the view must fit 1366×768 with the form above it).
const PAIRING_HEIGHT: f32 = 190.0;

/// Largest height of the reason a guess is needed, points (it names
/// both reasons for both sides: long; the rest scrolls).
const WHY_HEIGHT: f32 = 70.0;

/// Width of a hand-eye number field, points.
const NUMBER_WIDTH: f32 = 70.0;

/// The pose file's rows of the Files grid: the file, its layout and
/// convention, and what the sensor gave (profiles or centres).
pub(super) fn pose_file_rows(ui: &mut egui::Ui, cx: &mut Ctx<'_>, f: &mut ImportChoices) {
    let preview = cx
        .state
        .import
        .pose_preview
        .as_ref()
        .and_then(|p| p.as_ref().ok());
    let what = (
        "Pose file",
        "program (.ls .mod .dat .script) or pose table, .rob",
    );
    cx.path(ui, what, &mut f.poses, Purpose::ImportPoses);
    let l = ui.label("Layout");
    ui.horizontal(|ui| {
        let layouts = PoseFormat::ALL.map(|p| (p, format!("{} ({})", p.describe(), p.key())));
        let none = "detected from the content";
        let hover = "force the layout as --pose-format does";
        let id = ("import_pose_format", l.id);
        optional_combo(ui, id, &mut f.pose_format, none, &layouts).on_hover_text(hover);
        let l = ui.label("convention");
        let conventions = FlangeConvention::ALL.map(|c| (c, c.describe().to_string()));
        let none = "as the program's language says";
        let hover = "how a pose table or JSON list writes a pose (--pose-convention); a robot program's language fixes its own";
        let id = ("import_pose_convention", l.id);
        optional_combo(ui, id, &mut f.pose_convention, none, &conventions).on_hover_text(hover);
    });
    ui.end_row();
    // What the layout needs of the convention, once it is known.
    if let Some(p) = preview {
        let said = match (p.format.convention(), f.pose_convention) {
            (Some(fixed), None) => {
                Some(RichText::new(format!("the program writes {}", fixed.describe())).weak())
            }
            (Some(fixed), Some(given)) if fixed != given => {
                let (format, fixed) = (p.format.describe(), fixed.describe());
                let why = format!(
                    "a {format} writes {fixed}: choose that or \"as the program's language says\""
                );
                Some(RichText::new(why).color(BAD))
            }
            _ => None,
        };
        if let Some(text) = said {
            ui.label("");
            ui.label(text);
            ui.end_row();
        }
    }
}

/// A drop-down of `none` and `options`, labelled by `label`.
fn optional_combo<T: Copy + PartialEq>(
    ui: &mut egui::Ui,
    (id, label): (&str, egui::Id),
    value: &mut Option<T>,
    none: &str,
    options: &[(T, String)],
) -> egui::Response {
    let shown = options
        .iter()
        .find(|(v, _)| Some(*v) == *value)
        .map_or(none, |(_, text)| text);
    egui::ComboBox::from_id_salt(id)
        .selected_text(shown)
        .width(260.0)
        .show_ui(ui, |ui| {
            ui.selectable_value(value, None, none);
            for (v, text) in options {
                ui.selectable_value(value, Some(*v), text);
            }
        })
        .response
        .labelled_by(label)
}

/// What the engine read in the pose file and the pairing, below the
/// Files grid.
pub(super) fn detected_ui(ui: &mut egui::Ui, cx: &mut Ctx<'_>) {
    let (state, commands) = (cx.state, &mut *cx.commands);
    let view = &state.import;
    let scanning = state.jobs.runs(&Slot::PoseScan);
    ui.horizontal(|ui| {
        ui.label(RichText::new("Read in the pose file").strong());
        if scanning {
            ui.spinner();
        }
        let hover = "read the pose file and list the profiles again (after files changed)";
        let scan = Command::Import(ImportCommand::Scan);
        command_button(ui, !scanning, "Read again", hover, scan, commands);
    });
    let Some(preview) = &view.pose_preview else {
        weak(
            ui,
            "Choose the pose file: its layout is detected and the pairing with the profiles shown here before the import.",
        );
        return;
    };
    let p = match preview {
        Ok(p) => p,
        Err(e) => {
            coloured(ui, BAD, format!("The pose file cannot be read: {e}"));
            weak(
                ui,
                "The layout and the convention above change how it is read.",
            );
            return;
        }
    };
    ui.label(RichText::new(p.summary()).strong());
    ui.label(if p.joints {
        "joint targets: a session with joints (give the nominal robot below)"
    } else {
        "flange poses: a pose-only session (the hand-eye and the sphere centres are calibrated)"
    });
    for w in &p.warnings {
        coloured(ui, WARN, format!("warning: {w}"));
    }
    match &p.pairing {
        Ok(pairing) => pairing_ui(ui, p, pairing),
        Err(why) => drop(coloured(ui, MUTED, format!("Pairing: {why}"))),
    }
}

/// The pairing: how, each pair (a scrolled list that draws only the rows
/// on show), what is left over, the files skipped.
fn pairing_ui(ui: &mut egui::Ui, p: &PosePreview, pairing: &PairingPreview) {
    ui.label(format!(
        "Pairing: {} ({} pairs)",
        pairing.how,
        pairing.pairs.len()
    ));
    if let Some(problem) = &pairing.problem {
        coloured(ui, BAD, problem);
    }
    if let Some(w) = &pairing.warning {
        coloured(ui, WARN, format!("warning: {w}"));
    }
    if !pairing.pairs.is_empty() {
        let row_height = ui.text_style_height(&egui::TextStyle::Monospace);
        egui::Frame::group(ui.style()).show(ui, |ui| {
            egui::ScrollArea::vertical()
                .id_salt("import_pairing")
                .max_height(PAIRING_HEIGHT)
                .auto_shrink([false, true])
                .show_rows(ui, row_height, pairing.pairs.len(), |ui, rows| {
                    for (pose, observation) in &pairing.pairs[rows] {
                        // A table row's name is its line already.
                        let name = p.poses.get(*pose).map_or_else(String::new, |(n, l)| {
                            if n.starts_with("line ") {
                                n.clone()
                            } else {
                                format!("{n}, line {l}")
                            }
                        });
                        ui.label(
                            RichText::new(format!("{:>5}  {name:<22} ↔ {observation}", pose + 1))
                                .monospace(),
                        );
                    }
                });
        });
    }
    // What is left over, a line each.
    let mut left = |colour, what: &str, list: Vec<String>| {
        if !list.is_empty() {
            coloured(ui, colour, format!("{what}: {}", name_list(&list)));
        }
    };
    let without = pairing.poses_without.iter();
    let without = without.filter_map(|&k| p.poses.get(k).map(|(n, l)| format!("{n} (line {l})")));
    left(BAD, "poses without a profile", without.collect());
    left(BAD, "profiles without a pose", pairing.unpaired.clone());
    let skipped = pairing
        .skipped
        .iter()
        .map(|(n, why)| format!("{n} ({why})"));
    left(MUTED, "skipped", skipped.collect());
}

/// The initial hand-eye: whether eq. 6-9 can start, the choice of a
/// guess, and the engine's reason when the last import found none.
pub(super) fn hand_eye_ui(ui: &mut egui::Ui, cx: &mut Ctx<'_>, f: &mut ImportChoices) {
    let state = cx.state;
    let fixed = f.mount == Mount::Fixed;
    let title = if fixed {
        "Initial base_from_sensor"
    } else {
        "Initial hand-eye"
    };
    ui.label(RichText::new(title).strong());
    let preview = state
        .import
        .pose_preview
        .as_ref()
        .and_then(|p| p.as_ref().ok());
    if let Some(p) = preview {
        if p.uses_given {
            weak(
                ui,
                "the pose file gives every pose its use: the session's groups start the calibration",
            );
        } else {
            match &p.translation_group {
                Some(Ok(group)) => {
                    let list: Vec<String> = group
                        .iter()
                        .filter_map(|&k| p.poses.get(k).map(|(n, _)| n.clone()))
                        .collect();
                    let (n, others) = (group.len(), p.poses.len() - group.len());
                    let list = name_list(&list);
                    coloured(
                        ui,
                        GOOD,
                        format!(
                            "eq. 6-9 can start: {n} poses of one orientation (pure translations: {list}) and {others} others"
                        ),
                    );
                }
                Some(Err(why)) => {
                    coloured(
                        ui,
                        WARN,
                        format!(
                            "No pure-translation group: {why}. The import tries the general solution on all poses at once (it needs orientations turned about two axes); if it cannot, a guess is needed."
                        ),
                    );
                }
                None => {
                    weak(
                        ui,
                        "joint targets: the groups are judged once the robot places them",
                    );
                }
            }
        }
    }
    if let Some(why) = &state.import.guess_needed {
        let colour = if f.hand_eye == HandEyeChoice::Computed {
            BAD
        } else {
            MUTED
        };
        let title = "A hand-eye guess is needed: these poses give none";
        boxed(ui, colour, title, |ui| {
            let what = "Give x y z (mm) and roll pitch yaw (deg) of the sensor on the flange, or a file, below; the calibration refines it.";
            ui.label(RichText::new(what).strong());
            scrolled_text(
                ui,
                "import_guess_why",
                WHY_HEIGHT,
                RichText::new(why).weak(),
            );
        });
    }
    let computed = if fixed {
        "computed (the linear start from all identify poses)"
    } else {
        "computed (eq. 6-9, else the general solution)"
    };
    let choices = [
        (HandEyeChoice::Computed, computed),
        (HandEyeChoice::Numbers, "a guess: numbers"),
        (HandEyeChoice::File, "a guess from a file"),
    ];
    ui.horizontal_wrapped(|ui| radios(ui, &mut f.hand_eye, &choices));
    match f.hand_eye {
        HandEyeChoice::Computed => {}
        HandEyeChoice::Numbers => {
            // Translation on one row, rotation on the next.
            let (translation, rotation) = f.hand_eye_numbers.split_at_mut(3);
            for (values, names, unit) in [
                (translation, ["x", "y", "z"], " mm"),
                (rotation, ["roll", "pitch", "yaw"], "°"),
            ] {
                ui.horizontal(|ui| {
                    for (name, v) in names.iter().zip(values.iter_mut()) {
                        let l = ui.label(format!("hand-eye {name}"));
                        ui.add_sized(
                            [NUMBER_WIDTH + 20.0, ui.spacing().interact_size.y],
                            egui::DragValue::new(v)
                                .speed(0.1)
                                .max_decimals(4)
                                .suffix(unit),
                        )
                        .labelled_by(l.id);
                    }
                });
            }
            ui.label(
                RichText::new(if fixed {
                    "bT_s, the sensor frame in the base frame: R = Rz(yaw)·Ry(pitch)·Rx(roll)"
                } else {
                    "eT_s, the sensor frame in the flange frame: R = Rz(yaw)·Ry(pitch)·Rx(roll)"
                })
                .weak()
                .small(),
            );
        }
        HandEyeChoice::File => {
            form_grid(ui, "import_hand_eye_file", 3, |ui| {
                let what = (
                    "Hand-eye file",
                    "a 4×4 JSON matrix (rows, mm), or a session or result file",
                );
                let (path, purpose) = (&mut f.hand_eye_file, Purpose::ImportHandEye);
                cx.path(ui, what, path, purpose);
            });
        }
    }
}
