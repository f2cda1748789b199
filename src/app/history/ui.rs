//! The History view: the library of a folder of sessions and results
//! ([`crate::engine::tools::history::read_library`]) as a table, and for one robot the
//! drift of the hand-eye and of its main kinematic deviations over the
//! ticked results, with every change beyond `k` combined σ flagged
//! ([`crate::engine::tools::history::drift`]). Nothing is computed here.

use egui::RichText;
use egui_plot::{Line, LineStyle, MarkerShape, Plot, PlotPoints, Points};

use crate::app::AppState;
use crate::app::Forms;
use crate::app::command::{Command, HistoryCommand};
use crate::app::dialog::Purpose;
use crate::app::job::Slot;
use crate::app::widgets::plots::{DATE_LABEL_GAP, labelled_x, readable_y};
use crate::app::widgets::{
    AFTER, BAD, MUTED, WARN, coloured, command_button, labelled_drag, labelled_field, table, weak,
};
use crate::engine::tools::history::{self, Drift, Entry, Library, Mount, Series, Verdict};

/// Height of one drift plot, points.
const DRIFT_PLOT_HEIGHT: f32 = 170.0;
/// Room left of the first and right of the last result on a drift plot's
/// x axis, in results.
const DATE_ROOM: f64 = 0.6;
/// Drift plots per row.
const PLOTS_PER_ROW: usize = 3;
/// Most rows of the library table before it scrolls.
const TABLE_HEIGHT: f32 = 220.0;

/// The whole History view.
pub fn history_ui(
    ui: &mut egui::Ui,
    state: &AppState,
    forms: &mut Forms,
    commands: &mut Vec<Command>,
) {
    egui::ScrollArea::vertical()
        .id_salt("history_scroll")
        .auto_shrink([false, false])
        .show(ui, |ui| {
            ui.heading("History: past calibrations of a cell");
            ui.horizontal(|ui| {
                let field = labelled_field(
                    ui,
                    "Library folder",
                    &mut forms.history.folder,
                    "/path/to/folder with sessions and results",
                    420.0,
                );
                let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                let busy = state.jobs.runs(&Slot::Library);
                let hover = "choose the folder with the desktop's dialog";
                let (idle, browse) = (!state.jobs.runs(&Slot::Dialog), Purpose::HistoryFolder);
                command_button(ui, idle, "Browse…", hover, Command::Browse(browse), commands);
                let scan = Command::History(HistoryCommand::Scan);
                let hover = "read every session and result file in the folder and its subfolders";
                let clicked = command_button(ui, !busy, "Scan", hover, scan.clone(), commands);
                if entered && !busy && !clicked.clicked() {
                    commands.push(scan);
                }
                if busy {
                    ui.spinner();
                }
            });
            crate::app::widgets::dialog_note_ui(ui, state, &[Purpose::HistoryFolder]);
            match &state.history.library {
                None => {
                    weak(ui, "Choose a folder of session and result files (e.g. sessions/history) and press Scan.");
                }
                Some(Err(e)) => {
                    coloured(ui, BAD, format!("Could not scan: {e}"));
                }
                Some(Ok(library)) => {
                    library_ui(ui, library, forms);
                    ui.separator();
                    if let Some(job) = state.jobs.get(&Slot::Drift) {
                        ui.horizontal(|ui| crate::app::widgets::job_ui(ui, job));
                    }
                    if let (Some(drift), Some(of)) =
                        (&state.history.drift, &state.history.drift_of)
                    {
                        match drift {
                            Ok(d) => drift_ui(ui, d, of),
                            Err(e) => drop(coloured(ui, WARN, e)),
                        }
                    }
                }
            }
        });
}

fn library_ui(ui: &mut egui::Ui, library: &Library, forms: &mut Forms) {
    let waiting = library.sessions_without_result().count();
    ui.label(format!(
        "{} results, {} sessions ({} not calibrated yet), {} other JSON files ignored",
        library.entries.len(),
        library.sessions.len(),
        waiting,
        library.ignored.len()
    ));
    if !library.problems.is_empty() {
        let title = format!("{} file(s) could not be used", library.problems.len());
        egui::CollapsingHeader::new(RichText::new(title).color(WARN))
            .id_salt("history_problems")
            .show(ui, |ui| {
                for p in &library.problems {
                    ui.label(p.to_string());
                }
            });
    }
    let robots = library.robots();
    // A choice made here makes the drift on show stale: the ledger has
    // it made again.
    ui.horizontal(|ui| {
        let l = ui.label("Robot");
        let text = forms.history.robot.clone().unwrap_or_default();
        egui::ComboBox::from_id_salt("history_robot")
            .selected_text(text)
            .show_ui(ui, |ui| {
                for (name, n) in &robots {
                    ui.selectable_value(
                        &mut forms.history.robot,
                        Some(name.clone()),
                        format!("{name} ({n} results)"),
                    );
                }
            })
            .response
            .labelled_by(l.id);
        let k = egui::DragValue::new(&mut forms.history.options.k).range(0.5..=20.0);
        let k = k.speed(0.05).max_decimals(2).suffix(" σ combined");
        labelled_drag(ui, "Jump beyond", k).on_hover_text(
            "flag a change between consecutive results larger than k·sqrt(σ₁² + σ₂²)",
        );
    });
    table_ui(ui, library, forms);
}

/// The library table; the ticks choose the results of the drift.
fn table_ui(ui: &mut egui::Ui, library: &Library, forms: &mut Forms) {
    // Solid scroll bars take their own space: a floating one would cover
    // the last row's tick box.
    ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
    let mounts = library.entries.iter().map(|e| e.mount);
    let sensor = format!("{} x y z (mm)", history::sensor_name(mounts));
    let headers = [
        "result file",
        "date",
        "robot",
        "session",
        "method",
        "validation std after",
        "ε after",
        sensor.as_str(),
        "roll pitch yaw (deg)",
    ];
    egui::ScrollArea::both()
        .id_salt("history_table")
        .max_height(TABLE_HEIGHT)
        .show(ui, |ui| {
            // The table's spacing: a gap between columns, rows close.
            ui.spacing_mut().item_spacing = egui::vec2(12.0, 4.0);
            table(ui, "history_entries", &headers, |ui| {
                for e in &library.entries {
                    entry_row(ui, e, forms);
                }
            });
        });
}

fn entry_row(ui: &mut egui::Ui, e: &Entry, forms: &mut Forms) {
    let of_robot = forms.history.robot.as_deref() == Some(e.robot.as_str());
    let name = e.path.file_name().unwrap_or(e.path.as_os_str());
    let mut ticked = !forms.history.unselected.contains(&e.path);
    let tick = egui::Checkbox::new(&mut ticked, name.to_string_lossy());
    let changed = ui
        .add_enabled(of_robot, tick)
        .on_hover_text(e.path.display().to_string())
        .on_disabled_hover_text("another robot: choose it above to plot its drift")
        .changed();
    if changed && ticked {
        forms.history.unselected.remove(&e.path);
    } else if changed {
        forms.history.unselected.insert(e.path.clone());
    }
    let mut cell = |t: String| {
        let t = RichText::new(t);
        ui.label(if of_robot { t } else { t.color(MUTED) })
    };
    let source = e.date_source.as_str();
    let shown = if e.date_source.is_from_name() {
        String::new()
    } else {
        format!(" ({source})")
    };
    cell(format!("{}{shown}", e.date)).on_hover_text(format!("date from the {source}"));
    let validation = e.validation_std_after();
    let validation = validation.map_or_else(|| "no validation".into(), |s| format!("{s:.3} mm"));
    for text in [
        e.robot.clone(),
        e.session.clone(),
        e.method.clone(),
        validation,
    ] {
        cell(text);
    }
    cell(format!("{:.4} mm", e.epsilon_after));
    let ([x, y, z], [r, p, w]) = (e.hand_eye.translation, e.hand_eye.rpy_deg);
    let which = match e.mount {
        Mount::Flange => "hand-eye eT_s",
        Mount::Fixed => "base_from_sensor bT_s (a fixed sensor)",
    };
    cell(format!("{x:.3} {y:.3} {z:.3}")).on_hover_text(which);
    cell(format!("{r:.4} {p:.4} {w:.4}"));
    ui.end_row();
}

/// The date of the library's result `i` (empty when there is none).
fn date(library: &Library, i: usize) -> String {
    let entry = library.entries.get(i);
    entry.map_or_else(String::new, |e| e.date.to_string())
}

fn drift_ui(ui: &mut egui::Ui, drift: &Drift, library: &Library) {
    let jumps: Vec<_> = drift.jumps().collect();
    ui.horizontal(|ui| {
        ui.heading(format!("Drift of {}", drift.robot));
        ui.label(format!(
            "{} results · jump = change beyond {} combined σ",
            drift.entries.len(),
            drift.k
        ));
    });
    if jumps.is_empty() {
        let text = "No jump: every checked change is within its combined uncertainty.";
        coloured(ui, AFTER, text);
    } else {
        ui.label(
            RichText::new(format!("{} jump(s) flagged", jumps.len()))
                .color(BAD)
                .strong()
                .size(16.0),
        );
        let headers = [
            "parameter",
            "between",
            "change",
            "combined σ",
            "ratio",
            "notes",
        ];
        table(ui, "history_jumps", &headers, |ui| {
            for j in &jumps {
                let unit = j.unit.as_str();
                coloured(ui, BAD, &j.parameter);
                let (from, to) = (date(library, j.from), date(library, j.to));
                ui.label(format!("{from} → {to}"));
                ui.label(format!("{:+.4} {unit}", j.change));
                ui.label(j.combined.map_or("–".into(), |c| format!("{c:.4} {unit}")));
                ui.label(j.ratio.map_or("–".into(), |r| format!("{r:.1}")));
                let notes = j.notes.join("; ");
                ui.add(egui::Label::new(&notes).truncate())
                    .on_hover_text(notes);
                ui.end_row();
            }
        });
    }
    let unchecked: Vec<_> = drift
        .checks
        .iter()
        .filter_map(|c| match &c.verdict {
            Verdict::NotChecked(why) => Some((c, why)),
            _ => None,
        })
        .collect();
    if !unchecked.is_empty() {
        let title = format!("{} change(s) could not be checked", unchecked.len());
        let header = egui::CollapsingHeader::new(title).id_salt("history_unchecked");
        header.show(ui, |ui| {
            for (c, why) in unchecked {
                ui.label(format!("{}: {why}", c.parameter));
            }
        });
    }
    for note in &drift.notes {
        coloured(ui, WARN, note);
    }
    let dates: Vec<String> = drift.entries.iter().map(|&i| date(library, i)).collect();
    ui.label(
        RichText::new("Each plot: the value per result in date order, bars ±1σ; a red segment is a flagged jump. Kinematic values are calibrated − the earliest result's nominal.")
            .small()
            .weak(),
    );
    for row in drift.series.chunks(PLOTS_PER_ROW) {
        ui.columns(PLOTS_PER_ROW, |cols| {
            for (col, series) in cols.iter_mut().zip(row) {
                series_plot_ui(col, series, drift, &dates);
            }
        });
    }
}

fn series_plot_ui(ui: &mut egui::Ui, series: &Series, drift: &Drift, dates: &[String]) {
    let (name, unit, kind) = (
        &series.name,
        series.unit.as_str(),
        series.kind.label(drift.mount),
    );
    ui.label(RichText::new(format!("{name} ({unit}) · {kind}")).strong());
    // x = position in date order; the tick labels are the dates.
    let position = |entry: usize| drift.entries.iter().position(|&e| e == entry);
    let points: Vec<[f64; 2]> = series
        .points
        .iter()
        .filter_map(|p| position(p.entry).map(|x| [x as f64, p.value]))
        .collect();
    // The ±1σ bars (muted) and the jumps (red): a segment each.
    let segment = |name: &str, ends: [[f64; 2]; 2], colour, width| {
        let line = Line::new(name, PlotPoints::from(ends.to_vec()));
        line.color(colour).width(width)
    };
    let jumps = drift.jumps().filter(|j| j.parameter == series.name);
    let jumps: Vec<[[f64; 2]; 2]> = jumps
        .filter_map(|j| {
            let (from, to) = (position(j.from)? as f64, position(j.to)? as f64);
            Some([[from, j.before], [to, j.after]])
        })
        .collect();
    // Half a result of room each side: the first and last dates, centred
    // on their ticks, stay inside the plot.
    let last = dates.len().saturating_sub(1) as f64;
    let plot = Plot::new(("drift", name.as_str()))
        .height(DRIFT_PLOT_HEIGHT)
        .include_x(-DATE_ROOM)
        .include_x(last + DATE_ROOM)
        .allow_scroll(false);
    labelled_x(readable_y(plot), dates.to_vec(), DATE_LABEL_GAP)
        .y_axis_label(unit)
        .show(ui, |p| {
            for pt in &series.points {
                if let (Some(x), Some(s)) = (position(pt.entry), pt.sigma) {
                    let (x, y) = (x as f64, pt.value);
                    p.line(segment("", [[x, y - s], [x, y + s]], MUTED, 1.5));
                }
            }
            let line = Line::new(name.as_str(), PlotPoints::from(points.clone()));
            p.line(
                line.color(AFTER)
                    .style(LineStyle::dotted_loose())
                    .width(1.0),
            );
            let points = Points::new(name.as_str(), PlotPoints::from(points));
            p.points(points.color(AFTER).shape(MarkerShape::Circle).radius(3.5));
            for ends in jumps {
                p.line(segment("jump", ends, BAD, 2.5));
            }
        });
}
