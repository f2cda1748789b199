//! The Results view's part for a fixed sensor (FORMAT.md `sensor.mount:
//! "fixed"`): what the hand-eye table holds, the targets on the flange and
//! the validate poses' prediction error, as the engine computes them.

use egui::RichText;

use crate::app::results::ResultView;
use crate::app::widgets::MUTED;
use crate::engine::base::session::Mount;
use crate::engine::files::format::stations::prediction_errors;

/// The hand-eye table's title for the result's mount.
pub(super) fn hand_eye_title(view: &ResultView) -> &'static str {
    match view.file.mount() {
        Mount::Flange => "Hand-eye eT_s (sensor to flange)",
        Mount::Fixed => "Base from sensor bT_s (a fixed sensor: its pose in the base frame)",
    }
}

/// The targets and the prediction error, for a fixed sensor only.
pub(super) fn fixed_ui(ui: &mut egui::Ui, view: &ResultView) {
    if view.file.mount() != Mount::Fixed {
        return;
    }
    ui.add_space(8.0);
    ui.label(RichText::new("Targets on the flange (flange frame, mm)").strong());
    egui::Grid::new("fixed_targets")
        .striped(true)
        .num_columns(4)
        .show(ui, |ui| {
            for t in ["target", "x", "y", "z"] {
                ui.strong(t);
            }
            ui.end_row();
            for st in &view.file.stations {
                ui.label(&st.id);
                for v in st.point {
                    ui.label(format!("{v:.3}"));
                }
                ui.end_row();
            }
        });
    let errors: Vec<f64> = prediction_errors(&view.file.centres, &view.file.stations)
        .iter()
        .map(|p| p.error)
        .collect();
    let text = if errors.is_empty() {
        "No validate measurements: the prediction is not checked.".to_string()
    } else {
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
        let max = errors.iter().copied().fold(0.0, f64::max);
        format!(
            "Validate poses, predicted point against the measured one (sensor frame): rms {rms:.4} mm, max {max:.4} mm over {} measurements",
            errors.len()
        )
    };
    ui.label(text);
    ui.label(
        RichText::new(
            "The first joint's parameters are held at nominal (base_from_sensor takes them up); the centres in the Centres view are the targets in the flange frame.",
        )
        .color(MUTED),
    );
    crate::app::scene::fixed::results_scene_ui(ui, &view.file);
}
