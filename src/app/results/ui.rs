//! The Results view: the headline figures in large type, the paper's
//! Fig. 5 (within-station centre distances, before and after, per pair)
//! and Fig. 6 (reference-distance errors, before and after, per distance),
//! ε per iteration, the singular values with the truncation line, the
//! hand-eye before and after, the Table 1 view of the joint errors with
//! the non-identifiable ones marked, and the export buttons. A stale
//! result is marked over everything and its exports are refused with
//! what changed.
//!
//! Split by idea: [`figures`] (the four plots), [`sets`] (calibration
//! set against validation set, with the error histogram), [`fail`] (the
//! way forward after a FAIL), [`tables`] (hand-eye, joints, `ml`'s
//! diagnostics), [`range_map`](super::range_map) (the predicted error over the range).

use super::{fail, figures, sets, tables};
use egui::RichText;

use crate::app::AppState;
use crate::app::Forms;
use crate::app::command::ExportKind;
use crate::app::command::{Command, ViewCommand};
use crate::app::dialog::Purpose;
use crate::app::ledger::{Artefact, Stale};
use crate::app::results::{ResultOrigin, ResultView};
use crate::app::widgets::{
    AFTER, BAD, GOOD, MUTED, WARN, export_folder_ui, number_field, ratio_text,
};
use crate::engine::tools::result_view::Verdict;

/// Height of each of the four plots, points.
pub(super) const PLOT_HEIGHT: f32 = 230.0;

/// The Results view.
pub fn results_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    let Some(view) = &state.result else {
        ui.add_space(20.0);
        ui.label(RichText::new("No result yet.").size(18.0));
        ui.label("Press ▶ Run in the solver panel on the left, or open a result file (path field or Open…) to review it beside its session.");
        return;
    };
    let stale = state.ledger.stale(Artefact::Result);
    // Its own scroll offset: not the Import view's (it opened mid-page),
    // and each new result's from the top (a run of another session opened
    // where the last one was scrolled to, its verdict off screen).
    egui::ScrollArea::vertical()
        .id_salt(("results_scroll", state.results_shown))
        .auto_shrink([false, false])
        .show(ui, |ui| {
            if let Some(s) = &stale {
                crate::app::widgets::stale_banner_ui(
                    ui,
                    s,
                    "What is shown below no longer matches the inputs: its verdict does not hold and its exports are refused until you run again.",
                );
            }
            origin_ui(ui, view);
            export_ui(ui, state, forms, stale.as_ref(), commands);
            headline_ui(ui, view, forms, stale.is_some(), commands);
            fail::after_fail_ui(ui, state, forms, commands);
            ui.add_space(4.0);
            sets::sets_ui(ui, view);
            ui.add_space(4.0);
            figures::plots_ui(ui, view);
            ui.add_space(8.0);
            tables::tables_ui(ui, view, &forms.tolerance);
        });
}

fn origin_ui(ui: &mut egui::Ui, view: &ResultView) {
    let text = match &view.origin {
        ResultOrigin::Run { seconds, excluded } => {
            let left_out = if *excluded > 0 {
                format!(", {excluded} measurement(s) left out")
            } else {
                String::new()
            };
            format!(
                "Run of session \"{}\" in this window ({seconds:.2} s{left_out}), method {}.",
                view.file.session,
                view.method()
            )
        }
        ResultOrigin::Review(path) => format!(
            "Reviewing {} (session \"{}\", method {}): shown as it was computed, the solver was not run.",
            path.display(),
            view.file.session,
            view.method()
        ),
    };
    ui.label(RichText::new(text).weak());
    if let Some(stop) = view.file.solver.stop_reason() {
        ui.label(RichText::new(stop).small());
    }
    for w in &view.shown.warnings {
        ui.label(RichText::new(format!("warning: {w}")).color(WARN));
    }
    for n in &view.notes {
        ui.label(RichText::new(format!("note: {n}")).color(WARN));
    }
}

/// Validation std and max before → after in large type, with the ratio,
/// and the verdict against the acceptance tolerance (editable here).
fn headline_ui(
    ui: &mut egui::Ui,
    view: &ResultView,
    forms: &Forms,
    stale: bool,
    commands: &mut Vec<Command>,
) {
    egui::Frame::group(ui.style()).show(ui, |ui| {
        ui.set_width(ui.available_width());
        if let Some(h) = &view.shown.headline {
            ui.label(RichText::new(&h.what).strong());
            let (b, a) = (h.stats.before, h.stats.after);
            ui.horizontal_wrapped(|ui| {
                for (what, b, a) in [("std", b.std, a.std), ("max", b.max, a.max)] {
                    let text = format!("{what} {b:.3} → {a:.3} mm");
                    ui.label(RichText::new(text).size(28.0).strong());
                    ui.label(RichText::new(ratio_text(b, a)).size(16.0).color(AFTER));
                    // The gap between the two, none after the last.
                    if what == "std" {
                        ui.add_space(24.0);
                    }
                }
            });
        } else {
            let text = "Validation skipped: no validate data (the session has no validate measurements), so accuracy is not checked; the report says so.";
            ui.label(RichText::new(text).color(WARN));
        }
        verdict_ui(ui, view, forms, stale, commands);
        let w = &view.shown.within_stats;
        ui.label(format!(
            "{} stations, centre distances (true value 0): std {:.3} → {:.3} mm, max {:.3} → {:.3} mm · ε {:.4} → {:.4} mm",
            view.shown.within_of.as_str(),
            w.before.std,
            w.after.std,
            w.before.max,
            w.after.max,
            view.file.epsilon_before,
            view.file.epsilon_after
        ));
        let (b, a) = view.shown.identify_scatter;
        ui.label(format!(
            "identify centres about their station's mean (3-D rms): {b:.3} → {a:.3} mm"
        ));
        if let Some(v) = &view.shown.volume_error {
            ui.label(format!(
                "predicted measuring error over the session's volume: rms {:.3} mm, max {:.3} mm",
                v.rms_mm, v.max_mm
            ))
            .on_hover_text(v.summary());
        }
        held_out_ui(ui, view);
    });
}

/// The held-out figure beside the fit's own scatter: each identify centre
/// predicted by a calibration made without it.
fn held_out_ui(ui: &mut egui::Ui, view: &ResultView) {
    let Some(h) = &view.shown.held_out else {
        ui.label(
            RichText::new("held out: not in this result (written before spherecal computed it, or with --no-held-out)")
                .color(MUTED),
        );
        return;
    };
    ui.horizontal_wrapped(|ui| {
        ui.label(RichText::new(format!("held out ({})", h.label())).strong());
        ui.label(
            RichText::new(format!("rms {:.3} mm, max {:.3} mm", h.rms, h.max))
                .size(16.0)
                .strong(),
        )
        .on_hover_text(format!(
            "each identify centre predicted by a calibration made without it, against its station's centre from the other measurements; largest: {}. Refit: {}",
            h.max_measurement, h.refit
        ));
        ui.label(format!(
            "· fit's own scatter rms {:.3} mm, max {:.3} mm ({:.2}× the fit's own)",
            h.fit_rms,
            h.fit_max,
            h.ratio()
        ));
    });
    if !h.undetermined.is_empty() {
        ui.label(
            RichText::new(format!(
                "not predictable without themselves: {}",
                h.undetermined.join(", ")
            ))
            .color(WARN),
        );
    }
}

/// PASS / FAIL in large type against the tolerance, which is edited
/// beside it (remembered for the session's robot); struck out and grey
/// while the result is stale.
fn verdict_ui(
    ui: &mut egui::Ui,
    view: &ResultView,
    forms: &Forms,
    stale: bool,
    commands: &mut Vec<Command>,
) {
    let tolerance = forms.tolerance;
    let verdict = Verdict::of(view.shown.headline.as_ref(), &tolerance);
    ui.horizontal_wrapped(|ui| {
        let colour = match verdict {
            _ if stale => MUTED,
            Verdict::Pass => GOOD,
            Verdict::Fail(_) => BAD,
            Verdict::NotChecked => MUTED,
        };
        let word = RichText::new(verdict.word()).size(28.0).strong();
        let word = if stale { word.strikethrough() } else { word };
        ui.label(word.color(colour))
            .on_hover_text(verdict.describe(&tolerance));
        if stale {
            ui.label(RichText::new(STALE_VERDICT).color(WARN));
        }
        ui.add_space(12.0);
        // Typed, never dragged: a sideways drag must not turn a PASS
        // into a FAIL. A value takes effect on Enter or leaving the field.
        let mut edited = tolerance;
        let (std, max) = (&mut edited.std_mm, &mut edited.max_mm);
        for (id, label, value) in [
            ("tolerance_std", "tolerance: std ≤", std),
            ("tolerance_max", "max ≤", max),
        ] {
            if let Some(v) = number_field(ui, id, label, *value, TOLERANCE_MM, "mm") {
                *value = v;
            }
        }
        if edited != tolerance {
            commands.push(Command::View(ViewCommand::SetTolerance(edited)));
        }
        if let Verdict::Fail(reasons) = &verdict {
            ui.label(RichText::new(reasons.join(", ")).color(BAD));
        }
    });
}

/// Beside the verdict of a stale result.
pub const STALE_VERDICT: &str = "does not hold: the result is stale, run again";

/// The tolerances one may type, mm.
const TOLERANCE_MM: std::ops::RangeInclusive<f64> = 0.001..=100.0;

fn export_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    stale: Option<&Stale>,
    commands: &mut Vec<Command>,
) {
    ui.horizontal_wrapped(|ui| {
        export_folder_ui(ui, "Export to folder", &mut forms.export_dir, 220.0, commands);
        ui.separator();
        let hand_eye_only = state
            .result
            .as_ref()
            .is_some_and(|v| v.hand_eye_only.is_some());
        for kind in ExportKind::ALL {
            let model = matches!(
                kind,
                ExportKind::ModelJson | ExportKind::ModelCsv | ExportKind::ModelUrdf
            );
            let enabled = !(model && hand_eye_only) && stale.is_none();
            let why = match stale {
                Some(s) => format!("refused: {s}; run again, then export"),
                None => "a pose-only result calibrated the hand-eye only: there is no kinematic model to export".to_string(),
            };
            if ui
                .add_enabled(enabled, egui::Button::new(kind.label()))
                .on_hover_text(export_hint(kind))
                .on_disabled_hover_text(why)
                .clicked()
            {
                commands.push(Command::Export(kind));
            }
        }
    });
    if let Some(view) = &state.result {
        super::export::use_exports_ui(ui, view, forms, stale.is_some(), commands);
    }
    crate::app::widgets::dialog_note_ui(ui, state, &[Purpose::ExportFolder, Purpose::UrdfSource]);
    crate::app::widgets::written_ui(ui, state, &[Artefact::Result, Artefact::Report]);
}

fn export_hint(kind: ExportKind) -> &'static str {
    match kind {
        ExportKind::ResultJson => {
            "the result file of FORMAT.md (what `spherecal calibrate` writes)"
        }
        ExportKind::CentresCsv => {
            "every sphere centre: sensor frame, base frame before and after (mm)"
        }
        ExportKind::DistancesCsv => {
            "reference-distance errors and within-station distances, before and after (mm)"
        }
        ExportKind::PlotsPng => {
            "Fig. 5, Fig. 6, ε and the singular values on one white sheet, whole, for print (2 pixels per point)"
        }
        ExportKind::ReportHtml => {
            "one self-contained HTML file: provenance (SHA-256), settings, stripe quality, figures, hand-eye, joint errors, validation"
        }
        ExportKind::ModelJson => {
            "the calibrated robot as the FORMAT.md robot block (deg, mm), pasteable into a session"
        }
        ExportKind::ModelCsv => {
            "the calibrated MDH table with the deltas, then base, flange and hand-eye matrices (deg, mm)"
        }
        ExportKind::ModelUrdf => {
            "a URDF fragment with the calibrated joint origins and the sensor link (m, rad), for ROS"
        }
    }
}
