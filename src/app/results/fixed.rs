//! The Results view's part for a fixed sensor (FORMAT.md `sensor.mount:
//! "fixed"`): what the hand-eye table holds, the targets on the flange and
//! the validate poses' prediction error, as the engine computes them.

use egui::RichText;

use crate::app::results::ResultView;
use crate::app::widgets::MUTED;
use crate::engine::base::session::Mount;
use crate::engine::calibrate::validate::Stats;
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
    crate::app::widgets::table(ui, "fixed_targets", &["target", "x", "y", "z"], |ui| {
        for st in &view.file.stations {
            let [x, y, z] = st.point.map(|v| format!("{v:.3}"));
            super::tables::row(ui, [st.id.clone(), x, y, z]);
        }
    });
    let errors: Vec<f64> = prediction_errors(&view.file.centres, &view.file.stations)
        .iter()
        .map(|p| p.error)
        .collect();
    let text = if errors.is_empty() {
        "No validate measurements: the prediction is not checked.".to_string()
    } else {
        let Stats { rms, max, .. } = Stats::of(&errors);
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
