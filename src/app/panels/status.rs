//! The status bar: the last thing that happened, and what is in flight.

use egui::RichText;

use super::{BAD, WARN};
use crate::app::state::{AppState, Level};

/// The status bar.
pub fn status_ui(ui: &mut egui::Ui, state: &AppState) {
    ui.horizontal(|ui| {
        ui.set_min_height(22.0);
        if state.is_busy() {
            ui.spinner();
        }
        if let Some(s) = &state.status {
            let text = RichText::new(&s.text);
            let text = match s.level {
                Level::Info => text,
                Level::Warning => text.color(WARN),
                Level::Error => text.color(BAD),
            };
            // Whole, on as many lines as it takes: a cut status hides
            // what happened.
            ui.add(egui::Label::new(text).wrap());
        }
    });
}
