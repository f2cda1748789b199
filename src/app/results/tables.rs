//! The Results view's tables: the hand-eye before and after with ± 1σ,
//! the joint errors in the layout of the paper's Table 1 (or, for a
//! pose-only result, what was calibrated), the SVD's dropped directions,
//! `ml`'s diagnostics (outliers, leave-one-station-out, correlations) and
//! the solver block as written.

use egui::RichText;

use crate::app::results::{HandEyeView, ResultView};
use crate::app::widgets::{MUTED, WARN, table};
use crate::engine::base::geometry::{rows_from_isometry, wrap_deg};
use crate::engine::base::robot::{PARAM_NAMES, PARAMS_PER_JOINT};
use crate::engine::calibrate::solve::estimate::HAND_EYE_LABELS;
use crate::engine::files::format::result::solver_block;

/// Longest solver-block value shown in full (longer ones are cut, the
/// whole value is in the tooltip and the exported JSON).
const SOLVER_ENTRY_CHARS: usize = 300;

/// One row of plain cells.
pub(super) fn row(ui: &mut egui::Ui, cells: impl IntoIterator<Item = impl Into<egui::WidgetText>>) {
    for c in cells {
        ui.label(c);
    }
    ui.end_row();
}

pub(super) fn tables_ui(
    ui: &mut egui::Ui,
    view: &ResultView,
    tolerance: &crate::engine::tools::result_view::Tolerance,
) {
    // One above the other: with ± 1σ the joint table needs the width.
    hand_eye_ui(ui, view);
    super::fixed::fixed_ui(ui, view);
    ui.add_space(8.0);
    match &view.hand_eye_only {
        Some(lines) => hand_eye_only_ui(ui, lines),
        None => joint_errors_ui(ui, view),
    }
    let paper = view.file.solver.paper();
    let dropped = paper.and_then(|p| p.dropped_directions.as_deref());
    if let Some(dropped) = dropped.filter(|d| !d.is_empty()) {
        ui.add_space(6.0);
        let title = format!("Directions the SVD dropped ({})", dropped.len());
        egui::CollapsingHeader::new(title).show(ui, |ui| {
            for d in dropped {
                ui.monospace(d.to_string());
            }
        });
    }
    ml_tables_ui(ui, view, tolerance);
    let title = "Details: the solver block as written in the result file";
    egui::CollapsingHeader::new(title).show(ui, |ui| {
        let grid = egui::Grid::new("solver_entries").striped(true);
        grid.num_columns(2).show(ui, |ui| {
            for (k, v) in solver_block(&view.file.solver) {
                let v = v.as_str().map_or_else(|| v.to_string(), str::to_owned);
                ui.monospace(k);
                let mut shown: String = v.chars().take(SOLVER_ENTRY_CHARS).collect();
                if shown.len() < v.len() {
                    shown.push('…');
                }
                ui.add(egui::Label::new(shown).wrap()).on_hover_text(v);
                ui.end_row();
            }
        });
    });
}

fn marked_cell(ui: &mut egui::Ui, view: &ResultView, label: &str, text: String) {
    if let Some(why) = view.shown.marked.get(label) {
        ui.label(RichText::new(format!("{text} †")).color(MUTED))
            .on_hover_text(format!("{label} is not identifiable from this data: {why}"));
    } else {
        ui.label(text);
    }
}

fn hand_eye_ui(ui: &mut egui::Ui, view: &ResultView) {
    ui.label(RichText::new(super::fixed::hand_eye_title(view)).strong());
    let (b, a): (&HandEyeView, &HandEyeView) =
        (&view.shown.hand_eye_before, &view.shown.hand_eye_after);
    let sigma = view.shown.hand_eye_sigma;
    let header = ["", "initial", "calibrated", "± 1σ", "change"];
    table(ui, "hand_eye", &header, |ui| {
        let names = [
            "x (mm)",
            "y (mm)",
            "z (mm)",
            "roll (deg)",
            "pitch (deg)",
            "yaw (deg)",
        ];
        let before = [b.translation, b.rpy_deg].concat();
        let after = [a.translation, a.rpy_deg].concat();
        for (k, (name, label)) in names.into_iter().zip(HAND_EYE_LABELS).enumerate() {
            ui.label(name);
            ui.label(format!("{:.4}", before[k]));
            marked_cell(ui, view, label, format!("{:.4}", after[k]));
            match sigma {
                Some(s) if !view.shown.marked.contains_key(label) => {
                    ui.label(RichText::new(format!("± {:.4}", s[k])).color(MUTED))
                }
                _ => ui.label(RichText::new("–").color(MUTED)),
            }
            .on_hover_text(format!(
                "1σ a posteriori (ml's covariance × variance factor {:.3}), in the row's frame and unit (flange-frame x, y, z; roll, pitch, yaw); a priori (the covariance as written): ± {}",
                view.shown.variance_factor,
                view.shown
                    .hand_eye_sigma_a_priori
                    .map_or_else(|| "–".to_owned(), |p| format!("{:.4}", p[k]))
            ));
            let change = after[k] - before[k];
            let change = if k < 3 { change } else { wrap_deg(change) };
            ui.label(format!("{change:+.4}"));
            ui.end_row();
        }
    });
    ui.label(
        RichText::new(format!(
            "rotation changed by {:.4}°",
            view.shown.hand_eye_rotation_change_deg
        ))
        .small(),
    );
    egui::CollapsingHeader::new("matrices").show(ui, |ui| {
        for (title, m) in [
            ("initial", &view.file.hand_eye_initial),
            ("calibrated", &view.file.hand_eye),
        ] {
            ui.label(title);
            for r in rows_from_isometry(m) {
                ui.monospace(format!(
                    "{:>10.5} {:>10.5} {:>10.5} {:>10.3}",
                    r[0], r[1], r[2], r[3]
                ));
            }
        }
    });
}

/// A pose-only result: no joint table; what was calibrated and how well.
fn hand_eye_only_ui(ui: &mut egui::Ui, lines: &[String]) {
    ui.label(RichText::new("Hand-eye only: no kinematic model").strong());
    for (k, line) in lines.iter().enumerate() {
        let text = RichText::new(line);
        ui.label(if line.starts_with("weakly") {
            text.color(WARN)
        } else if k == 0 {
            text
        } else {
            text.color(MUTED)
        });
    }
}

fn joint_errors_ui(ui: &mut egui::Ui, view: &ResultView) {
    ui.label(RichText::new("Joint errors, calibrated − nominal (cf. paper Table 1)").strong());
    const HEADER: [&str; PARAMS_PER_JOINT + 1] = [
        "joint",
        "Δα (deg)",
        "Δa (mm)",
        "Δβ (deg)",
        "Δθ (deg)",
        "Δd (mm)",
    ];
    table(ui, "joint_errors", &HEADER, |ui| {
        for (j, e) in view.file.joint_errors.iter().enumerate() {
            ui.label(format!("{}", j + 1));
            for (p, name) in PARAM_NAMES.iter().enumerate() {
                let label = format!("{name}{}", j + 1);
                let text = match view.shown.sigma.get(&label) {
                    Some(s) => format!("{:+.4} ± {:.4}", e.get(p), s.std),
                    None => format!("{:+.4}", e.get(p)),
                };
                marked_cell(ui, view, &label, text);
            }
            ui.end_row();
        }
    });
    if !view.shown.marked.is_empty() {
        ui.label(
            RichText::new(format!(
                "± 1σ a posteriori: ml's covariance × variance factor {:.3}. † not identifiable from this data ({} parameter(s)): they lie in a direction the SVD dropped (or the method held them fixed), so the value is not a measurement of the robot. Hover a value for the direction.",
                view.shown.variance_factor,
                view.shown.marked.len()
            ))
            .small()
            .color(MUTED),
        );
    }
}

/// `ml`'s diagnostics as tables: outliers, leave-one-station-out and the
/// strong correlations (each collapsible, open when it has something to
/// say).
fn ml_tables_ui(
    ui: &mut egui::Ui,
    view: &ResultView,
    tolerance: &crate::engine::tools::result_view::Tolerance,
) {
    let Some(ml) = view.file.solver.ml() else {
        return;
    };
    ui.add_space(6.0);
    if let Some(r) = &ml.range_error {
        ui.label(r.summary()).on_hover_text(format!(
            "1σ of points of the laser plane on a {} × {} grid at {} working poses, from ml's covariance, after the best rigid alignment",
            r.grid, r.grid, r.poses
        ));
        if let Some(w) = &r.warning {
            ui.label(RichText::new(format!("warning: {w}")).color(WARN));
        }
        super::range_map::range_map_ui(ui, r, tolerance.std_mm);
    }
    egui::CollapsingHeader::new(format!(
        "Outliers ({}; limit {:.1} σ)",
        ml.outliers.len(),
        ml.outlier_limit_sigma
    ))
    .default_open(!ml.outliers.is_empty())
    .show(ui, |ui| {
        if ml.outliers.is_empty() {
            ui.label("No identify measurement's standardised residual exceeds the limit.");
            return;
        }
        let header = ["measurement", "station", "residual (mm)", "σ", "reason"];
        table(ui, "outliers", &header, |ui| {
            for o in &ml.outliers {
                let (residual, sigma) =
                    (format!("{:.4}", o.residual_mm), format!("{:.1}", o.sigma));
                row(
                    ui,
                    [&o.measurement, &o.station, &residual, &sigma, &o.reason],
                );
            }
        });
    });
    if let Some(cv) = &ml.cross_validation {
        let (rms, n) = (cv.rms, cv.stations.len());
        let title = format!("Leave-one-station-out: rms {rms:.4} mm over {n} stations");
        egui::CollapsingHeader::new(title).show(ui, |ui| {
            let text = "Each station's within-station centre distances predicted by the model fitted without it: an accuracy estimate without a tracker.";
            ui.label(RichText::new(text).color(MUTED));
            let mut rows: Vec<_> = cv.stations.iter().collect();
            rows.sort_by(|a, b| b.rms.total_cmp(&a.rms));
            table(ui, "loso", &["station", "pairs", "rms (mm)"], |ui| {
                for s in rows {
                    row(ui, [s.station.clone(), s.pairs.to_string(), format!("{:.4}", s.rms)]);
                }
            });
        });
    }
    egui::CollapsingHeader::new(format!(
        "Strong correlations ({}, |r| ≥ 0.95)",
        ml.strong_correlations.len()
    ))
    .show(ui, |ui| {
        if ml.strong_correlations.is_empty() {
            ui.label("No two estimated parameters correlate by 0.95 or more.");
        }
        for c in &ml.strong_correlations {
            ui.label(c);
        }
    });
}
