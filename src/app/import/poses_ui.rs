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

use crate::app::AppState;
use crate::app::command::{Command, ImportCommand};
use crate::app::dialog::Purpose;
use crate::app::import::form::{HandEyeChoice, ImportForm, ObservationKind};
use crate::app::job::Slot;
use crate::app::widgets::{BAD, GOOD, MUTED, WARN, boxed, path_row, scrolled_text};
use crate::engine::files::import::{FlangeConvention, PairingPreview, PoseFormat, PosePreview};

/// Height of the pairing list, points: a dozen rows, the rest scrolled
/// (the view must fit 1366×768 with the form above it).
const PAIRING_HEIGHT: f32 = 190.0;

/// Names listed in one line before "… (n in all)".
const NAMES_SHOWN: usize = 12;

/// Largest height of the reason a guess is needed, points (it names
/// both reasons for both sides: long; the rest scrolls).
const WHY_HEIGHT: f32 = 70.0;

/// Width of a hand-eye number field, points.
const NUMBER_WIDTH: f32 = 70.0;

/// The pose file's rows of the Files grid: the file, its layout and
/// convention, and what the sensor gave (profiles or centres).
pub fn pose_file_rows(
    ui: &mut egui::Ui,
    busy: bool,
    f: &mut ImportForm,
    preview: Option<&PosePreview>,
    commands: &mut Vec<Command>,
) {
    path_row(
        ui,
        "Pose file",
        &mut f.poses,
        "program (.ls .mod .dat .script) or pose table, .rob",
        busy,
        Purpose::ImportPoses,
        commands,
    );
    let l = ui.label("Layout");
    ui.horizontal(|ui| {
        let shown = f.pose_format.map_or_else(
            || "detected from the content".to_string(),
            |p| format!("{} ({})", p.describe(), p.key()),
        );
        egui::ComboBox::from_id_salt("import_pose_format")
            .selected_text(shown)
            .width(260.0)
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut f.pose_format, None, "detected from the content");
                for p in PoseFormat::ALL {
                    ui.selectable_value(
                        &mut f.pose_format,
                        Some(p),
                        format!("{} ({})", p.describe(), p.key()),
                    );
                }
            })
            .response
            .labelled_by(l.id)
            .on_hover_text("force the layout as --pose-format does");
        let l = ui.label("convention");
        let shown = f
            .pose_convention
            .map_or("as the program's language says", FlangeConvention::describe);
        egui::ComboBox::from_id_salt("import_pose_convention")
            .selected_text(shown)
            .width(260.0)
            .show_ui(ui, |ui| {
                ui.selectable_value(
                    &mut f.pose_convention,
                    None,
                    "as the program's language says",
                );
                for c in FlangeConvention::ALL {
                    ui.selectable_value(&mut f.pose_convention, Some(c), c.describe());
                }
            })
            .response
            .labelled_by(l.id)
            .on_hover_text(
                "how a pose table or JSON list writes a pose (--pose-convention); a robot program's language fixes its own",
            );
    });
    ui.end_row();
    // What the layout needs of the convention, once it is known.
    if let Some(p) = preview {
        match (p.format.convention(), f.pose_convention) {
            (Some(fixed), None) => {
                ui.label("");
                ui.label(RichText::new(format!("the program writes {}", fixed.describe())).weak());
                ui.end_row();
            }
            (Some(fixed), Some(given)) if fixed != given => {
                ui.label("");
                ui.label(
                    RichText::new(format!(
                        "a {} writes {}: choose that or \"as the program's language says\"",
                        p.format.describe(),
                        fixed.describe()
                    ))
                    .color(BAD),
                );
                ui.end_row();
            }
            _ => {}
        }
    }
    ui.label("The sensor gives");
    ui.horizontal(|ui| {
        ui.radio_value(
            &mut f.observations,
            ObservationKind::Profiles,
            "stripe profiles",
        );
        ui.radio_value(
            &mut f.observations,
            ObservationKind::Centres,
            "sphere centres (its own sphere fit)",
        )
        .on_hover_text(
            "a table with one x y z a pose, sensor frame, mm (any separator, header optional): --centres",
        );
    });
    ui.end_row();
    if f.observations == ObservationKind::Centres {
        path_row(
            ui,
            "Centres file",
            &mut f.centres,
            "x y z a pose (sensor frame, mm), paired with the poses in order",
            busy,
            Purpose::ImportCentres,
            commands,
        );
    }
}

/// What the engine read in the pose file and the pairing, below the
/// Files grid.
pub fn detected_ui(ui: &mut egui::Ui, state: &AppState, commands: &mut Vec<Command>) {
    let view = &state.import;
    let scanning = state.jobs.runs(&Slot::PoseScan);
    ui.horizontal(|ui| {
        ui.label(RichText::new("Read in the pose file").strong());
        if scanning {
            ui.spinner();
        }
        if ui
            .add_enabled(!scanning, egui::Button::new("Read again"))
            .on_hover_text("read the pose file and list the profiles again (after files changed)")
            .clicked()
        {
            commands.push(Command::Import(ImportCommand::Scan));
        }
    });
    let Some(preview) = &view.pose_preview else {
        ui.label(
            RichText::new(
                "Choose the pose file: its layout is detected and the pairing with the profiles shown here before the import.",
            )
            .weak(),
        );
        return;
    };
    let p = match preview {
        Ok(p) => p,
        Err(e) => {
            ui.label(RichText::new(format!("The pose file cannot be read: {e}")).color(BAD));
            ui.label(
                RichText::new("The layout and the convention above change how it is read.").weak(),
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
        ui.label(RichText::new(format!("warning: {w}")).color(WARN));
    }
    match &p.pairing {
        Ok(pairing) => pairing_ui(ui, p, pairing),
        Err(why) => {
            ui.label(RichText::new(format!("Pairing: {why}")).color(MUTED));
        }
    }
}

/// "a, b, c, … (n in all)".
fn names(list: &[String]) -> String {
    if list.len() <= NAMES_SHOWN {
        list.join(", ")
    } else {
        format!(
            "{}, … ({} in all)",
            list[..NAMES_SHOWN].join(", "),
            list.len()
        )
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
        ui.label(RichText::new(problem).color(BAD));
    }
    if let Some(w) = &pairing.warning {
        ui.label(RichText::new(format!("warning: {w}")).color(WARN));
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
    if !pairing.poses_without.is_empty() {
        let list: Vec<String> = pairing
            .poses_without
            .iter()
            .filter_map(|&k| p.poses.get(k).map(|(n, l)| format!("{n} (line {l})")))
            .collect();
        ui.label(RichText::new(format!("poses without a profile: {}", names(&list))).color(BAD));
    }
    if !pairing.unpaired.is_empty() {
        ui.label(
            RichText::new(format!(
                "profiles without a pose: {}",
                names(&pairing.unpaired)
            ))
            .color(BAD),
        );
    }
    if !pairing.skipped.is_empty() {
        let list: Vec<String> = pairing
            .skipped
            .iter()
            .map(|(n, why)| format!("{n} ({why})"))
            .collect();
        ui.label(RichText::new(format!("skipped: {}", names(&list))).color(MUTED));
    }
}

/// The initial hand-eye: whether eq. 6-9 can start, the choice of a
/// guess, and the engine's reason when the last import found none.
pub fn hand_eye_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    busy: bool,
    f: &mut ImportForm,
    commands: &mut Vec<Command>,
) {
    ui.label(RichText::new("Initial hand-eye").strong());
    let preview = state
        .import
        .pose_preview
        .as_ref()
        .and_then(|p| p.as_ref().ok());
    if let Some(p) = preview {
        if p.uses_given {
            ui.label(
                RichText::new(
                    "the pose file gives every pose its use: the session's groups start the calibration",
                )
                .weak(),
            );
        } else {
            match &p.translation_group {
                Some(Ok(group)) => {
                    let list: Vec<String> = group
                        .iter()
                        .filter_map(|&k| p.poses.get(k).map(|(n, _)| n.clone()))
                        .collect();
                    ui.label(
                        RichText::new(format!(
                            "eq. 6-9 can start: {} poses of one orientation (pure translations: {}) and {} others",
                            group.len(),
                            names(&list),
                            p.poses.len() - group.len()
                        ))
                        .color(GOOD),
                    );
                }
                Some(Err(why)) => {
                    ui.label(
                        RichText::new(format!(
                            "No pure-translation group: {why}. The import tries the general solution on all poses at once (it needs orientations turned about two axes); if it cannot, a guess is needed."
                        ))
                        .color(WARN),
                    );
                }
                None => {
                    ui.label(
                        RichText::new(
                            "joint targets: the groups are judged once the robot places them",
                        )
                        .weak(),
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
    ui.horizontal_wrapped(|ui| {
        ui.radio_value(
            &mut f.hand_eye,
            HandEyeChoice::Computed,
            "computed (eq. 6-9, else the general solution)",
        );
        ui.radio_value(&mut f.hand_eye, HandEyeChoice::Numbers, "a guess: numbers");
        ui.radio_value(&mut f.hand_eye, HandEyeChoice::File, "a guess from a file");
    });
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
                RichText::new(
                    "eT_s, the sensor frame in the flange frame: R = Rz(yaw)·Ry(pitch)·Rx(roll)",
                )
                .weak()
                .small(),
            );
        }
        HandEyeChoice::File => {
            egui::Grid::new("import_hand_eye_file")
                .num_columns(3)
                .spacing([8.0, 6.0])
                .show(ui, |ui| {
                    path_row(
                        ui,
                        "Hand-eye file",
                        &mut f.hand_eye_file,
                        "a 4×4 JSON matrix (rows, mm), or a session or result file",
                        busy,
                        Purpose::ImportHandEye,
                        commands,
                    );
                });
        }
    }
}
